// SIMD helpers of the kernels' pair and particle passes (private to the
// kernel): GCC vector types of W doubles, unaligned loads and stores,
// emulated gathers, correctly rounded square roots, selects, maxima. Used
// by the 2D passes (contact.cpp) and the sphere passes (sphere_contact.cpp);
// the code path (W) is chosen once per process (kernel_simd()).
#pragma once

#include <cmath>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__)
#include <emmintrin.h>
#define DEMCAL_X86_64 1
#endif

namespace demcal {
namespace {

// ---------------------------------------------------------------- SIMD

// The vector helpers are always inlined: no vector crosses a call boundary,
// so the ABI note about passing AVX vectors does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

template <int W>
struct Simd {
  typedef double D __attribute__((vector_size(8 * W)));
  typedef long long M __attribute__((vector_size(8 * W)));  // lane masks (0 or −1)
};

#define DEMCAL_INLINE inline __attribute__((always_inline))

#ifdef DEMCAL_X86_64
// The targets of the AVX2 and AVX-512 entry points (the kernels' dispatch
// tables in contact.cpp and sphere_contact.cpp).
#define DEMCAL_V3 __attribute__((target("arch=x86-64-v3")))
#define DEMCAL_V4 __attribute__((target("arch=x86-64-v4")))
#endif

template <int W>
DEMCAL_INLINE typename Simd<W>::D load(const double *p) {
  typename Simd<W>::D v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <int W>
DEMCAL_INLINE void store(double *p, typename Simd<W>::D v) {
  // A typed (unaligned) vector store, not memcpy: a memcpy may alias any
  // object, so GCC would reload every array pointer of a pass's argument
  // struct after each store; a store of doubles cannot alias a pointer.
  typedef double U __attribute__((vector_size(8 * W), aligned(8)));
  *reinterpret_cast<U *>(p) = v;
}
// How a pass reads the W values b[j[0..W-1]] of its neighbours. kEmulated:
// W scalar loads put together in a register. kHardware: one AVX-512
// vgatherdpd (W = 8; GCC only: Clang rejects a 512-bit asm operand in the
// baseline target, see vsqrt, and gets kEmulated). The same loads of the
// same addresses, so the same bits; only the cost differs, and by CPU: the
// shuffles that put the scalars together run on the ports the law's
// arithmetic needs, where Intel's 512-bit work has two (p0, p5) — hardware
// gathers 1.13-1.28x faster there — while AMD's Zen 3 and Zen 5 run their
// hardware gathers 1.3-1.7x slower (reports/performance.md, 2026-12-06).
enum class Gather { kEmulated, kHardware };

#if defined(DEMCAL_X86_64) && !defined(__clang__)
constexpr bool kHardwareGatherBuilt = true;
#else
constexpr bool kHardwareGatherBuilt = false;
#endif

template <int W, Gather G>
DEMCAL_INLINE typename Simd<W>::D gather(const double *__restrict b, const int *__restrict j) {
  static_assert(G == Gather::kEmulated || W == 8, "hardware gathers: the AVX-512 path only");
#if defined(DEMCAL_X86_64) && !defined(__clang__)
  if constexpr (G == Gather::kHardware) {
    typedef int I8 __attribute__((vector_size(32)));
    I8 idx;
    std::memcpy(&idx, j, sizeof idx);
    typename Simd<W>::D r{};
    // The asm reads memory at b: a memory operand as wide as any array.
    struct Whole {
      double v[1 << 26];
    };
    asm("kxnorw %%k1, %%k1, %%k1\n\tvgatherdpd (%1,%2,8), %0%{%%k1%}"
        : "+&v"(r)
        : "r"(b), "v"(idx), "m"(*reinterpret_cast<const Whole *>(b))
        : "k1");
    return r;
  }
#endif
  if constexpr (W == 8)
    return
        typename Simd<W>::D{b[j[0]], b[j[1]], b[j[2]], b[j[3]], b[j[4]], b[j[5]], b[j[6]], b[j[7]]};
  else if constexpr (W == 4)
    return typename Simd<W>::D{b[j[0]], b[j[1]], b[j[2]], b[j[3]]};
  else
    return typename Simd<W>::D{b[j[0]], b[j[1]]};
}

// Correctly rounded square roots. The template bodies are compiled for the
// baseline target and only inlined into the AVX2 / AVX-512 entry points
// (contact.cpp), so an AVX intrinsic would not inline there. GCC: the 256-
// and 512-bit forms are inline assembly, which the assembler takes as it
// is. Clang checks an asm operand's size against the baseline target and
// rejects them; it gets the 128-bit SSE2 form on each half instead (in the
// AVX entry points the VEX encoding of the same instruction). Every form is
// IEEE sqrt, correctly rounded: the results are the same bits.
DEMCAL_INLINE Simd<2>::D vsqrt(Simd<2>::D a) {
#ifdef DEMCAL_X86_64
  return reinterpret_cast<Simd<2>::D>(_mm_sqrt_pd(reinterpret_cast<__m128d>(a)));
#else
  return Simd<2>::D{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
#ifdef DEMCAL_X86_64
#ifdef __clang__
DEMCAL_INLINE Simd<4>::D vsqrt(Simd<4>::D a) {
  const Simd<2>::D lo = vsqrt(Simd<2>::D(__builtin_shufflevector(a, a, 0, 1)));
  const Simd<2>::D hi = vsqrt(Simd<2>::D(__builtin_shufflevector(a, a, 2, 3)));
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3);
}
DEMCAL_INLINE Simd<8>::D vsqrt(Simd<8>::D a) {
  const Simd<4>::D lo = vsqrt(Simd<4>::D(__builtin_shufflevector(a, a, 0, 1, 2, 3)));
  const Simd<4>::D hi = vsqrt(Simd<4>::D(__builtin_shufflevector(a, a, 4, 5, 6, 7)));
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
}
#else
DEMCAL_INLINE Simd<4>::D vsqrt(Simd<4>::D a) {
  Simd<4>::D r;
  asm("vsqrtpd %1, %0" : "=x"(r) : "x"(a));
  return r;
}
DEMCAL_INLINE Simd<8>::D vsqrt(Simd<8>::D a) {
  Simd<8>::D r;
  asm("vsqrtpd %1, %0" : "=v"(r) : "v"(a));
  return r;
}
#endif
#endif

// Makes v opaque to the optimiser (an empty asm the value must pass
// through): it is used as rounded, never fused into an FMA with what
// follows. Clang rejects a 256- or 512-bit asm operand in the baseline
// target (see vsqrt): it passes the 128-bit halves.
template <int W>
DEMCAL_INLINE void opaque(typename Simd<W>::D &v) {
#ifdef DEMCAL_X86_64
#ifdef __clang__
  if constexpr (W == 2) {
    asm("" : "+x"(v));
  } else {
    using H = typename Simd<W / 2>::D;
    H lo, hi;
    std::memcpy(&lo, &v, sizeof lo);
    std::memcpy(&hi, reinterpret_cast<const char *>(&v) + sizeof lo, sizeof hi);
    opaque<W / 2>(lo);
    opaque<W / 2>(hi);
    std::memcpy(&v, &lo, sizeof lo);
    std::memcpy(reinterpret_cast<char *>(&v) + sizeof lo, &hi, sizeof hi);
  }
#else
  if constexpr (W == 8)
    asm("" : "+v"(v));
  else
    asm("" : "+x"(v));
#endif
#else
  (void)v;
#endif
}

template <int W>
DEMCAL_INLINE typename Simd<W>::D select(typename Simd<W>::M m, typename Simd<W>::D a,
                                         typename Simd<W>::D b) {
  return m ? a : b;
}

template <int W>
DEMCAL_INLINE double hmax(typename Simd<W>::D v) {
  double m = v[0];
  for (int l = 1; l < W; ++l) m = v[l] > m ? v[l] : m;
  return m;
}

}  // namespace
}  // namespace demcal
