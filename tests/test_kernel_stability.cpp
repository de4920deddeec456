// Stable-step estimates (World::stability_estimate) and divergence detection.
//
// The undamped central-difference scheme is stable iff ω_max·Δt < 2, ω²_max
// the largest eigenvalue of A = M^-½·K·M^-½ (K: stiffness of the contact
// network, translations and rotations coupled); with the global damping of
// src/kernel/solver.cpp the boundary is the same (the characteristic polynomial at
// z = −1 is 4 − ω²Δt², independent of the damping). In units of
// Δt_crit = 2·sqrt(m/kn): α_stable = 1/sqrt(λ), λ = ω²_max·m/kn.
#include <gtest/gtest.h>

// GCC's -Wmaybe-uninitialized misfires inside Eigen's tridiagonalisation at
// -O3 (a false positive in the library, not in this file).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Dense>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "support/pair_stability.hpp"
#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kEps;

// Dense M^-½·K·M^-½ of the current contact network, built from the contact
// kinematics: the contact point of j moves relative to i's by
//   Δ = u_j − u_i − (a_i·θ_i + a_j·θ_j)·t,  a = r − δ/2,
// (for a wall, Δ = u_i − dist·θ_i·t), and the contact stores
// ½·kn·(Δ·n)² + ½·kt·(Δ·t)². A sliding contact can stick again, so kt counts
// whenever the friction coefficient is positive (as in the kernel).
Eigen::MatrixXd dense_dynamical_matrix(const World& w, bool rotation) {
  const int n = w.size(), dofs = 3 * n;
  const Material& mat = w.material();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dofs, dofs);
  auto add = [&](const Eigen::VectorXd& b, double k) { K += k * b * b.transpose(); };
  const double kt = mat.particle.friction > 0.0 ? mat.particle.kt : 0.0;
  for (const auto& c : w.contacts()) {
    const double tx = -c.ny, ty = c.nx;
    const double ai = w.radius()[c.i] - 0.5 * c.overlap, aj = w.radius()[c.j] - 0.5 * c.overlap;
    Eigen::VectorXd bn = Eigen::VectorXd::Zero(dofs), bt = bn;
    bn[3 * c.i] = -c.nx;
    bn[3 * c.i + 1] = -c.ny;
    bn[3 * c.j] = c.nx;
    bn[3 * c.j + 1] = c.ny;
    bt[3 * c.i] = -tx;
    bt[3 * c.i + 1] = -ty;
    bt[3 * c.j] = tx;
    bt[3 * c.j + 1] = ty;
    bt[3 * c.i + 2] = -ai;
    bt[3 * c.j + 2] = -aj;
    add(bn, mat.particle.kn);
    add(bt, kt);
  }
  const double ktw = mat.wall.friction > 0.0 ? mat.wall.kt : 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = w.radius()[i];
    // inward normal g and centre distance to each wall
    const double g[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    const double dist[4] = {w.x()[i] - w.wall(kLeft).position, w.wall(kRight).position - w.x()[i],
                            w.y()[i] - w.wall(kBottom).position, w.wall(kTop).position - w.y()[i]};
    for (int s = 0; s < 4; ++s) {
      if (dist[s] >= r) continue;
      Eigen::VectorXd bn = Eigen::VectorXd::Zero(dofs), bt = bn;
      bn[3 * i] = g[s][0];
      bn[3 * i + 1] = g[s][1];
      bt[3 * i] = -g[s][1];
      bt[3 * i + 1] = g[s][0];
      bt[3 * i + 2] = -dist[s];
      add(bn, mat.wall.kn);
      add(bt, ktw);
    }
  }
  // Keep the requested dofs and scale by M^-½.
  std::vector<int> keep;
  Eigen::VectorXd scale(dofs);
  for (int i = 0; i < n; ++i) {
    const double m = w.mass()[i], inertia = 0.5 * m * w.radius()[i] * w.radius()[i];
    scale[3 * i] = scale[3 * i + 1] = 1.0 / std::sqrt(m);
    scale[3 * i + 2] = 1.0 / std::sqrt(inertia);
    keep.push_back(3 * i);
    keep.push_back(3 * i + 1);
    if (rotation) keep.push_back(3 * i + 2);
  }
  const int nk = static_cast<int>(keep.size());
  Eigen::MatrixXd A(nk, nk);
  for (int p = 0; p < nk; ++p)
    for (int q = 0; q < nk; ++q) A(p, q) = scale[keep[p]] * K(keep[p], keep[q]) * scale[keep[q]];
  return A;
}

