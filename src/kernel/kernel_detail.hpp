// What both kernels' private state is made of: 64-byte aligned arrays and
// the handle of a World's worker threads (solver.cpp runs them), and how
// both share their passes among those threads. Private to src/kernel, like
// world_impl.hpp and sphere_world_impl.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace demcal {

namespace detail {
/// Arrays from this size on start at staggered offsets in their pages.
constexpr std::size_t kStaggeredBytes = 4096;

/// Where in its 4 KiB page the next array of `bytes` starts: a multiple of
/// 64 from 64 to 4032, the next of 63 such offsets for every array of
/// kStaggeredBytes or more (consecutive arrays 19 lines apart), 0 for a
/// smaller one (which malloc packs among others anyway).
///
/// Why: glibc serves a block beyond its mmap threshold (128 KiB at first,
/// raised by each such block freed) from fresh pages, so such arrays all
/// start at the same offset in their pages. A pass that reads element k of
/// many of them at once — the sphere pair pass reads and writes 11 slot
/// arrays at slot k and gathers 9 particle arrays at neighbour j — then
/// maps them all to one set of the 8-way L1 cache (4 KiB per way) and makes
/// every load look as if it may depend on the stores to the others (the
/// same address mod 4096). Whether a run met this depended on what it had
/// allocated and freed before: the benchmark's 4 000-sphere world did, and
/// runs 1.2x faster staggered (reports/performance.md, 2026-12-05), while
/// `demcal run` on the same sample did not. Addresses change no result.
inline std::size_t page_offset_for(std::size_t bytes) {
  if (bytes < kStaggeredBytes) return 0;
  static std::atomic<unsigned> next{0};
  const unsigned k = next.fetch_add(1, std::memory_order_relaxed) % 63;
  return 64 * (1 + (19 * k) % 63);
}

/// 64-byte aligned storage for the particle and slot arrays (one SIMD
/// register of 8 doubles per load), large arrays at staggered offsets in
/// their pages (page_offset_for).
template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() noexcept = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T), offset = page_offset_for(bytes);
    if (offset == 0) return static_cast<T*>(::operator new(bytes, std::align_val_t(64)));
    // The page-aligned block, `offset` bytes of it skipped; the block's
    // address is kept just before the array for deallocate.
    char* block = static_cast<char*>(::operator new(bytes + offset, std::align_val_t(4096)));
    char* array = block + offset;
    std::memcpy(array - sizeof(char*), &block, sizeof(char*));
    return reinterpret_cast<T*>(array);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kStaggeredBytes) {
      ::operator delete(p, std::align_val_t(64));
      return;
    }
    char* block;
    std::memcpy(&block, reinterpret_cast<char*>(p) - sizeof(char*), sizeof(char*));
    ::operator delete(block, std::align_val_t(4096));
  }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const noexcept {
    return true;
  }
};
template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

/// The sum of 8 SIMD lanes (a block's, or 8 wall candidates'), one tree
/// whatever the path's width: ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 +
/// l7)). A pass keeps such a sum lane by lane and writes the 8 lanes; the
/// caller adds them here (block_lanes_sum for a whole pass). (Reduced W
/// lanes wide inside a pass, lane l and lane l + W of the narrower path
/// would meet first, so AVX2 and AVX-512 would round the sphere kernel's
/// wall forces and its ledger differently and, through the triaxial test's
/// servo, end in different samples.)
inline double lane_sum(const double* l) {
  return ((l[0] + l[4]) + (l[2] + l[6])) + ((l[1] + l[5]) + (l[3] + l[7]));
}
/// The sum of `nblocks` blocks' lanes (8 per block, as the passes write
/// them): each lane over the blocks in block order, then lane_sum.
inline double block_lanes_sum(const double* lanes, int nblocks) {
  double lane[8] = {};
  for (int b = 0; b < nblocks; ++b)
    for (int l = 0; l < 8; ++l) lane[l] += lanes[8 * b + l];
  return lane_sum(lane);
}

