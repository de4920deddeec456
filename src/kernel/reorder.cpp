// Renumbering the particles (WorldImpl::reorder) and the order that fills the
// SIMD blocks (WorldImpl::block_friendly_order, block_order.cpp). See
// world.hpp.
#include <algorithm>
#include <tuple>
#include <vector>

#include "block_order.hpp"
#include "world_impl.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
}  // namespace

double WorldImpl::neighbour_slot_fill() const {
  const int slots = block_slot_[nblocks_];
  if (slots == 0) return 1.0;
  int real = 0;
  for (int s = 0; s < slots; ++s) real += slot_j_[s] != ghost_;
  return static_cast<double>(real) / slots;
}

std::vector<int> WorldImpl::block_friendly_order() const {
  return detail::block_friendly_order(n_, pair_i_, pair_j_);
}

void WorldImpl::reorder(std::span<const int> order) {
  const int n = n_;
  const std::vector<int> new_index = detail::inverse_permutation(n, order, "WorldImpl::reorder");
  // The identity (a lattice's block_friendly_order) rebuilds nothing.
  if (detail::is_identity(order)) return;

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