World jammed_packing(int nx, int ny, uint32_t seed, double mu, double wall_mu) {
  auto scene = kernel_test::random_loose_scene(nx, ny, seed);
  World w = scene.make(kernel_test::reference_material(mu, wall_mu));
  kernel_test::compact(w, 0.84, mu, 2000);
  return w;
}

TEST(KernelStability, LanczosEstimateMatchesDenseEigenSolveAndGershgorinBoundsIt) {
  // Frictional particles and walls: every coupling of the network is present.
  World w = jammed_packing(6, 6, 21, 0.3, 0.2);
  ASSERT_GT(w.measure().particle_contacts, 50);
  const StabilityEstimate est = w.stability_estimate(400);  // ≥ dofs: complete Krylov space
  for (bool rotation : {true, false}) {
    const Eigen::MatrixXd A = dense_dynamical_matrix(w, rotation);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A, Eigen::EigenvaluesOnly);
    const double lmax = es.eigenvalues().maxCoeff();
    // Lanczos over the whole Krylov space: its largest Ritz value is the
    // largest eigenvalue up to the round-off of the recurrence, at most
    // (iterations)·ε·‖A‖ ≈ 400·2.2e-16 ≈ 1e-13 relative (loss of
    // orthogonality only duplicates converged values, it never moves them
    // past the spectrum); the dense solver is accurate to a few ε·‖A‖.
    const double lanczos =
        rotation
            ? est.omega2_max
            : std::pow(2.0 / (est.dt_ratio_stable_translation * w.reference_scales().dt_crit), 2);
    EXPECT_NEAR(lanczos, lmax, 1e-12 * lmax) << "rotation " << rotation;
    if (rotation) {
      // Gershgorin: the kernel sums |A| contact by contact, an upper bound
      // of the row sums of |A| itself, which bound every eigenvalue.
      double row_max = 0.0;
      for (int p = 0; p < A.rows(); ++p) row_max = std::max(row_max, A.row(p).cwiseAbs().sum());
      EXPECT_GE(est.omega2_gershgorin, row_max * (1.0 - 1e-12));
      EXPECT_GE(row_max, lmax);
      EXPECT_GE(est.omega2_gershgorin, est.omega2_max);
      // dt_stable is 2/ω_max, in units of dt_crit.
      EXPECT_NEAR(est.dt_ratio_stable, 2.0 / std::sqrt(lmax) / w.reference_scales().dt_crit, 1e-9);
    }
  }
}

