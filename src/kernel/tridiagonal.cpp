#include "tridiagonal.hpp"

#include <algorithm>
#include <cmath>
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

}  // namespace demcal::detail
