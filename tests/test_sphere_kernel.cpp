// Sphere kernel against analytical results: the stress identities, b = σ
// and σ symmetric at rest, the global damping's discrete decay, the stable
// step of a contact pair, and energy conservation without damping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "demcal/scene/sphere_packing.hpp"
#include "support/pair_stability.hpp"
#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using sphere_test::kEps;
using sphere_test::kR;
using sphere_test::test_material;

SphereWorld fcc_world(int n, double eps, double mu) {
  const SphereAssembly a = fcc_packing(n, n, n, kR, eps);
  return SphereWorld(test_material(mu), a.x, a.y, a.z, a.r, a.lo, a.hi);
}

// Relax with global damping (ζ = 1, α = 0.2) for `steps`.
void relax(SphereWorld& w, int steps) {
  sphere_test::set_damped(w, 0.2, 1.0);
  ASSERT_TRUE(w.step(steps));
}

// Σ_p |x_p − c|·|F_p| / V: the size of the terms of the identity, for the
// round-off tolerance and the bound on |b − σ| at rest.
double moment_scale(const SphereWorld& w) {
  double s = 0.0;
  for (int i = 0; i < w.size(); ++i)
    s += (sphere_test::position(w, i) - w.centre()).norm() * sphere_test::force(w, i).norm();
  return s / w.volume();
}

// Σ_c |arm|·|f| / V over all contacts: the size of the terms of σ.
double stress_scale(const SphereWorld& w) {
  const SphereMeasures m = w.measure();
  return m.homogenized_stress.cwiseAbs().maxCoeff() + m.boundary_stress.cwiseAbs().maxCoeff();
}

// The antisymmetric part of σ is the net torque: σ_ij − σ_ji = ε_ijk·ΣM_k/V,
// since each contact adds arm ⊗ f to σ and arm × f to its particle's torque.
Matrix3d torque_skew(const SphereWorld& w) {
  Vector3d t = Vector3d::Zero();
  for (int i = 0; i < w.size(); ++i) t += sphere_test::torque(w, i);
  t /= w.volume();
  Matrix3d s;
  s << 0.0, t.z(), -t.y(), -t.z(), 0.0, t.x(), t.y(), -t.x(), 0.0;
  return s;
}

