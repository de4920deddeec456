// Contact law (README.md "Physics in one paragraph"): linear normal spring kn·δ; incremental
// tangential spring kt capped by Coulomb μ·Fn. The tangential force is kept
// as a scalar along the contact tangent t = (−n_y, n_x), so it turns with the
// contact as the pair rolls around itself.
//
// Contact point: x^c = x_i + (r_i − δ/2)·n, the middle of the overlap. The
// same lever arms enter the torques and the stress, so a moment-free particle
// contributes a symmetric term to σ exactly.
//
// The particle–particle loop runs over the half neighbour list (pairs i <
// j, broad_phase.cpp) in blocks of 8 particles, W lanes at a time with GCC
// vector extensions: W = 8 on x86-64-v4 (AVX-512), 4 on x86-64-v3 (AVX2),
// 2 on baseline x86-64 (SSE2). The path is chosen once from the CPU; the
// default build needs no -march flag. Every pair is evaluated once, from
// its lower index: each particle's force and torque are written as the
// plain sum over its own slots (pairs j > i, increasing j), and per slot the
// pass writes the pair's force on i and its torque on j; the sums
// (sum_blocks) then add to each particle j, from its mirror list in
// increasing i, the opposite of that force and that torque. Both sums run
// in a fixed order whatever the thread split (each pass writes only its own
// particles' or slots' values), so results are bit-identical for any thread
// count; non-touching slots add exact zeros. With one thread each block's
// sums run right after its pairs (its mirrored slots lie in blocks ≤ its
// own), the pair terms still in cache; with threads, in a second pass after
// the barrier. (Until the half list, issue #17, the list was full and each
// pair was evaluated twice, once from either side, the rotational term
// written ½[(ω_i + ω_j)(a_i + a_j) + (ω_i − ω_j)(a_i − a_j)] so that both
// copies came out exact opposites under FMA contraction; evaluated once, it
// takes the plain form. reports/performance.md has what it bought.)
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

#include "contact_law.hpp"
#include "simd.hpp"
#include "world_impl.hpp"

