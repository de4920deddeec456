// Broad phase (cell grid + Verlet skin): the kernel's contact set must be
// exactly the O(N²) brute-force one at every step, across many neighbour-list
// rebuilds, for particles and walls alike. The comparison is exact: both
// sides decide contact by the same floating-point test d² < (r_i + r_j)².
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <utility>
#include <vector>

#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kEps;

std::vector<std::pair<int, int>> brute_force_pairs(const World& w) {
  std::vector<std::pair<int, int>> out;
  const int n = w.size();
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double dx = w.x()[j] - w.x()[i], dy = w.y()[j] - w.y()[i];
      const double rs = w.radius()[i] + w.radius()[j];
      if (dx * dx + dy * dy < rs * rs) out.emplace_back(i, j);
    }
  return out;
}

// Overlaps of every particle with one wall, from the geometry.
std::vector<double> wall_overlaps(const World& w, WallSide s) {
  std::vector<double> out;
  for (int i = 0; i < w.size(); ++i) {
    const double r = w.radius()[i];
    double dist = 0.0;
    switch (s) {
      case kLeft:
        dist = w.x()[i] - w.wall(kLeft).position;
        break;
      case kRight:
        dist = w.wall(kRight).position - w.x()[i];
        break;
      case kBottom:
        dist = w.y()[i] - w.wall(kBottom).position;
        break;
      case kTop:
        dist = w.wall(kTop).position - w.y()[i];
        break;
    }
    if (r - dist > 0.0) out.push_back(r - dist);
  }
  return out;
}

struct Check {
  int64_t particle_contacts_seen = 0, wall_contacts_seen = 0;
  int64_t contacts_made = 0;  // pairs in contact that were not on the previous step
  std::vector<std::pair<int, int>> previous;
};

void expect_contacts_match_brute_force(const World& w, Check& check, int step) {
  const auto expected = brute_force_pairs(w);
  const auto got = w.contacts();
  ASSERT_EQ(got.size(), expected.size()) << "step " << step;
  const double kn = w.material().particle.kn;
  for (size_t k = 0; k < got.size(); ++k) {
    ASSERT_EQ(got[k].i, expected[k].first) << "step " << step;
    ASSERT_EQ(got[k].j, expected[k].second) << "step " << step;
    // fn = kn·δ up to the round-off of δ = (r_i + r_j) − d.
    const double rs = w.radius()[got[k].i] + w.radius()[got[k].j];
    EXPECT_NEAR(got[k].fn, kn * got[k].overlap, kn * 8.0 * kEps * rs);
  }
  check.particle_contacts_seen += static_cast<int64_t>(got.size());
  std::vector<std::pair<int, int>> made;
  std::set_difference(expected.begin(), expected.end(), check.previous.begin(),
                      check.previous.end(), std::back_inserter(made));
  check.contacts_made += static_cast<int64_t>(made.size());
  check.previous = expected;
  // Walls: the number of touching particles, and the normal force they put
  // on the wall, Σ kn_w·δ (friction acts along the wall only).
  const double kw = w.material().wall.kn;
  for (int s = 0; s < 4; ++s) {
    const auto side = static_cast<WallSide>(s);
    const auto ov = wall_overlaps(w, side);
    ASSERT_EQ(w.wall(side).contacts, static_cast<int>(ov.size()))
        << "wall " << s << " step " << step;
    double sum = 0.0, scale = 0.0;
    for (double o : ov) {
      sum += kw * o;
      scale += kw * 8.0 * kEps * 4.0 * w.radius()[0];  // round-off of each δ
    }
    const double normal =
        (s == kLeft || s == kRight) ? w.wall(side).force.x() : w.wall(side).force.y();
    const double sign = (s == kLeft || s == kBottom) ? -1.0 : 1.0;  // pushed outward
    EXPECT_NEAR(normal, sign * sum, scale + 1e-12 * sum) << "wall " << s << " step " << step;
    check.wall_contacts_seen += static_cast<int64_t>(ov.size());
  }
}

