// Where the pair pass writes its per-slot pair terms, one algorithm for both
// kernels (WorldImpl::layout_terms, SphereWorldImpl::layout_terms): blocks
// share places in a ring once no sum needs their terms any more, so that
// the terms stay in cache between the pair pass that writes them and the
// mirrored sums that read them back. Private to src/kernel, like
// kernel_detail.hpp.
#pragma once

#include <span>
#include <vector>

#include "kernel_detail.hpp"

namespace demcal::detail {

/// The places of the pair terms of a half list of blocks of 8: block b's
/// slot s (block_slot[b] ≤ s < block_slot[b + 1]) has its terms at
/// term_block[b] + s − block_slot[b]; mirror_term the mirror list's entries
/// (mirror_slot, the zero slot block_slot.back() for padding) as places,
/// the padding at the zero place. mirror_src_block[b]: the lowest block
/// holding one of b's mirrored slots (b itself if none; an empty span reads
/// so for every block). pair_bounds: the threads' block ranges of the pair
/// pass (with more than one thread, a thread's pair pass sums the blocks
/// whose mirrored slots it wrote all of, the sum pass after the barrier the
/// others; one thread sums every block right after its pairs).
/// Returns the number of places: term_block has nblocks + 1 entries, the
/// last that number, which is also the index of the zero place.
int layout_terms(std::span<const int> block_slot, std::span<const int> mirror_src_block,
                 std::span<const int> pair_bounds, std::span<const int> mirror_slot,
                 std::vector<int>& term_block, AlignedVector<int>& mirror_term);

}  // namespace demcal::detail
