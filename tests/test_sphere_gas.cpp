// Energy of a small random cluster of spheres colliding in a box, undamped
// (the contacts open and close, unlike the vibrating packings of
// test_sphere_kernel.cpp).
//
// Bound: while a single contact acts, its normal relative motion is the
// linear oscillator of the head-on test, and the scheme conserves
// J = v(n+½)² + ω²·δ(n)·δ(n+1) exactly (test_kernel_contact.cpp), so the
// outgoing normal speed obeys |e² − 1| ≤ ω²·2·(v·Δt)²/4/v² = h²/2 with
// h = ω·Δt, ω = sqrt(kn/m_eff) (m_eff = m for a wall). The kinetic energy
// of a collision's normal motion, E_c = ½·m_eff·v_n², thus changes by at
// most (h²/2)·E_c, and between contacts the kinetic energy is exact. So at
// contact-free instants |E − E0| ≤ Σ_c (h_c²/2)·E_c, the sum over the
// collisions so far (approach speed taken at the step the contact
// appears). Friction can only take energy away: with μ > 0 only the upper
// side of the bound holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

using Eigen::Vector3d;
using sphere_test::kR;

struct GasRun {
  double e0 = 0.0, e_end = 0.0, bound = 0.0;
  double ledger = 0.0;  // the kernel's energy-ledger reading at the end
  int collisions = 0;
};

GasRun run_gas(double mu, uint32_t seed) {
  sphere_test::Scene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), rad(0.8 * kR, 1.2 * kR);
  const int side = 3;
  const double spacing = 3.0 * kR;
  for (int k = 0; k < side; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i)
        s.add(Vector3d(i + 0.5, j + 0.5, k + 0.5) * spacing +
                  0.2 * kR * Vector3d(u(rng), u(rng), u(rng)),
              rad(rng));
  s.lo = {0.0, 0.0, 0.0};
  s.hi = {side * spacing, side * spacing, side * spacing};
  SphereWorld w = s.make(sphere_test::test_material(mu, mu));
  const Integration in = sphere_test::set_undamped(w, 0.05);
  // ~13 radii of travel over the run; overlaps at impact v/ω ≈ 1 % of r.
  const double v0 = 20.0;
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(
        i, v0 * Vector3d(u(rng), u(rng), u(rng)),
        mu > 0.0 ? Vector3d(v0 / kR * Vector3d(u(rng), u(rng), u(rng))) : Vector3d::Zero());
  const double kn = 1e8;
  auto kinetic = [&] {
    const SphereMeasures m = w.measure();
    return m.kinetic_energy_translation + m.kinetic_energy_rotation;
  };
  GasRun out;
  out.e0 = kinetic();
  // Active contacts: pairs (i, j) and walls (i, −1 − side).
  std::map<std::pair<int, int>, bool> active;
  for (int step = 0; step < 40000; ++step) {
    EXPECT_TRUE(w.step(1));
    std::map<std::pair<int, int>, bool> now;
    for (const auto& c : w.contacts()) {
      const auto key = std::make_pair(c.i, c.j);
      now[key] = true;
      if (active.count(key)) continue;
      const double mi = w.mass()[c.i], mj = w.mass()[c.j], meff = mi * mj / (mi + mj);
      const double vn =
          (sphere_test::velocity(w, c.i) - sphere_test::velocity(w, c.j)).dot(c.normal);
      const double h = std::sqrt(kn / meff) * in.dt;
      out.bound += 0.5 * h * h * 0.5 * meff * vn * vn;
      ++out.collisions;
    }
    for (int i = 0; i < w.size(); ++i)
      for (int side_index = 0; side_index < 6; ++side_index) {
        const int axis = side_index / 2;
        const double p = sphere_test::position(w, i)[axis];
        const double wall = w.wall(static_cast<SphereWallSide>(side_index)).position;
        if (std::abs(p - wall) >= w.radius()[i]) continue;
        const auto key = std::make_pair(i, -1 - side_index);
        now[key] = true;
        if (active.count(key)) continue;
        const double m = w.mass()[i], vn = sphere_test::velocity(w, i)[axis];
        const double h = std::sqrt(kn / m) * in.dt;
        out.bound += 0.5 * h * h * 0.5 * m * vn * vn;
        ++out.collisions;
      }
    active.swap(now);
  }
  // End at a contact-free instant.
  for (int extra = 0; extra < 20000 && !active.empty(); ++extra) {
    EXPECT_TRUE(w.step(1));
    const SphereMeasures m = w.measure();
    if (m.particle_contacts + m.wall_contacts == 0) active.clear();
  }
  EXPECT_TRUE(active.empty());
  out.e_end = kinetic();
  out.ledger = w.energy_created();
  std::printf("gas mu %.1f: %d collisions, (E_end - E0)/E0 = %.2e, bound/E0 = %.2e, ledger %.2e\n",
              mu, out.collisions, (out.e_end - out.e0) / out.e0, out.bound / out.e0, out.ledger);
  return out;
}

TEST(SphereGas, FrictionlessCollisionsKeepTheEnergyWithinTheSchemeBound) {
  const GasRun r = run_gas(0.0, 21);
  EXPECT_GT(r.collisions, 50);
  EXPECT_LE(std::abs(r.e_end - r.e0), r.bound);
  EXPECT_LT(r.bound, 0.1 * r.e0);  // the bound says something
}