namespace demcal {

namespace {

constexpr int kBlock = 8;

struct PairArgs {
  const int *__restrict block_slot;
  const int *__restrict slot_j;
  double *__restrict slot_ft;
  const double *__restrict slot_r, *__restrict slot_ir;  // the slot's neighbour: r, 1/r
  double *__restrict pfx, *__restrict pfy;               // per slot: the pair's force on i
  double *__restrict pti, *__restrict ptj;               // per slot: its torques on i and j
  const double *__restrict x, *__restrict y, *__restrict vx, *__restrict vy, *__restrict om;
  const double *__restrict r, *__restrict inv_r, *__restrict m;
  double *__restrict fx, *__restrict fy, *__restrict tq;
  double *__restrict block_power;    // per lane (8 per block): power of the contact dashpots
  double kn, kdt, mu, beta2;         // beta2 = 2·contact damping ratio
  const int *__restrict term_block;  // where block b's slots have their pair terms
  const int *__restrict mirror_block;
  const int *__restrict mirror_term;  // places of the mirrored pair terms
  // Threads: block b's sums run right after its pairs where this pass has
  // written all its mirrored slots (its lowest source block src_block[b] is
  // in the pass's range); fused[b] tells the sum pass which are left.
  const int *__restrict src_block;
  unsigned char *__restrict fused;
};

// Sums each particle's force and torque over its pairs in increasing index
// of the partner, and writes them: first its pairs (i, j), i < j, from its
// mirror list (the opposite of the force on i, the torque on j), then its
// own slots (pairs j > i). That is the order, and the terms are the bits,
// of the full list this kernel had until issue #17 ("each particle's
// neighbours in increasing index": a pair's two evaluations there gave
// exact opposites), so the forces are bit-identical to that kernel's. The
// pair pass calls it fused (one thread) and the sum pass after the barrier
// (threads): the same sums in the same order.
template <int W, Gather G>
DEMCAL_INLINE void sum_blocks(const PairArgs &a, int b0, int b1, bool skip_fused = false) {
  using D = typename Simd<W>::D;
  const D zero{};
  const int *__restrict p_mirror_term = a.mirror_term;  // locals: see pair_blocks
  const double *p_pfx = a.pfx, *p_pfy = a.pfy, *p_pti = a.pti, *p_ptj = a.ptj;
  double *__restrict p_fx = a.fx, *__restrict p_fy = a.fy, *__restrict p_tq = a.tq;
  for (int b = b0; b < b1; ++b) {
    if (skip_fused && a.fused[b]) continue;
    const int m0 = a.mirror_block[b], m1 = a.mirror_block[b + 1];
    const int s0 = a.block_slot[b], s1 = a.block_slot[b + 1];
    const int t0 = a.term_block[b] - s0;  // slot s's terms at t0 + s
    for (int sub = 0; sub < kBlock; sub += W) {
      const int i0 = kBlock * b + sub;
      D fx = zero, fy = zero, tq = zero;
      for (int s = m0 + sub; s < m1; s += kBlock) {
        const int *S = p_mirror_term + s;
        fx -= gather<W, G>(p_pfx, S);
        fy -= gather<W, G>(p_pfy, S);
        tq += gather<W, G>(p_ptj, S);
      }
      for (int s = s0 + sub; s < s1; s += kBlock) {
        fx += load<W>(p_pfx + t0 + s);
        fy += load<W>(p_pfy + t0 + s);
        tq += load<W>(p_pti + t0 + s);
      }
      store<W>(p_fx + i0, fx);
      store<W>(p_fy + i0, fy);
      store<W>(p_tq + i0, tq);
    }
  }
}

// Pairs of blocks [b0, b1) on the half list (each pair once, from i < j):
// per slot the pair's force on i and its torques on i and j; and each
// block's sums right after its pairs, the pair terms still in cache, where
// this pass wrote all of its mirrored slots (they lie in blocks ≤ b): with
// one thread (kAll) every block; with threads the blocks whose mirrored
// slots all lie in the thread's own range, the others in the sum pass after
// the barrier (the same sums). Returns the largest
// overlap/min(r_i, r_j). The damped pass also writes each block's dashpot
// power, Σ (fe − fn)·v_n over its slots, for the energy ledger.
template <int W, Gather G, bool kDamped, bool kAll>
DEMCAL_INLINE double pair_blocks(const PairArgs &a, int b0, int b1) {
  using D = typename Simd<W>::D;
  const D zero{};
  D mo = zero;
  const double kn = a.kn, kdt = a.kdt, mu = a.mu;
  // The arrays as locals: the stores (memcpy) could otherwise alias the
  // pointers in `a`, which the loop would reload every iteration.
  const int *__restrict p_slot_j = a.slot_j;
  double *__restrict p_slot_ft = a.slot_ft;
  const double *__restrict p_slot_r = a.slot_r, *__restrict p_slot_ir = a.slot_ir;
  const double *__restrict p_x = a.x, *__restrict p_y = a.y, *__restrict p_vx = a.vx,
                           *__restrict p_vy = a.vy, *__restrict p_om = a.om;
  const double *__restrict p_r = a.r, *__restrict p_inv_r = a.inv_r, *__restrict p_m = a.m;
  double *p_pfx = a.pfx, *p_pfy = a.pfy, *p_pti = a.pti, *p_ptj = a.ptj;  // sum_blocks reads them
  for (int b = b0; b < b1; ++b) {
    const int s0 = a.block_slot[b], s1 = a.block_slot[b + 1];
    const int t0 = a.term_block[b] - s0;  // slot s's terms at t0 + s
    for (int sub = 0; sub < kBlock; sub += W) {
      const int i0 = kBlock * b + sub;
      D power = zero;  // this sub-block's lanes, into block_power after the slots
      const D xi = load<W>(p_x + i0), yi = load<W>(p_y + i0);
      const D vxi = load<W>(p_vx + i0), vyi = load<W>(p_vy + i0), omi = load<W>(p_om + i0);
      const D ri = load<W>(p_r + i0), iri = load<W>(p_inv_r + i0);
      D mi = zero;
      if constexpr (kDamped) mi = load<W>(p_m + i0);
      for (int s = s0 + sub; s < s1; s += kBlock) {
        const int *J = p_slot_j + s;
        const D rj = load<W>(p_slot_r + s);
        const D dx = gather<W, G>(p_x, J) - xi, dy = gather<W, G>(p_y, J) - yi;
        const D d2 = dx * dx + dy * dy;
        const D rs = ri + rj;
        const typename Simd<W>::M touch = d2 < rs * rs;
        const D d = vsqrt(d2);
        const D inv = 1.0 / d;
        const D nx = dx * inv, ny = dy * inv;
        const D ov = rs - d;
        const D ai = ri - 0.5 * ov, aj = rj - 0.5 * ov;
        const D omj = gather<W, G>(p_om, J);
        const D dvx = gather<W, G>(p_vx, J) - vxi, dvy = gather<W, G>(p_vy, J) - vyi;
        D fn = law::elastic_normal_force(kn, ov);
        if constexpr (kDamped) {
          const D meff = reduced_mass(mi, gather<W, G>(p_m, J));
          const D vn = dvx * nx + dvy * ny;  // > 0 when separating
          const D fe = fn;
          fn = law::damped_normal_force(fe, a.beta2, vsqrt(kn * meff), vn);
          power += select<W>(touch, law::dashpot_power(fe, fn, vn), zero);
        }
        fn = select<W>(touch, fn, zero);
        // Tangential velocity of j's contact point relative to i's, along t.
        // (The symmetric form of ω_i·a_i + ω_j·a_j: the full list needed it
        // for its two copies of a pair to come out exact opposites; kept, so
        // that the forces stay those bits, see sum_blocks.)
        const D rot = 0.5 * ((omi + omj) * (ai + aj) + (omi - omj) * (ai - aj));
        const D vt = (dvy * nx - dvx * ny) - rot;
        const D cap = mu * fn;
        D t = law::coulomb_clamp(load<W>(p_slot_ft + s) + kdt * vt, cap);
        t = select<W>(touch, t, zero);
        store<W>(p_slot_ft + s, t);
        // Force on i: −fn·n + ft·t (on j its opposite); torques a_i·ft on
        // i, a_j·ft on j.
        store<W>(p_pfx + t0 + s, -fn * nx - t * ny);
        store<W>(p_pfy + t0 + s, -fn * ny + t * nx);
        store<W>(p_pti + t0 + s, ai * t);
        store<W>(p_ptj + t0 + s, aj * t);
        // overlap/min(r_i, r_j) (ov ≥ 0 where touching: the product is
        // monotone, the larger of the two ratios exactly).
        const D irj = load<W>(p_slot_ir + s);
        const D ovr = select<W>(touch, ov * (iri > irj ? iri : irj), zero);
        mo = mo > ovr ? mo : ovr;
      }
      if constexpr (kDamped) store<W>(a.block_power + i0, power);
    }
    if constexpr (kAll) {
      sum_blocks<W, G>(a, b, b + 1);
    } else {
      const bool complete = a.src_block[b] >= b0;
      a.fused[b] = complete;
      if (complete) sum_blocks<W, G>(a, b, b + 1);
    }
  }
  return hmax<W>(mo);
}

struct IntegrateArgs {
  double *__restrict x, *__restrict y, *__restrict vx, *__restrict vy, *__restrict th,
                                                                           *__restrict om;
  const double *__restrict fx, *__restrict fy, *__restrict tq;
  const double *__restrict ca_t, *__restrict cb_t, *__restrict ca_r, *__restrict cb_r;
  const double *__restrict x_built, *__restrict y_built;
  double dt;
};

// Central difference with global damping for blocks [b0, b1); returns the
// largest squared displacement since the last neighbour-list build.
template <int W, bool kRotation>
DEMCAL_INLINE double integrate_blocks(const IntegrateArgs &a, int b0, int b1) {
  using D = typename Simd<W>::D;
  D md = D{};
  const double dt = a.dt;
  for (int i = kBlock * b0; i < kBlock * b1; i += W) {
    const D vx = load<W>(a.ca_t + i) * load<W>(a.vx + i) + load<W>(a.cb_t + i) * load<W>(a.fx + i);
    const D vy = load<W>(a.ca_t + i) * load<W>(a.vy + i) + load<W>(a.cb_t + i) * load<W>(a.fy + i);
    const D x = load<W>(a.x + i) + vx * dt, y = load<W>(a.y + i) + vy * dt;
    store<W>(a.vx + i, vx);
    store<W>(a.vy + i, vy);
    store<W>(a.x + i, x);
    store<W>(a.y + i, y);
    if constexpr (kRotation) {
      const D om =
          load<W>(a.ca_r + i) * load<W>(a.om + i) + load<W>(a.cb_r + i) * load<W>(a.tq + i);
      store<W>(a.om + i, om);
      store<W>(a.th + i, load<W>(a.th + i) + om * dt);
    }
    const D dx = x - load<W>(a.x_built + i), dy = y - load<W>(a.y_built + i);
    const D d2 = dx * dx + dy * dy;
    md = d2 > md ? d2 : md;
  }
  return hmax<W>(md);
}

// ---------------------------------------------------------------- dispatch

using PairFn = double (*)(const PairArgs &, int, int);
using SumFn = void (*)(const PairArgs &, int, int);
using IntegrateFn = double (*)(const IntegrateArgs &, int, int);

struct Kernels {
  PairFn pairs, pairs_damped;              // one thread: the sums fused
  PairFn pairs_split, pairs_damped_split;  // threads: the sums in the sum pass
  SumFn sums;
  IntegrateFn integrate, integrate_locked;
  const char *name;    // the SIMD path (kernel_simd())
  const char *gather;  // how it gathers (kernel_gather())
};

#define DEMCAL_KERNELS(SUFFIX, NAME, TARGET, W, G)                                  \
  TARGET double pairs_##SUFFIX(const PairArgs &a, int b0, int b1) {                 \
    return pair_blocks<W, G, false, true>(a, b0, b1);                               \
  }                                                                                 \
  TARGET double pairs_damped_##SUFFIX(const PairArgs &a, int b0, int b1) {          \
    return pair_blocks<W, G, true, true>(a, b0, b1);                                \
  }                                                                                 \
  TARGET double pairs_split_##SUFFIX(const PairArgs &a, int b0, int b1) {           \
    return pair_blocks<W, G, false, false>(a, b0, b1);                              \
  }                                                                                 \
  TARGET double pairs_damped_split_##SUFFIX(const PairArgs &a, int b0, int b1) {    \
    return pair_blocks<W, G, true, false>(a, b0, b1);                               \
  }                                                                                 \
  TARGET void sums_##SUFFIX(const PairArgs &a, int b0, int b1) {                    \
    sum_blocks<W, G>(a, b0, b1, true);                                              \
  }                                                                                 \
  TARGET double integrate_##SUFFIX(const IntegrateArgs &a, int b0, int b1) {        \
    return integrate_blocks<W, true>(a, b0, b1);                                    \
  }                                                                                 \
  TARGET double integrate_locked_##SUFFIX(const IntegrateArgs &a, int b0, int b1) { \
    return integrate_blocks<W, false>(a, b0, b1);                                   \
  }                                                                                 \
  constexpr Kernels kKernels_##SUFFIX{pairs_##SUFFIX,                               \
                                      pairs_damped_##SUFFIX,                        \
                                      pairs_split_##SUFFIX,                         \
                                      pairs_damped_split_##SUFFIX,                  \
                                      sums_##SUFFIX,                                \
                                      integrate_##SUFFIX,                           \
                                      integrate_locked_##SUFFIX,                    \
                                      NAME,                                         \
                                      G == Gather::kHardware ? "hardware" : "emulated"};

