// Broad phase of the sphere kernel: cell grid + Verlet skin, as the 2D
// kernel's (broad_phase.cpp). The list holds every pair closer than
// r_i + r_j + skin once, from its lower index i < j, in sliced ELLPACK
// blocks of 8 (sphere_world_impl.hpp), each particle's neighbours in
// increasing index; the CSR form beside it points to each pair's slot, and
// the mirror list gives each j the slots of its pairs (i, j). It is
// rebuilt only when some particle (or a wall) has moved far enough that a
// pair outside it could touch (the displacement scan is fused into the
// integration pass). A pair's tangential history carries over a rebuild.
#include <algorithm>
#include <cmath>

#include "sphere_world_impl.hpp"
#include "term_ring.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
}

double SphereWorldImpl::neighbour_slot_fill() const {
  const int slots = block_slot_[nblocks_];
  if (slots == 0) return 1.0;
  int real = 0;
  for (int s = 0; s < slots; ++s) real += slot_j_[s] != ghost_;
  return static_cast<double>(real) / slots;
}

bool SphereWorldImpl::needs_rebuild() const {
  if (!list_valid_) return true;
  double max_d2 = 0.0;
  for (int i = 0; i < n_; ++i) {
    const double dx = x_[i] - x_built_[i], dy = y_[i] - y_built_[i], dz = z_[i] - z_built_[i];
    max_d2 = std::max(max_d2, dx * dx + dy * dy + dz * dz);
  }
  return detail::skin_exceeded(max_d2, walls_, wall_built_, skin_);
}

void SphereWorldImpl::rebuild_neighbours() {
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
      // Clamped as a double before the cast: a particle flung far away
      // (a diverging run) has a cell index beyond int's range.
      c[a] = std::isfinite(f)
                 ? static_cast<int>(std::clamp(std::floor(f), 0.0, static_cast<double>(nc[a] - 1)))
                 : 0;
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

  // Half lists (CSR, pairs i < j), each sorted by index. The cut-off test
  // is symmetric in i and j bit for bit, so the pair is the same whichever
  // side finds it.
  nbr_start_.assign(static_cast<size_t>(n) + 1, 0);
  nbr_j_.clear();
  for (int i = 0; i < n; ++i) {
    std::array<int, 3> c;
    cell_of(i, c);
    const size_t first = nbr_j_.size();
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
            if (ddx * ddx + ddy * ddy + ddz * ddz < cut * cut) nbr_j_.push_back(j);
          }
        }
    std::sort(nbr_j_.begin() + static_cast<std::ptrdiff_t>(first), nbr_j_.end());
    nbr_start_[i + 1] = static_cast<int>(nbr_j_.size());
  }

  // Sliced ELLPACK: block b gets as many rows as its longest list.
  new_block_slot_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  for (int b = 0; b < nblocks_; ++b) {
    int rows = 0;
    for (int i = kBlock * b; i < std::min(n, kBlock * (b + 1)); ++i)
      rows = std::max(rows, nbr_start_[i + 1] - nbr_start_[i]);
    new_block_slot_[b + 1] = new_block_slot_[b] + kBlock * rows;
  }
  const size_t ns = static_cast<size_t>(new_block_slot_[nblocks_]);
  new_slot_j_.assign(ns, ghost_);
  new_slot_r_.assign(ns, 0.0);
  new_slot_ir_.assign(ns, 0.0);
  new_hx_.assign(ns, 0.0);
  new_hy_.assign(ns, 0.0);
  new_hz_.assign(ns, 0.0);
  pair_slot_.resize(nbr_j_.size());
  for (int i = 0; i < n; ++i) {
    const int b = i / kBlock, lane = i % kBlock;
    const int nb = new_block_slot_[b] + lane;
    // Carry the histories over by a merge with the old slots of i (in
    // increasing j, then ghosts).
    int o = block_slot_[b] + lane;
    const int old_end = block_slot_[b + 1];
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      const int s = nb + kBlock * (k - nbr_start_[i]);
      new_slot_j_[s] = j;
      new_slot_r_[s] = r_[j];
      new_slot_ir_[s] = inv_r_[j];
      while (o < old_end && slot_j_[o] < j) o += kBlock;
      if (o < old_end && slot_j_[o] == j) {
        new_hx_[s] = hx_[o];
        new_hy_[s] = hy_[o];
        new_hz_[s] = hz_[o];
      }
      pair_slot_[k] = s;
    }
  }
  block_slot_.swap(new_block_slot_);
  slot_j_.swap(new_slot_j_);
  slot_r_.swap(new_slot_r_);
  slot_ir_.swap(new_slot_ir_);
  hx_.swap(new_hx_);
  hy_.swap(new_hy_);
  hz_.swap(new_hz_);
  rebuild_mirror_list();
  update_thread_bounds();  // and the places of the pair terms (layout_terms)

  rebuild_wall_candidates();

  std::copy(x_.begin(), x_.begin() + n, x_built_.begin());
  std::copy(y_.begin(), y_.begin() + n, y_built_.begin());
  std::copy(z_.begin(), z_.begin() + n, z_built_.begin());
  for (int s = 0; s < 6; ++s) wall_built_[s] = walls_[s].position;
  list_valid_ = true;
}