// V·(b − σ) = Σ_p x^p ⊗ F_p and σ − σᵀ = ε·ΣM/V hold at every instant (they
// are rearrangements of the same sums), and so does b_aa = the walls'
// traction along a (frictionless walls): checked to round-off during a
// dynamic, frictional, sliding run with moving walls.
TEST(SphereStress, IdentitiesHoldToRoundOffDuringDynamicRun) {
  SphereWorld w = fcc_world(2, 2e-4, 0.3);
  Integration in;
  in.damping_ratio_translation = 0.1;
  in.damping_ratio_rotation = 0.1;
  w.set_integration(in);
  in.dt = 0.2 * w.reference_scales().dt_crit;
  w.set_integration(in);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double v = 0.01;
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(i, v * Vector3d(u(rng), u(rng), u(rng)),
                   v / kR * Vector3d(u(rng), u(rng), u(rng)));
  w.wall(kZMax).velocity = -1e-3;
  w.wall(kXMin).velocity = 5e-4;
  int checked = 0, walls_pressed = 0;
  for (int k = 0; k < 20; ++k) {
    ASSERT_TRUE(w.step(50));
    const SphereMeasures m = w.measure();
    ASSERT_GT(m.particle_contacts, 0);
    const double tol = 64.0 * kEps * (stress_scale(w) + moment_scale(w));
    EXPECT_LE(
        (m.boundary_stress - m.homogenized_stress - w.net_force_moment()).cwiseAbs().maxCoeff(),
        tol);
    EXPECT_LE((m.homogenized_stress - m.homogenized_stress.transpose() - torque_skew(w))
                  .cwiseAbs()
                  .maxCoeff(),
              tol);
    // Not trivially: the run is far from equilibrium.
    EXPECT_GT(w.net_force_moment().cwiseAbs().maxCoeff(), 1e3 * tol);
    // The walls are frictionless (test_material), so b's normal components
    // are their traction: each wall contact point lies on its wall's plane,
    // L_a/2 from the centre, and carries a force along the axis, so b_aa =
    // −(F_lo + F_hi)·(L_a/2)/V = (f_lo − f_hi)/(2·A_a), f the spheres' force
    // on each wall along a (F_lo = −f_lo, F_hi = f_hi the compressions) and
    // A_a = V/L_a the wall's area.
    for (int a = 0; a < 3; ++a) {
      const SphereWall& lo = w.wall(static_cast<SphereWallSide>(2 * a));
      const SphereWall& hi = w.wall(static_cast<SphereWallSide>(2 * a + 1));
      const double area = w.volume() / (hi.position - lo.position);
      EXPECT_NEAR(m.boundary_stress(a, a), (lo.force[a] - hi.force[a]) / (2.0 * area), tol);
      walls_pressed += lo.contacts + hi.contacts > 0;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 20);
  EXPECT_GT(walls_pressed, 20);  // pairs of walls with contacts, over the 20 checks
}

// At rest every particle is balanced (F_p = 0, M_p = 0), so b = σ and σ is
// symmetric; with the residual forces of a relaxed packing the identities
// above bound the gaps by Σ|x_p||F_p|/V and |ΣM|/V.
TEST(SphereStress, StaticFrictionalPackingHasBoundaryEqualHomogenizedAndSymmetricStress) {
  SphereWorld w = fcc_world(3, 1e-4, 0.3);
  relax(w, 20000);
  const SphereMeasures m = w.measure();
  const double s = m.boundary_stress.cwiseAbs().maxCoeff();
  ASSERT_GT(s, 0.0);
  EXPECT_LT(m.unbalanced_force_ratio, 1e-6);
  const double bound = moment_scale(w) + 64.0 * kEps * stress_scale(w);
  EXPECT_LE((m.boundary_stress - m.homogenized_stress).cwiseAbs().maxCoeff(), bound);
  EXPECT_LE((m.homogenized_stress - m.homogenized_stress.transpose()).cwiseAbs().maxCoeff(),
            torque_skew(w).cwiseAbs().maxCoeff() + 64.0 * kEps * stress_scale(w));
  // and both bounds are small: a static packing in the sense of the test.
  EXPECT_LT(bound, 1e-6 * s);
  // Isotropic compression of a cube: the three normal stresses agree.
  EXPECT_NEAR(m.boundary_stress(0, 0), m.boundary_stress(2, 2), 1e-6 * s);
  EXPECT_LT(m.boundary_stress(0, 0), 0.0);  // compression negative
}

// A free sphere (no contact) under global damping: the scheme gives
// v(n+½) = ρ·v(n−½), ρ = (1 − c)/(1 + c), c = D·Δt/(2m) = ζ_t·sqrt(kn/m)·Δt,
// and for ω the same with c_r = ζ_r·r·sqrt(kt/I)·Δt (D_r = ζ_r·2·sqrt(kt·r²·I)).
// ln ρ = −2c − (2/3)c³ − …: after N steps the continuous exp(−D·t/m) is
// matched to within N·c³ relative.
TEST(SphereDamping, FreeSphereDecaysAtTheDiscreteRate) {
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), kR);
  s.lo = {-10 * kR, -10 * kR, -10 * kR};
  s.hi = {10 * kR, 10 * kR, 10 * kR};
  SphereWorld w = s.make(test_material());
  Integration in;
  in.damping_ratio_translation = 0.7;
  in.damping_ratio_rotation = 0.4;
  w.set_integration(in);
  in.dt = 0.1 * w.reference_scales().dt_crit;
  w.set_integration(in);
  const Vector3d v0(1e-3, -2e-3, 3e-3), w0(1.0, 2.0, -0.5);
  w.set_velocity(0, v0, w0);
  const int n = 200;
  ASSERT_TRUE(w.step(n));
  const double m = w.mass()[0], inertia = w.inertia()[0];
  EXPECT_NEAR(m, 2650.0 * 4.0 / 3.0 * std::numbers::pi * kR * kR * kR, 4.0 * kEps * m);
  EXPECT_DOUBLE_EQ(inertia, 0.4 * m * kR * kR);
  const double c = 0.7 * std::sqrt(1e8 / m) * in.dt;
  const double cr = 0.4 * kR * std::sqrt(5e7 / inertia) * in.dt;
  const double rho = std::pow((1.0 - c) / (1.0 + c), n);
  const double rho_r = std::pow((1.0 - cr) / (1.0 + cr), n);
  EXPECT_LE((sphere_test::velocity(w, 0) - rho * v0).norm(), 1e-13 * v0.norm());
  EXPECT_LE((sphere_test::spin(w, 0) - rho_r * w0).norm(), 1e-13 * w0.norm());
  EXPECT_NEAR(rho, std::exp(-2.0 * c * n), n * c * c * c * rho);
  EXPECT_NEAR(rho_r, std::exp(-2.0 * cr * n), n * cr * cr * cr * rho_r);
  // The sphere moved along v(n+½)·Δt each step: Σ ρ^k = (1 − ρ^n)/(1 − ρ1).
  const double rho1 = (1.0 - c) / (1.0 + c);
  const Vector3d moved = v0 * rho1 * (1.0 - rho) / (1.0 - rho1) * in.dt;
  EXPECT_LE((sphere_test::position(w, 0) - moved).norm(), 1e-12 * moved.norm());
  // The energy ledger sums the damping's loss exactly, step by step: a free
  // sphere's books balance to round-off however fast it decays (sampled
  // rates would overestimate the loss here many times over).
  EXPECT_NEAR(w.energy_created(), 0.0, 1e-12);
  EXPECT_EQ(w.divergence(), Divergence::kNone);
}

