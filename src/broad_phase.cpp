// Broad phase: cell grid + Verlet skin. The neighbour list holds every pair
// closer than r_i + r_j + skin; it is rebuilt only when some particle (or a
// wall) has moved far enough that a pair outside the list could touch.
#include <algorithm>
#include <cmath>

#include "demcal/world.hpp"

namespace demcal {

bool World::needs_rebuild() const {
  if (!list_valid_) return true;
  const int n = size();
  double max_d2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double dx = x_[i] - x_built_[i];
    const double dy = y_[i] - y_built_[i];
    max_d2 = std::max(max_d2, dx * dx + dy * dy);
  }
  const double max_disp = std::sqrt(max_d2);
  double max_wall = 0.0;
  for (int w = 0; w < 4; ++w)
    max_wall = std::max(max_wall, std::abs(walls_[w].position - wall_built_[w]));
  // Two particles approach each other by at most 2·max_disp; a particle and
  // a wall by max_disp + max_wall.
  return 2.0 * max_disp >= skin_ || max_disp + max_wall >= skin_;
}

void World::rebuild_neighbours() {
  const int n = size();
  ++rebuilds_;
  // Grid over the box (particles that left it are clamped to the edge cells).
  const double cell = 2.0 * r_max_ + skin_;
  const double x0 = walls_[kLeft].position, y0 = walls_[kBottom].position;
  const double w = std::max(width(), cell), h = std::max(height(), cell);
  int ncx = std::max(1, static_cast<int>(w / cell));
  int ncy = std::max(1, static_cast<int>(h / cell));
  // Never more cells than a few per particle (a sparse box would waste memory).
  while (static_cast<int64_t>(ncx) * ncy > 4 * static_cast<int64_t>(n) + 16) {
    ncx = std::max(1, ncx / 2);
    ncy = std::max(1, ncy / 2);
  }
  const double csx = w / ncx, csy = h / ncy;
  cell_start_.assign(static_cast<size_t>(ncx) * ncy, -1);
  cell_next_.resize(n);
  auto cell_of = [&](int i, int& cx, int& cy) {
    const double fx = (x_[i] - x0) / csx, fy = (y_[i] - y0) / csy;
    cx = std::isfinite(fx) ? std::clamp(static_cast<int>(std::floor(fx)), 0, ncx - 1) : 0;
    cy = std::isfinite(fy) ? std::clamp(static_cast<int>(std::floor(fy)), 0, ncy - 1) : 0;
  };
  // Insert in reverse so that each cell's list runs in increasing index.
  for (int i = n - 1; i >= 0; --i) {
    int cx, cy;
    cell_of(i, cx, cy);
    const int c = cy * ncx + cx;
    cell_next_[i] = cell_start_[c];
    cell_start_[c] = i;
  }

  new_i_.clear();
  new_j_.clear();
  for (int i = 0; i < n; ++i) {
    int cx, cy;
    cell_of(i, cx, cy);
    const size_t first = new_j_.size();
    for (int dy = -1; dy <= 1; ++dy) {
      const int yy = cy + dy;
      if (yy < 0 || yy >= ncy) continue;
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = cx + dx;
        if (xx < 0 || xx >= ncx) continue;
        for (int j = cell_start_[yy * ncx + xx]; j >= 0; j = cell_next_[j]) {
          if (j <= i) continue;
          const double ddx = x_[j] - x_[i], ddy = y_[j] - y_[i];
          const double cut = r_[i] + r_[j] + skin_;
          if (ddx * ddx + ddy * ddy < cut * cut) {
            new_i_.push_back(i);
            new_j_.push_back(j);
          }
        }
      }
    }
    // Keep (i, j) sorted so that history carries over by a linear merge.
    std::sort(new_j_.begin() + static_cast<std::ptrdiff_t>(first), new_j_.end());
  }

  // Carry the tangential history of pairs present in both lists.
  const size_t np = new_i_.size();
  new_ft_.assign(np, 0.0);
  size_t o = 0;
  const size_t no = pair_i_.size();
  for (size_t k = 0; k < np; ++k) {
    const int64_t key = static_cast<int64_t>(new_i_[k]) * n + new_j_[k];
    while (o < no && static_cast<int64_t>(pair_i_[o]) * n + pair_j_[o] < key) ++o;
    if (o < no && pair_i_[o] == new_i_[k] && pair_j_[o] == new_j_[k]) new_ft_[k] = pair_ft_[o];
  }
  pair_i_.swap(new_i_);
  pair_j_.swap(new_j_);
  pair_ft_.swap(new_ft_);
  pair_fn_.assign(np, 0.0);
  pair_nx_.assign(np, 0.0);
  pair_ny_.assign(np, 0.0);

  // Wall candidates: particles within skin of a wall.
  for (int s = 0; s < 4; ++s) wall_candidates_[s].clear();
  for (int i = 0; i < n; ++i) {
    const double gaps[4] = {
        x_[i] - r_[i] - walls_[kLeft].position, walls_[kRight].position - x_[i] - r_[i],
        y_[i] - r_[i] - walls_[kBottom].position, walls_[kTop].position - y_[i] - r_[i]};
    for (int s = 0; s < 4; ++s) {
      if (gaps[s] < skin_) {
        wall_candidates_[s].push_back(i);
      } else {
        wall_ft_[s][i] = 0.0;  // cannot be touching: no history to keep
        wall_fn_[s][i] = 0.0;
      }
    }
  }

  x_built_ = x_;
  y_built_ = y_;
  for (int s = 0; s < 4; ++s) wall_built_[s] = walls_[s].position;
  list_valid_ = true;
}

}  // namespace demcal
