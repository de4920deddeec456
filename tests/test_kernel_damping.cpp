// Global damping (D = ζ·2·sqrt(k·m), src/kernel/solver.cpp) against the damped
// linear oscillator.
//
// A wall contact is one-sided, so a disk released against a single wall
// leaves it and never oscillates about an equilibrium. Here the disk is
// squeezed between two opposite walls, both in contact all the time: the
// oscillation is about the centred equilibrium, inside both contacts.
//  - Translation: two frictionless walls of stiffness kn/2 each act in
//    parallel, k = kn, so the damping ratio of the oscillator is exactly
//    D_t/(2·sqrt(k·m)) = ζ_t (D_t = ζ_t·2·sqrt(kn·m) per particle).
//  - Rotation: top and bottom walls with friction (never sliding) and
//    tangential stiffness kt_w; turning the disk by θ loads both tangential
//    springs by dist·θ and gives a pure couple −2·kt_w·dist²·θ (the two
//    tangential forces cancel). With kt_w = kt·r²/(2·dist²) the rotational
//    stiffness is kt·r², so D_r = ζ_r·2·sqrt(kt·r²·I) is ratio ζ_r exactly.
//
// Discrete theory used for the tolerances: the scheme
//   v(n+½) = [(1 − c)·v(n−½) + F·Δt/m]/(1 + c),  c = ζ·h,  h = ω·Δt
// has the characteristic polynomial (1 + c)z² − (2 − h²)z + (1 − c), roots
// z = ρ·e^{±iθ}, ρ² = (1 − c)/(1 + c), cos θ = (2 − h²)/(2·sqrt(1 − c²)).
// The discrete solution is a sampled ρⁿ-decaying sine: half a period is π/θ
// steps and the envelope shrinks by ρ^{π/θ} per half period, which tends to
// the continuous overshoot exp(−πζ/sqrt(1 − ζ²)) as h → 0.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kEps;
using kernel_test::kR;
using kernel_test::reference_material;

struct DiscreteOscillator {
  double rho, theta;
  DiscreteOscillator(double zeta, double h) {
    const double c = zeta * h;
    rho = std::sqrt((1.0 - c) / (1.0 + c));
    theta = std::acos((2.0 - h * h) / (2.0 * std::sqrt(1.0 - c * c)));
  }
  double overshoot() const { return std::pow(rho, std::numbers::pi / theta); }
};

double continuous_overshoot(double zeta) {
  return std::exp(-std::numbers::pi * zeta / std::sqrt(1.0 - zeta * zeta));
}

// Disk of radius r centred at x = u0 between walls at ±(r − δ0): released
// from rest 0 < u0 < δ0, both contacts stay closed.
struct SqueezedDisk {
  static constexpr double r = kR, delta0 = 2e-6, u0 = 1e-6;
  World world;
  double h = 0.0;  // ω·Δt, ω = sqrt(kn/m)
  explicit SqueezedDisk(double zeta, double alpha)
      : world(material(), std::vector<double>{u0}, std::vector<double>{0.0}, std::vector<double>{r},
              -(r - delta0), r - delta0, -10 * r, 10 * r) {
    Integration in;
    in.damping_ratio_translation = zeta;
    in.damping_ratio_rotation = 1.0;
    in.dt = alpha * world.reference_scales().dt_crit;
    world.set_integration(in);
    h = std::sqrt(world.material().particle.kn / world.mass()[0]) * in.dt;  // = 2α
  }
  static Material material() {
    Material m = reference_material(0.3, 0.0);
    m.wall.kn = 0.5 * m.particle.kn;  // two walls in parallel: k = kn
    return m;
  }
};

