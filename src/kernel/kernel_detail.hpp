// What both kernels' private state is made of: 64-byte aligned arrays and
// the handle of a World's worker threads (solver.cpp runs them). Private to
// src/kernel, like world_impl.hpp and sphere_world_impl.hpp.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <vector>

namespace demcal {

namespace detail {
/// 64-byte aligned storage for the particle and slot arrays (one SIMD
/// register of 8 doubles per load).
template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() noexcept = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(64)));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(64)); }
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
/// on the calling thread) and return when all are done. For the sphere
/// kernel, which shares the 2D kernel's team.
void team_run(TeamHandle& handle, int size, void (*fn)(void*, int), void* ctx);
}  // namespace detail

}  // namespace demcal
