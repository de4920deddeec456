// The sphere kernel's FCC peak against Thornton's analytical one
// (fcc_peak_ratio_walled in src/scene/sphere_packing.cpp derives it):
// a walled FCC cube of uniform frictional spheres, rotation locked,
// consolidated to σ3, then compressed axially at constant speed while the
// four lateral walls are servo-controlled at σ3. A minimal test-local
// driver, not the scene protocol.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "demcal/scene/sphere_packing.hpp"
#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

using sphere_test::kR;

// Stress on wall s (compression positive) [Pa].
double wall_stress(const SphereWorld& w, int s) {
  const int axis = s / 2;
  const double outward = (s % 2 == 0) ? -1.0 : 1.0;
  const double area = w.volume() / w.extent(axis);
  return outward * w.wall(static_cast<SphereWallSide>(s)).force[axis] / area;
}

// Servo: move wall s outward when its stress exceeds the target, at a
// speed that closes a fraction `gain` of the force error per step given the
// stiffness of its contacts (kn per contact).
void servo(SphereWorld& w, int s, double target, double gain) {
  const int axis = s / 2;
  const double outward = (s % 2 == 0) ? -1.0 : 1.0;
  const double area = w.volume() / w.extent(axis);
  SphereWall& wall = w.wall(static_cast<SphereWallSide>(s));
  const double stiffness = std::max(1, wall.contacts) * w.material().wall.kn;
  const double error = (wall_stress(w, s) - target) * area;  // force [N]
  wall.velocity = outward * gain * error / (stiffness * w.integration().dt);
}

// The energy ledger's largest reading while loading (energy created by the
// integration, relative to the energy scale; the kernel's divergence check
// trips at 0.1): a stable step at α = 0.2 creates none beyond the ledger's
// sampling error, measured ≤ 1.0e-6 in these runs.
constexpr double kLedgerBound = 1e-4;

struct TriaxialResult {
  double peak_ratio = 0.0;     // max of σ_zz/σ_xx (wall stresses)
  double peak_strain = 0.0;    // axial strain at the peak
  double lateral_error = 0.0;  // max |σ_lateral/σ3 − 1| up to the peak
  double consolidated = 0.0;   // mean wall stress after consolidation / σ3
  double ledger_max = -1e300;  // largest energy-ledger reading while loading
};

TriaxialResult run_fcc_triaxial(int nx, int ny, int nz, double mu, bool lock_rotation,
                                int64_t nstep) {
  const SphereAssembly a = fcc_packing(nx, ny, nz, kR);
  SphereMaterial mat = sphere_test::test_material(0.0, 0.0);
  SphereWorld w(mat, a.x, a.y, a.z, a.r, a.lo, a.hi);
  Integration in;
  in.damping_ratio_translation = 1.0;
  in.damping_ratio_rotation = 1.0;
  in.lock_rotation = lock_rotation;
  w.set_integration(in);
  in.dt = 0.2 * w.reference_scales().dt_crit;
  w.set_integration(in);
  // σ3 = 1e7 Pa: contact forces √2·r²·σ3 ≈ 3.5 N, overlaps ≈ 7e-5·r, so the
  // contact geometry barely moves (the elastic tilt of the inclined
  // contacts is of that order).
  const double s3 = 1e7;
  // Consolidation, frictionless: all walls but the bottom servo to σ3.
  for (int k = 0; k < 20000; ++k) {
    for (int s : {kXMin, kXMax, kYMin, kYMax, kZMax}) servo(w, s, s3, 0.1);
    EXPECT_TRUE(w.step(1));
  }
  TriaxialResult out;
  double mean = 0.0;
  for (int s = 0; s < 6; ++s) mean += wall_stress(w, s) / 6.0;
  out.consolidated = mean / s3;
  w.set_particle_friction(mu);
  for (int k = 0; k < 2000; ++k) {
    for (int s : {kXMin, kXMax, kYMin, kYMax, kZMax}) servo(w, s, s3, 0.1);
    EXPECT_TRUE(w.step(1));
  }
  // Axial compression: the top wall moves down to a strain of 5e-4 over
  // nstep steps (the peak comes near 2e-4).
  const double h0 = w.extent(2), strain_total = 5e-4;
  const double speed = strain_total * h0 / (static_cast<double>(nstep) * in.dt);
  w.wall(kZMax).velocity = -speed;
  for (int64_t k = 0; k < nstep; ++k) {
    for (int s : {kXMin, kXMax, kYMin, kYMax}) servo(w, s, s3, 0.1);
    if (!w.step(1)) {
      ADD_FAILURE() << "diverged: " << to_string(w.divergence());
      break;
    }
    out.ledger_max = std::max(out.ledger_max, w.energy_created());
    const double sxx = 0.5 * (wall_stress(w, kXMin) + wall_stress(w, kXMax));
    const double syy = 0.5 * (wall_stress(w, kYMin) + wall_stress(w, kYMax));
    const double szz = 0.5 * (wall_stress(w, kZMin) + wall_stress(w, kZMax));
    const double ratio = szz / (0.5 * (sxx + syy));
    if (std::getenv("SPHERE_TRIAXIAL_TRACE") && k % (nstep / 25) == 0)
      std::printf("  strain %.3e ratio %.4f sxx %.4f\n", 1.0 - w.extent(2) / h0, ratio, sxx / s3);
    if (ratio > out.peak_ratio) {
      out.peak_ratio = ratio;
      out.peak_strain = 1.0 - w.extent(2) / h0;
      out.lateral_error =
          std::max(out.lateral_error, std::max(std::abs(sxx / s3 - 1.0), std::abs(syy / s3 - 1.0)));
    }
  }
  return out;
}

