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

#include "demcal/kernel/particle_scales.hpp"
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
constexpr double kServoGain = 0.1;
void servo(SphereWorld& w, int s, double target, double gain = kServoGain) {
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
  double lateral_error = 0.0;  // max |σ_lateral/σ3 − 1| over the loading up to the peak
  double lateral_lag = 0.0;    // the servo's lag at the sliding rate (below), max up to the peak
  double drag = 0.0;           // the global damping's drag on the ratio at the peak (below)
  double tilt = 0.0;           // the largest overlap/r up to the peak
  double consolidated = 0.0;   // mean wall stress after consolidation / σ3
  double ledger_max = -1e300;  // largest energy-ledger reading while loading
};

// How fast the lateral walls must move. Rotation locked, the lattice deforms
// homogeneously. Up to the peak it is elastic: at constant σ3 the lateral
// strain rate is ν·|ε̇_z|, ν = 1/3 with the normal springs alone (the xz
// contacts (±a/2, 0, ±a/2) shorten by ε_x + ε_z, the xy ones by 2ε_x, and
// as many of each push on an x wall: ε_x + ε_z + 2ε_x = 0), less with the
// tangential ones. Sliding, every inclined contact keeps its length (ε_x +
// ε_z = ε_y + ε_z = 0) and the horizontal ones open: ε̇_x = ε̇_y = −ε̇_z,
// the fastest. So each of the two walls on a lateral axis moves at most at
// v = L_lat·|ε̇_z|/2, |ε̇_z| = speed/L_z.
//
// The servo's lag. The servo moves a wall at gain·ΔF/(N_w·kn_w·Δt) for a
// force error ΔF (N_w its contacts), so a wall that must move at v to hold
// σ3 does so with ΔF = v·N_w·kn_w·Δt/gain; the error follows the needed
// speed as a first-order lag (it closes ≤ gain = 0.1 of itself per step, no
// overshoot), so it stays below that value for the largest v:
//   |σ_lat/σ3 − 1| ≤ (L_lat·speed·Δt/(2·L_z))·N_w·kn_w/(gain·σ3·A_lat),
// A_lat = L_other·L_z the wall's area. On the 3×3×3 cube (N_w = 18) 0.25 %
// at 40 000 steps. The sliding rate is the rigid contacts' exactly; on
// top of it the elastic part, the overlaps' change (δ/r ≈ 1e-4), which on
// the plateau (the ratio moves by 0.03 % there) is far below 1 % of the
// sliding rate, allowed as kLagSlack. (Measured up to the plateau the
// elastic rate is 7 % of the sliding one: lateral error 1.8e-4.) Any
// mechanism that keeps the inclined contacts' lengths (rolling too) moves
// the walls at this rate. (The ratio the tests read divides by the
// measured lateral stresses, so this lag does not enter it.)
constexpr double kLagSlack = 0.01;
double lateral_lag(const SphereWorld& w, int s, double speed, double s3) {
  const int axis = s / 2, other = axis == 0 ? 1 : 0;
  const double L = w.extent(axis), Lz = w.extent(2), area = w.extent(other) * Lz;
  const double v = 0.5 * L * speed / Lz;
  const int contacts = w.wall(static_cast<SphereWallSide>(s)).contacts;
  return v * w.integration().dt * contacts * w.material().wall.kn / (kServoGain * s3 * area);
}