// Polydisperse disks (radii 1:3), jammed, then shaken with random velocities
// while the walls first back off and then close in again: contacts open and
// close all the time. Undamped, frictional particles and walls.
TEST(KernelNeighbours, ContactSetEqualsBruteForceAcrossRebuildsInShakenPacking) {
  auto scene = kernel_test::random_loose_scene(15, 15, 17, 0.5);
  World w = scene.make(kernel_test::reference_material(0.3, 0.2));
  kernel_test::compact(w, 0.84, 0.3, 0);
  Integration in = w.integration();
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);
  const double rmin = *std::min_element(w.radius().begin(), w.radius().end());
  // Each particle moves ~1e-3·r_min per step: a rebuild every ~100 steps
  // from the shaking alone (skin 0.3·r_min), more with the walls.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double v = 1e-3 * rmin / in.dt;
  for (int i = 0; i < w.size(); ++i) w.set_velocity(i, v * u(rng), v * u(rng), v / rmin * u(rng));
  // Walls back off, then close in, at 1e-3·r_min per step (2 r_min each way).
  const double vw = 1e-3 * rmin / in.dt;
  Check check;
  check.previous = brute_force_pairs(w);
  const int64_t rebuilds0 = w.rebuilds();
  for (int s = 0; s < 4000; ++s) {
    const double sign = s < 2000 ? -1.0 : 1.0;
    w.wall(kLeft).velocity = sign * vw;
    w.wall(kRight).velocity = -sign * vw;
    w.wall(kBottom).velocity = sign * vw;
    w.wall(kTop).velocity = -sign * vw;
    ASSERT_TRUE(w.step(1));
    expect_contacts_match_brute_force(w, check, s);
    if (HasFatalFailure()) return;
  }
  EXPECT_GE(w.rebuilds() - rebuilds0, 30);
  EXPECT_GT(check.particle_contacts_seen, 100000);
  EXPECT_GT(check.contacts_made, 1000);
  EXPECT_GT(check.wall_contacts_seen, 10000);
}

// A sparse gas in a large box: the grid is coarsened (never more than a few
// cells per particle), and fast particles cross many cells between rebuilds.
// Velocities v·(ax·u, ay·u), u uniform in [−1, 1]: `ax`, `ay` 1 for a gas
// moving every way, one of them 0 for a gas moving along one axis (until
// its collisions turn it), where the skin's displacement scan must see the
// motion along that axis alone.
void expect_sparse_gas_matches_brute_force(double ax, double ay, int min_rebuilds,
                                           int min_contacts_made) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> pos(2.0, 98.0), rad(0.5, 1.5), u(-1.0, 1.0);
  kernel_test::Scene scene;
  const double r0 = kernel_test::kR;
  while (scene.x.size() < 40) {
    const double x = pos(rng) * r0, y = pos(rng) * r0, r = rad(rng) * r0;
    bool free = true;
    for (size_t k = 0; k < scene.x.size(); ++k)
      free = free && std::hypot(x - scene.x[k], y - scene.y[k]) > r + scene.r[k];
    if (free) {
      scene.x.push_back(x);
      scene.y.push_back(y);
      scene.r.push_back(r);
    }
  }
  scene.left = 0.0;
  scene.right = 100.0 * r0;
  scene.bottom = 0.0;
  scene.top = 100.0 * r0;
  World w = scene.make(kernel_test::reference_material(0.3, 0.0));
  Integration in;
  in.dt = 0.2 * w.reference_scales().dt_crit;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);
  // 2e-2·r per step: a particle crosses the box in ~5000 steps.
  const double v = 2e-2 * r0 / in.dt;
  for (int i = 0; i < w.size(); ++i) {
    const double ux = u(rng), uy = u(rng);  // drawn in this order whatever ax, ay
    w.set_velocity(i, ax * v * ux, ay * v * uy, 0.0);
  }
  Check check;
  check.previous = brute_force_pairs(w);
  const int64_t rebuilds0 = w.rebuilds();
  for (int s = 0; s < 20000; ++s) {
    ASSERT_TRUE(w.step(1));
    expect_contacts_match_brute_force(w, check, s);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GE(w.rebuilds() - rebuilds0, min_rebuilds);
  EXPECT_GT(check.particle_contacts_seen, 50);
  EXPECT_GT(check.contacts_made, min_contacts_made);
  EXPECT_GT(check.wall_contacts_seen, 50);
}

TEST(KernelNeighbours, ContactSetEqualsBruteForceInSparseGas) {
  expect_sparse_gas_matches_brute_force(1.0, 1.0, 500, 20);
}

TEST(KernelNeighbours, ContactSetEqualsBruteForceInAGasMovingAlongOneAxis) {
  for (const int axis : {0, 1}) {
    SCOPED_TRACE(axis == 0 ? "along x" : "along y");
    expect_sparse_gas_matches_brute_force(axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, 500, 5);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace demcal