#define DEMCAL_NO_TARGET
DEMCAL_KERNELS(sse2, "sse2", DEMCAL_NO_TARGET, 2, Gather::kEmulated)
#ifdef DEMCAL_X86_64
DEMCAL_KERNELS(avx2, "avx2", DEMCAL_V3, 4, Gather::kEmulated)
DEMCAL_KERNELS(avx512, "avx512", DEMCAL_V4, 8, Gather::kEmulated)
#if !defined(__clang__)
DEMCAL_KERNELS(avx512_hw, "avx512", DEMCAL_V4, 8, Gather::kHardware)
#endif
#endif

// How the AVX-512 path gathers (simd.hpp, Gather): the DEMCAL_GATHER the
// environment names, else in hardware on Intel CPUs since Sapphire Rapids
// and emulated on others. A value that is no way, or "hardware" on another
// path or in a build without it, throws std::invalid_argument, as
// DEMCAL_SIMD does.
Gather choose_gather(const char *path) {
  const char *env = std::getenv("DEMCAL_GATHER");
  const std::string_view want = env ? env : "";
  const bool avx512 = std::string_view(path) == "avx512";
  auto refused = [&](const std::string &why) {
    return std::invalid_argument("DEMCAL_GATHER=\"" + std::string(want) + "\"" + why);
  };
  if (want.empty()) {
#if defined(DEMCAL_X86_64) && !defined(__clang__)
    // Measured on Emerald Rapids. AVX512-FP16 marks Intel's cores since
    // Sapphire Rapids; the earlier AVX-512 ones (Skylake-SP to Ice Lake)
    // run their gathers under the microcode that mitigates Gather Data
    // Sampling, which slows them: unmeasured here, they keep the emulation.
    if (avx512 && __builtin_cpu_is("intel") && __builtin_cpu_supports("avx512fp16"))
      return Gather::kHardware;
#endif
    return Gather::kEmulated;
  }
  if (want == "emulated") return Gather::kEmulated;
  if (want != "hardware") throw refused(" is not a way to gather; accepted: hardware|emulated");
  if (!avx512)
    throw refused(": only the avx512 path gathers in hardware, and this process runs " +
                  std::string(path));
  if (!kHardwareGatherBuilt)
    throw refused(": this build has no hardware gathers (built with Clang)");
  return Gather::kHardware;
}