void SphereWorldImpl::rebuild_mirror_list() {
  const int n = n_;
  const size_t ns = static_cast<size_t>(block_slot_[nblocks_]);
  // Mirror list: the slots of the pairs (i, j), i < j, by j, in increasing i.
  mirror_count_.assign(static_cast<size_t>(kBlock) * nblocks_, 0);
  for (int k = 0; k < nbr_start_[n]; ++k) ++mirror_count_[nbr_j_[k]];
  mirror_block_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  for (int b = 0; b < nblocks_; ++b) {
    const int rows = *std::max_element(mirror_count_.begin() + kBlock * b,
                                       mirror_count_.begin() + kBlock * (b + 1));
    mirror_block_[b + 1] = mirror_block_[b] + kBlock * rows;
  }
  mirror_slot_.assign(static_cast<size_t>(mirror_block_[nblocks_]), static_cast<int>(ns));
  std::fill(mirror_count_.begin(), mirror_count_.end(), 0);
  mirror_src_block_.resize(nblocks_);
  for (int b = 0; b < nblocks_; ++b) mirror_src_block_[b] = b;
  for (int i = 0; i < n; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      mirror_src_block_[j / kBlock] = std::min(mirror_src_block_[j / kBlock], i / kBlock);
      const int row = mirror_count_[j]++;
      mirror_slot_[mirror_block_[j / kBlock] + j % kBlock + kBlock * row] = pair_slot_[k];
    }
}

void SphereWorldImpl::layout_terms() {
  // A ring of places per thread, as the 2D kernel's (one algorithm:
  // term_ring.hpp).
  const int place = detail::layout_terms(block_slot_, mirror_src_block_, pair_bounds_, mirror_slot_,
                                         term_block_, mirror_term_);
  // The terms, and the zero place at index place.
  for (auto* p : {&pfx_, &pfy_, &pfz_, &ptx_, &pty_, &ptz_})
    p->assign(static_cast<size_t>(place) + 1, 0.0);
}

void SphereWorldImpl::rebuild_wall_candidates() {
  const int n = n_;
  // Wall candidates: particles within skin of a wall, in increasing index;
  // a candidate keeps its history (a merge with the old list), the others
  // cannot be touching: no history to keep.
  for (int s = 0; s < 6; ++s) {
    std::vector<int>& cand = wall_candidates_[s];
    new_slot_j_.clear();  // the old list (scratch)
    new_slot_j_.insert(new_slot_j_.end(), cand.begin(), cand.end());
    cand.clear();
    for (int i = 0; i < n; ++i)
      if (wall_distance(s, i) - r_[i] < skin_) cand.push_back(i);
    const size_t padded = (cand.size() + kBlock - 1) / kBlock * kBlock;
    new_wall_hx_.assign(padded, 0.0);
    new_wall_hy_.assign(padded, 0.0);
    new_wall_hz_.assign(padded, 0.0);
    size_t o = 0;
    for (size_t k = 0; k < cand.size(); ++k) {
      while (o < new_slot_j_.size() && new_slot_j_[o] < cand[k]) ++o;
      if (o < new_slot_j_.size() && new_slot_j_[o] == cand[k]) {
        new_wall_hx_[k] = wall_hx_[s][o];
        new_wall_hy_[k] = wall_hy_[s][o];
        new_wall_hz_[k] = wall_hz_[s][o];
      }
    }
    wall_hx_[s].swap(new_wall_hx_);
    wall_hy_[s].swap(new_wall_hy_);
    wall_hz_[s].swap(new_wall_hz_);
    wall_fn_[s].assign(padded, 0.0);  // written by the next force pass
    wall_gather_[s].assign(padded, ghost_);
    std::copy(cand.begin(), cand.end(), wall_gather_[s].begin());
  }
}

}  // namespace demcal