// Rotation locked: within 2 % of the walled-cube value 2(1 + μ)/(1 − μ)
// (3.714 at μ = 0.3; for a cube the walls change nothing). The ratio rises
// to a plateau (the sliding regime) at the analytical value. Measured:
// 3.7152 (+0.02 %) at 40 000 steps, 3.7233 (+0.24 %) at 20 000 (4×4×4
// cells, 256 spheres: 3.7221, +0.21 %, at 40 000); the remaining
// differences are the loading rate and the elastic tilt of the contacts
// (~1e-4).
TEST(SphereTriaxial, FccPeakWithRotationLockedMatchesThornton) {
  const double mu = 0.3;
  const int n = 3;
  const double analytical = fcc_peak_ratio_walled(mu, n, n, n);
  EXPECT_NEAR(analytical, 2.0 * 1.3 / 0.7, 1e-12);
  const TriaxialResult r = run_fcc_triaxial(n, n, n, mu, true, 40000);
  std::printf(
      "FCC %dx%dx%d, mu %.2f, rotation locked: peak %.4f (analytical %.4f, %+.2f %%) at "
      "strain %.2e, consolidated %.4f sigma3, lateral error %.2e, ledger <= %.2e\n",
      n, n, n, mu, r.peak_ratio, analytical, 100.0 * (r.peak_ratio / analytical - 1.0),
      r.peak_strain, r.consolidated, r.lateral_error, r.ledger_max);
  EXPECT_NEAR(r.consolidated, 1.0, 1e-3);
  EXPECT_NEAR(r.peak_ratio, analytical, 0.02 * analytical);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

// The finite box's correction, run: in a 2×2×4 box (64 spheres) the walls
// carry a larger share of the lateral contacts than in a cube, and the
// walled value fcc_peak_ratio_walled is 18 % below the periodic 2(1 +
// μ)/(1 − μ) (3.034 against 3.714 at μ = 0.3), so the kernel's peak tells
// the two apart. Tolerance 1 %: the loading rate adds +0.24 % at 20 000
// steps on the cube (≈ 1/Nstep; here 40 000) and the contacts' elastic
// tilt ~1e-4; the correction itself is 18 times larger. Measured 3.034
// (−0.01 %); the 3×3×2 box gives 4.258 against 4.260.
TEST(SphereTriaxial, FccPeakInANonCubicBoxMatchesTheWalledValue) {
  const double mu = 0.3, periodic = 2.0 * 1.3 / 0.7;
  const double walled = fcc_peak_ratio_walled(mu, 2, 2, 4);
  ASSERT_LT(walled, 0.9 * periodic);
  const TriaxialResult r = run_fcc_triaxial(2, 2, 4, mu, true, 40000);
  std::printf(
      "FCC 2x2x4, mu %.2f, rotation locked: peak %.4f (walled %.4f, %+.2f %%; periodic "
      "%.4f) at strain %.2e, ledger <= %.2e\n",
      mu, r.peak_ratio, walled, 100.0 * (r.peak_ratio / walled - 1.0), periodic, r.peak_strain,
      r.ledger_max);
  EXPECT_NEAR(r.consolidated, 1.0, 1e-3);
  EXPECT_NEAR(r.peak_ratio, walled, 0.01 * walled);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

// Free rotation: the spheres can roll, which opens failure mechanisms the
// locked lattice does not have, so the peak cannot exceed the locked
// (analytical) one. Measured 3.178 at 40 000 steps, 14 % below (4×4×4:
// 3.327, 10 % below) — the 2D kernel's hexagonal samples show 10–15 %.
// A bound, not an analytical value: no closed form covers the rolling
// mechanisms, so rotation itself is checked by the contact tests (lever
// arms, torques, the history's turn) and here only the ordering and the
// energy ledger.
TEST(SphereTriaxial, FccPeakWithFreeRotationIsBelowTheLockedOne) {
  const double mu = 0.3;
  const int n = 3;
  const double analytical = fcc_peak_ratio_walled(mu, n, n, n);
  const TriaxialResult r = run_fcc_triaxial(n, n, n, mu, false, 40000);
  std::printf(
      "FCC %dx%dx%d, mu %.2f, free rotation: peak %.4f (%+.2f %% of the locked "
      "analytical %.4f) at strain %.2e, ledger <= %.2e\n",
      n, n, n, mu, r.peak_ratio, 100.0 * (r.peak_ratio / analytical - 1.0), analytical,
      r.peak_strain, r.ledger_max);
  EXPECT_GT(r.peak_ratio, 1.0);
  EXPECT_LT(r.peak_ratio, analytical);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

}  // namespace
}  // namespace demcal