// The path for this process: the widest this CPU runs, or the one
// DEMCAL_SIMD names (unset or empty: the widest). A name that is no path,
// or a path this CPU cannot run, throws std::invalid_argument (ignored
// silently, a run meant for one path ran on another).
const Kernels &choose_path() {
  const char *env = std::getenv("DEMCAL_SIMD");
  const std::string_view want = env ? env : "";
#ifdef DEMCAL_X86_64
  __builtin_cpu_init();
#ifdef __clang__
  // Clang 14 knows no "x86-64-vN" level names: the levels' features one
  // by one (x86-64-v3's F16C, LZCNT, MOVBE and XSAVE it cannot query;
  // every CPU with AVX2, FMA and BMI2 has them).
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
#else
  const bool v4 = __builtin_cpu_supports("x86-64-v4") != 0;
  const bool v3 = __builtin_cpu_supports("x86-64-v3") != 0;
#endif
  const struct {
    const Kernels &kernels;
    bool runs;
  } paths[] = {{kKernels_sse2, true}, {kKernels_avx2, v3}, {kKernels_avx512, v4}};
  if (want.empty()) return v4 ? kKernels_avx512 : v3 ? kKernels_avx2 : kKernels_sse2;
  std::string runs;
  for (const auto &p : paths)
    if (p.runs) runs += (runs.empty() ? "" : ", ") + std::string(p.kernels.name);
  auto refused = [&](const char *why) {
    return std::invalid_argument("DEMCAL_SIMD=\"" + std::string(want) + "\"" + why +
                                 "; accepted: sse2|avx2|avx512, of which this CPU runs " + runs);
  };
  for (const auto &p : paths)
    if (want == p.kernels.name) {
      if (p.runs) return p.kernels;
      throw refused(": this CPU cannot run that path");
    }
  throw refused(" is not a SIMD path");
#else
  if (!want.empty())
    throw std::invalid_argument("DEMCAL_SIMD=\"" + std::string(want) +
                                "\": this build has one code path (generic); unset DEMCAL_SIMD");
  return kKernels_sse2;
#endif
}