TEST(KernelDamping, TranslationUnderdampedOvershootMatchesDampedOscillator) {
  const double zeta = 0.5, alpha = 0.005;  // h = 0.01: π/θ ≈ 363 steps per half period
  SqueezedDisk d(zeta, alpha);
  World& w = d.world;
  double umin = d.u0;
  int steps = 0;
  // Run to the first minimum (the velocity turns positive again).
  while (steps < 5000) {
    ASSERT_TRUE(w.step(1));
    ++steps;
    ASSERT_EQ(w.wall(kLeft).contacts, 1);
    ASSERT_EQ(w.wall(kRight).contacts, 1);
    umin = std::min(umin, w.x()[0]);
    if (w.x()[0] < 0.0 && w.vx()[0] > 0.0) break;
  }
  const double os = -umin / d.u0;
  const DiscreteOscillator disc(zeta, d.h);
  const double os_cont = continuous_overshoot(zeta);  // 0.1630
  // The kernel starts from v(−½) = 0 at x(0) = u0: the discrete turning point
  // is at n = −½ and its amplitude A = u0/cos(θ/2) ≤ u0·(1 + h²/8); the
  // sampled minimum lies within a factor cos(θ/2) ≥ 1 − h²/8 of the discrete
  // crest. Hence |os − os_disc| ≤ os·h²/4 (≈ 4e-6 here), and the discrete
  // overshoot differs from the continuous one by the computable
  // |os_disc − os_cont| (O(h²); vanishing to O(h⁴) at ζ = 0.5).
  const double tol_sampling = os_cont * d.h * d.h / 4.0;
  EXPECT_NEAR(os, disc.overshoot(), tol_sampling);
  EXPECT_NEAR(os, os_cont, tol_sampling + std::abs(disc.overshoot() - os_cont));
  // And the minimum occurs half a damped period after the release, π/θ
  // steps (the crest is sampled within a step; the loop stops one after).
  EXPECT_NEAR(steps, std::numbers::pi / disc.theta, 2.0);
}

TEST(KernelDamping, TranslationCriticallyDampedReturnsWithoutOvershoot) {
  const double alpha = 0.005;  // h = 0.01
  SqueezedDisk d(1.0, alpha);
  World& w = d.world;
  const double h = d.h;
  // Discrete critical damping, c = h: the characteristic polynomial
  // (1 + h)z² − (2 − h²)z + (1 − h) has the real, positive roots
  // z1 = 1/(1 + h) and z2 = 1 − h (ln z = −h ± h²/2 + O(h³): the continuous
  // double root −ω split symmetrically, the discrete image of
  // (1 + ωt)·e^{−ωt}). So x(n) = a·z1ⁿ + b·z2ⁿ with x(0) = u0 and, from
  // v(−½) = 0, x(1) = u0·(1 − h²/(1 + h)): a monotone return that never
  // crosses the equilibrium. The kernel must follow it to round-off: the
  // overlaps δ = r − |x − wall| carry a few ulps of r each step, and the
  // damped response sums those errors with a gain of order one.
  const double z1 = 1.0 / (1.0 + h), z2 = 1.0 - h;
  const double x1 = d.u0 * (1.0 - h * h / (1.0 + h));
  const double b = (x1 - d.u0 * z1) / (z2 - z1), a = d.u0 - b;
  const double tol_eq = 16.0 * kEps * d.r;
  double prev = d.u0;
  for (int n = 1; n <= 3000; ++n) {  // 30/ω
    ASSERT_TRUE(w.step(1));
    const double u = w.x()[0];
    EXPECT_NEAR(u, a * std::pow(z1, n) + b * std::pow(z2, n), tol_eq) << "step " << n;
    EXPECT_GE(u, -tol_eq) << "overshoot at step " << n;
    EXPECT_LE(u, prev + tol_eq) << "not monotone at step " << n;
    prev = u;
  }
  // Thirty time constants later it has settled: (1 + 30)·e^{−30} ≈ 3e-12.
  EXPECT_LT(std::abs(w.x()[0]), 1e-10 * d.u0 + tol_eq);
}