// Two disks in contact, no walls (the 3D kernel's
// SphereStability.ContactPairEstimateMatchesEigenvalues). The linearised
// pair has, for the normal, ω² = 2kn/m; for the tangent t, the mode of the
// tangential spring with both translations and spins, b = (−t, −a, t, −a)
// over (u_0, θ_0, u_1, θ_1): ω² = kt·|M^-½ b|² = (2kt/m)·(1 + a²·m/I) =
// (2kt/m)·(1 + 2a²/r²), a = r − δ/2. With rotation locked only
// translations: max(2kn/m, 2kt/m). Gershgorin must stay above: with the
// branch along an axis its rows are nearest to the eigenvalue (the spin
// rows' sum (kt/m)·(2√2 + 4) = 6.83·kt/m against 6·kt/m), with a skewed
// branch the tangent's components spread over both axes and loosen it.
TEST(KernelStability, ContactPairEstimateMatchesEigenvalues) {
  const double r = kernel_test::kR, delta = 1e-6;
  for (const double angle : {0.0, 0.6}) {
    SCOPED_TRACE(angle);
    const double d = 2.0 * r - delta;
    const std::vector<double> x{0.0, d * std::cos(angle)}, y{0.0, d * std::sin(angle)}, rad{r, r};
    World w(kernel_test::reference_material(0.3), x, y, rad, -10 * r, 10 * r, -10 * r, 10 * r);
    const double m = w.mass()[0], kn = w.material().particle.kn, kt = w.material().particle.kt;
    const double a = r - 0.5 * delta;
    const double w2_rot = 2.0 * kt / m * (1.0 + 2.0 * a * a / (r * r));
    const double w2_trans = std::max(2.0 * kn / m, 2.0 * kt / m);
    test::expect_pair_estimate(w.stability_estimate(), w2_rot, w2_trans,
                               w.reference_scales().dt_crit, m, kn);
  }
}

// Hexagonal packing, kt = kn/2: the in-phase rotation of all disks loads
// every contact tangentially by 2a·θ (a = r − δ/2 = r(1 − ε)), six contacts
// give the moment 12·kt·a²·θ, I = m·r²/2, so ω² = 24·kt·(1 − ε)²/m =
// 12·(1 − ε)²·kn/m: α_rot = 1/(sqrt(12)·(1 − ε)) ≈ 0.2889 (1/sqrt(12)
// without pre-strain). In the infinite lattice this mode is the top of the
// spectrum (a dense solve of the periodic lattice gives exactly 12, the
// translational branches end near 7). With walls, the boundary disks have
// fewer contacts and the top mode is this rotation under an envelope that
// vanishes near the walls: ω²(n) = ω²_∞·(1 − C/n² + O(n⁻³)) for n×n disks,
// so α(n) = α_∞·(1 + C'/n² + O(n⁻³)).
TEST(KernelStability, HexPackingRotationLimitConvergesToOneOverSqrt12) {
  const double eps = 1e-3;
  const double alpha_inf = 1.0 / (std::sqrt(12.0) * (1.0 - eps));
  auto estimate = [&](int n, int iterations) {
    auto scene = kernel_test::hex_scene(n, n, eps);
    World w = scene.make(kernel_test::reference_material(0.3));
    Integration in;
    in.dt = 0.1 * w.reference_scales().dt_crit;
    w.set_integration(in);
    w.update_forces();
    const StabilityEstimate e = w.stability_estimate(iterations);
    EXPECT_GE(e.omega2_gershgorin, e.omega2_max);
    EXPECT_GT(e.dt_ratio_stable_translation, e.dt_ratio_stable);  // rotation binds
    return e.dt_ratio_stable;
  };
  const double a16 = estimate(16, 300), a32 = estimate(32, 300);
  // Converges from above (the boundary only softens the rotation).
  EXPECT_GT(a16, a32);
  EXPECT_GT(a32, alpha_inf);
  // Richardson: removing the n⁻² term leaves the O(n⁻³) one. Its size,
  // 2C'·δ_b/n³ for a boundary layer δ_b of about one lattice spacing
  // (C' ≈ 1.1 from the two sizes), amplified by the extrapolation,
  // is ≈ 2C'·δ_b·(1/32 − 1/16)/(32² − 16²) ≈ 1e-4 at δ_b = 1.
  const double extrapolated = (32.0 * 32.0 * a32 - 16.0 * 16.0 * a16) / (32.0 * 32.0 - 16.0 * 16.0);
  EXPECT_NEAR(extrapolated / alpha_inf, 1.0, 1e-4);
  // The Lanczos value has converged: more iterations do not change it
  // (its top Ritz value can only grow with the iteration count).
  const double a32_long = estimate(32, 1000);
  EXPECT_LE(a32_long, a32 * (1.0 + 1e-12));
  EXPECT_NEAR(a32_long, a32, 1e-6 * a32);
}

