// Energy conservation of the undamped kernel (central-difference integration,
// src/kernel/solver.cpp).
//
// Scene: a 10×10 hexagonal packing pre-compressed by the four walls
// (overlap 1e-6 m = 2rε, ε = 1e-3, at every contact), first relaxed to
// rest with global damping, then given random velocities and run undamped at
// α = Δt/Δt_crit = 0.1 for 10⁴ steps. The vibration amplitude (≈ 0.1 of the
// overlap) keeps every contact closed, so the system is linear about the
// rest state to O(amplitude/d) ≈ 1e-4.
//
// Theory (leapfrog on M·ẍ = −K·x, velocities synchronised to full steps,
// v(n) = v(n−½) + F(n)·Δt/(2m)): the quadratic form
//   H̃ = ½·vᵀMv + ½·xᵀKx − (Δt²/8)·FᵀM⁻¹F
// is conserved exactly (a short calculation from the invariant
// v(n+½)ᵀMv(n+½) + x(n)ᵀK·x(n+1)). Mode by mode, the true energy H then
// lies in [H̃, H̃/(1 − q²)], q = ω·Δt/2, so for every step
//   |E(n) − E(0)| ≤ κ·E_vib,  κ = q²/(1 − q²),  q = ω_max·Δt/2,
// with E_vib = energy above the rest state = the kinetic energy given. This
// bounds the drift of KE + elastic energy rigorously, and the modified
// energy E − (Δt²/8)·Σ(F²/m + M²/I) must stay constant up to the
// non-linearity of the contact geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::Energies;
using kernel_test::synchronized_energies;

struct EnergyRun {
  double kappa = 0.0;                            // bound on |ΔE|/E_vib
  double e_vib = 0.0;                            // energy above the rest state
  double rest_kinetic = 0.0;                     // kinetic energy left by the relaxation
  double max_rel_error = 0.0;                    // max |E(n) − E(0)|/E_vib
  double max_rel_modified = 0.0;                 // max |E_mod(n) − E_mod(0)|/E_vib
  int min_contacts = 1 << 30, max_contacts = 0;  // particle and wall contacts
};

EnergyRun run_vibrating_hex(double mu, double alpha, uint32_t seed) {
  auto scene = kernel_test::hex_scene(10, 10);
  World w = scene.make(kernel_test::reference_material(mu, 0.0));
  // Relax to rest (the shifted rows are not balanced at the side walls),
  // frictionless, so that no tangential force is locked in at rest. (A
  // locked-in Ft makes the rotating incremental spring non-conservative: the
  // force Ft·t(x) turns with the branch vector, a field with a curl of
  // order Ft/d, i.e. Ft/(kt·d) relative to the tangential stiffness — up to
  // 7e-4 here if relaxed with friction on — and the modified energy then
  // drifts by about that much over the run. That is the contact model, not
  // an integration error.)
  w.set_particle_friction(0.0);
  Integration in;
  in.dt = 0.2 * w.reference_scales().dt_crit;
  in.damping_ratio_translation = 1.0;
  in.damping_ratio_rotation = 1.0;
  w.set_integration(in);
  w.step(20000);
  w.set_particle_friction(mu);
  const Measures rest = w.measure();
  for (const auto& c : w.contacts()) EXPECT_EQ(c.ft, 0.0);

  // Random velocities, amplitude 0.1·overlap·ω0 (and ω·r alike if frictional).
  const double m = w.mass()[0], kn = w.material().particle.kn;
  const double vamp = 0.1 * 1e-6 * std::sqrt(kn / m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < w.size(); ++i) {
    const double vx = vamp * u(rng), vy = vamp * u(rng), om = vamp * u(rng) / kernel_test::kR;
    w.set_velocity(i, vx, vy, mu > 0.0 ? om : 0.0);
  }

  in.dt = alpha * w.reference_scales().dt_crit;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);

  EnergyRun out;
  const StabilityEstimate est = w.stability_estimate();
  const double q = std::sqrt(est.omega2_max) * in.dt / 2.0;
  out.kappa = q * q / (1.0 - q * q);
  const Energies e0 = synchronized_energies(w);
  out.rest_kinetic = rest.kinetic_energy_translation + rest.kinetic_energy_rotation;
  out.e_vib = e0.total() - rest.elastic_energy;
  for (int n = 1; n <= 10000; ++n) {
    if (!w.step(1)) break;
    const Energies e = synchronized_energies(w);
    out.max_rel_error = std::max(out.max_rel_error, std::abs(e.total() - e0.total()) / out.e_vib);
    out.max_rel_modified =
        std::max(out.max_rel_modified, std::abs(e.modified - e0.modified) / out.e_vib);
    const Measures mm = w.measure();
    const int nc = mm.particle_contacts + mm.wall_contacts;
    out.min_contacts = std::min(out.min_contacts, nc);
    out.max_contacts = std::max(out.max_contacts, nc);
  }
  EXPECT_EQ(w.divergence(), Divergence::kNone);
  EXPECT_EQ(w.steps_taken(), 20000 + 10000);
  return out;
}