// Two spheres in contact, no walls. The linearised network has, for the
// normal, ω² = 2kn/m; for each tangent direction e, the mode of the
// tangential spring with both translations and spins, b = (−e, a·(e × n),
// e, a·(e × n)) over (u_0, θ_0, u_1, θ_1): ω² = kt·|M^-½ b|² =
// (2kt/m)·(1 + a²·m/I) = (2kt/m)·(1 + 2.5·a²/r²). With rotation locked only
// translations: max(2kn/m, 2kt/m). The Gershgorin bound must stay above:
// with the branch along an axis its rows are nearest to the eigenvalue (the
// spin rows' sum (kt/m)·√2.5·(2 + 2√2.5) = 8.16·kt/m against 7·kt/m),
// with a skewed branch the directions' components spread over the axes and
// loosen it.
TEST(SphereStability, ContactPairEstimateMatchesEigenvalues) {
  const double delta = 1e-6;
  for (const Vector3d& branch :
       {Vector3d(Vector3d(1.0, -2.0, 2.0) / 3.0), Vector3d(1.0, 0.0, 0.0)}) {
    SCOPED_TRACE(branch.transpose());
    sphere_test::Scene s;
    s.add(Vector3d::Zero(), kR);
    s.add((2.0 * kR - delta) * branch, kR);
    s.lo = {-10 * kR, -10 * kR, -10 * kR};
    s.hi = {10 * kR, 10 * kR, 10 * kR};
    SphereWorld w = s.make(test_material(0.3));
    const double m = w.mass()[0], kn = 1e8, kt = 5e7, a = kR - 0.5 * delta;
    const double w2_rot = 2.0 * kt / m * (1.0 + 2.5 * a * a / (kR * kR));
    const double w2_trans = std::max(2.0 * kn / m, 2.0 * kt / m);
    test::expect_pair_estimate(w.stability_estimate(), w2_rot, w2_trans,
                               w.reference_scales().dt_crit, m, kn);
  }
}