// The loading rate's effect on the ratio. The global damping (ζ = 1: D =
// 2·sqrt(kn·m) per sphere) drags every sphere by D·v against the
// deformation's velocity field. Vertically (v_z = −speed·(z − z_lo)/L_z)
// it sums to D·speed·N/2, which the top wall carries and the bottom one
// does not: the axial stress falls from top to bottom by d_z = D·speed·N/
// (2·A_z·σ_zz) of itself. Laterally (each wall at ≤ L_x·speed/(2·L_z), as
// above) the N/2 spheres of either half sum to D·N·speed·L_x/(8·L_z), by
// which the lateral stress at a wall is below the centre's: d_x = that/
// (A_x·σ3). The ratio the test reads (mean wall stresses) and the one
// where the sample first slides can thus differ by at most d_z + d_x: 0.20
// % + 0.19 % on the 3×3×3 cube at 40 000 steps, twice that at 20 000.
// Inertia: the inertial number ε̇·d·sqrt(ρ/σ3) ≈ 4e-6 at 40 000 steps, and
// its stresses go as its square. (Both lateral axes alike: d_x uses L_x,
// L_y for the y walls gives the same on the cube; the larger is taken.)
double damping_drag(const SphereWorld& w, double speed, double szz, double s3) {
  const int n = w.size();
  const double D = w.integration().damping_ratio_translation *
                   critical_damping_translation(w.material().particle.kn, w.mass()[0]);
  const double Lx = w.extent(0), Ly = w.extent(1), Lz = w.extent(2);
  const double dz = D * speed * n / (2.0 * Lx * Ly * szz);
  const double dx = D * n * speed * std::max(Lx / (Ly * Lz), Ly / (Lx * Lz)) / (8.0 * Lz * s3);
  return dz + dx;
}

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
    for (int s : {kXMin, kXMax, kYMin, kYMax, kZMax}) servo(w, s, s3);
    EXPECT_TRUE(w.step(1));
  }
  TriaxialResult out;
  double mean = 0.0;
  for (int s = 0; s < 6; ++s) mean += wall_stress(w, s) / 6.0;
  out.consolidated = mean / s3;
  w.set_particle_friction(mu);
  for (int k = 0; k < 2000; ++k) {
    for (int s : {kXMin, kXMax, kYMin, kYMax, kZMax}) servo(w, s, s3);
    EXPECT_TRUE(w.step(1));
  }
  // Axial compression: the top wall moves down to a strain of 5e-4 over
  // nstep steps (the ratio reaches its plateau near 3.6e-4).
  const double h0 = w.extent(2), strain_total = 5e-4;
  const double speed = strain_total * h0 / (static_cast<double>(nstep) * in.dt);
  w.wall(kZMax).velocity = -speed;
  double lateral_error = 0.0, lag = 0.0, overlap = 0.0;  // so far
  for (int64_t k = 0; k < nstep; ++k) {
    for (int s : {kXMin, kXMax, kYMin, kYMax}) servo(w, s, s3);
    if (!w.step(1)) {
      ADD_FAILURE() << "diverged: " << to_string(w.divergence());
      break;
    }
    out.ledger_max = std::max(out.ledger_max, w.energy_created());
    const double sxx = 0.5 * (wall_stress(w, kXMin) + wall_stress(w, kXMax));
    const double syy = 0.5 * (wall_stress(w, kYMin) + wall_stress(w, kYMax));
    const double szz = 0.5 * (wall_stress(w, kZMin) + wall_stress(w, kZMax));
    const double ratio = szz / (0.5 * (sxx + syy));
    if (k % 64 == 0)  // the overlaps change by < 1 % of themselves in 64 steps
      for (const auto& c : w.contacts()) overlap = std::max(overlap, c.overlap / kR);
    for (int s : {kXMin, kXMax, kYMin, kYMax}) {
      lateral_error = std::max(lateral_error, std::abs(wall_stress(w, s) / s3 - 1.0));
      lag = std::max(lag, lateral_lag(w, s, speed, s3));
    }
    if (std::getenv("SPHERE_TRIAXIAL_TRACE") && k % (nstep / 25) == 0)
      std::printf("  strain %.3e ratio %.4f sxx %.5f syy %.5f lag %.2e\n", 1.0 - w.extent(2) / h0,
                  ratio, sxx / s3, syy / s3, lag);
    if (ratio > out.peak_ratio) {
      out.peak_ratio = ratio;
      out.peak_strain = 1.0 - w.extent(2) / h0;
      out.lateral_error = lateral_error;
      out.lateral_lag = lag;
      out.drag = damping_drag(w, speed, szz, s3);
      out.tilt = overlap;
    }
  }
  return out;
}

// The peak's distance from the rigid-contact analytical value: the drag
// of the loading rate (damping_drag), and the elastic geometry. The
// overlaps (δ_max/r ≈ 2.6e-4 at the peak) strain the lattice by at most
// δ_max/(2r) along each axis, which turns the 45° inclined contacts by
// |ε_x − ε_z|/2 ≤ δ_max/(2r); a contact inclined at θ slides at σ_zz/σ_xx
// ∝ tan θ·(tan θ + μ)/(1 − μ·tan θ), whose logarithmic slope at 45° is 2
// + 2/(1 + μ) + 2μ/(1 − μ) = 4.4 at μ = 0.3: 2.2·δ_max/r. The walled
// value's factor L_z/L_x moves with the box by |ε_z − ε_x| ≤ δ_max/r
// more. Hence (drag + 3.2·δ_max/r) of the analytical value.
double peak_bound(const TriaxialResult& r) { return r.drag + 3.2 * r.tilt; }

