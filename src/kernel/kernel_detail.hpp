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