// Energy conservation, undamped. Scene: FCC 2×2×2 (32 spheres)
// pre-compressed by the walls, relaxed frictionless to rest, then given
// random velocities (amplitude 0.1 of the overlap times ω0, so every
// contact stays closed) and run undamped at α = 0.1 for 10⁴ steps. The
// leapfrog conserves H̃ = ½vᵀMv + ½xᵀKx − (Δt²/8)FᵀM⁻¹F exactly on the
// linear system, so |E(n) − E(0)| ≤ κ·E_vib with κ = q²/(1 − q²),
// q = ω_max·Δt/2 (test_kernel_energy.cpp derives it), and the modified
// energy stays constant up to the neglected non-linearity
// (amplitude/spacing).
void expect_energy_conserved(double mu, uint32_t seed) {
  SphereWorld w = fcc_world(2, 1e-3, 0.0);
  relax(w, 20000);
  w.set_particle_friction(mu);
  const SphereMeasures rest = w.measure();
  const double m = w.mass()[0];
  const double amp = 0.1 * 2.0 * kR * 1e-3;  // 0.1 of the overlap 2rε
  const double vamp = amp * std::sqrt(1e8 / m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(
        i, vamp * Vector3d(u(rng), u(rng), u(rng)),
        mu > 0.0 ? Vector3d(vamp / kR * Vector3d(u(rng), u(rng), u(rng))) : Vector3d::Zero());
  const Integration in = sphere_test::set_undamped(w, 0.1);
  const StabilityEstimate est = w.stability_estimate();
  const double q = std::sqrt(est.omega2_max) * in.dt / 2.0;
  const double kappa = q * q / (1.0 - q * q);
  const sphere_test::Energies e0 = sphere_test::synchronized_energies(w);
  const double e_vib = e0.total() - rest.elastic_energy;
  ASSERT_GT(e_vib, 0.0);
  EXPECT_LT(rest.kinetic_energy_translation + rest.kinetic_energy_rotation, 1e-9 * e_vib);
  const int contacts0 = rest.particle_contacts + rest.wall_contacts;
  double max_err = 0.0, max_mod = 0.0;
  for (int n = 1; n <= 10000; ++n) {
    ASSERT_TRUE(w.step(1));
    const sphere_test::Energies e = sphere_test::synchronized_energies(w);
    max_err = std::max(max_err, std::abs(e.total() - e0.total()) / e_vib);
    max_mod = std::max(max_mod, std::abs(e.modified - e0.modified) / e_vib);
    if (n % 100 == 0) {
      const SphereMeasures mm = w.measure();
      EXPECT_EQ(mm.particle_contacts + mm.wall_contacts, contacts0);
    }
  }
  const double nonlinearity = amp / (2.0 * kR);  // 1e-4
  EXPECT_LE(max_err, kappa);
  EXPECT_LE(max_mod, nonlinearity);
  EXPECT_GT(max_err, 1e-3 * kappa);  // the bound is not vacuous
}

TEST(SphereEnergy, FrictionlessFccConservesEnergyUndamped) { expect_energy_conserved(0.0, 7); }

TEST(SphereEnergy, StickingFrictionalFccConservesEnergyUndamped) {
  // μ = 10: no contact slides; tangential springs and spins take part.
  expect_energy_conserved(10.0, 8);
}

}  // namespace
}  // namespace demcal

