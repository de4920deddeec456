// The contact dashpot (Material::contact_damping_ratio) against closed-form
// results: a head-on collision of two equal disks; a disk on each of the
// four walls (m_eff = m) and on a moving wall; two unequal disks (m_eff =
// reduced_mass(m_i, m_j)), with the scheme's bounds of the sphere kernel's
// tests (support/head_on.hpp: clamped_restitution_tolerance,
// bounce_ledger_bound; test_sphere_restitution.cpp derives them — the same
// central difference with a dashpot reading v(n−½), in 2D as in 3D).
//
// The kernel's normal force is fn = max(0, kn·δ + c·δ̇) with δ the overlap
// and c = 2ζ·sqrt(kn·m_eff) (contact_law.hpp): while fn > 0 the overlap is a
// damped oscillator of ratio ζ and angular frequency ω = sqrt(kn/m_eff),
//   δ(t) = (v/ω_d)·e^(−ζωt)·sin(ω_d·t),  ω_d = ω·sqrt(1 − ζ²).
// The dashpot never pulls, so the disks part when kn·δ + c·δ̇ = 0, before δ
// returns to 0 (a spring-dashpot that could pull would give the textbook
// e = exp(−ζπ/sqrt(1 − ζ²))): with ω_d·t* = π − atan(2ζ·sqrt(1−ζ²)/(1−2ζ²))
// (ζ < 1/√2) the restitution is
//   e = |δ̇(t*)|/v = e^(−ζωt*)·|cos(ω_d·t*) − ζ/sqrt(1−ζ²)·sin(ω_d·t*)|.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "support/head_on.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kR;
using kernel_test::reference_material;

using test::bounce_ledger_bound;
using test::bounce_ledger_lower_bound;
using test::clamped_restitution;
using test::clamped_restitution_tolerance;

struct Collision {
  double restitution = 0.0;
  double max_energy_gap = 0.0;  // |measured elastic energy − ½kn·δ²| / (½kn·δ_max²)
  double energy_created = 0.0;
};

/// No global damping, the step α·Δt_crit: set on `w` and returned.
Integration set_undamped(World& w, double alpha) {
  Integration in;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  in.dt = alpha * w.reference_scales().dt_crit;
  w.set_integration(in);
  return in;
}

Collision collide(double zeta, double alpha) {
  Material mat = reference_material(0.3);
  mat.contact_damping_ratio = zeta;
  const double r = kR, v0 = 0.05;
  const std::vector<double> x{0.0, 2.0 * r + 2e-3 * r}, y{0.0, 0.0}, rad{r, r};
  World w(mat, x, y, rad, -10 * r, 12 * r, -10 * r, 10 * r);
  set_undamped(w, alpha);
  w.set_velocity(0, v0, 0.0, 0.0);
  w.set_velocity(1, -v0, 0.0, 0.0);
  const double kn = mat.particle.kn;
  auto overlap = [&] { return 2.0 * r - std::hypot(w.x()[1] - w.x()[0], w.y()[1] - w.y()[0]); };
  Collision out;
  bool touched = false;
  double worst_gap = 0.0, max_overlap = 0.0;
  for (int s = 0; s < 100000; ++s) {
    EXPECT_TRUE(w.step(1));
    const double d = overlap();
    if (d > 0.0) {
      touched = true;
      max_overlap = std::max(max_overlap, d);
      // The springs' energy is ½kn·δ² whatever the dashpot does.
      worst_gap = std::max(worst_gap, std::abs(w.measure().elastic_energy - 0.5 * kn * d * d));
    } else if (touched && w.vx()[1] - w.vx()[0] > 0.0 && w.fx()[0] == 0.0) {
      break;
    }
  }
  out.restitution = (w.vx()[1] - w.vx()[0]) / (2.0 * v0);
  out.max_energy_gap = worst_gap / (0.5 * kn * max_overlap * max_overlap);
  out.energy_created = w.energy_created();
  return out;
}

TEST(KernelContactDamping, RestitutionOfTheDampedHeadOnCollision) {
  const double alpha = 0.005;
  // The dashpot acts with the velocity half a step old, the integrator is
  // second order: the restitution is right to first order in ω·Δt.
  const double h = 2.0 * alpha * std::sqrt(2.0);  // ω·Δt with m_eff = m/2
  for (double zeta : {0.05, 0.2, 0.5}) {
    const Collision c = collide(zeta, alpha);
    const double e = clamped_restitution(zeta);
    EXPECT_NEAR(c.restitution, e, 2.0 * h * e) << "zeta " << zeta;
    // Distinct from the law that can pull, which these tolerances separate
    // from ζ = 0.2 on.
    if (zeta >= 0.2) {
      EXPECT_GT(e - std::exp(-zeta * std::numbers::pi / std::sqrt(1.0 - zeta * zeta)), 4.0 * h * e)
          << "zeta " << zeta;
    }
  }
}