// Rotation locked: the walled-cube value 2(1 + μ)/(1 − μ) (3.714 at μ =
// 0.3; for a cube the walls change nothing) within peak_bound, the loading
// rate's drag (0.39 % at 40 000 steps) and the elastic geometry (3.2·δ_max/r
// = 0.12 %): 0.51 % (the bar was 2 %). The ratio rises to a plateau
// (the sliding regime) at the analytical value. Measured 3.7152 (+0.025 %)
// at 40 000 steps on every SIMD path, 3.7233 (+0.24 %) at 20 000 (4×4×4
// cells, 256 spheres: 3.7221, +0.21 %, at 40 000): far inside the bound,
// as the drag's first-order part cancels in the mean of two opposite walls
// (d_z and d_x bound the spread inside the sample, which shows only where
// it makes some part slide first). A Coulomb cap 1 % high (1.01·μ·fn in
// the kernel: +0.66 % on the ratio) fails it; it passed the 2 %. The
// lateral walls hold σ3 to the servo's lag at the sliding rate (measured
// 2.470e-3 against 2.483e-3).
TEST(SphereTriaxial, FccPeakWithRotationLockedMatchesThornton) {
  const double mu = 0.3;
  const int n = 3;
  const double analytical = fcc_peak_ratio_walled(mu, n, n, n);
  EXPECT_NEAR(analytical, 2.0 * 1.3 / 0.7, 1e-12);
  const TriaxialResult r = run_fcc_triaxial(n, n, n, mu, true, 40000);
  const double bound = peak_bound(r);
  std::printf(
      "FCC %dx%dx%d, mu %.2f, rotation locked: peak %.4f (analytical %.4f, %+.3f %%; bound %.3f "
      "%% = drag %.3f %% + 3.2 x overlap/r %.2e) at strain %.2e, consolidated %.4f sigma3, "
      "lateral error %.3e (lag bound %.3e), ledger <= %.2e\n",
      n, n, n, mu, r.peak_ratio, analytical, 100.0 * (r.peak_ratio / analytical - 1.0),
      100.0 * bound, 100.0 * r.drag, r.tilt, r.peak_strain, r.consolidated, r.lateral_error,
      r.lateral_lag, r.ledger_max);
  EXPECT_NEAR(r.consolidated, 1.0, 1e-3);
  EXPECT_NEAR(r.peak_ratio, analytical, bound * analytical);
  EXPECT_LT(r.lateral_error, (1.0 + kLagSlack) * r.lateral_lag);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

// The finite box's correction, run: in a 2×2×4 box (64 spheres) the walls
// carry a larger share of the lateral contacts than in a cube, and the
// walled value fcc_peak_ratio_walled is 18 % below the periodic 2(1 +
// μ)/(1 − μ) (3.034 against 3.714 at μ = 0.3), so the kernel's peak tells
// the two apart. Tolerance peak_bound (0.60 % here), as on the cube; the
// correction itself is 30 times larger. Measured 3.0329 (−0.05 %), lateral
// error 1.37e-3 against the lag 1.68e-3; the 3×3×2 box gives 4.258 against
// 4.260.
TEST(SphereTriaxial, FccPeakInANonCubicBoxMatchesTheWalledValue) {
  const double mu = 0.3, periodic = 2.0 * 1.3 / 0.7;
  const double walled = fcc_peak_ratio_walled(mu, 2, 2, 4);
  ASSERT_LT(walled, 0.9 * periodic);
  const TriaxialResult r = run_fcc_triaxial(2, 2, 4, mu, true, 40000);
  std::printf(
      "FCC 2x2x4, mu %.2f, rotation locked: peak %.4f (walled %.4f, %+.2f %%; periodic "
      "%.4f; bound %.3f %%) at strain %.2e, lateral error %.3e (lag bound %.3e), ledger <= %.2e\n",
      mu, r.peak_ratio, walled, 100.0 * (r.peak_ratio / walled - 1.0), periodic,
      100.0 * peak_bound(r), r.peak_strain, r.lateral_error, r.lateral_lag, r.ledger_max);
  EXPECT_NEAR(r.consolidated, 1.0, 1e-3);
  EXPECT_NEAR(r.peak_ratio, walled, peak_bound(r) * walled);
  EXPECT_LT(r.lateral_error, (1.0 + kLagSlack) * r.lateral_lag);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

// Free rotation: the spheres can roll, which opens failure mechanisms the
// locked lattice does not have, so the peak cannot exceed the locked
// (analytical) one. Measured 3.178 at 40 000 steps, 14 % below (4×4×4:
// 3.327, 10 % below) — the 2D kernel's hexagonal samples show 10–15 %.
// A bound, not an analytical value: no closed form covers the rolling
// mechanisms, so rotation itself is checked by the contact tests (lever
// arms, torques, the history's turn) and here only the ordering, the
// energy ledger and the lateral servo's lag (measured 2.475e-3 against
// 2.482e-3: rolling keeps the contacts' lengths as sliding does).
TEST(SphereTriaxial, FccPeakWithFreeRotationIsBelowTheLockedOne) {
  const double mu = 0.3;
  const int n = 3;
  const double analytical = fcc_peak_ratio_walled(mu, n, n, n);
  const TriaxialResult r = run_fcc_triaxial(n, n, n, mu, false, 40000);
  std::printf(
      "FCC %dx%dx%d, mu %.2f, free rotation: peak %.4f (%+.2f %% of the locked "
      "analytical %.4f) at strain %.2e, lateral error %.3e (lag bound %.3e), ledger <= %.2e\n",
      n, n, n, mu, r.peak_ratio, 100.0 * (r.peak_ratio / analytical - 1.0), analytical,
      r.peak_strain, r.lateral_error, r.lateral_lag, r.ledger_max);
  EXPECT_GT(r.peak_ratio, 1.0);
  EXPECT_LT(r.peak_ratio, analytical);
  EXPECT_LT(r.lateral_error, (1.0 + kLagSlack) * r.lateral_lag);
  EXPECT_LT(r.ledger_max, kLedgerBound);
}

}  // namespace
}  // namespace demcal
