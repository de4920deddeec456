// Broad phase: cell grid + Verlet skin. The neighbour list holds every pair
// closer than r_i + r_j + skin; it is rebuilt only when some particle (or a
// wall) has moved far enough that a pair outside the list could touch (the
// displacement scan is fused into the integration pass, solver.cpp).
//
// The list is a half list (each pair (i, j) once, in i's row, i < j) stored
// as sliced ELLPACK in blocks of 8 particles (world_impl.hpp); the mirror
// list gives each particle j the slots of its pairs (i, j) in increasing i,
// for the sums of the pair terms (contact.cpp). The tangential history of
// a pair carries over a rebuild by a merge of the old and new rows.
#include <algorithm>
#include <cmath>

#include "term_ring.hpp"
#include "world_impl.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
}

void WorldImpl::layout_blocks(const std::vector<int>& start, std::vector<int>& block_slot) const {
  // Sliced ELLPACK: block b gets as many rows as its longest list.
  block_slot.assign(static_cast<size_t>(nblocks_) + 1, 0);
  for (int b = 0; b < nblocks_; ++b) {
    int rows = 0;
    for (int i = kBlock * b; i < std::min(n_, kBlock * (b + 1)); ++i)
      rows = std::max(rows, start[i + 1] - start[i]);
    block_slot[b + 1] = block_slot[b] + kBlock * rows;
  }
}

bool WorldImpl::needs_rebuild() const {
  if (!list_valid_) return true;
  double max_d2 = 0.0;
  for (int i = 0; i < n_; ++i) {
    const double dx = x_[i] - x_built_[i];
    const double dy = y_[i] - y_built_[i];
    max_d2 = std::max(max_d2, dx * dx + dy * dy);
  }
  return detail::skin_exceeded(max_d2, walls_, wall_built_, skin_);
}

void WorldImpl::rebuild_neighbours() {
  const int n = n_;
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
    cx = std::isfinite(fx) ? static_cast<int>(std::clamp(std::floor(fx), 0.0, ncx - 1.0)) : 0;
    cy = std::isfinite(fy) ? static_cast<int>(std::clamp(std::floor(fy), 0.0, ncy - 1.0)) : 0;
  };
  for (int i = n - 1; i >= 0; --i) {
    int cx, cy;
    cell_of(i, cx, cy);
    const int c = cy * ncx + cx;
    cell_next_[i] = cell_start_[c];
    cell_start_[c] = i;
  }

  // Half neighbour lists (CSR, pairs i < j), each sorted by index. The
  // cut-off test is symmetric in i and j bit for bit, so the pair is the
  // same whichever side finds it.
  nbr_start_.assign(static_cast<size_t>(n) + 1, 0);
  nbr_list_.clear();
  for (int i = 0; i < n; ++i) {
    int cx, cy;
    cell_of(i, cx, cy);
    const size_t first = nbr_list_.size();
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
          if (ddx * ddx + ddy * ddy < cut * cut) nbr_list_.push_back(j);
        }
      }
    }
    std::sort(nbr_list_.begin() + static_cast<std::ptrdiff_t>(first), nbr_list_.end());
    nbr_start_[i + 1] = static_cast<int>(nbr_list_.size());
  }

  layout_blocks(nbr_start_, new_block_slot_);
  const size_t ns = static_cast<size_t>(new_block_slot_[nblocks_]);
  new_slot_j_.assign(ns, ghost_);
  new_slot_ft_.assign(ns, 0.0);
  new_slot_r_.assign(ns, 0.0);
  new_slot_ir_.assign(ns, 0.0);
  pair_i_.clear();
  pair_j_.clear();
  pair_slot_.clear();
  for (int i = 0; i < n; ++i) {
    const int b = i / kBlock, lane = i % kBlock;
    const int nb = new_block_slot_[b] + lane, ob = block_slot_[b] + lane;
    const int old_end = block_slot_[b + 1];
    // Carry the tangential history over by a merge of the two sorted lists
    // (old slots of i run in increasing j, then ghosts).
    int o = ob;
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_list_[k];
      const int s = nb + kBlock * (k - nbr_start_[i]);
      new_slot_j_[s] = j;
      new_slot_r_[s] = r_[j];
      new_slot_ir_[s] = inv_r_[j];
      while (o < old_end && slot_j_[o] < j) o += kBlock;
      if (o < old_end && slot_j_[o] == j) new_slot_ft_[s] = slot_ft_[o];
      pair_i_.push_back(i);
      pair_j_.push_back(j);
      pair_slot_.push_back(s);
    }
  }
  block_slot_.swap(new_block_slot_);
  slot_j_.swap(new_slot_j_);
  slot_ft_.swap(new_slot_ft_);
  slot_r_.swap(new_slot_r_);
  slot_ir_.swap(new_slot_ir_);
  rebuild_mirror_list();
  update_thread_bounds();  // and the places of the pair terms (layout_terms)

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

  std::copy(x_.begin(), x_.begin() + n, x_built_.begin());
  std::copy(y_.begin(), y_.begin() + n, y_built_.begin());
  for (int s = 0; s < 4; ++s) wall_built_[s] = walls_[s].position;
  list_valid_ = true;
}

void WorldImpl::rebuild_mirror_list() {
  const int ns = block_slot_[nblocks_];
  // The slots of the pairs (i, j), i < j, by j, in increasing i (pair_i_ is
  // sorted by (i, j)); padded with the zero slot ns.
  mirror_count_.assign(static_cast<size_t>(kBlock) * nblocks_, 0);
  for (int j : pair_j_) ++mirror_count_[j];
  mirror_block_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  for (int b = 0; b < nblocks_; ++b) {
    const int rows = *std::max_element(mirror_count_.begin() + kBlock * b,
                                       mirror_count_.begin() + kBlock * (b + 1));
    mirror_block_[b + 1] = mirror_block_[b] + kBlock * rows;
  }
  mirror_slot_.assign(static_cast<size_t>(mirror_block_[nblocks_]), ns);
  std::fill(mirror_count_.begin(), mirror_count_.end(), 0);
  mirror_src_block_.resize(nblocks_);
  for (int b = 0; b < nblocks_; ++b) mirror_src_block_[b] = b;
  block_fused_.assign(nblocks_, 0);
  for (size_t k = 0; k < pair_j_.size(); ++k) {
    const int j = pair_j_[k];
    mirror_src_block_[j / kBlock] = std::min(mirror_src_block_[j / kBlock], pair_i_[k] / kBlock);
    const int row = mirror_count_[j]++;
    mirror_slot_[mirror_block_[j / kBlock] + j % kBlock + kBlock * row] = pair_slot_[k];
  }
}

void WorldImpl::layout_terms() {
  // A ring of places per thread, one algorithm for both kernels
  // (term_ring.hpp); the pair pass sums the blocks it completes.
  const int place = detail::layout_terms(block_slot_, mirror_src_block_, pair_bounds_, mirror_slot_,
                                         term_block_, mirror_term_);
  // The terms, and the zero slot at index place.
  for (Array* p : {&pfx_, &pfy_, &pti_, &ptj_}) p->assign(static_cast<size_t>(place) + 1, 0.0);
}

}  // namespace demcal
