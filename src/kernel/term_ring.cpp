// The places of the pair terms (term_ring.hpp), for both kernels.
#include "term_ring.hpp"

#include <algorithm>
#include <cstdint>

namespace demcal::detail {

int layout_terms(std::span<const int> block_slot, std::span<const int> mirror_src_block,
                 std::span<const int> pair_bounds, std::span<const int> mirror_slot,
                 std::vector<int>& term_block, AlignedVector<int>& mirror_term) {
  // The pair terms of block b are needed until the sums of the last block
  // that mirrors one of its slots; with the sums fused into the pair pass
  // (one thread: every block) that is at most the window of blocks
  // [mirror_src_block[c], c] behind. So each thread's blocks take their
  // places in a ring that holds the longest such window, and the terms stay
  // in cache instead of streaming a per-slot array to memory and back (at
  // 10^5 disks, 32 B per slot each way). The blocks the sum pass needs after
  // the barrier (threads: the windows of the blocks not summed in the pair
  // pass) get places of their own, outside the rings. The values and the
  // order of the sums are those of a per-slot array: only where a term
  // waits changes.
  const int nb = static_cast<int>(block_slot.size()) - 1;
  const int ns = block_slot[nb];
  const int t = static_cast<int>(pair_bounds.size()) - 1;
  const bool mirrored = static_cast<int>(mirror_src_block.size()) == nb;
  auto src = [&](int b) { return mirrored ? mirror_src_block[b] : b; };
  auto size = [&](int b) { return block_slot[b + 1] - block_slot[b]; };
  std::vector<char> own_place(nb, 0);
  for (int k = 0; k < t; ++k)
    for (int b = pair_bounds[k]; b < pair_bounds[k + 1]; ++b)
      if (src(b) < pair_bounds[k])
        for (int c = src(b); c <= b; ++c) own_place[c] = 1;
  term_block.assign(static_cast<size_t>(nb) + 1, 0);
  int place = 0;
  for (int b = 0; b < nb; ++b)
    if (own_place[b]) {
      term_block[b] = place;
      place += size(b);
    }
  std::vector<int64_t> at(nb);  // a ring block's place, counted without wrapping
  for (int k = 0; k < t; ++k) {
    const int b0 = pair_bounds[k], b1 = pair_bounds[k + 1];
    int64_t total = 0, span = 0;
    int largest = 0;
    // The first ring block of block b's window, or b + 1 if none.
    auto first_in_ring = [&](int b) {
      int first = src(b);
      while (first <= b && own_place[first]) ++first;
      return first;
    };
    // Places for capacity `cap`: a block that would cross the ring's end
    // starts it again. Returns the longest window, from the start of its
    // first ring block to the end of its last, over the blocks the pass sums
    // (a block with a place of its own may be one of them: its window's
    // ring blocks must wait too).
    auto place_ring = [&](int64_t cap) {
      int64_t a = 0, longest = 0;
      for (int b = b0; b < b1; ++b) {
        if (!own_place[b]) {
          if (a % cap + size(b) > cap) a = (a / cap + 1) * cap;
          at[b] = a;
          a += size(b);
        }
        if (src(b) < b0) continue;  // summed after the barrier
        const int first = first_in_ring(b);
        if (first <= b) longest = std::max(longest, a - at[first]);
      }
      return longest;
    };
    for (int b = b0; b < b1; ++b) {
      if (!own_place[b]) {
        total += size(b);
        largest = std::max(largest, size(b));
      }
      const int first = first_in_ring(b);
      if (src(b) >= b0 && first <= b)
        span = std::max<int64_t>(span, block_slot[b + 1] - block_slot[first]);
    }
    int64_t cap = std::max<int64_t>(span + largest, 1);
    if (cap >= total) cap = std::max<int64_t>(total, 1);
    // A window fits when its blocks all lie within one capacity of its first.
    for (int64_t longest; (longest = place_ring(cap)) > cap;) cap = std::min(longest, total);
    for (int b = b0; b < b1; ++b)
      if (!own_place[b]) term_block[b] = place + static_cast<int>(at[b] % cap);
    place += static_cast<int>(std::min(cap, total));
  }
  term_block[nb] = place;
  // The mirror list's entries as places; its padding (the zero slot ns) at
  // the zero place, index `place`.
  mirror_term.resize(mirror_slot.size());
  for (size_t e = 0; e < mirror_slot.size(); ++e) {
    const int s = mirror_slot[e];
    if (s >= ns) {
      mirror_term[e] = place;
      continue;
    }
    const int b = static_cast<int>(std::upper_bound(block_slot.begin(), block_slot.end(), s) -
                                   block_slot.begin()) -
                  1;
    mirror_term[e] = term_block[b] + (s - block_slot[b]);
  }
  return place;
}

}  // namespace demcal::detail
