// Renumbering the particles (WorldImpl::reorder) and the order that fills the
// SIMD blocks (WorldImpl::block_friendly_order). See world.hpp.
#include <algorithm>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "world_impl.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
constexpr int kWindow = 64;  // particles sorted together: 8 blocks
}  // namespace

double WorldImpl::neighbour_slot_fill() const {
  const int slots = block_slot_[nblocks_];
  if (slots == 0) return 1.0;
  int real = 0;
  for (int s = 0; s < slots; ++s) real += slot_j_[s] != ghost_;
  return static_cast<double>(real) / slots;
}

std::vector<int> WorldImpl::block_friendly_order() const {
  // The pair pass pads each block's rows to its longest half row (h: the
  // neighbours j > i) and the sums to its longest mirror row (m: the
  // neighbours j < i), so a block costs max h + max m over its lanes. Each
  // window of 64 consecutive particles (locality kept) is filled from its
  // last position down: a particle's h is then known when it is placed (its
  // neighbours in later windows and those already placed after it), and
  // each pick is the one that raises its block's cost least (ties: the most
  // neighbours, then the lowest index; a block's first pick: the most
  // neighbours).
  const int n = n_;
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    ++start[pair_i_[k] + 1];
    ++start[pair_j_[k] + 1];
  }
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<int> adj(static_cast<size_t>(start[n])), fill(start.begin(), start.end() - 1);
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    adj[fill[pair_i_[k]]++] = pair_j_[k];
    adj[fill[pair_j_[k]]++] = pair_i_[k];
  }
  std::vector<int> order(n), after(n, 0);
  std::vector<char> placed(n, 0);
  for (int w = 0; w < n; w += kWindow) {
    const int e = std::min(n, w + kWindow);
    for (int p = w; p < e; ++p)
      for (int k = start[p]; k < start[p + 1]; ++k) after[p] += adj[k] >= e;
    for (int pos = e - 1; pos >= w;) {
      const int lo = std::max(w, pos / kBlock * kBlock);
      int H = 0, M = 0;
      for (int q = pos; q >= lo; --q) {
        int best = -1, best_inc = 0, best_deg = 0;
        for (int p = w; p < e; ++p) {
          if (placed[p]) continue;
          const int deg = start[p + 1] - start[p], h = after[p], m = deg - h;
          const int inc = q == pos ? 0 : std::max(H, h) + std::max(M, m) - (H + M);
          if (best < 0 || inc < best_inc || (inc == best_inc && deg > best_deg)) {
            best = p;
            best_inc = inc;
            best_deg = deg;
          }
        }
        order[q] = best;
        placed[best] = 1;
        H = std::max(H, after[best]);
        M = std::max(M, best_deg - after[best]);
        for (int k = start[best]; k < start[best + 1]; ++k)
          if (adj[k] >= w && adj[k] < e) ++after[adj[k]];
      }
      pos = lo - 1;
    }
  }
  return order;
}

void WorldImpl::reorder(std::span<const int> order) {
  const int n = n_;
  if (static_cast<int>(order.size()) != n)
    throw std::invalid_argument("WorldImpl::reorder: order must list every particle once");
  std::vector<int> new_index(n, -1);
  for (int k = 0; k < n; ++k) {
    const int i = order[k];
    if (i < 0 || i >= n || new_index[i] >= 0)
      throw std::invalid_argument("WorldImpl::reorder: order is not a permutation");
    new_index[i] = k;
  }

  // Contact histories by pair (i, j), i < j in the new numbering (the
  // scalar tangential force is the same seen from either side).
  std::vector<std::tuple<int, int, double>> history;
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = new_index[pair_i_[k]], j = new_index[pair_j_[k]];
    history.emplace_back(std::min(i, j), std::max(i, j), slot_ft_[pair_slot_[k]]);
  }
  std::sort(history.begin(), history.end());

  // Per-particle state.
  Array tmp(static_cast<size_t>(n));
  for (Array* a : {&x_, &y_, &vx_, &vy_, &theta_, &omega_, &r_, &inv_r_, &m_, &inertia_, &fx_, &fy_,
                   &tq_, &ca_t_, &cb_t_, &ca_r_, &cb_r_, &x_built_, &y_built_}) {
    for (int k = 0; k < n; ++k) tmp[k] = (*a)[order[k]];
    std::copy(tmp.begin(), tmp.end(), a->begin());
  }
  for (auto* walls : {&wall_ft_, &wall_fn_})
    for (auto& h : *walls) {
      for (int k = 0; k < n; ++k) tmp[k] = h[order[k]];
      std::copy(tmp.begin(), tmp.end(), h.begin());
    }

  // The histories as an "old" half list in the new numbering (each
  // particle's neighbours j > i in increasing index, as
  // rebuild_neighbours() expects), which
  // the rebuild then carries over slot by slot.
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (const auto& h : history) ++start[std::get<0>(h) + 1];
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  layout_blocks(start, block_slot_);
  slot_j_.assign(static_cast<size_t>(block_slot_[nblocks_]), ghost_);
  slot_ft_.assign(slot_j_.size(), 0.0);
  for (int i = 0; i < n; ++i) {
    const int b = i / kBlock, lane = i % kBlock;
    for (int k = start[i]; k < start[i + 1]; ++k) {
      const int s = block_slot_[b] + lane + kBlock * (k - start[i]);
      slot_j_[s] = std::get<1>(history[k]);
      slot_ft_[s] = std::get<2>(history[k]);
    }
  }
  list_valid_ = false;
  rebuild_neighbours();
  update_forces();
}

}  // namespace demcal