// Vibration amplitude / contact spacing: the relative size of the terms the
// linear theory neglects (contact normals turning, tangential springs
// turning with them).
constexpr double kNonlinearity = 1e-7 / (2.0 * kernel_test::kR);  // 1e-4

void expect_conserved(const EnergyRun& r) {
  // The rest state is really at rest: E_vib is the energy given.
  EXPECT_LT(r.rest_kinetic, 1e-9 * r.e_vib);
  // Every contact stays closed: the system is the smooth one of the theory.
  EXPECT_EQ(r.min_contacts, r.max_contacts);
  // KE + elastic energy never departs from its initial value by more than
  // the leapfrog bound κ·E_vib (κ ≈ 0.06 frictionless, 0.13 with rotation).
  EXPECT_LE(r.max_rel_error, r.kappa);
  // The modified energy, exactly conserved by the linear scheme, shows no
  // drift beyond the neglected non-linearity.
  EXPECT_LE(r.max_rel_modified, kNonlinearity);
}

TEST(KernelEnergy, FrictionlessHexPackingConservesEnergyUndamped) {
  expect_conserved(run_vibrating_hex(0.0, 0.1, 7));
}

TEST(KernelEnergy, StickingFrictionalHexPackingConservesEnergyUndamped) {
  // μ = 10: no contact slides; the tangential springs and the rotations
  // take part, and the elastic energy includes Ft²/(2kt).
  expect_conserved(run_vibrating_hex(10.0, 0.1, 8));
}

// A wall's springs store ½·Fn²/kn_w + ½·Ft²/kt_w, with the wall's own
// stiffnesses (here 3e8 and 2e7 N/m, not the particles' 1e8 and 5e7): a
// disk pressed 1e-6 m into the bottom wall and dragged 2e-7 m along it
// (heavy, undamped, rotation locked: the set velocity is the motion) holds
// Fn = kn_w·δ and Ft = kt_w·2e-7 m, and World::measure's elastic energy
// is their sum (to round-off).
TEST(KernelEnergy, WallSpringsStoreTheirEnergyWithTheWallsStiffnesses) {
  Material mat = kernel_test::reference_material(0.3, 0.4);
  mat.wall.kn = 3e8;
  mat.wall.kt = 2e7;
  const double r = kernel_test::kR;
  World w = kernel_test::disk_on_bottom_wall(mat, 1e-6);
  for (int s = 0; s < 200; ++s) {
    w.set_velocity(0, 1e-3, 0.0, 0.0);
    ASSERT_TRUE(w.step(1));
  }
  const double overlap = r - (w.y()[0] - w.wall(kBottom).position);
  const double fn = mat.wall.kn * overlap, ft = w.wall(kBottom).force.x();
  ASSERT_NEAR(ft, mat.wall.kt * 2e-7, 1e-6 * mat.wall.kt * 2e-7);
  const double expected = 0.5 * fn * fn / mat.wall.kn + 0.5 * ft * ft / mat.wall.kt;
  EXPECT_NEAR(w.measure().elastic_energy, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace demcal