// Disk between top and bottom walls with friction, spun by an initial ω.
struct SpunDisk {
  static constexpr double r = kR, delta0 = 2e-6;
  World world;
  double h = 0.0;  // ω_θ·Δt
  SpunDisk(double zeta_r, double alpha)
      : world(material(), std::vector<double>{0.0}, std::vector<double>{0.0},
              std::vector<double>{r}, -10 * r, 10 * r, -(r - delta0), r - delta0) {
    Integration in;
    in.damping_ratio_translation = 1.0;
    in.damping_ratio_rotation = zeta_r;
    in.dt = alpha * world.reference_scales().dt_crit;
    world.set_integration(in);
    const double m = world.mass()[0], inertia = 0.5 * m * r * r;
    h = std::sqrt(world.material().particle.kt * r * r / inertia) * in.dt;
  }
  static Material material() {
    Material m = reference_material(0.3, 10.0);  // wall friction never reached
    const double dist = r - delta0;
    m.wall.kt = m.particle.kt * r * r / (2.0 * dist * dist);
    return m;
  }
};

TEST(KernelDamping, RotationUnderdampedSuccessiveExtremaMatchDampedOscillator) {
  // kt·r²/I = 2·kt/m = kn/m: ω_θ = ω0 and h = 2α = 0.01.
  const double zeta = 0.5, alpha = 0.005;
  SpunDisk d(zeta, alpha);
  World& w = d.world;
  w.set_velocity(0, 0.0, 0.0, 1.0);  // ω·r = 5e-4 m/s: slip ≪ μ·Fn/kt_w
  double th_max = 0.0, th_min = 0.0;
  bool past_max = false;
  // θ is the angle the walls' springs see: each step both contact points
  // slip by dist·ω·Δt, the step's turn, so the couple is −2·kt_w·dist²·θ
  // (to the round-off of sums of the ~500 increments of the run, n·ε ≈
  // 1e-13 of the largest couple; the amplitude of θ is ω(0)/ω_θ = Δt/h).
  const double dist = SpunDisk::r - SpunDisk::delta0, ktw = w.material().wall.kt;
  const double couple_scale = 2.0 * ktw * dist * dist * w.integration().dt / d.h;
  for (int s = 0; s < 5000; ++s) {
    ASSERT_TRUE(w.step(1));
    // Pure couple: the disk does not translate at all.
    ASSERT_EQ(w.vx()[0], 0.0);
    ASSERT_EQ(w.vy()[0], 0.0);
    const double th = w.rotation()[0];
    ASSERT_NEAR(w.torque()[0], -2.0 * ktw * dist * dist * th, 1e-12 * couple_scale) << "step " << s;
    if (!past_max) {
      th_max = std::max(th_max, th);
      past_max = w.omega()[0] < 0.0;
    } else {
      th_min = std::min(th_min, th);
      if (th < 0.0 && w.omega()[0] > 0.0) break;
    }
  }
  ASSERT_GT(th_max, 0.0);
  ASSERT_LT(th_min, 0.0);
  const DiscreteOscillator disc(zeta, d.h);
  const double ratio = -th_min / th_max;
  const double os_cont = continuous_overshoot(zeta);
  // Successive crests of the discrete solution are exactly ρ^{π/θ} apart;
  // sampling each crest costs at most a factor cos(θ/2) ≥ 1 − θ²/8.
  const double tol_sampling = os_cont * disc.theta * disc.theta / 4.0;
  EXPECT_NEAR(ratio, disc.overshoot(), tol_sampling);
  EXPECT_NEAR(ratio, os_cont, tol_sampling + std::abs(disc.overshoot() - os_cont));
}

TEST(KernelDamping, RotationCriticallyDampedDoesNotSwingBack) {
  SpunDisk d(1.0, 0.005);  // h = 0.01
  World& w = d.world;
  w.set_velocity(0, 0.0, 0.0, 1.0);
  double th_max = 0.0;
  for (int s = 0; s < 3000; ++s) {  // 30 time constants 1/ω_θ
    ASSERT_TRUE(w.step(1));
    const double th = w.rotation()[0];
    th_max = std::max(th_max, th);
    // Real positive roots: θ rises once and decays to 0 without crossing.
    ASSERT_GE(th, 0.0) << "swing-back at step " << s;
  }
  // θ(t) ∝ t·e^{−ω_θ t}, crest 1/e: at ω_θ·t = 30, θ/θ_max = 30·e^{−29} ≈ 8e-12.
  EXPECT_LT(w.rotation()[0], 1e-10 * th_max);
}

}  // namespace
}  // namespace demcal