namespace demcal {
namespace {

// The Verlet skin only decides which pairs are examined: a run that
// rebuilds its list every step (tiny skin) and one that rarely does must
// agree bit for bit, contact histories carried over every rebuild.
TEST(SphereNeighbours, SkinDoesNotChangeTheTrajectory) {
  auto run = [](double skin_ratio, int64_t& rebuilds) {
    const SphereAssembly a = fcc_packing(2, 2, 2, sphere_test::kR, 2e-4);
    KernelOptions options;
    options.skin_ratio = skin_ratio;
    SphereWorld w(sphere_test::test_material(0.3), a.x, a.y, a.z, a.r, a.lo, a.hi, options);
    Integration in;
    in.damping_ratio_translation = 0.05;
    in.damping_ratio_rotation = 0.05;
    w.set_integration(in);
    in.dt = 0.2 * w.reference_scales().dt_crit;
    w.set_integration(in);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < w.size(); ++i)
      w.set_velocity(i, 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng)),
                     0.05 / sphere_test::kR * Eigen::Vector3d(u(rng), u(rng), u(rng)));
    w.wall(kZMax).velocity = -2e-3;
    EXPECT_TRUE(w.step(3000));
    rebuilds = w.rebuilds();
    return w;
  };
  int64_t rebuilds_small = 0, rebuilds_large = 0;
  const SphereWorld a = run(1e-6, rebuilds_small), b = run(0.5, rebuilds_large);
  EXPECT_GT(rebuilds_small, 1000);
  EXPECT_LT(rebuilds_large, rebuilds_small / 10);
  // Every sphere's state, force and torque, and every contact's forces.
  int mismatches = 0;
  for (auto f : {&SphereWorld::x, &SphereWorld::y, &SphereWorld::z, &SphereWorld::vx,
                 &SphereWorld::vy, &SphereWorld::vz, &SphereWorld::omega_x, &SphereWorld::omega_y,
                 &SphereWorld::omega_z, &SphereWorld::fx, &SphereWorld::fy, &SphereWorld::fz,
                 &SphereWorld::torque_x, &SphereWorld::torque_y, &SphereWorld::torque_z})
    for (int i = 0; i < a.size(); ++i) mismatches += (a.*f)()[i] != (b.*f)()[i];
  EXPECT_EQ(mismatches, 0);
  const auto ca = a.contacts(), cb = b.contacts();
  ASSERT_EQ(ca.size(), cb.size());
  int loaded = 0;
  for (size_t k = 0; k < ca.size(); ++k) {
    EXPECT_EQ(ca[k].i, cb[k].i);
    EXPECT_EQ(ca[k].j, cb[k].j);
    EXPECT_EQ(ca[k].fn, cb[k].fn);
    EXPECT_EQ(ca[k].tangential, cb[k].tangential);
    loaded += ca[k].tangential.norm() > 0.0;
  }
  // The run collided and the contacts carry tangential forces: the
  // histories, carried over every rebuild, were compared too.
  EXPECT_GT(loaded, 0);
  std::printf("skin test: %zu contacts at the end, %d with a tangential force\n", ca.size(),
              loaded);
}

}  // namespace
}  // namespace demcal