TEST(SphereGas, FrictionOnlyTakesEnergyAway) {
  const GasRun r = run_gas(0.5, 22);
  EXPECT_GT(r.collisions, 50);
  EXPECT_LE(r.e_end - r.e0, r.bound);
  EXPECT_LT(r.e_end, r.e0);  // sliding contacts dissipated something
  // The ledger books friction's loss (the Coulomb work of sliding and the
  // spring energy left at opening): it accounts for the energy lost — most
  // of it — up to the scheme's error per collision, the normal bound above
  // (the tangential spring is integrated by the same scheme, with an error
  // of the same order). Unbooked, the reading would be (E_end − E0)/E0.
  EXPECT_LT(r.e_end - r.e0, -0.5 * r.e0);
  EXPECT_LE(std::abs(r.ledger), r.bound / r.e0);
}

// Friction's share of the energy ledger: a contact that opens gives up the
// |h|²/(2·kt) its tangential spring held at its last touching step, and one
// that slides the Coulomb work μ·fn·(|h_trial| − μ·fn)/kt
// (sphere_contact.cpp, file comment). A dense, hot cluster, where contacts
// open beside others that stay shut in the same SIMD vector of slots,
// undamped, the walls fixed and frictionless, μ = 1000 so that contacts
// slide only as fn vanishes just before they open: the loss the kernel
// booked, read back from its ledger (reading r = (E − E0 + lost)/(E0 +
// lost), walls doing no work), must hold the springs' energy at every
// opening seen in contacts() step by step, plus the slides' work, which is
// at most μ·fn·(|h_prev| + kt·Δt·|v_rel| − μ·fn)/kt a slide (the turn keeps
// |h_prev|; v_t is a part of v_rel) and small here.
TEST(SphereGas, OpeningContactsBookTheirTangentialSpringsEnergy) {
  sphere_test::Scene s;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), rad(0.99 * kR, 1.01 * kR);
  const int side = 4;
  // On a cubic lattice of spacing 2r, in a box that fits it: about half the
  // neighbours overlap (by up to 0.02·r), the rest have gaps as small.
  const double spacing = 2.0 * kR;
  for (int k = 0; k < side; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) s.add(Vector3d(i + 0.5, j + 0.5, k + 0.5) * spacing, rad(rng));
  s.lo = {0.0, 0.0, 0.0};
  s.hi = {side * spacing, side * spacing, side * spacing};
  KernelOptions options;
  options.check_interval = 1;
  options.energy_check_interval = 1;  // a reading after every step
  options.max_energy_created = 1.0;
  const double mu = 1000.0;
  SphereWorld w = s.make(sphere_test::test_material(mu, 0.0), options);
  const Integration in = sphere_test::set_undamped(w, 0.05);
  const double v0 = 0.5, kt = w.material().particle.kt;
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(i, v0 * Vector3d(u(rng), u(rng), u(rng)),
                   v0 / kR * Vector3d(u(rng), u(rng), u(rng)));
  auto energy = [&] {
    const SphereMeasures m = w.measure();
    return m.kinetic_energy_translation + m.kinetic_energy_rotation + m.elastic_energy;
  };
  ASSERT_TRUE(w.step(1));  // the ledger starts at this step's reading
  const double e0 = energy();
  std::map<std::pair<int, int>, double> before;  // touching pair → |h|
  for (const auto& c : w.contacts()) before[{c.i, c.j}] = c.tangential.norm();
  double released = 0.0, slip_bound = 0.0;
  int openings = 0, slides = 0, most_touching = 0;
  for (int step = 0; step < 20000; ++step) {
    ASSERT_TRUE(w.step(1));
    std::map<std::pair<int, int>, double> now;
    for (const auto& c : w.contacts()) {
      const double h = c.tangential.norm(), cap = mu * c.fn;
      now[{c.i, c.j}] = h;
      if (h < (1.0 - 1e-9) * cap) continue;
      // Slid this step (the cut leaves |h| = μ·fn): bound its work.
      const auto prev = before.find({c.i, c.j});
      const double ai = w.radius()[c.i] - 0.5 * c.overlap, aj = w.radius()[c.j] - 0.5 * c.overlap;
      const Vector3d v_rel =
          sphere_test::velocity(w, c.j) - sphere_test::velocity(w, c.i) -
          (ai * sphere_test::spin(w, c.i) + aj * sphere_test::spin(w, c.j)).cross(c.normal);
      const double h_prev = prev == before.end() ? 0.0 : prev->second;
      slip_bound += cap * (h_prev + kt * in.dt * v_rel.norm() - cap) / kt;
      ++slides;
    }
    for (const auto& [pair, h] : before)
      if (!now.count(pair)) {
        released += h * h / (2.0 * kt);
        ++openings;
      }
    most_touching = std::max(most_touching, static_cast<int>(now.size()));
    before.swap(now);
  }
  const double r = w.energy_created(), e = energy();
  const double lost = (e0 + r * e0 - e) / (1.0 - r);
  std::printf(
      "openings %d, slides %d, most touching at once %d; E0 %.6e J, released %.6e J, slides' work "
      "at most %.6e J, booked %.6e J\n",
      openings, slides, most_touching, e0, released, slip_bound, lost);
  EXPECT_GT(openings, 1000);
  EXPECT_GT(most_touching, 60);
  EXPECT_GT(released, 0.1 * e0);           // the openings matter
  EXPECT_LT(slip_bound, 0.01 * released);  // and the slides little
  const double tol = 1e-12 * e0;           // round-off
  EXPECT_GE(lost, released - tol);
  EXPECT_LE(lost, released + slip_bound + tol);
}

}  // namespace
}  // namespace demcal
