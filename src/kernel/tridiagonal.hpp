// Private to the kernel: both kernels' Lanczos estimates of the largest
// eigenvalue of M^-1/2 K M^-1/2 (stability.cpp, sphere_stability.cpp): the
// iteration, given the kernel's operator, and its last step on the
// tridiagonal matrix it builds.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace demcal::detail {

/// Largest eigenvalue of the symmetric tridiagonal matrix with diagonal `d`
/// and off-diagonal `e` (one entry shorter).
double tridiagonal_max_eigenvalue(const std::vector<double>& d, const std::vector<double>& e);

/// y = A·x for the symmetric operator whose largest eigenvalue is sought.
using LinearOperator = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& y)>;

/// Largest eigenvalue of `apply` by Lanczos without re-orthogonalisation
/// (the extreme Ritz value converges first and copies do not exceed it): at
/// most `iterations` steps from a deterministic, generic start vector, over
/// `particles` particles of `dofs_per_particle` dofs each, the first
/// `translation_dofs` of them translations and the rest rotations. Without
/// `rotation` the rotational dofs start at 0 (`apply` keeps them there) and
/// the steps are at most the translational dofs. 0 without dofs.
double lanczos_max_eigenvalue(int particles, int dofs_per_particle, int translation_dofs,
                              bool rotation, int iterations, const LinearOperator& apply);

}  // namespace demcal::detail