// The path, then its way to gather.
const Kernels &choose_kernels() {
  const Kernels &path = choose_path();
  if (choose_gather(path.name) == Gather::kHardware) {
#if defined(DEMCAL_X86_64) && !defined(__clang__)
    return kKernels_avx512_hw;
#endif
  }
  return path;
}

const Kernels &kernels() {
  static const Kernels &chosen = choose_kernels();
  return chosen;
}

}  // namespace

const char *kernel_simd() {
#ifdef DEMCAL_X86_64
  return kernels().name;
#else
  kernels();  // DEMCAL_SIMD checked
  return "generic";
#endif
}

const char *kernel_gather() { return kernels().gather; }

double WorldImpl::pair_pass(int b0, int b1) { return pair_kernel(b0, b1, false); }

double WorldImpl::sum_pass(int b0, int b1) { return pair_kernel(b0, b1, true); }

double WorldImpl::pair_kernel(int b0, int b1, bool sums) {
  const PairArgs a{block_slot_.data(),
                   slot_j_.data(),
                   slot_ft_.data(),
                   slot_r_.data(),
                   slot_ir_.data(),
                   pfx_.data(),
                   pfy_.data(),
                   pti_.data(),
                   ptj_.data(),
                   x_.data(),
                   y_.data(),
                   vx_.data(),
                   vy_.data(),
                   omega_.data(),
                   r_.data(),
                   inv_r_.data(),
                   m_.data(),
                   fx_.data(),
                   fy_.data(),
                   tq_.data(),
                   block_power_.data(),
                   material_.particle.kn,
                   material_.particle.kt * integration_.dt,
                   material_.particle.friction,
                   2.0 * material_.contact_damping_ratio,
                   term_block_.data(),
                   mirror_block_.data(),
                   mirror_term_.data(),
                   mirror_src_block_.data(),
                   block_fused_.data()};
  const Kernels &k = kernels();
  const bool damped = material_.contact_damping_ratio > 0.0;
  if (sums) {
    k.sums(a, b0, b1);
    return 0.0;
  }
  if (active_threads() <= 1) return damped ? k.pairs_damped(a, b0, b1) : k.pairs(a, b0, b1);
  return damped ? k.pairs_damped_split(a, b0, b1) : k.pairs_split(a, b0, b1);
}