namespace demcal {
namespace {

// The stable step of the coupled 6-DOF network is sharp: a vibrating FCC
// packing (all contacts closed and sticking, so the system is linear) run
// undamped just below 2/ω_max stays bounded, just above it blows up — the
// unstable mode grows by |z| ≈ 1.2 per step at ω·Δt = 2.01 (roots of
// z² − (2 − ω²Δt²)z + 1). The Gershgorin bound is safe (not above it).
// The kernel's own check must see it: past the step the growing mode
// rattles contacts open and shut, and the ledger reads the energy created
// once friction's loss (the springs released at opening) is booked.
TEST(SphereStability, LanczosStepIsTheSharpStabilityLimitOfAPacking) {
  auto run = [](double factor, bool& stable, double& gershgorin_ratio, Divergence& flagged) {
    SphereWorld w = fcc_world(2, 1e-3, 0.0);
    relax(w, 20000);
    w.set_particle_friction(10.0);
    const StabilityEstimate e = w.stability_estimate();
    gershgorin_ratio = e.dt_stable_gershgorin / e.dt_stable;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double vamp = 0.01 * 2e-3 * kR * std::sqrt(1e8 / w.mass()[0]);
    for (int i = 0; i < w.size(); ++i)
      w.set_velocity(i, vamp * Vector3d(u(rng), u(rng), u(rng)),
                     vamp / kR * Vector3d(u(rng), u(rng), u(rng)));
    Integration in = sphere_test::set_undamped(w, 0.1);
    in.dt = factor * e.dt_stable;
    w.set_integration(in);
    const double e0 = w.measure().kinetic_energy_translation + w.measure().kinetic_energy_rotation;
    stable = w.step(20000);
    flagged = w.divergence();
    {
      const SphereMeasures mm = w.measure();
      std::printf(
          "FCC 2x2x2 sticking at %.2f x the Lanczos step (alpha %.3f): divergence %s, KE/KE0 "
          "%.2e, ledger %.2e, KE/elastic %.2e\n",
          factor, factor * e.dt_ratio_stable, to_string(w.divergence()),
          (mm.kinetic_energy_translation + mm.kinetic_energy_rotation) / e0, w.energy_created(),
          (mm.kinetic_energy_translation + mm.kinetic_energy_rotation) / mm.elastic_energy);
    }
    const SphereMeasures m = w.measure();
    if (stable) stable = m.kinetic_energy_translation + m.kinetic_energy_rotation < 1e3 * e0;
  };
  bool below = false, above = true;
  double g = 0.0;
  Divergence below_flag = Divergence::kNone, above_flag = Divergence::kNone;
  run(0.99, below, g, below_flag);
  run(1.01, above, g, above_flag);
  EXPECT_TRUE(below);
  EXPECT_FALSE(above);
  EXPECT_EQ(below_flag, Divergence::kNone);
  EXPECT_NE(above_flag, Divergence::kNone);
  std::printf("FCC 2x2x2 sticking: Gershgorin step / Lanczos step = %.3f\n", g);
  EXPECT_LE(g, 1.0 + 1e-12);
  EXPECT_GT(g, 0.2);  // and not uselessly small
}

// Contact dashpots are explicit and shorten the stable step (stability.cpp's
// file comment): the estimate is 2/ω·f(γ_max·ω/2), f(ζ) = sqrt(1 + ζ²) − ζ,
// γ_max = 2ζ_c·sqrt(m_eff/k) over the contacts — here a wall contact of one
// sphere (m_eff = m, the largest). Checked against that formula, and for
// safety: the vibrating packing of the test above with ζ_c = 0.5 stays
// bounded at 0.99 of it. (Not sharp: the dashpots act on the normal springs
// only, while the binding mode is rotational.)
TEST(SphereStability, ContactDashpotsShortenTheEstimatedStep) {
  const double zeta_c = 0.5;
  SphereMaterial mat = test_material(10.0);
  const SphereAssembly a = fcc_packing(2, 2, 2, kR, 1e-3);
  SphereWorld plain(mat, a.x, a.y, a.z, a.r, a.lo, a.hi);
  relax(plain, 20000);
  mat.contact_damping_ratio = zeta_c;
  SphereWorld w(mat, a.x, a.y, a.z, a.r, a.lo, a.hi);
  sphere_test::set_damped(w, 0.05, 1.0);  // α = 0.2 is beyond the dashpots' limit
  ASSERT_TRUE(w.step(80000));
  const StabilityEstimate e0 = plain.stability_estimate(), e = w.stability_estimate();
  const double m = w.mass()[0];
  const double gamma = 2.0 * zeta_c * std::sqrt(m / mat.wall.kn);
  const double omega = std::sqrt(e.omega2_max);
  const double f = std::sqrt(1.0 + 0.25 * gamma * gamma * omega * omega) - 0.5 * gamma * omega;
  EXPECT_NEAR(e.dt_stable, 2.0 / omega * f, 1e-12 * e.dt_stable);
  EXPECT_NEAR(e.omega2_max, e0.omega2_max, 1e-6 * e0.omega2_max);  // the same network
  EXPECT_LT(e.dt_stable, 0.9 * e0.dt_stable);                      // a real cut at ζ_c = 0.5
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double vamp = 0.01 * 2e-3 * kR * std::sqrt(1e8 / m);
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(i, vamp * Vector3d(u(rng), u(rng), u(rng)),
                   vamp / kR * Vector3d(u(rng), u(rng), u(rng)));
  Integration in = sphere_test::set_undamped(w, 0.1);
  in.dt = 0.99 * e.dt_stable;
  w.set_integration(in);
  EXPECT_TRUE(w.step(20000));
  EXPECT_EQ(w.divergence(), Divergence::kNone);
}

}  // namespace
}  // namespace demcal