// A bounce stepped one step at a time until the bodies part
// (test::step_until_parted, as the sphere kernel's tests): restitution,
// ω·Δt and the ledger's largest and smallest readings, the ledger's stop
// on (a false "energy created" fails).
struct Bounce2D {
  double restitution = 0.0, h = 0.0, ledger_max = -1e300, ledger_min = 1e300;
  int contact_steps = 0;
  bool parted = false;
};

constexpr double kAlpha = 0.002;  // Δt/Δt_crit: ≈ 800 steps in contact
constexpr double kZetas[] = {0.05, 0.3, 0.7};

/// A disk of radius kR a gap of 1e-5·r from wall `side`, moving onto it at
/// v0 (and 0.02 m/s along it: the wall is frictionless), the wall moving
/// towards it at wall_speed.
Bounce2D wall_bounce(WallSide side, double zeta, double v0, double wall_speed) {
  Material mat = reference_material(0.3, 0.0);
  mat.contact_damping_ratio = zeta;
  const double r = kR, L = 10.0 * r, gap = 1e-5 * r;
  const bool vertical = side == kLeft || side == kRight;                // a wall of constant x
  const double sign = (side == kLeft || side == kBottom) ? 1.0 : -1.0;  // inward normal
  const double along = -sign * L + (r + gap) * sign;
  const std::vector<double> x{vertical ? along : 0.3 * r}, y{vertical ? 0.3 * r : along}, rad{r};
  World w(mat, x, y, rad, -L, L, -L, L);
  const Integration in = set_undamped(w, kAlpha);
  const double un = -v0 * sign, ut = 0.02;  // normal and tangential velocity
  w.set_velocity(0, vertical ? un : ut, vertical ? ut : un, 0.0);
  Wall& wall = w.wall(side);
  wall.velocity = sign * wall_speed;
  auto pos = [&] { return vertical ? w.x()[0] : w.y()[0]; };
  auto overlap = [&] { return r - (pos() - wall.position) * sign; };
  Bounce2D out;
  out.h = std::sqrt(mat.wall.kn / w.mass()[0]) * in.dt;
  test::step_until_parted(w, overlap, out);
  const double v_after = vertical ? w.vx()[0] : w.vy()[0];
  out.restitution = -(v_after - wall.velocity) * sign / ((un - wall.velocity) * sign);
  EXPECT_EQ(vertical ? w.vy()[0] : w.vx()[0], ut);  // frictionless: untouched
  EXPECT_EQ(w.omega()[0], 0.0);
  return out;
}

TEST(KernelContactDamping, ADiskBouncesOffEachWallWithTheClampedDashpotsRestitution) {
  for (double zeta : kZetas)
    for (WallSide side : {kLeft, kRight, kBottom, kTop}) {
      SCOPED_TRACE("zeta " + std::to_string(zeta) + " wall " + std::to_string(side));
      const Bounce2D b = wall_bounce(side, zeta, 0.05, 0.0);
      ASSERT_TRUE(b.parted);
      EXPECT_GT(b.contact_steps, 400);
      EXPECT_NEAR(b.restitution, clamped_restitution(zeta),
                  clamped_restitution_tolerance(zeta, b.h));
      EXPECT_LE(b.ledger_max, bounce_ledger_bound(zeta, b.h));
      EXPECT_GE(b.ledger_min, -bounce_ledger_lower_bound(zeta, b.h));
    }
}

TEST(KernelContactDamping, AMovingWallHitsARestingDiskWithTheSameRestitution) {
  // The dashpot reads the velocity relative to the wall. The ledger is not
  // held to bounce_ledger_bound here: the 2D ledger samples the walls' work
  // (and the global damping) every energy_check_interval steps, so this
  // collision reads 0.020 (ζ 0.05) and 0.017 (ζ 0.3) as created, beyond
  // the bound (0.0052, 0.011), below the stop at 0.1 (a stop fails the
  // test: step_until_parted). Summing the walls' work every step alone, as
  // the 3D ledger does, exposed the sampled damping's overestimate (a gas
  // compacted at ζ = 1 then read 0.79 and stopped); both must move to
  // per-step sums together, as in 3D (sphere_energy_balance.cpp).
  for (double zeta : kZetas)
    for (WallSide side : {kRight, kBottom}) {
      SCOPED_TRACE("zeta " + std::to_string(zeta) + " wall " + std::to_string(side));
      const Bounce2D b = wall_bounce(side, zeta, 0.0, 0.05);
      ASSERT_TRUE(b.parted);
      EXPECT_NEAR(b.restitution, clamped_restitution(zeta),
                  clamped_restitution_tolerance(zeta, b.h));
    }
}

