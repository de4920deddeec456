#include "empty_slab.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

#include "demcal/io/format.hpp"

namespace demcal::detail {

EmptySlab widest_empty_slab(std::span<const std::span<const double>> centres,
                            std::span<const double> r) {
  EmptySlab best;
  const size_t n = r.size();
  if (n < 2) return best;
  std::vector<size_t> order(n);
  for (size_t axis = 0; axis < centres.size(); ++axis) {
    const std::span<const double> c = centres[axis];
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return c[a] - r[a] < c[b] - r[b]; });
    // Sweep the extents by their lower ends: a gap opens where one starts
    // beyond every extent before it.
    double reach = c[order[0]] + r[order[0]];
    double covered = reach - (c[order[0]] - r[order[0]]);
    double gap_from = 0.0, gap_to = 0.0;
    for (size_t k = 1; k < n; ++k) {
      const size_t i = order[k];
      const double lo = c[i] - r[i], hi = c[i] + r[i];
      if (lo > reach) {
        if (lo - reach > gap_to - gap_from) gap_from = reach, gap_to = lo;
        covered += hi - lo;
      } else if (hi > reach) {
        covered += hi - reach;
      }
      reach = std::max(reach, hi);
    }
    if (gap_to - gap_from > best.width()) {
      best.axis = static_cast<int>(axis);
      best.from = gap_from;
      best.to = gap_to;
      best.covered = covered;
    }
  }
  if (best.axis < 0) return best;
  // The side with fewer particles, and the one of them nearest the slab.
  const std::span<const double> c = centres[static_cast<size_t>(best.axis)];
  int below = 0;
  for (size_t i = 0; i < n; ++i) below += c[i] < best.from;
  const bool low_side = below <= static_cast<int>(n) - below;
  best.beyond = low_side ? below : static_cast<int>(n) - below;
  double nearest_gap = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if ((c[i] < best.from) != low_side) continue;
    const double gap = low_side ? best.from - (c[i] + r[i]) : (c[i] - r[i]) - best.to;
    if (best.nearest < 0 || gap < nearest_gap)
      best.nearest = static_cast<int>(i), nearest_gap = gap;
  }
  return best;
}

std::string stray_particle_note(std::span<const std::span<const double>> centres,
                                std::span<const double> r) {
  const EmptySlab slab = widest_empty_slab(centres, r);
  if (slab.axis < 0) return "";
  const double d_max = 2.0 * *std::max_element(r.begin(), r.end());
  if (!(slab.width() > slab.covered && slab.width() > 2.0 * d_max)) return "";
  const char* axis = slab.axis == 0 ? "x" : slab.axis == 1 ? "y" : "z";
  const size_t i = static_cast<size_t>(slab.nearest);
  std::string at = "(";
  for (size_t d = 0; d < centres.size(); ++d) at += (d ? ", " : "") + num(centres[d][i], 6);
  at += ")";
  return "; the particles leave an empty slab " + num(slab.width(), 3) +
         " m wide across the box along " + axis + " (from " + num(slab.from, 6) + " to " +
         num(slab.to, 6) + " m), wider than the " + num(slab.covered, 3) +
         " m they cover along it: " + std::to_string(slab.beyond) +
         (slab.beyond == 1 ? " particle lies" : " particles lie") + " beyond it (the nearest at " +
         at +
         " m), which a wall meets alone and cannot press against the rest — a stray particle? "
         "(check the particle file's rows)";
}

}  // namespace demcal::detail
