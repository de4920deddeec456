// Threads (KernelOptions::threads): the kernel must give bit-identical
// results for any thread count. Every particle's force is summed by one
// thread, over its own neighbours in a fixed order, so the partition of the
// blocks among threads cannot change a single bit. Checked on a dense
// frictional packing over many steps, through neighbour-list rebuilds,
// against one thread: positions, velocities, spins, forces, torques, every
// contact force, wall forces and the stress measures.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "support/same_bits.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using test::same_bits;

void expect_identical(const World& a, const World& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.steps_taken(), b.steps_taken());
  EXPECT_EQ(a.rebuilds(), b.rebuilds());
  int mismatches = 0;
  for (int i = 0; i < a.size(); ++i) {
    const bool same = same_bits(a.x()[i], b.x()[i]) && same_bits(a.y()[i], b.y()[i]) &&
                      same_bits(a.vx()[i], b.vx()[i]) && same_bits(a.vy()[i], b.vy()[i]) &&
                      same_bits(a.omega()[i], b.omega()[i]) &&
                      same_bits(a.rotation()[i], b.rotation()[i]) &&
                      same_bits(a.fx()[i], b.fx()[i]) && same_bits(a.fy()[i], b.fy()[i]) &&
                      same_bits(a.torque()[i], b.torque()[i]);
    if (!same && ++mismatches <= 5) ADD_FAILURE() << "particle " << i << " differs";
  }
  EXPECT_EQ(mismatches, 0);
  test::expect_same_contacts(a.contacts(), b.contacts(), [](const auto& ca, const auto& cb) {
    return same_bits(ca.fn, cb.fn) && same_bits(ca.ft, cb.ft);
  });
  test::expect_same_walls<WallSide, 4>(a, b);
  const Measures ma = a.measure(), mb = b.measure();
  test::expect_same_stresses(ma, mb);
  EXPECT_TRUE(same_bits(ma.kinetic_energy_translation, mb.kinetic_energy_translation));
  EXPECT_TRUE(same_bits(ma.elastic_energy, mb.elastic_energy));
}

// 30 × 30 polydisperse disks jammed with friction on the walls too (once,
// on one thread).
const World& jammed(double contact_damping) {
  auto make = [](double damping) {
    Material mat = kernel_test::reference_material(0.3, 0.2);
    mat.contact_damping_ratio = damping;
    auto scene = kernel_test::random_loose_scene(30, 30, 7);
    World w = scene.make(mat);
    kernel_test::compact(w, 0.84, 0.3, 500);
    return w;
  };
  static const World plain = make(0.0), damped = make(0.2);
  return contact_damping > 0.0 ? damped : plain;
}

// Shear the jammed packing (top wall down, side walls out) with light
// damping on `threads` threads: contacts open, close and slide, and the
// neighbour list is rebuilt many times.
World sheared(const World& start, int threads, int64_t steps) {
  World w = start;
  w.set_threads(threads);
  Integration in = w.integration();
  in.damping_ratio_translation = 0.1;
  in.damping_ratio_rotation = 0.1;
  w.set_integration(in);
  const double v = 5e-4 * kernel_test::kR / in.dt;
  w.wall(kTop).velocity = -v;
  w.wall(kLeft).velocity = -0.3 * v;
  w.wall(kRight).velocity = 0.3 * v;
  EXPECT_TRUE(w.step(steps)) << to_string(w.divergence());
  return w;
}

TEST(KernelThreads, TwoAndThreeThreadsGiveBitIdenticalResultsToOne) {
  const World& start = jammed(0.0);
  const World one = sheared(start, 1, 4000);
  ASSERT_GT(one.measure().particle_contacts, 1000);
  ASSERT_GE(one.rebuilds() - start.rebuilds(), 5);  // the list was rebuilt during the run
  const World two = sheared(start, 2, 4000);
  EXPECT_EQ(two.threads(), 2);
  expect_identical(one, two);
  const World three = sheared(start, 3, 4000);
  expect_identical(one, three);
}

// With many threads most blocks border another thread's range: their pair
// terms wait for the sum pass after the barrier in places of their own, the
// rest in each thread's ring (layout_terms, broad_phase.cpp).
TEST(KernelThreads, ManyThreadsGiveBitIdenticalResultsToo) {
  const World& start = jammed(0.0);
  const World one = sheared(start, 1, 1500);
  for (int threads : {5, 8}) {
    SCOPED_TRACE(threads);
    const World many = sheared(start, threads, 1500);
    EXPECT_EQ(many.threads(), threads);
    expect_identical(one, many);
  }
}

TEST(KernelThreads, ContactDampingIsBitIdenticalToo) {
  const World& start = jammed(0.2);
  const World one = sheared(start, 1, 2000);
  const World two = sheared(start, 2, 2000);
  expect_identical(one, two);
}

