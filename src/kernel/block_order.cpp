// The order that fills the kernels' SIMD blocks (block_order.hpp).
#include "block_order.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace demcal::detail {

namespace {
constexpr int kBlock = 8;
constexpr int kWindow = 64;  // particles sorted together: 8 blocks

std::vector<int> greedy_order(int n, std::span<const int> pair_i, std::span<const int> pair_j) {
  // The pair pass pads each block's rows to its longest half row (h: the
  // neighbours j > i) and the sums to its longest mirror row (m: the
  // neighbours j < i), so a block costs max h + max m over its lanes. Each
  // window of 64 consecutive particles (locality kept) is filled from its
  // last position down: a particle's h is then known when it is placed (its
  // neighbours in later windows and those already placed after it), and
  // each pick is the one that raises its block's cost least (ties: the most
  // neighbours, then the lowest index; a block's first pick: the most
  // neighbours).
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (size_t k = 0; k < pair_i.size(); ++k) {
    ++start[pair_i[k] + 1];
    ++start[pair_j[k] + 1];
  }
  for (int i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<int> adj(static_cast<size_t>(start[n])), fill(start.begin(), start.end() - 1);
  for (size_t k = 0; k < pair_i.size(); ++k) {
    adj[fill[pair_i[k]]++] = pair_j[k];
    adj[fill[pair_j[k]]++] = pair_i[k];
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

}  // namespace

std::vector<int> block_friendly_order(int n, std::span<const int> pair_i,
                                      std::span<const int> pair_j) {
  // The current numbering where the greedy order would not fill the blocks
  // better (the FCC lattice in lattice order: 2.39 slots per pair, the
  // greedy order 2.53; the consolidated hex_10x10: 74 slot rows, the greedy
  // order 82).
  std::vector<int> order = greedy_order(n, pair_i, pair_j);
  std::vector<int> identity(n);
  for (int i = 0; i < n; ++i) identity[i] = i;
  if (block_slot_rows(n, pair_i, pair_j, order) >= block_slot_rows(n, pair_i, pair_j, identity))
    return identity;
  return order;
}

long block_slot_rows(int n, std::span<const int> pair_i, std::span<const int> pair_j,
                     std::span<const int> order) {
  std::vector<int> new_index(n), h(n, 0), m(n, 0);
  for (int k = 0; k < n; ++k) new_index[order[k]] = k;
  for (size_t k = 0; k < pair_i.size(); ++k) {
    const int a = new_index[pair_i[k]], b = new_index[pair_j[k]];
    ++h[std::min(a, b)];
    ++m[std::max(a, b)];
  }
  long rows = 0;
  for (int b = 0; b < n; b += kBlock) {
    const int e = std::min(n, b + kBlock);
    rows += *std::max_element(h.begin() + b, h.begin() + e) +
            *std::max_element(m.begin() + b, m.begin() + e);
  }
  return rows;
}

bool is_identity(std::span<const int> order) {
  for (size_t k = 0; k < order.size(); ++k)
    if (order[k] != static_cast<int>(k)) return false;
  return true;
}

std::vector<int> inverse_permutation(int n, std::span<const int> order, std::string_view caller) {
  if (static_cast<int>(order.size()) != n)
    throw std::invalid_argument(std::string(caller) + ": order must list every particle once");
  std::vector<int> new_index(n, -1);
  for (int k = 0; k < n; ++k) {
    const int i = order[k];
    if (i < 0 || i >= n || new_index[i] >= 0)
      throw std::invalid_argument(std::string(caller) + ": order is not a permutation");
    new_index[i] = k;
  }
  return new_index;
}

}  // namespace demcal::detail