namespace demcal {
namespace {

// The ledger books a moving wall's work every step: a wall that hits a
// resting sphere and throws it off within one sampling interval of the
// ledger (a contact lasts π/ω ≈ 16 steps here, the ledger samples every
// 128) does work the samples alone would miss — the sphere's energy would
// read as created (from a start with no energy at all, any amount is
// "everything"). Undamped, frictionless: the books balance to the scheme's
// error per collision, (ω·Δt)²/2 of the collision energy (test_sphere_gas.cpp).
TEST(SphereEnergy, MovingWallWorkIsBookedWithinASamplingInterval) {
  sphere_test::Scene s;
  s.add(Vector3d(5.0 * kR, 5.0 * kR, 8.999 * kR), kR);  // 0.001·r below the top wall
  s.lo = {0.0, 0.0, 0.0};
  s.hi = {10.0 * kR, 10.0 * kR, 10.0 * kR};
  SphereWorld w = s.make(sphere_test::test_material(0.0, 0.0));
  const Integration in = sphere_test::set_undamped(w, 0.1);
  // A slow drift along x: a little energy at the start, so that the ledger
  // has a scale to read against.
  w.set_velocity(0, Vector3d(1e-2, 0.0, 0.0), Vector3d::Zero());
  w.wall(kZMax).velocity = -0.5;  // reaches the sphere in ~40 steps
  int64_t steps = 0;
  while (w.wall(kZMax).velocity != 0.0 && steps < 2000) {
    ASSERT_TRUE(w.step(1)) << to_string(w.divergence());
    ++steps;
    if (w.vz()[0] < -0.9) w.wall(kZMax).velocity = 0.0;  // thrown off at ~2·|v_wall|
  }
  ASSERT_EQ(w.wall(kZMax).velocity, 0.0);
  // Past the collision and a bounce off the bottom wall, well beyond
  // several sampling intervals.
  ASSERT_TRUE(w.step(4000)) << to_string(w.divergence());
  const double h = std::sqrt(1e8 / w.mass()[0]) * in.dt;
  EXPECT_LE(std::abs(w.energy_created()), 0.5 * h * h);
  std::printf("wall throws a sphere: ledger %.2e (scheme bound %.2e)\n", w.energy_created(),
              0.5 * h * h);
}

// The kinetic-energy check weighs the spins as the velocities (the 2D
// kernel's KernelStability.TheKineticEnergyCheckWeighsSpinsAsVelocities): two
// frictionless spheres pressed together along (2, 3, 6)/7 hold E =
// ½·kn·δ²; one of them spun, or moved along the contact plane, with
// ½·I·|ω|² (or ½·m·|v|²) = f·1e3·E is a divergence at the next check for
// f = 2 and not for f = 0.5.
TEST(SphereStability, TheKineticEnergyCheckWeighsSpinsAsVelocities) {
  const double r = kR, delta = 1e-6;
  const Vector3d n = Vector3d(2.0, 3.0, 6.0) / 7.0, t = Vector3d(3.0, -2.0, 0.0).normalized();
  for (const bool spin : {true, false})
    for (const double f : {0.5, 2.0}) {
      SCOPED_TRACE(std::string(spin ? "spin" : "velocity") + " at " + std::to_string(f));
      sphere_test::Scene s;
      s.add(Vector3d::Zero(), r);
      s.add((2.0 * r - delta) * n, r);
      s.lo = {-10 * r, -10 * r, -10 * r};
      s.hi = {10 * r, 10 * r, 10 * r};
      KernelOptions options;
      options.check_interval = 1;
      SphereWorld w = s.make(sphere_test::test_material(0.0), options);
      sphere_test::set_undamped(w, 0.01);
      const double energy = w.measure().elastic_energy;
      ASSERT_NEAR(energy, 0.5 * w.material().particle.kn * delta * delta, 1e-6 * energy);
      ASSERT_TRUE(w.step(1));  // the kernel's energy scale: E
      const double ke = f * options.max_energy_ratio * energy;
      const double m = w.mass()[0], inertia = 0.4 * m * r * r;
      if (spin)
        w.set_velocity(0, Vector3d::Zero(), std::sqrt(2.0 * ke / inertia) * Vector3d(1, 2, 2) / 3);
      else
        w.set_velocity(0, std::sqrt(2.0 * ke / m) * t, Vector3d::Zero());
      const bool ran = w.step(1);
      EXPECT_EQ(ran, f < 1.0);
      EXPECT_EQ(w.divergence(), f < 1.0 ? Divergence::kNone : Divergence::kEnergy);
    }
}

// The unbalanced-force ratio of two spheres pressed together along (2, 3,
// 6)/7, the walls far: each sphere's net force is the one contact force,
// so the ratio is 1 (to round-off).
TEST(SphereStress, UnbalancedForceRatioOfALonePairIsOne) {
  const double r = kR;
  sphere_test::Scene s;
  s.add(Vector3d::Zero(), r);
  s.add((2.0 * r - 1e-6) * Vector3d(2.0, 3.0, 6.0) / 7.0, r);
  s.lo = {-10 * r, -10 * r, -10 * r};
  s.hi = {10 * r, 10 * r, 10 * r};
  const SphereWorld w = s.make(sphere_test::test_material(0.3));
  const SphereMeasures m = w.measure();
  ASSERT_EQ(m.particle_contacts, 1);
  ASSERT_EQ(m.wall_contacts, 0);
  EXPECT_NEAR(m.unbalanced_force_ratio, 1.0, 16 * kEps);
}

// A wall's springs store ½·Fn²/kn_w + ½·|h|²/kt_w with the wall's own
// stiffnesses (the 2D kernel's
// KernelEnergy.WallSpringsStoreTheirEnergyWithTheWallsStiffnesses): a
// sphere pressed 1e-6 m into the z-min wall and dragged 2e-7 m along x
// (mass scaling 1e15: the set velocity is the motion).
TEST(SphereEnergy, WallSpringsStoreTheirEnergyWithTheWallsStiffnesses) {
  SphereMaterial mat = test_material(0.3, 0.4);
  mat.wall.kn = 3e8;
  mat.wall.kt = 2e7;
  const double r = kR;
  SphereWorld w = sphere_test::sphere_on_wall(mat, kZMin, 1e-6, 10 * r);
  for (int k = 0; k < 200; ++k) {
    w.set_velocity(0, Vector3d(1e-3, 0.0, 0.0), Vector3d::Zero());
    ASSERT_TRUE(w.step(1));
  }
  const double overlap = r - (w.z()[0] - w.wall(kZMin).position);
  const double fn = mat.wall.kn * overlap, ft = -sphere_test::force(w, 0).x();
  ASSERT_NEAR(ft, mat.wall.kt * 2e-7, 1e-6 * mat.wall.kt * 2e-7);
  const double expected = 0.5 * fn * fn / mat.wall.kn + 0.5 * ft * ft / mat.wall.kt;
  EXPECT_NEAR(w.measure().elastic_energy, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace demcal