// A jammed frictional packing at rest, shaken slightly, stepped at a given
// fraction of the estimated limit.
struct Shaken {
  World world;
  explicit Shaken(double mu = 0.3) : world(jammed_packing(6, 6, 31, mu, 0.0)) {
    const double vamp = 1e-3;  // m/s: displacements ~ vamp/ω0 ≈ 5e-9 m, 1e-3 of the overlaps
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < world.size(); ++i)
      world.set_velocity(i, vamp * u(rng), vamp * u(rng), vamp * u(rng) / kernel_test::kR);
  }
  StabilityEstimate estimate() const { return world.stability_estimate(); }
  void set(double dt, double zeta, bool lock = false) {
    Integration in;
    in.dt = dt;
    in.damping_ratio_translation = zeta;
    in.damping_ratio_rotation = zeta;
    in.lock_rotation = lock;
    world.set_integration(in);
  }
};

TEST(KernelStability, RunBelowEstimatedLimitStaysBounded) {
  for (double zeta : {0.0, 1.0}) {
    SCOPED_TRACE(zeta);
    Shaken s;
    World& w = s.world;
    const StabilityEstimate est = s.estimate();
    s.set(0.95 * est.dt_ratio_stable * w.reference_scales().dt_crit, zeta);
    const double e_rest = w.measure().elastic_energy;
    const kernel_test::Energies e0 = kernel_test::synchronized_energies(w);
    const double e_vib = e0.total() - e_rest;
    // Linear theory (see test_kernel_energy.cpp): undamped, |E − E0| ≤ κ·E_vib
    // with q = ω_max·Δt/2 = 0.95, κ = q²/(1 − q²) ≈ 9.3; damping and sliding
    // only dissipate. An unstable mode would grow without bound instead.
    const double q = 0.95, kappa = q * q / (1.0 - q * q);
    double worst = 0.0;
    for (int k = 0; k < 200; ++k) {
      ASSERT_TRUE(w.step(100)) << to_string(w.divergence());
      const kernel_test::Energies e = kernel_test::synchronized_energies(w);
      worst = std::max(worst, (e.total() - e0.total()) / e_vib);
    }
    EXPECT_EQ(w.divergence(), Divergence::kNone);
    EXPECT_EQ(w.divergence_step(), -1);
    EXPECT_LE(worst, kappa);
  }
}

// Above the limit the top mode grows by |z| per step, z the root of
// z² − (2 − ω²Δt²)z + 1 outside the unit circle (|z| ≈ 1.88 at 1.05×, 6.9 at
// 1.5×), from the ~1e-9 m of the shaking to the 0.5·r overlap criterion in
// a few dozen steps: detection must come within a few check intervals.
void expect_diverges_quickly(World& w) {
  const int64_t before = w.steps_taken();
  EXPECT_FALSE(w.step(10000000));
  EXPECT_NE(w.divergence(), Divergence::kNone);
  EXPECT_GT(w.divergence_step(), before);
  EXPECT_LT(w.steps_taken() - before, 2000);
  EXPECT_EQ(w.divergence_step(), w.steps_taken());
  EXPECT_FALSE(w.step(1));  // stays stopped
}

