// The particle files' overlap check, for disks (2D) and spheres (3D) alike.
// Private to src/scene (packing.cpp, sphere_packing.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"
#include "demcal/scene/packing.hpp"

namespace demcal::detail {

/// Throws naming both lines when two particles overlap by more than 5 % of
/// the smaller radius (beyond that a file is not a packing but an error);
/// `what` names them in the message ("particle", "sphere").
///
/// O(N) for any radius distribution: particles are grouped in levels by
/// radius (level = binary exponent of r, so radii within a level differ by
/// less than 2x), each level on its own grid of cells 2·r_max(level) wide.
/// A pair is tested once, from its smaller particle: that one looks at the
/// at most 3^D cells of each level at or above its own that can hold a
/// partner. Cells of one level hold O(1) particles that do not overlap, so
/// the work is N·3^D·O(1) per occupied level (a single grid sized by the
/// largest particle degenerates to O(N²) when one is 100x the others).
template <size_t D>
void check_overlaps(const std::array<std::span<const double>, D>& x, std::span<const double> r,
                    const std::vector<int>& lines, const std::string& path, const char* what) {
  const int n = static_cast<int>(r.size());
  if (n == 0) return;
  std::array<double, D> lo, hi;
  for (size_t d = 0; d < D; ++d) {
    lo[d] = *std::min_element(x[d].begin(), x[d].end());
    hi[d] = *std::max_element(x[d].begin(), x[d].end());
  }
  double extent = 0.0;
  for (size_t d = 0; d < D; ++d) extent = std::max(extent, hi[d] - lo[d]);
  if (!std::isfinite(extent))
    throw InputError(path, "", "coordinates span more than a double can hold");

  // A cell key: the cell indices from the last axis to the first, then the
  // particle (sorted, a row of cells along the first axis is contiguous).
  using Key = std::array<int64_t, D + 1>;
  struct Level {
    double r_max = 0.0, cell = 0.0;
    std::vector<Key> cells;  // sorted
  };
  std::vector<Level> levels;  // by increasing exponent
  std::vector<int> level_of(n);
  {
    std::vector<int> exponents(n);
    for (int i = 0; i < n; ++i) exponents[i] = std::ilogb(r[i]);
    std::vector<int> distinct = exponents;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    levels.resize(distinct.size());
    for (int i = 0; i < n; ++i) {
      level_of[i] = static_cast<int>(
          std::lower_bound(distinct.begin(), distinct.end(), exponents[i]) - distinct.begin());
      levels[level_of[i]].r_max = std::max(levels[level_of[i]].r_max, r[i]);
    }
  }
  // Cells never more than 2^40 a side (a sparse, huge domain would overflow
  // the integer cell keys): larger cells only cost time, never a missed pair.
  constexpr double kMaxCellsPerSide = 1099511627776.0;  // 2^40
  for (auto& level : levels) level.cell = std::max(2.0 * level.r_max, extent / kMaxCellsPerSide);
  // Clamped: a coordinate plus a radius may pass the last cell (even
  // overflow to inf near the largest double); no particle lies beyond it.
  auto cell_index = [&](double v, size_t d, double cell) {
    return static_cast<int64_t>(std::clamp(std::floor((v - lo[d]) / cell), -0x1p62, 0x1p62));
  };
  for (int i = 0; i < n; ++i) {
    Level& level = levels[level_of[i]];
    Key key;
    for (size_t d = 0; d < D; ++d) key[D - 1 - d] = cell_index(x[d][i], d, level.cell);
    key[D] = i;
    level.cells.push_back(key);
  }
  for (auto& level : levels) std::sort(level.cells.begin(), level.cells.end());

  for (int i = 0; i < n; ++i) {
    for (size_t b = level_of[i]; b < levels.size(); ++b) {
      const Level& level = levels[b];
      const double reach = r[i] + level.r_max;  // centres closer than this may overlap
      std::array<int64_t, D> c0, c1;
      for (size_t d = 0; d < D; ++d) {
        c0[d] = cell_index(x[d][i] - reach, d, level.cell);
        c1[d] = cell_index(x[d][i] + reach, d, level.cell);
      }
      // Every row of cells along the first axis in the box c0..c1 (an
      // odometer over the other axes), each scanned from c0[0] to c1[0].
      std::array<int64_t, D> c = c0;
      while (true) {
        Key from;
        for (size_t d = 1; d < D; ++d) from[D - 1 - d] = c[d];
        from[D - 1] = c0[0];
        from[D] = -1;
        for (auto it = std::lower_bound(level.cells.begin(), level.cells.end(), from);
             it != level.cells.end(); ++it) {
          bool same_row = (*it)[D - 1] <= c1[0];
          for (size_t d = 1; d < D; ++d) same_row = same_row && (*it)[D - 1 - d] == c[d];
          if (!same_row) break;
          const int j = static_cast<int>((*it)[D]);
          if (static_cast<int>(b) == level_of[i] && j <= i) continue;  // once per pair
          const double dist = centre_distance<D>(x, i, j);
          const double overlap = r[i] + r[j] - dist;
          const double smaller = std::min(r[i], r[j]);
          if (overlap > 0.05 * smaller)
            throw InputError(path, "line " + std::to_string(lines[std::max(i, j)]),
                             std::string(what) + " overlaps the one on line " +
                                 std::to_string(lines[std::min(i, j)]) + " by " +
                                 std::to_string(100.0 * overlap / smaller) +
                                 " % of the smaller radius (limit 5 %)");
        }
        size_t d = 1;
        while (d < D && c[d] == c1[d]) c[d] = c0[d], ++d;
        if (d == D) break;
        ++c[d];
      }
    }
  }
}

}  // namespace demcal::detail