TEST(KernelContactDamping, UnequalDisksBounceWithTheReducedMassesRestitution) {
  for (double zeta : kZetas) {
    SCOPED_TRACE("zeta " + std::to_string(zeta));
    Material mat = reference_material(0.3);
    mat.contact_damping_ratio = zeta;
    const double r0 = kR, r1 = 0.8 * kR, L = 10.0 * kR, v0 = 0.05;
    const double ux = 0.6, uy = 0.8;  // the line of centres
    const double d = r0 + r1 + 1e-5 * kR;
    const std::vector<double> x{0.0, d * ux}, y{0.0, d * uy}, rad{r0, r1};
    World w(mat, x, y, rad, -L, L, -L, L);
    const Integration in = set_undamped(w, kAlpha);
    w.set_velocity(0, v0 * ux, v0 * uy, 0.0);
    w.set_velocity(1, -v0 * ux, -v0 * uy, 0.0);
    auto overlap = [&] { return r0 + r1 - std::hypot(w.x()[1] - w.x()[0], w.y()[1] - w.y()[0]); };
    Bounce2D b;
    b.h = std::sqrt(mat.particle.kn / reduced_mass(w.mass()[0], w.mass()[1])) * in.dt;
    test::step_until_parted(w, overlap, b);
    ASSERT_TRUE(b.parted);
    EXPECT_GT(b.contact_steps, 400);
    b.restitution = ((w.vx()[1] - w.vx()[0]) * ux + (w.vy()[1] - w.vy()[0]) * uy) / (2.0 * v0);
    EXPECT_NEAR(b.restitution, clamped_restitution(zeta), clamped_restitution_tolerance(zeta, b.h));
    EXPECT_LE(b.ledger_max, bounce_ledger_bound(zeta, b.h));
    EXPECT_GE(b.ledger_min, -bounce_ledger_lower_bound(zeta, b.h));
    std::printf(
        "2D pair, zeta %.2f: e %.6f, clamped %.6f (%+.2e, bound %.1e), ledger in [%.1e, %.1e]\n",
        zeta, b.restitution, clamped_restitution(zeta), b.restitution - clamped_restitution(zeta),
        clamped_restitution_tolerance(zeta, b.h), b.ledger_min, b.ledger_max);
  }
}

TEST(KernelContactDamping, ElasticEnergyIsTheSpringsWhateverTheDashpot) {
  // Measures::elastic_energy and the energy ledger both take ½kn·δ² (the
  // elastic part of the normal force), not ½fn²/kn of the damped force.
  const Collision c = collide(0.3, 0.005);
  EXPECT_LT(c.max_energy_gap, 1e-6);
  // The dashpot's dissipation is booked: no energy reads as created.
  EXPECT_LE(c.energy_created, 0.012);
}

// Issue 14: contact damping 0.2, a common value, failed consolidation on the
// hexagonal REVs with "energy created by the integrator". Two causes in the
// consolidation (biaxial.cpp): the servo ignored the wall dashpots'
// resistance c/Δt, so with gain·ζ_c/α > 1 the wall velocity flipped and
// grew every step; and consolidation ran at α = 0.2, beyond the stable step
// the dashpots leave (estimate 0.16 on hex_5x5). Both REVs now consolidate
// and load to the end at ζ_c = 0.2 and 0.5, the loading at 0.9 × the
// estimate.
TEST(KernelContactDamping, ConsolidationAndLoadingCompleteWithContactDamping) {
  for (const char* name : {"hex_5x5", "hex_10x10"})
    for (const double zeta_c : {0.2, 0.5}) {
      SceneConfig c = load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/" + name + ".json");
      c.material.contact_damping_ratio = zeta_c;
      const ConsolidatedState state = consolidate(c, make_assembly(c));
      ASSERT_TRUE(state.converged) << name << " zeta_c " << zeta_c;
      AlgorithmSpec a = c.algorithm;
      const double stable = estimated_stable_dt_ratio(state, a);
      a.dt_ratio = 0.9 * stable;
      const LoadingResult run = run_loading(state, c.test, a);
      EXPECT_FALSE(run.diverged) << name << " zeta_c " << zeta_c << ": "
                                 << to_string(run.divergence) << " at step " << run.divergence_step;
      EXPECT_EQ(run.steps_run, run.steps_planned) << name << " zeta_c " << zeta_c;
    }
}

}  // namespace
}  // namespace demcal
