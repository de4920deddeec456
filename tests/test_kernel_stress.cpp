// Stress measures (README.md "Physics in one paragraph"), tension positive,
// origin at the box centre:
//   b_ij = (1/V) Σ_{wall contacts} x^c_i f^c_j,
//   σ_ij = (1/V) Σ_p Σ_{c∈p} (x^c − x^p)_i f^c_j.
// Exact identities, for any state (pair contacts cancel in Σ x^c ⊗ f^c):
//   V·(b − σ) = Σ_p (x^p − x_0) ⊗ F_p          (F_p net force on p),
//   V·(σ_xy − σ_yx) = Σ_p M_p                   (M_p net moment on p).
// So a static packing (F_p = 0, M_p = 0) has b = σ and a symmetric σ.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_kernel_helpers.hpp"

namespace demcal {
namespace {

using kernel_test::kEps;

double max_abs(const Eigen::Matrix2d& m) { return m.cwiseAbs().maxCoeff(); }

// Round-off scale of the identity: every term of the three sums is bounded
// by (distance from the centre) × |contact force|; each particle's net
// force is a sum of its contact forces. A sum of n terms carries at most
// n·ε·Σ|terms| of round-off (the standard recursive-summation bound), so
// |V(b − σ) − Σ x^p ⊗ F_p| ≤ n·ε·S with S below and n = particles +
// contacts.
struct RoundOff {
  double scale = 0.0;   // S/V [Pa]
  double torque = 0.0;  // Σ_c (arm)·|f_c| / V [Pa]
  int terms = 0;
};

RoundOff round_off(const World& w) {
  RoundOff out;
  const Eigen::Vector2d c = w.centre();
  double rmax = 0.0, reach = 0.0;
  for (int i = 0; i < w.size(); ++i) {
    rmax = std::max(rmax, w.radius()[i]);
    reach = std::max(reach, std::hypot(w.x()[i] - c.x(), w.y()[i] - c.y()));
  }
  reach += rmax;  // contact points lie within a radius of their particle
  double sum_f = 0.0;
  int count = 0;
  for (const auto& k : w.contacts()) {
    sum_f += std::hypot(k.fn, k.ft);
    ++count;
  }
  // Wall contacts: |f| ≤ kn_w·δ·sqrt(1 + μ_w²).
  const Material& mat = w.material();
  for (int i = 0; i < w.size(); ++i) {
    const double r = w.radius()[i];
    const double ov[4] = {
        r - (w.x()[i] - w.wall(kLeft).position), r - (w.wall(kRight).position - w.x()[i]),
        r - (w.y()[i] - w.wall(kBottom).position), r - (w.wall(kTop).position - w.y()[i])};
    for (double o : ov)
      if (o > 0.0) {
        sum_f += mat.wall.kn * o * std::sqrt(1.0 + mat.wall.friction * mat.wall.friction);
        ++count;
      }
  }
  // Three sums (b, σ, Σ x^p ⊗ F_p), each taking every contact force at most
  // twice, at a lever of at most `reach`.
  out.scale = 3.0 * reach * 2.0 * sum_f / w.volume();
  out.torque = 2.0 * rmax * sum_f / w.volume();
  out.terms = w.size() + count;
  return out;
}

double net_torque(const World& w) {
  double s = 0.0;
  for (int i = 0; i < w.size(); ++i) s += w.torque()[i];
  return s;
}

double moment_bound(const World& w) {
  // Σ_p |x^p − x_0|·|F_p|/V bounds |b − σ| through the identity.
  const Eigen::Vector2d c = w.centre();
  double s = 0.0;
  for (int i = 0; i < w.size(); ++i)
    s += std::hypot(w.x()[i] - c.x(), w.y()[i] - c.y()) * std::hypot(w.fx()[i], w.fy()[i]);
  return s / w.volume();
}

double abs_torque_sum(const World& w) {
  double s = 0.0;
  for (int i = 0; i < w.size(); ++i) s += std::abs(w.torque()[i]);
  return s;
}

// b from the wall forces alone (frictionless walls): the mean wall stress of
// each pair of opposite walls, compression negative.
void expect_boundary_stress_is_wall_stress(const World& w, const Measures& m, double tol) {
  const double t = w.material().thickness;
  const double bxx = (w.wall(kLeft).force.x() - w.wall(kRight).force.x()) / (2.0 * w.height() * t);
  const double byy = (w.wall(kBottom).force.y() - w.wall(kTop).force.y()) / (2.0 * w.width() * t);
  EXPECT_NEAR(m.boundary_stress(0, 0), bxx, tol);
  EXPECT_NEAR(m.boundary_stress(1, 1), byy, tol);
}

TEST(KernelStress, StaticFrictionalPackingHasBoundaryEqualHomogenizedAndSymmetricStress) {
  auto scene = kernel_test::random_loose_scene(8, 8, 3);
  World w = scene.make(kernel_test::reference_material(0.3));
  kernel_test::compact(w, 0.84, 0.3, 0);
  // Relax with the walls fixed and critical damping until static.
  w.step(20000);
  const Measures m = w.measure();
  ASSERT_GT(m.particle_contacts, 100);
  const double s = max_abs(m.homogenized_stress);
  ASSERT_GT(s, 1e5);  // jammed: about 2 MPa
  const RoundOff ro = round_off(w);
  const double tol = ro.terms * kEps * ro.scale;
  // Static to 1e-6: the residual net forces and moments, carried to the
  // stress scale by the identities (Σ|x^p − x_0|·|F_p|/V and Σ|M_p|/V),
  // are below 1e-6 of σ. (The relaxation gets them far lower; 1e-6 is what
  // a calibration would call static.)
  EXPECT_LT(moment_bound(w), 1e-6 * s);
  EXPECT_LT(abs_torque_sum(w) / w.volume(), 1e-6 * s);
  // The identities then bound the differences by exactly those sums (plus
  // round-off): b = σ component by component, σ symmetric.
  const Eigen::Matrix2d gap = m.boundary_stress - m.homogenized_stress;
  EXPECT_LE(max_abs(gap), moment_bound(w) + tol);
  const double asym = m.homogenized_stress(0, 1) - m.homogenized_stress(1, 0);
  EXPECT_LE(std::abs(asym), abs_torque_sum(w) / w.volume() + ro.terms * kEps * ro.torque);
  EXPECT_LT(max_abs(gap), 1e-6 * s);
  EXPECT_LT(std::abs(asym), 1e-6 * s);
  // The assembly is in equilibrium as a whole: the wall forces have no net
  // moment about the centre, so b is symmetric too. V·(b_xy − b_yx) is that
  // moment, Σ_p (M_p + (x^p − x_0) × F_p).
  EXPECT_LE(std::abs(m.boundary_stress(0, 1) - m.boundary_stress(1, 0)),
            abs_torque_sum(w) / w.volume() + moment_bound(w) + tol);
  // Compressive (tension positive), and b is the wall stress.
  EXPECT_LT(m.homogenized_stress(0, 0), -0.1 * s);
  EXPECT_LT(m.homogenized_stress(1, 1), -0.1 * s);
  expect_boundary_stress_is_wall_stress(w, m, tol);
}

TEST(KernelStress, NetForceMomentIdentityHoldsToRoundOffDuringDynamicRun) {
  auto scene = kernel_test::random_loose_scene(10, 10, 5);
  World w = scene.make(kernel_test::reference_material(0.3));
  kernel_test::compact(w, 0.84, 0.3, 2000);
  // Fast, lightly damped shear: top wall down, side walls out, 1e-3 r per step.
  Integration in = w.integration();
  in.damping_ratio_translation = 0.05;
  in.damping_ratio_rotation = 0.05;
  w.set_integration(in);
  const double v = 1e-3 * kernel_test::kR / in.dt;
  w.wall(kTop).velocity = -v;
  w.wall(kLeft).velocity = -0.3 * v;
  w.wall(kRight).velocity = 0.3 * v;
  double largest_gap = 0.0, largest_asym = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(w.step(20));
    const Measures m = w.measure();
    const RoundOff ro = round_off(w);
    const double tol = ro.terms * kEps * ro.scale;
    const Eigen::Matrix2d gap = m.boundary_stress - m.homogenized_stress;
    const Eigen::Matrix2d moment = w.net_force_moment();
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) EXPECT_NEAR(gap(a, b), moment(a, b), tol) << a << b;
    const double asym = m.homogenized_stress(0, 1) - m.homogenized_stress(1, 0);
    EXPECT_NEAR(asym, net_torque(w) / w.volume(), ro.terms * kEps * ro.torque);
    expect_boundary_stress_is_wall_stress(w, m, tol);
    largest_gap = std::max(largest_gap, max_abs(gap) / tol);
    largest_asym = std::max(largest_asym, std::abs(asym) / (ro.terms * kEps * ro.torque));
  }
  // The run is genuinely dynamic: the identities are tested on differences
  // many orders of magnitude above their round-off tolerance.
  EXPECT_GT(largest_gap, 1e6);
  EXPECT_GT(largest_asym, 1e6);
}

// The unbalanced-force ratio mean|F_net|/mean|f_c| of two disks pressed
// together along (0.6, 0.8), the walls far: each disk's net force is the
// one contact force, so the ratio is 1, along whatever direction the pair
// lies. To the round-off of the overlap: the force pass and measure() each
// compute δ = (r_i + r_j) − d, on different paths (the SIMD pass may fuse
// d² into FMAs), an ulp or so of d apart, i.e. 8ε·(r_i + r_j)/δ of fn.
TEST(KernelStress, UnbalancedForceRatioOfALonePairIsOne) {
  const double r = kernel_test::kR, delta = 1e-6, d = 2.0 * r - delta;
  const std::vector<double> x{0.0, 0.6 * d}, y{0.0, 0.8 * d}, rad{r, r};
  const World w(kernel_test::reference_material(0.3), x, y, rad, -10 * r, 10 * r, -10 * r, 10 * r);
  const Measures m = w.measure();
  ASSERT_EQ(m.particle_contacts, 1);
  ASSERT_EQ(m.wall_contacts, 0);
  EXPECT_NEAR(m.unbalanced_force_ratio, 1.0, 8.0 * kEps * 2.0 * r / delta);
}

}  // namespace
}  // namespace demcal
