// Private to the kernel: the last step of both kernels' Lanczos estimates
// of the largest eigenvalue of M^-1/2 K M^-1/2 (stability.cpp,
// sphere_stability.cpp).
#pragma once

#include <vector>

namespace demcal::detail {

/// Largest eigenvalue of the symmetric tridiagonal matrix with diagonal `d`
/// and off-diagonal `e` (one entry shorter).
double tridiagonal_max_eigenvalue(const std::vector<double>& d, const std::vector<double>& e);

}  // namespace demcal::detail