TEST(KernelThreads, CopiesAndThreadChangesMidRunKeepTheTrajectory) {
  World a = sheared(jammed(0.0), 1, 500);
  World b = a;  // a copy does not share threads; give it two of its own
  b.set_threads(2);
  World c = b;  // copy of a threaded world
  ASSERT_TRUE(a.step(2000));
  ASSERT_TRUE(b.step(1000));
  b.set_threads(1);
  ASSERT_TRUE(b.step(1000));
  ASSERT_TRUE(c.step(2000));
  expect_identical(a, b);
  expect_identical(a, c);
}

// The kernel evaluates each pair once (half list) and adds the pair's force
// and torque to the second particle in a separate sum (the mirror list):
// every particle's force and torque must equal the plain sum over all its
// touching pairs, found by brute force over all N² pairs, with the law
// written out here (fn = kn·δ; the tangential force ft, the history, from
// contacts(); force on i −fn·n + ft·t, t = (−n_y, n_x), on j the opposite;
// torques (r − δ/2)·ft on both). Particles touching a wall are left out
// (the wall law is checked in test_kernel_contact.cpp). Tolerance, per
// contact: the overlap δ = (r_i + r_j) − d is a small difference of large
// numbers, and d² rounds differently with FMA (the wide paths), so fn is
// good to kn·8ε·(r_i + r_j) (as in test_kernel_neighbours.cpp); the sums
// run in another order: 1e-12 of the particle's force scale Σ|f| covers
// that. Far below any missing, doubled or misdirected contact (≥ 1e-4 of
// the scale in this jammed packing). Run per path with DEMCAL_SIMD.
TEST(KernelThreads, ForcesEqualABruteForceSumOverPairs) {
  using kernel_test::kEps;
  for (int threads : {1, 2}) {
    const World w = sheared(jammed(0.0), threads, 600);
    const int n = w.size();
    const double kn = w.material().particle.kn;
    std::vector<double> fx(n, 0.0), fy(n, 0.0), tq(n, 0.0), scale(n, 0.0), round_off(n, 0.0);
    const auto views = w.contacts();
    size_t v = 0;
    int pairs = 0, sliding_or_loaded = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const double dx = w.x()[j] - w.x()[i], dy = w.y()[j] - w.y()[i];
        const double rs = w.radius()[i] + w.radius()[j];
        const double d2 = dx * dx + dy * dy;
        if (!(d2 < rs * rs)) continue;
        ++pairs;
        while (v < views.size() && (views[v].i < i || (views[v].i == i && views[v].j < j))) ++v;
        ASSERT_LT(v, views.size());
        ASSERT_EQ(views[v].i, i);
        ASSERT_EQ(views[v].j, j);
        const double ft = views[v].ft;
        sliding_or_loaded += ft != 0.0;
        const double d = std::sqrt(d2), nx = dx / d, ny = dy / d, ov = rs - d;
        const double fn = kn * ov;
        const double px = -fn * nx - ft * ny, py = -fn * ny + ft * nx;
        fx[i] += px;
        fy[i] += py;
        fx[j] -= px;
        fy[j] -= py;
        tq[i] += (w.radius()[i] - 0.5 * ov) * ft;
        tq[j] += (w.radius()[j] - 0.5 * ov) * ft;
        const double f = std::hypot(fn, ft);
        scale[i] += f;
        scale[j] += f;
        round_off[i] += kn * 8.0 * kEps * rs;
        round_off[j] += kn * 8.0 * kEps * rs;
      }
    ASSERT_GT(pairs, 1000);
    ASSERT_GT(sliding_or_loaded, pairs / 2);  // the tangential springs carry load
    int checked = 0;
    for (int i = 0; i < n; ++i) {
      const double r = w.radius()[i];
      const bool on_wall =
          w.x()[i] - r < w.wall(kLeft).position || w.x()[i] + r > w.wall(kRight).position ||
          w.y()[i] - r < w.wall(kBottom).position || w.y()[i] + r > w.wall(kTop).position;
      if (on_wall || scale[i] == 0.0) continue;
      ++checked;
      const double tol = round_off[i] + 1e-12 * scale[i];
      EXPECT_NEAR(w.fx()[i], fx[i], tol) << "particle " << i << ", " << threads << " threads";
      EXPECT_NEAR(w.fy()[i], fy[i], tol) << "particle " << i << ", " << threads << " threads";
      EXPECT_NEAR(w.torque()[i], tq[i], tol * r)
          << "particle " << i << ", " << threads << " threads";
    }
    EXPECT_GT(checked, n / 2);
  }
}

}  // namespace
}  // namespace demcal