double WorldImpl::integrate_pass(int b0, int b1) {
  const IntegrateArgs a{x_.data(),     y_.data(),       vx_.data(),      vy_.data(),
                        theta_.data(), omega_.data(),   fx_.data(),      fy_.data(),
                        tq_.data(),    ca_t_.data(),    cb_t_.data(),    ca_r_.data(),
                        cb_r_.data(),  x_built_.data(), y_built_.data(), integration_.dt};
  const Kernels &k = kernels();
  return integration_.lock_rotation ? k.integrate_locked(a, b0, b1) : k.integrate(a, b0, b1);
}

WorldImpl::PairState WorldImpl::pair_state(int i, int j) const {
  // The same operations as pair_blocks, one lane.
  PairState p{};
  const double dx = x_[j] - x_[i], dy = y_[j] - y_[i];
  const double d2 = dx * dx + dy * dy;
  const double rs = r_[i] + r_[j];
  p.touching = d2 < rs * rs;
  const double d = std::sqrt(d2);
  const double inv = 1.0 / d;
  p.nx = dx * inv;
  p.ny = dy * inv;
  p.overlap = rs - d;
  const double kn = material_.particle.kn;
  p.vn = (vx_[j] - vx_[i]) * p.nx + (vy_[j] - vy_[i]) * p.ny;
  const double fe = law::elastic_normal_force(kn, p.overlap);
  double fn = fe;
  const double beta2 = 2.0 * material_.contact_damping_ratio;
  if (beta2 > 0.0)
    fn = law::damped_normal_force(fe, beta2, std::sqrt(kn * reduced_mass(m_[i], m_[j])), p.vn);
  p.fn_elastic = p.touching ? fe : 0.0;
  p.fn = p.touching ? fn : 0.0;
  return p;
}

