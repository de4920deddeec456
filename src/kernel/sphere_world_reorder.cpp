// Renumbering the spheres (SphereWorldImpl::reorder) and the order that
// fills the SIMD blocks (block_friendly_order, block_order.cpp), as
// reorder.cpp is for the 2D kernel. See sphere_world.hpp.
#include <algorithm>
#include <tuple>
#include <vector>

#include "block_order.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
}  // namespace

double SphereWorldImpl::mirror_slot_fill() const {
  const int entries = mirror_block_[nblocks_];
  if (entries == 0) return 1.0;
  return static_cast<double>(nbr_start_[n_]) / entries;
}

std::vector<int> SphereWorldImpl::block_friendly_order() const {
  std::vector<int> pair_i(nbr_j_.size());
  for (int i = 0; i < n_; ++i)
    std::fill(pair_i.begin() + nbr_start_[i], pair_i.begin() + nbr_start_[i + 1], i);
  return detail::block_friendly_order(n_, pair_i, nbr_j_);
}

void SphereWorldImpl::reorder(std::span<const int> order) {
  const int n = n_;
  const std::vector<int> new_index = detail::inverse_permutation(n, order, "SphereWorld::reorder");
  if (detail::is_identity(order)) return;
  // The list must describe the current pairs (a step or update_forces()
  // leaves it so; a set_position() since may not have).
  if (!list_valid_) rebuild_neighbours();

  // Contact histories by pair (i, j), i < j in the new numbering. A history
  // is the tangential force on the pair's lower index: where the new
  // numbering swaps the pair, it is the opposite vector.
  struct Pair {
    int i, j;
    double hx, hy, hz;
  };
  std::vector<Pair> history;
  history.reserve(nbr_j_.size());
  for (int i = 0; i < n; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int a = new_index[i], b = new_index[nbr_j_[k]];
      const int s = pair_slot_[k];
      const double sign = a < b ? 1.0 : -1.0;
      history.push_back(
          {std::min(a, b), std::max(a, b), sign * hx_[s], sign * hy_[s], sign * hz_[s]});
    }
  std::sort(history.begin(), history.end(),
            [](const Pair& p, const Pair& q) { return std::tie(p.i, p.j) < std::tie(q.i, q.j); });

  // Per-particle state (padding lanes and the ghost stay where they are).
  Array tmp(static_cast<size_t>(n));
  for (Array* a :
       {&x_,     &y_,    &z_,       &vx_,  &vy_,  &vz_,      &wx_,      &wy_,     &wz_, &r_,
        &inv_r_, &m_,    &inertia_, &fx_,  &fy_,  &fz_,      &tx_,      &ty_,     &tz_, &ca_t_,
        &cb_t_,  &ca_r_, &cb_r_,    &d_t_, &d_r_, &x_built_, &y_built_, &z_built_}) {
    for (int k = 0; k < n; ++k) tmp[k] = (*a)[order[k]];
    std::copy(tmp.begin(), tmp.end(), a->begin());
  }

  // Wall contacts: each wall's candidates in the new numbering, in
  // increasing index with their histories (rebuild_wall_candidates() merges
  // with this list).
  for (int s = 0; s < 6; ++s) {
    std::vector<int>& cand = wall_candidates_[s];
    std::vector<std::tuple<int, double, double, double>> w;
    w.reserve(cand.size());
    for (size_t k = 0; k < cand.size(); ++k)
      w.emplace_back(new_index[cand[k]], wall_hx_[s][k], wall_hy_[s][k], wall_hz_[s][k]);
    std::sort(w.begin(), w.end(),
              [](const auto& p, const auto& q) { return std::get<0>(p) < std::get<0>(q); });
    for (size_t k = 0; k < cand.size(); ++k) {
      cand[k] = std::get<0>(w[k]);
      wall_hx_[s][k] = std::get<1>(w[k]);
      wall_hy_[s][k] = std::get<2>(w[k]);
      wall_hz_[s][k] = std::get<3>(w[k]);
    }
  }

  // The histories as an "old" half list in the new numbering (each
  // particle's neighbours j > i in increasing index, then ghosts, as
  // rebuild_neighbours() expects), which the rebuild then carries over slot
  // by slot.
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (const Pair& p : history) ++start[p.i + 1];
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  block_slot_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  for (int b = 0; b < nblocks_; ++b) {
    int rows = 0;
    for (int i = kBlock * b; i < std::min(n, kBlock * (b + 1)); ++i)
      rows = std::max(rows, start[i + 1] - start[i]);
    block_slot_[b + 1] = block_slot_[b] + kBlock * rows;
  }
  const size_t ns = static_cast<size_t>(block_slot_[nblocks_]);
  slot_j_.assign(ns, ghost_);
  for (auto* h : {&hx_, &hy_, &hz_}) h->assign(ns, 0.0);
  for (int i = 0; i < n; ++i) {
    const int b = i / kBlock, lane = i % kBlock;
    for (int k = start[i]; k < start[i + 1]; ++k) {
      const int s = block_slot_[b] + lane + kBlock * (k - start[i]);
      slot_j_[s] = history[k].j;
      hx_[s] = history[k].hx;
      hy_[s] = history[k].hy;
      hz_[s] = history[k].hz;
    }
  }
  list_valid_ = false;
  update_forces();
}

}  // namespace demcal