/// Whether a neighbour list built with Verlet skin `skin` is out of date:
/// the particles moved by at most sqrt(max_d2) since it was built, the walls
/// from `built` (their positions then) to walls[w].position. Two particles
/// approach each other by at most 2·max_disp; a particle and a wall by
/// max_disp + max_wall.
template <class Walls, std::size_t N>
bool skin_exceeded(double max_d2, const Walls& walls, const std::array<double, N>& built,
                   double skin) {
  const double max_disp = std::sqrt(max_d2);
  double max_wall = 0.0;
  for (std::size_t w = 0; w < N; ++w)
    max_wall = std::max(max_wall, std::abs(walls[w].position - built[w]));
  return 2.0 * max_disp >= skin || max_disp + max_wall >= skin;
}

class KernelTeam;  // worker threads of one World (solver.cpp)
/// Owns a World's worker threads. Copying a World does not copy its threads:
/// the copy starts its own on first use.
struct TeamHandle {
  std::unique_ptr<KernelTeam> team;
  TeamHandle() noexcept;
  TeamHandle(const TeamHandle&) noexcept;
  TeamHandle(TeamHandle&&) noexcept;
  TeamHandle& operator=(const TeamHandle&) noexcept;
  TeamHandle& operator=(TeamHandle&&) noexcept;
  ~TeamHandle();
};
/// Run fn(ctx, t) for t = 0 .. size − 1 on `handle`'s team of `size`
/// threads (started on first use, restarted if its size differs; t = 0 runs
/// on the calling thread) and return when all are done. Both kernels' passes
/// (run_pass).
void team_run(TeamHandle& handle, int size, void (*fn)(void*, int), void* ctx);

/// KernelOptions::threads as a count (0: the machine's hardware threads,
/// at least 1); a negative count throws std::invalid_argument naming
/// `kernel` (World, SphereWorld).
inline int thread_count(int threads, const char* kernel) {
  if (threads < 0) throw std::invalid_argument(std::string(kernel) + ": threads must be >= 0");
  if (threads == 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return threads;
}

/// The threads worth using for `nblocks` blocks of 8 particles, of the
/// `threads` asked for: at least 8 blocks (64 particles) per thread, or the
/// hand-over costs more than it saves; at most 64.
inline int active_threads(int threads, int nblocks) {
  return std::max(1, std::min({threads, nblocks / 8, 64}));
}

/// The block ranges of `t` threads, thread k taking [bounds[k], bounds[k +
/// 1]): for the particle passes equal shares of the blocks; for the pair
/// pass equal shares of the slots (`block_slot`, non-decreasing, holds each
/// block's first slot, its last entry the total).
inline void thread_bounds(int t, int nblocks, const std::vector<int>& block_slot,
                          std::vector<int>& particle_bounds, std::vector<int>& pair_bounds) {
  particle_bounds.assign(static_cast<size_t>(t) + 1, 0);
  pair_bounds.assign(static_cast<size_t>(t) + 1, 0);
  for (int k = 0; k <= t; ++k)
    particle_bounds[k] = static_cast<int>(static_cast<int64_t>(nblocks) * k / t);
  const int64_t total = block_slot.back();
  int b = 0;
  for (int k = 1; k < t; ++k) {
    const int64_t target = total * k / t;
    while (b < nblocks && block_slot[b] < target) ++b;
    pair_bounds[k] = b;
  }
  pair_bounds[t] = nblocks;
}

/// One pass (w->*pass)(b0, b1) over blocks [0, nblocks), split among `t`
/// threads of `team` by `bounds` (one thread: a single call on the calling
/// thread); returns the largest value the calls returned. Maxima are exact
/// whatever the split: the result does not depend on t.
template <class Impl>
double run_pass(TeamHandle& team, int t, int nblocks, Impl* w, double (Impl::*pass)(int, int),
                const std::vector<int>& bounds) {
  if (t <= 1) return (w->*pass)(0, nblocks);
  struct Ctx {
    Impl* w;
    double (Impl::*pass)(int, int);
    const std::vector<int>* bounds;
    double out[64];
  } ctx{w, pass, &bounds, {}};
  team_run(
      team, t,
      [](void* p, int k) {
        auto* c = static_cast<Ctx*>(p);
        c->out[k] = (c->w->*c->pass)((*c->bounds)[k], (*c->bounds)[k + 1]);
      },
      &ctx);
  return *std::max_element(ctx.out, ctx.out + t);
}
}  // namespace detail

}  // namespace demcal
