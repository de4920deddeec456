// Broad phase of the sphere kernel: cell grid + Verlet skin, as the 2D
// kernel's (broad_phase.cpp). The list holds every pair i < j closer than
// r_i + r_j + skin, row by row sorted by j; it is rebuilt only when some
// particle (or a wall) has moved far enough that a pair outside it could
// touch (the displacement scan is fused into the integration,
// sphere_world.cpp). A pair's tangential history carries over a rebuild.
#include <algorithm>
#include <cmath>

#include "demcal/kernel/sphere_world.hpp"

namespace demcal {

bool SphereWorld::needs_rebuild() const {
  if (!list_valid_) return true;
  double max_d2 = 0.0;
  for (int i = 0; i < n_; ++i) {
    const double dx = x_[i] - x_built_[i], dy = y_[i] - y_built_[i], dz = z_[i] - z_built_[i];
    max_d2 = std::max(max_d2, dx * dx + dy * dy + dz * dz);
  }
  const double max_disp = std::sqrt(max_d2);
  double max_wall = 0.0;
  for (int s = 0; s < 6; ++s)
    max_wall = std::max(max_wall, std::abs(walls_[s].position - wall_built_[s]));
  return 2.0 * max_disp >= skin_ || max_disp + max_wall >= skin_;
}

void SphereWorld::rebuild_neighbours() {
  const int n = n_;
  ++rebuilds_;
  // Grid over the box (particles outside it are clamped to the edge cells).
  const double cell = 2.0 * r_max_ + skin_;
  std::array<int, 3> nc{};
  std::array<double, 3> origin{}, size{};
  for (int a = 0; a < 3; ++a) {
    origin[a] = walls_[2 * a].position;
    const double len = std::max(extent(a), cell);
    nc[a] = std::max(1, static_cast<int>(len / cell));
    size[a] = len;
  }
  // Never more cells than a few per particle (a sparse box would waste memory).
  while (static_cast<int64_t>(nc[0]) * nc[1] * nc[2] > 4 * static_cast<int64_t>(n) + 64)
    for (int& c : nc) c = std::max(1, c / 2);
  std::array<double, 3> cs{};
  for (int a = 0; a < 3; ++a) cs[a] = size[a] / nc[a];
  cell_start_.assign(static_cast<size_t>(nc[0]) * nc[1] * nc[2], -1);
  cell_next_.resize(n);
  const double* pos[3] = {x_.data(), y_.data(), z_.data()};
  auto cell_of = [&](int i, std::array<int, 3>& c) {
    for (int a = 0; a < 3; ++a) {
      const double f = (pos[a][i] - origin[a]) / cs[a];
      c[a] = std::isfinite(f) ? std::clamp(static_cast<int>(std::floor(f)), 0, nc[a] - 1) : 0;
    }
  };
  auto index = [&](const std::array<int, 3>& c) { return (c[2] * nc[1] + c[1]) * nc[0] + c[0]; };
  for (int i = n - 1; i >= 0; --i) {
    std::array<int, 3> c;
    cell_of(i, c);
    const int k = index(c);
    cell_next_[i] = cell_start_[k];
    cell_start_[k] = i;
  }

  // Half list (j > i), each row sorted; histories merged from the old list.
  new_start_.assign(static_cast<size_t>(n) + 1, 0);
  new_j_.clear();
  new_hx_.clear();
  new_hy_.clear();
  new_hz_.clear();
  for (int i = 0; i < n; ++i) {
    std::array<int, 3> c;
    cell_of(i, c);
    const size_t first = new_j_.size();
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::array<int, 3> o{c[0] + dx, c[1] + dy, c[2] + dz};
          if (o[0] < 0 || o[0] >= nc[0] || o[1] < 0 || o[1] >= nc[1] || o[2] < 0 || o[2] >= nc[2])
            continue;
          for (int j = cell_start_[index(o)]; j >= 0; j = cell_next_[j]) {
            if (j <= i) continue;
            const double ddx = x_[j] - x_[i], ddy = y_[j] - y_[i], ddz = z_[j] - z_[i];
            const double cut = r_[i] + r_[j] + skin_;
            if (ddx * ddx + ddy * ddy + ddz * ddz < cut * cut) new_j_.push_back(j);
          }
        }
    std::sort(new_j_.begin() + static_cast<std::ptrdiff_t>(first), new_j_.end());
    new_start_[i + 1] = static_cast<int>(new_j_.size());
    // Carry the histories over by a merge of the two sorted rows.
    int o = nbr_start_[i];
    const int old_end = nbr_start_[i + 1];
    for (size_t k = first; k < new_j_.size(); ++k) {
      while (o < old_end && nbr_j_[o] < new_j_[k]) ++o;
      const bool kept = o < old_end && nbr_j_[o] == new_j_[k];
      new_hx_.push_back(kept ? hx_[o] : 0.0);
      new_hy_.push_back(kept ? hy_[o] : 0.0);
      new_hz_.push_back(kept ? hz_[o] : 0.0);
    }
  }
  nbr_start_.swap(new_start_);
  nbr_j_.swap(new_j_);
  hx_.swap(new_hx_);
  hy_.swap(new_hy_);
  hz_.swap(new_hz_);

  // Wall candidates: particles within skin of a wall.
  for (int s = 0; s < 6; ++s) {
    wall_candidates_[s].clear();
    for (int i = 0; i < n; ++i) {
      if (wall_distance(s, i) - r_[i] < skin_) {
        wall_candidates_[s].push_back(i);
      } else {  // cannot be touching: no history to keep
        wall_hx_[s][i] = wall_hy_[s][i] = wall_hz_[s][i] = 0.0;
        wall_fn_[s][i] = 0.0;
      }
    }
  }

  x_built_ = x_;
  y_built_ = y_;
  z_built_ = z_;
  for (int s = 0; s < 6; ++s) wall_built_[s] = walls_[s].position;
  list_valid_ = true;
}

}  // namespace demcal
