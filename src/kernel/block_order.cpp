// The order that fills the kernels' SIMD blocks (block_order.hpp).
#include "block_order.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace demcal::detail {

namespace {
constexpr int kBlock = 8;
constexpr int kWindow = 64;  // particles sorted together: 8 blocks

// Each particle's neighbours, both ways: adj[start[p] … start[p + 1]).
struct Adjacency {
  std::vector<int> start, adj;
};

Adjacency adjacency(int n, std::span<const int> pair_i, std::span<const int> pair_j) {
  Adjacency g;
  g.start.assign(static_cast<size_t>(n) + 1, 0);
  for (size_t k = 0; k < pair_i.size(); ++k) {
    ++g.start[pair_i[k] + 1];
    ++g.start[pair_j[k] + 1];
  }
  for (int i = 0; i < n; ++i) g.start[i + 1] += g.start[i];
  g.adj.resize(static_cast<size_t>(g.start[n]));
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (size_t k = 0; k < pair_i.size(); ++k) {
    g.adj[fill[pair_i[k]]++] = pair_j[k];
    g.adj[fill[pair_j[k]]++] = pair_i[k];
  }
  return g;
}

std::vector<int> greedy_order(int n, const Adjacency& g) {
  // The pair pass pads each block's rows to its longest half row (h: the
  // neighbours j > i) and the sums to its longest mirror row (m: the
  // neighbours j < i), so a block costs max h + max m over its lanes. Each
  // window of 64 consecutive particles (locality kept) is filled from its
  // last position down: a particle's h is then known when it is placed (its
  // neighbours in later windows and those already placed after it), and
  // each pick is the one that raises its block's cost least (ties: the most
  // neighbours, then the lowest index; a block's first pick: the most
  // neighbours).
  const std::vector<int>& start = g.start;
  const std::vector<int>& adj = g.adj;
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

// A block's cost in the pair pass: its longest half row evaluates the law,
// its longest mirror row only adds the pair terms back (6 gathers against
// the law's 9 and ≈ 150 arithmetic operations): in the 3D profile the
// mirror sums take ≈ 17 % of the pass with as many mirror rows as half
// rows, so a half row costs about four mirror rows.
constexpr long kHalfRowWeight = 4;
constexpr long kMirrorRowWeight = 1;

// Local search on an order: swaps of two particles in different blocks at
// most kReach positions apart (locality kept), kept when the blocks'
// weighted cost grows by no more than a threshold that falls from
// kThreshold to 0 over the search ("threshold accepting", Dueck & Scheuer
// 1990: early on it lets the order cross small rises; at the end it only
// descends). Integer costs and a fixed-seed generator: the same order on
// every machine. Each swap touches only the rows of the two particles and
// of their neighbours, O(degree); the search makes kSwapsPerParticle·n of
// them, at most kMaxSwaps (≈ 0.3 µs each).
//
// Measured (slot fill, half / mirror: pairs over the slots the pass
// evaluates): the FCC bench, 256 spheres in lattice order 0.835 / 0.835 ->
// 0.942 / 0.855; 4 000 spheres 0.959 / 0.959 kept as numbered; the sheared
// random 300 of SphereReorder's test, greedy order 0.731 / 0.694 -> 0.884 /
// 0.806. More swaps per particle (4 096, 16 384) gain 1-3 % more fill for
// 4-16 times the search.
class OrderSearch {
 public:
  OrderSearch(int n, const std::vector<int>& start, const std::vector<int>& adj,
              std::vector<int> order)
      : n_(n),
        start_(start),
        adj_(adj),
        order_(std::move(order)),
        where_(n),
        h_(n, 0),
        m_(n, 0),
        hb_((n + kBlock - 1) / kBlock, 0),
        mb_(hb_.size(), 0),
        stamp_(hb_.size(), 0) {
    for (int k = 0; k < n; ++k) where_[order_[k]] = k;
    for (int p = 0; p < n; ++p)
      for (int k = start_[p]; k < start_[p + 1]; ++k)
        if (adj_[k] > p) count(where_[p], where_[adj_[k]], +1);
    for (size_t b = 0; b < hb_.size(); ++b) block_max(static_cast<int>(b), hb_[b], mb_[b]);
  }

  std::vector<int> run() {
    std::uint64_t state = 0x9e3779b97f4a7c15ULL;
    const long swaps = std::min(kSwapsPerParticle * static_cast<long>(n_), kMaxSwaps);
    for (long s = 0; s < swaps; ++s) {
      const std::uint64_t r = next(state);
      const int P = static_cast<int>(r % static_cast<std::uint64_t>(n_));
      const int Q = P + static_cast<int>((r >> 32) % (2 * kReach + 1)) - kReach;
      if (Q < 0 || Q >= n_ || P / kBlock == Q / kBlock) continue;
      try_swap(P, Q, kThreshold * (swaps - 1 - s) / swaps);
    }
    return order_;
  }

 private:
  static constexpr int kReach = 64;
  static constexpr long kSwapsPerParticle = 1024;
  static constexpr long kMaxSwaps = 1L << 24;
  static constexpr long kThreshold = 3;  // in mirror rows (block_cost's unit)

  static std::uint64_t next(std::uint64_t& s) {  // splitmix64
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  // A pair at positions u and v: a half slot in the row of the lower, a
  // mirror slot in the row of the higher.
  void count(int u, int v, int d) {
    const int lo = std::min(u, v), hi = std::max(u, v);
    h_[lo] += d;
    m_[hi] += d;
    touch(lo / kBlock);
    touch(hi / kBlock);
  }
  void touch(int b) {
    if (stamp_[b] == epoch_) return;
    stamp_[b] = epoch_;
    touched_.push_back(b);
  }
  void block_max(int b, int& H, int& M) const {
    H = M = 0;
    const int e = std::min(n_, (b + 1) * kBlock);
    for (int q = b * kBlock; q < e; ++q) {
      H = std::max(H, h_[q]);
      M = std::max(M, m_[q]);
    }
  }
  // Moves the pairs of particles a (at P) and b (at Q) as if they swapped
  // places (d = +1) or back (the same call again): the pair (a, b) itself
  // keeps its two positions.
  void move_pairs(int a, int P, int b, int Q) {
    for (int k = start_[a]; k < start_[a + 1]; ++k) {
      const int o = adj_[k];
      if (o == b) continue;
      count(P, where_[o], -1);
      count(Q, where_[o], +1);
    }
    for (int k = start_[b]; k < start_[b + 1]; ++k) {
      const int o = adj_[k];
      if (o == a) continue;
      count(Q, where_[o], -1);
      count(P, where_[o], +1);
    }
  }
  void try_swap(int P, int Q, long allowance) {
    ++epoch_;
    touched_.clear();
    const int a = order_[P], b = order_[Q];
    move_pairs(a, P, b, Q);
    long delta = 0;
    saved_.clear();
    for (int blk : touched_) {
      int H, M;
      block_max(blk, H, M);
      saved_.push_back({hb_[blk], mb_[blk]});
      delta += kHalfRowWeight * (H - hb_[blk]) + kMirrorRowWeight * (M - mb_[blk]);
      hb_[blk] = H;
      mb_[blk] = M;
    }
    if (delta <= allowance) {
      std::swap(order_[P], order_[Q]);
      where_[a] = Q;
      where_[b] = P;
      return;
    }
    for (size_t t = 0; t < touched_.size(); ++t) {
      hb_[touched_[t]] = saved_[t].first;
      mb_[touched_[t]] = saved_[t].second;
    }
    move_pairs(a, Q, b, P);  // back: a at P, b at Q
  }

  int n_;
  const std::vector<int>& start_;
  const std::vector<int>& adj_;
  std::vector<int> order_, where_, h_, m_, hb_, mb_;
  std::vector<unsigned> stamp_;
  unsigned epoch_ = 0;
  std::vector<int> touched_;
  std::vector<std::pair<int, int>> saved_;
};

}  // namespace

std::vector<int> block_friendly_order(int n, std::span<const int> pair_i,
                                      std::span<const int> pair_j) {
  // The local search starts from the better of the greedy order and the
  // current numbering (the FCC lattice in lattice order: 2.39 slots per
  // pair, the greedy order 2.53; the consolidated hex_10x10: 74 slot rows,
  // the greedy order 82), and returns the identity unless it found a cheaper
  // order: reorder() of the identity changes nothing.
  const Adjacency g = adjacency(n, pair_i, pair_j);
  std::vector<int> identity(n);
  for (int i = 0; i < n; ++i) identity[i] = i;
  std::vector<int> greedy = greedy_order(n, g);
  const long identity_cost = block_cost(n, pair_i, pair_j, identity);
  std::vector<int> start =
      block_cost(n, pair_i, pair_j, greedy) < identity_cost ? std::move(greedy) : identity;
  // No order costs less than every row full (a block's longest row is at
  // least its mean row): within 5 % of that (the FCC lattice of 4 000
  // spheres in lattice order), the search is not worth its time (≈ 1 µs a
  // swap there, seconds in all).
  const long full = (kHalfRowWeight + kMirrorRowWeight) * static_cast<long>(pair_i.size());
  const long start_cost = std::min(identity_cost, block_cost(n, pair_i, pair_j, start));
  std::vector<int> order = 100 * kBlock * start_cost <= 105 * full
                               ? std::move(start)
                               : OrderSearch(n, g.start, g.adj, std::move(start)).run();
  if (block_cost(n, pair_i, pair_j, order) >= identity_cost) return identity;
  return order;
}

long block_cost(int n, std::span<const int> pair_i, std::span<const int> pair_j,
                std::span<const int> order) {
  std::vector<int> new_index(n), h(n, 0), m(n, 0);
  for (int k = 0; k < n; ++k) new_index[order[k]] = k;
  for (size_t k = 0; k < pair_i.size(); ++k) {
    const int a = new_index[pair_i[k]], b = new_index[pair_j[k]];
    ++h[std::min(a, b)];
    ++m[std::max(a, b)];
  }
  long cost = 0;
  for (int b = 0; b < n; b += kBlock) {
    const int e = std::min(n, b + kBlock);
    cost += kHalfRowWeight * *std::max_element(h.begin() + b, h.begin() + e) +
            kMirrorRowWeight * *std::max_element(m.begin() + b, m.begin() + e);
  }
  return cost;
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
