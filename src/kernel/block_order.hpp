// The particle order that fills the kernels' SIMD blocks, one algorithm for
// both (World::block_friendly_order, SphereWorld::block_friendly_order), and
// the check and inversion of an order both reorder()s take. Private to
// src/kernel, like kernel_detail.hpp.
#pragma once

#include <span>
#include <string_view>
#include <vector>

namespace demcal::detail {

/// An order for reorder() of n particles whose neighbour pairs are
/// (pair_i[k], pair_j[k]) (each pair once, either way round): order[k] is
/// the particle to become particle k. The pair pass evaluates blocks of 8
/// particles and pads their half rows (neighbours of higher index) and
/// mirror rows (lower index) to the longest of the block; a greedy order
/// (each window of 64 consecutive particles, locality kept, ordered so that
/// the particles of a block have as many neighbours on either side) or the
/// current numbering, whichever costs less (block_cost), is improved by a
/// local search of swaps between nearby blocks. The identity unless that
/// order costs less than the current numbering.
std::vector<int> block_friendly_order(int n, std::span<const int> pair_i,
                                      std::span<const int> pair_j);

/// What the pair pass costs under `order` (as block_friendly_order returns
/// it), in mirror-row units: over the blocks of 8 new indices, the longest
/// half row, weighted 4 (the law), plus the longest mirror row (the sums).
long block_cost(int n, std::span<const int> pair_i, std::span<const int> pair_j,
                std::span<const int> order);

/// True when `order` keeps every particle where it is (order[k] = k): both
/// reorder()s then change nothing, not even the last bits of the forces,
/// and rebuild nothing.
bool is_identity(std::span<const int> order);

/// The inverse of an order for reorder() of n particles: new_index[order[k]]
/// = k. Throws std::invalid_argument, its message starting with `caller`
/// ("<caller>: order must list every particle once" unless order has n
/// entries, "<caller>: order is not a permutation" for an entry out of
/// 0 … n − 1 or repeated).
std::vector<int> inverse_permutation(int n, std::span<const int> order, std::string_view caller);

}  // namespace demcal::detail