// The estimate is the limit itself, not a safety margin: 5 % above it the
// undamped run blows up. This holds where the contact network is linear:
// frictionless, or friction high enough that nothing slides (μ = 10).
// (Not asserted, because it does not happen: with sliding friction, or with
// global damping, the growing mode saturates instead — at the Coulomb cap,
// or where contacts open every other step and the damping absorbs what the
// instability feeds in — into a bounded period-two chatter that the
// divergence criteria do not flag. On this packing, 10⁵ steps at 1.05× the
// limit end with KE ≈ 3 % of the elastic energy at ζ = 0.3 or 1, at 1.5×
// with KE ≈ 65 % at ζ = 1, and with μ = 0.3 undamped, spins of ω·r ≈ 3 m/s
// on lightly loaded disks; none is reported as diverged.)
TEST(KernelStability, UndampedRunJustAboveEstimatedLimitDiverges) {
  for (double mu : {0.0, 10.0}) {
    Shaken s(mu);
    const StabilityEstimate est = s.estimate();
    s.set(1.05 * est.dt_ratio_stable * s.world.reference_scales().dt_crit, 0.0);
    SCOPED_TRACE(testing::Message() << "mu " << mu);
    expect_diverges_quickly(s.world);
  }
}

TEST(KernelStability, RunWellAboveTranslationalLimitIsReportedDivergedWithoutHanging) {
  for (bool lock : {false, true}) {
    Shaken s;
    const StabilityEstimate est = s.estimate();
    s.set(1.5 * est.dt_ratio_stable_translation * s.world.reference_scales().dt_crit, 0.0, lock);
    SCOPED_TRACE(lock);
    expect_diverges_quickly(s.world);
  }
}

// The kinetic-energy check (KernelOptions::max_energy_ratio) weighs the
// spins as the velocities: a kinetic energy beyond that ratio of the largest
// energy the springs have held is an unstable mode growing, whether it
// turns or moves. Two frictionless disks pressed together along (0.6, 0.8)
// hold E = ½·kn·δ² and nothing else; one of them is then given a spin of
// ½·I·ω² = f·1e3·E (frictionless: the spin touches nothing else). f = 2 is
// a divergence at the next check, f = 0.5 is not; a velocity of the same
// energy, along the contact plane, reads the same.
TEST(KernelStability, TheKineticEnergyCheckWeighsSpinsAsVelocities) {
  const double r = kernel_test::kR, delta = 1e-6;
  const Material mat = kernel_test::reference_material(0.0);
  const double d = 2.0 * r - delta;
  const std::vector<double> x{0.0, 0.6 * d}, y{0.0, 0.8 * d}, rad{r, r};
  for (const bool spin : {true, false})
    for (const double f : {0.5, 2.0}) {
      SCOPED_TRACE(std::string(spin ? "spin" : "velocity") + " at " + std::to_string(f));
      KernelOptions options;
      options.check_interval = 1;
      World w(mat, x, y, rad, -10 * r, 10 * r, -10 * r, 10 * r, options);
      Integration in;
      in.dt = 0.01 * w.reference_scales().dt_crit;
      in.damping_ratio_translation = in.damping_ratio_rotation = 0.0;
      w.set_integration(in);
      const double energy = w.measure().elastic_energy;
      ASSERT_NEAR(energy, 0.5 * mat.particle.kn * delta * delta, 1e-6 * energy);
      ASSERT_TRUE(w.step(1));  // the kernel's energy scale: E
      const double ke = f * options.max_energy_ratio * energy;
      const double m = w.mass()[0], inertia = 0.5 * m * r * r;
      if (spin)
        w.set_velocity(0, 0.0, 0.0, std::sqrt(2.0 * ke / inertia));
      else
        w.set_velocity(0, -0.8 * std::sqrt(2.0 * ke / m), 0.6 * std::sqrt(2.0 * ke / m), 0.0);
      // The measured kinetic energy is that energy: the spin's ½·I·ω² (I =
      // m·r²/2), or ½·m·|v|² and the other disk's from the first step (8e-7
      // of it at f = 0.5).
      const Measures ms = w.measure();
      EXPECT_NEAR(spin ? ms.kinetic_energy_rotation : ms.kinetic_energy_translation, ke, 2e-6 * ke);
      const bool ran = w.step(1);
      EXPECT_EQ(ran, f < 1.0);
      EXPECT_EQ(w.divergence(), f < 1.0 ? Divergence::kNone : Divergence::kEnergy);
    }
}

}  // namespace
}  // namespace demcal
