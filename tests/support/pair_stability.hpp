// Test support: a contact pair's stable-step estimate against its exact
// eigenvalues, for the stability tests of both kernels
// (test_kernel_stability.cpp, test_sphere_kernel.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "demcal/kernel/world.hpp"  // StabilityEstimate

namespace demcal::test {

/// Checks the estimate `e` of two equal particles of mass `m` in contact
/// (normal stiffness `kn`), whose largest mode is the tangential spring's
/// with both spins, ω² = `w2_rot`, and whose largest with the rotation
/// locked is `w2_trans`: Lanczos finds ω²_max (to 1e-9), the Gershgorin
/// bound stays above it, and the steps are 2/ω in units of Δt_crit =
/// 2·sqrt(m/kn).
inline void expect_pair_estimate(const StabilityEstimate& e, double w2_rot, double w2_trans,
                                 double dt_crit, double m, double kn) {
  ASSERT_GT(w2_rot, w2_trans);  // the rotational mode binds
  EXPECT_NEAR(e.omega2_max, w2_rot, 1e-9 * w2_rot);
  EXPECT_GE(e.omega2_gershgorin, e.omega2_max * (1.0 - 1e-12));
  EXPECT_NEAR(dt_crit, 2.0 * std::sqrt(m / kn), 1e-15 * dt_crit);
  EXPECT_NEAR(e.dt_ratio_stable_translation, 2.0 / std::sqrt(w2_trans) / dt_crit, 1e-9);
  EXPECT_NEAR(e.dt_ratio_stable, 2.0 / std::sqrt(w2_rot) / dt_crit, 1e-9);
}

}  // namespace demcal::test
