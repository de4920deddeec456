#include "tridiagonal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace demcal::detail {

// Largest eigenvalue of the symmetric tridiagonal matrix (diagonal `d`,
// off-diagonal `e`, one entry shorter) by Sturm-sequence bisection. Eigen's
// SelfAdjointEigenSolver::computeFromTridiagonal runs out of QR iterations
// on the long Lanczos matrices of large packings (their spectra hold many
// near-copies of the converged Ritz values) and then returns wrong
// eigenvalues silently; bisection cannot fail and costs O(m) per halving.
double tridiagonal_max_eigenvalue(const std::vector<double>& d, const std::vector<double>& e) {
  const size_t m = d.size();
  if (m == 0) return 0.0;
  // Gershgorin interval of the tridiagonal matrix.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (size_t k = 0; k < m; ++k) {
    const double off = (k > 0 ? std::abs(e[k - 1]) : 0.0) + (k + 1 < m ? std::abs(e[k]) : 0.0);
    lo = std::min(lo, d[k] - off);
    hi = std::max(hi, d[k] + off);
  }
  // Number of eigenvalues below x: negative pivots of the LDLᵀ of T − x·I.
  auto count_below = [&](double x) {
    size_t count = 0;
    double q = 1.0;
    const double tiny = std::numeric_limits<double>::min() / std::numeric_limits<double>::epsilon();
    for (size_t k = 0; k < m; ++k) {
      q = d[k] - x - (k > 0 ? e[k - 1] * e[k - 1] / q : 0.0);
      if (q == 0.0) q = -tiny;
      if (q < 0.0) ++count;
    }
    return count;
  };
  // Invariant: count_below(lo) < m ≤ count_below(hi), i.e. λ_max ∈ [lo, hi).
  const double scale = std::max(std::abs(lo), std::abs(hi));
  hi += 4.0 * std::numeric_limits<double>::epsilon() * scale + std::numeric_limits<double>::min();
  for (int it = 0; it < 200 && hi - lo > 2.0 * std::numeric_limits<double>::epsilon() * scale;
       ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (count_below(mid) >= m)
      hi = mid;
    else
      lo = mid;
  }
  return 0.5 * (lo + hi);
}

double lanczos_max_eigenvalue(int particles, int dofs_per_particle, int translation_dofs,
                              bool rotation, int iterations, const LinearOperator& apply) {
  const int dofs = dofs_per_particle * particles;
  if (dofs == 0) return 0.0;
  Eigen::VectorXd v(dofs), v_prev = Eigen::VectorXd::Zero(dofs), w(dofs);
  uint64_t state = 0x9E3779B97F4A7C15ull;  // deterministic, generic start vector
  for (int k = 0; k < dofs; ++k) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    v[k] = static_cast<double>(state % 2001) / 1000.0 - 1.0;
    if (!rotation && k % dofs_per_particle >= translation_dofs) v[k] = 0.0;
  }
  v.normalize();
  std::vector<double> alpha, beta;
  double b = 0.0;
  const int steps = std::min(iterations, rotation ? dofs : translation_dofs * particles);
  for (int k = 0; k < steps; ++k) {
    apply(v, w);
    const double a = w.dot(v);
    w -= a * v + b * v_prev;
    alpha.push_back(a);
    b = w.norm();
    if (b < 1e-12 * std::abs(a) || k + 1 == steps) break;
    beta.push_back(b);
    v_prev = v;
    v = w / b;
  }
  return tridiagonal_max_eigenvalue(alpha, beta);
}

}  // namespace demcal::detail