void WorldImpl::wall_pass() {
  // Walls. Contact point on the wall line; lever arm = distance to the wall.
  // Added to the pair forces, after them, wall by wall.
  const double dt = integration_.dt;
  const double beta2 = 2.0 * material_.contact_damping_ratio;
  const double kw = material_.wall.kn, ktw = material_.wall.kt, muw = material_.wall.friction;
  double max_overlap = 0.0;
  double power = 0.0;  // of the wall dashpots
  for (int s = 0; s < 4; ++s) {
    Wall &wall = walls_[s];
    const double gx = law::kWallNormal[s][0], gy = law::kWallNormal[s][1];
    const double tx = -gy, ty = gx;
    const bool vertical = (s == kLeft || s == kRight);
    const double wvx = vertical ? wall.velocity : 0.0, wvy = vertical ? 0.0 : wall.velocity;
    double wfx = 0.0, wfy = 0.0;
    int count = 0;
    double *hist = wall_ft_[s].data();
    double *hist_fn = wall_fn_[s].data();
    for (int i : wall_candidates_[s]) {
      // Signed distance from the wall line to the centre, along the inward normal.
      const double dist = vertical ? (x_[i] - wall.position) * gx : (y_[i] - wall.position) * gy;
      const double overlap = r_[i] - dist;
      if (overlap <= 0.0) {
        hist[i] = 0.0;
        hist_fn[i] = 0.0;
        continue;
      }
      ++count;
      max_overlap = std::max(max_overlap, overlap / r_[i]);
      // The wall as a partner of infinite mass: m_eff = m_i.
      const double fe = law::elastic_normal_force(kw, overlap);
      double fn = fe;
      const double dvx = wvx - vx_[i], dvy = wvy - vy_[i];  // wall relative to particle
      if (beta2 > 0.0) {
        const double vn = -(dvx * gx + dvy * gy);  // particle leaving the wall > 0
        fn = law::damped_normal_force(fe, beta2, std::sqrt(kw * m_[i]), vn);
        power += law::dashpot_power(fe, fn, vn);
      }
      // Particle contact point moves with v − ω·dist·t (arm = −dist·n).
      const double vt = dvx * tx + dvy * ty + omega_[i] * dist;
      double ft = hist[i] + ktw * vt * dt;
      const double cap = muw * fn;
      ft = law::coulomb_clamp(ft, cap);
      hist[i] = ft;
      hist_fn[i] = fn;
      const double fxi = fn * gx + ft * tx, fyi = fn * gy + ft * ty;
      fx_[i] += fxi;
      fy_[i] += fyi;
      tq_[i] += -dist * ft;
      wfx -= fxi;
      wfy -= fyi;
    }
    wall.force = Eigen::Vector2d(wfx, wfy);
    wall.contacts = count;
  }
  max_overlap_ratio_seen_ = std::max(max_overlap_ratio_seen_, max_overlap);
  wall_dashpot_power_ = power;
}

void WorldImpl::compute_forces() {
  max_overlap_ratio_seen_ = run_pair_pass();
  wall_pass();
}

double WorldImpl::dashpot_power() const {
  if (!(material_.contact_damping_ratio > 0.0)) return 0.0;
  // Lane by lane over the blocks in a fixed order: the same sum for any
  // thread count and on every path (detail::block_lanes_sum).
  return detail::block_lanes_sum(block_power_.data(), nblocks_) + wall_dashpot_power_;
}

}  // namespace demcal
