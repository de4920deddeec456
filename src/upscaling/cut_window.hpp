// The window a REV is cut with, disks (rev.cpp) and spheres (rev_3d.cpp)
// alike. Private to src/upscaling.
#pragma once

#include <cstdint>
#include <string>

#include "demcal/io/input_error.hpp"

namespace demcal::detail {

/// A REV of `count` of the prototype's `n` particles (`noun`: "particles",
/// "spheres"): at least 2, at most n; else an InputError.
inline void check_rev_count(int64_t count, int n, const std::string& noun) {
  if (count < 2) throw InputError("REV", "particles", "needs at least 2 particles");
  if (count > n)
    throw InputError("REV", "particles",
                     "asked for " + std::to_string(count) + " " + noun +
                         ", the prototype has only " + std::to_string(n));
}

/// The scale s of a window centred on the prototype whose count of centres
/// is nearest `count`. `inside(s, i)` says whether centre i of the `n` is
/// inside the window at scale s (the count grows with s); every centre is
/// inside at `hi`. Bisection to 1e-14 relative; of its two ends, the
/// smaller window when it is nearer and holds at least two.
template <class Inside>
double window_scale(int n, int64_t count, double hi, const Inside& inside) {
  auto count_at = [&](double s) {
    int64_t c = 0;
    for (int i = 0; i < n; ++i) c += inside(s, i);
    return c;
  };
  double lo = 0.0;
  for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (count_at(mid) >= count ? hi : lo) = mid;
  }
  const int64_t c_hi = count_at(hi), c_lo = count_at(lo);
  return (c_lo >= 2 && count - c_lo < c_hi - count) ? lo : hi;
}

}  // namespace demcal::detail
