// The window a REV is cut with, disks (rev.cpp) and spheres (rev_3d.cpp)
// alike. Private to src/upscaling.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

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
/// is nearest `count`, cutting between layers, never through one.
/// `critical(i)` is the smallest scale at which centre i of the `n` is
/// inside the window (centre i is inside at s exactly when critical(i) <=
/// s). The window's edge passes through the middle of a gap between
/// consecutive critical scales, and only through a gap at least a tenth of
/// their mean spacing about `count` (or over the whole prototype, if
/// wider): a gap narrower than that splits a layer. A consolidated lattice
/// keeps its layers to within about one overlap (5e-7 r for the shipped FCC
/// at σ3), far below the spacing, but rounding orders the centres of a
/// layer, and cutting through one leaves a part-layer whose spheres the
/// walls squeeze into the gaps beside them: `demcal rev
/// configs/fcc_4x4x4.json --particles 300` never reached a static state
/// that way. In a random packing nearly every gap is wider than a tenth of
/// the mean, so the count stays the nearest one. Of two counts as near, the
/// larger; never fewer than two.
template <class Critical>
double window_scale(int n, int64_t count, const Critical& critical) {
  std::vector<double> t(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<size_t>(i)] = critical(i);
  std::sort(t.begin(), t.end());
  // The window holding the k smallest critical scales has its edge in the
  // gap (t[k-1], t[k]); past the last centre every window holds them all.
  const auto k_of = [&](int64_t k) { return static_cast<size_t>(std::clamp<int64_t>(k, 1, n)); };
  const size_t lo = k_of(count / 2), hi = k_of(2 * count);
  const double local = hi > lo ? (t[hi - 1] - t[lo - 1]) / static_cast<double>(hi - lo) : 0.0;
  // Where count/2 to 2·count lie within one layer (a small count in a
  // lattice: 10 of the shells 4, 32, 108), the local spacing is the
  // rounding's own: the prototype's mean spacing keeps it a layer.
  const double mean = n > 1 ? (t[static_cast<size_t>(n) - 1] - t[0]) / (n - 1) : 0.0;
  const double narrowest = 0.1 * std::max(local, mean);
  auto edge_after = [&](size_t k) {  // the edge holding the k smallest
    return k == static_cast<size_t>(n) ? t[k - 1] : 0.5 * (t[k - 1] + t[k]);
  };
  auto clean = [&](size_t k) {
    return k == static_cast<size_t>(n) || t[k] - t[k - 1] >= narrowest;
  };
  size_t best = static_cast<size_t>(n);
  int64_t best_miss = std::numeric_limits<int64_t>::max();
  for (size_t k = 2; k <= static_cast<size_t>(n); ++k) {
    if (!clean(k)) continue;
    const int64_t miss = std::abs(static_cast<int64_t>(k) - count);
    if (miss <= best_miss) best = k, best_miss = miss;  // ascending k: ties take the larger
  }
  return edge_after(best);
}

}  // namespace demcal::detail
