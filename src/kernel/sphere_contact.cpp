// Contact law of the sphere kernel: linear normal spring kn·δ; incremental
// tangential spring kt with a 3-vector history h (the tangential force on
// the first particle of the pair), capped by Coulomb μ·Fn.
//
// Geometry of a pair (i, j): n = (x_j − x_i)/d, δ = r_i + r_j − d, contact
// point x^c = x_i + a_i·n with lever arms a_i = r_i − δ/2, a_j = r_j − δ/2
// (the middle of the overlap, as in 2D). The same lever arms enter the
// torques and σ, so a moment-free particle contributes a symmetric term.
// Velocity of j's contact point relative to i's:
//   v_rel = v_j − v_i − (a_i·ω_i + a_j·ω_j) × n,  v_t = v_rel − (v_rel·n)·n.
// (a_i + a_j = d, so a rigid motion of the pair gives v_rel = 0.)
//
// The history is turned with the contact every step before the increment,
// so that a rigid rotation of the pair turns the force with it:
//  1. tilt of the normal: project h onto the current contact plane and
//     rescale it to its former length — the scheme of Luding (Granular
//     Matter 10, 2008, eq. 17) and of LAMMPS' `pair granular` (tangential
//     linear_history). LAMMPS' older gran/hooke/history projects without
//     the rescaling, which shortens h by cos θ for a tilt θ: O(θ²) per step.
//     For a tilt about an axis normal to h the rescaled projection is the
//     exact rotation; otherwise it differs from it by O(θ²) in direction.
//  2. twist about the normal: the projection cannot see a rotation about n
//     itself, so h is turned about n by Δt·n·(ω_i + ω_j)/2, the mean spin of
//     the two bodies about the normal (as YADE's ScGeom::rotate does).
// Then h += kt·v_t·Δt, and if |h| > μ·Fn, h is scaled back to μ·Fn
// (sliding). The force on i is −Fn·n + h, on j its opposite; the torques
// are a_i·n × h on i and a_j·n × h on j.
//
// Friction's share of the energy ledger (sphere_energy_balance.cpp). The
// tangential spring stores |h|²/(2·kt). When the cap bites, the trial force
// h_trial is cut back to μFn: the contact slides by (|h_trial| − μFn)/kt
// while carrying μFn, so Coulomb friction takes μFn·(|h_trial| − μFn)/kt.
// (Not the spring energy (|h_trial|² − (μFn)²)/(2·kt) the cut removes: its
// excess over the Coulomb work is trial energy never stored — for a
// frictionless contact the whole (kt·|v_t|·Δt)²/(2·kt) of every step.) In
// continuous time the two agree. When a contact opens, Fn has fallen to 0
// and with it the cap: the spring has slid back to zero on the way, so the
// |h|²/(2·kt) it still held at the last touching step is dissipated too.
// Left out of the books, these losses hide energy the integrator creates: a
// step just past the stable one rattles contacts open and shut, and the
// ledger without them reads strongly negative.
//
// The pair pass (pair_blocks) runs over the half neighbour list (pairs i <
// j, sphere_broad_phase.cpp) in blocks of 8 particles, W lanes at a time on
// the SIMD path of this machine (the 2D kernel's, simd.hpp), so every pair
// is evaluated once. Each particle's force and torque are written as the
// plain sum over its own slots (pairs j > i, increasing j); per slot the
// pass also writes the pair's force on i and the torque a_j·n × h on j (at
// the slot's place in a ring that keeps them in cache until they are
// summed: term_ring.hpp), and the sum pass (sum_blocks) then adds to each
// particle j, from its mirror list in increasing i, the opposite of that
// force and that torque. Both sums run in a fixed order whatever the thread
// split (each pass writes only its own particles' or slots' values), so
// results are deterministic and bit-identical for any thread count;
// non-touching slots add exact zeros, so the skin does not change a bit
// either. Each block's sums run
// right after its own pairs, the pair terms still in cache, wherever the
// same pass has written all of its mirrored slots: with one thread every
// block; with threads the blocks whose mirrored slots all lie in the
// thread's own range (all but about one lattice layer at the start of each
// range), the others in a second pass after the barrier. (Until 365b7e6
// the list was full and each pair was evaluated twice, once from either
// side, the law written so that both copies came out exact opposites under FMA
// contraction, e.g. the lever-arm term a_i·ω_i + a_j·ω_j as ½[(ω_i + ω_j)
// (a_i + a_j) + (ω_i − ω_j)(a_i − a_j)]; evaluated once, it takes the
// plain form.) The twist is applied even when it is 0 (the identity then).
//
// Cost per slot: the rescale and the twist share one factor, h' = A·[(1 −
// c²)·p + 2c·n × p] with A = sqrt(|h|²/(|p|²·(1 + c²)²)) (the rescale
// sqrt(|h|²/|p|²) times the Cayley 1/(1 + c²)). A slot's values form one
// long chain — root, normal, history, its scale, the clamp — and what can
// leave it does (1.06-1.09×, reports/performance.md, 3D section, "The
// slot's dependency chain, not its arithmetic"), though the pass is bound
// by the throughput of its µops rather than by that chain (split in two
// passes over blocks of rows, it ran at par: same section, "Two tests of
// the 'one chain per slot' reading"): 1/|d| is d·(1/d²), the division
// beside the root;
// 1/A² = |p|²(1 + c²)²/|h|² takes |p|² = |h|² − hn² and the 1/|h|²
// divided at the load, and A comes from the series of
// y^(-1/2) where y = 1/A² is within 1e-4 of 1, as it is unless the contact
// turned a lot in one step (turn_scale; the exact quotient and root
// elsewhere). The Coulomb cap compares squares; its root and division run
// only for a vector with a touching lane that slides, and a vector with
// no touching lane only releases its histories. So the common slot takes
// one root and two divisions (1/d², 1/|h|²), none of the divisions on the
// chain; the skipped branches give the same bits as the full evaluation
// (cut = 1, h = 0 there), and each lane's series-or-root choice depends on
// its own inputs alone. Estimates of the root and divisions refined by
// Newton steps (vrsqrt14pd/vrcp14pd, or vrcpps on AVX2) measured 3-16 %
// slower on this kernel's test CPU (AMD family 26; performance.md,
// 2026-12-02): the results stay within an ulp or two of the correctly
// rounded ones.
//
// Walls: the inward normal g is fixed and the wall does not rotate, so a
// wall history stays in the wall plane with no turning; the contact point is
// the foot of the centre on the plane (lever arm −dist·g). The wall pass
// (wall_contacts) runs after the particles' pair sums, wall by wall in the
// order 0..5, over each wall's candidate list W at a time (particle values
// gathered by index, histories stored per candidate, contiguous), and adds
// each contact's force and torque to its particle: the same order as the
// scalar pass it replaced, and one order whatever the thread count (the
// pass is not split among threads: ≈ 1 % of the pair pass's work). A
// frictionless wall (μ = 0, the default) takes the normal force alone: the
// full law would cut every trial history to 0 anyway, through a root and a
// division per contact (the wall pass took 10 % of a 256-sphere step for
// nothing), and would let a trial force through where |h|² underflows to 0.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "contact_law.hpp"
#include "simd.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

namespace {
using V3 = Eigen::Vector3d;

constexpr int kBlock = 8;

struct PairArgs {
  const int *__restrict block_slot;
  const int *__restrict slot_j;
  double *__restrict hx, *__restrict hy, *__restrict hz;
  const double *__restrict slot_r, *__restrict slot_ir;
  // Per slot, at its place (term_block): the pair's force on i, the torque on j.
  double *__restrict pfx, *__restrict pfy, *__restrict pfz;
  double *__restrict ptx, *__restrict pty, *__restrict ptz;
  const double *__restrict x, *__restrict y, *__restrict z;
  const double *__restrict vx, *__restrict vy, *__restrict vz;
  const double *__restrict wx, *__restrict wy, *__restrict wz;
  const double *__restrict r, *__restrict inv_r, *__restrict m;
  double *__restrict fx, *__restrict fy, *__restrict fz;
  double *__restrict tx, *__restrict ty, *__restrict tz;
  double *__restrict block_released, *__restrict block_slid;
  double *__restrict block_power;      // the contact dashpots' power (damped pass only)
  double kn, kdt, half_dt, mu, beta2;  // beta2 = 2·contact damping ratio
  // Each block's mirrored sums right after its pairs where the pass has
  // written all its mirrored slots (its lowest source block src_block[b] ≥
  // the pass's first block); fused[b] says so to the sum pass. With one
  // thread (pair_blocks' kFuseAll), every block, fused not written.
  const int *__restrict term_block;  // where block b's slots have their pair terms
  const int *__restrict mirror_block;
  const int *__restrict mirror_term;  // places of the mirrored pair terms
  const int *__restrict src_block;
  unsigned char *__restrict fused;
};

// v itself, rounded: the compiler cannot fuse it into an FMA with what
// follows (an empty asm the value must pass through).
template <int W>
DEMCAL_INLINE typename Simd<W>::D rounded(typename Simd<W>::D v) {
  opaque<W>(v);
  return v;
}

// Normal geometry and force of a pair: unit normal, overlap, normal force
// (0 when apart), the dashpot's power (0 when apart or undamped), contact
// flag. One home for the pair pass and the scalar
// re-evaluation (SphereWorldImpl::pair_geometry, through one_pair below on the
// same SIMD path), so that both round alike, FMA contractions included.
template <int W>
struct Normal {
  typename Simd<W>::D nx, ny, nz, ov, fn, power;
  typename Simd<W>::M touch;
};
template <int W, bool kDamped>
DEMCAL_INLINE Normal<W> normal_part(typename Simd<W>::D dx, typename Simd<W>::D dy,
                                    typename Simd<W>::D dz, typename Simd<W>::D ri,
                                    typename Simd<W>::D rj, typename Simd<W>::D dvx,
                                    typename Simd<W>::D dvy, typename Simd<W>::D dvz,
                                    typename Simd<W>::D mi, typename Simd<W>::D mj, double kn,
                                    double beta2) {
  using D = typename Simd<W>::D;
  const D zero{};
  Normal<W> g;
  // The squared distance without FMA contraction (rounded products, as
  // the scalar |d|² of the tests and the old scalar kernel): the overlap
  // rs − d cancels most of d, so its last bits are the overlap's.
  const D d2 = rounded<W>(dx * dx) + rounded<W>(dy * dy) + rounded<W>(dz * dz);
  const D rs = ri + rj;
  g.touch = d2 < rs * rs;
  const D d = vsqrt(d2);
  // 1/d as d·(1/d²): the division runs beside the root instead of after
  // it (the normal heads the slot's dependency chain); within 1.5 ulp.
  const D inv = d * (1.0 / d2);
  g.nx = dx * inv;
  g.ny = dy * inv;
  g.nz = dz * inv;
  g.ov = rs - d;
  D fn = law::elastic_normal_force(kn, g.ov);
  g.power = zero;
  if constexpr (kDamped) {
    const D meff = reduced_mass(mi, mj);
    const D vn = dvx * g.nx + dvy * g.ny + dvz * g.nz;  // > 0 when separating
    const D fe = fn;
    fn = law::damped_normal_force(fe, beta2, vsqrt(kn * meff), vn);
    g.power = select<W>(g.touch, law::dashpot_power(fe, fn, vn), zero);
  }
  g.fn = select<W>(g.touch, fn, zero);
  return g;
}

template <int W>
DEMCAL_INLINE typename Simd<W>::D lane0(double v) {
  typename Simd<W>::D r{};
  r[0] = v;
  return r;
}

// One pair through normal_part on lane 0: in = {dx, dy, dz, r_i, r_j, dvx,
// dvy, dvz, m_i, m_j, kn, 2ζ}, out = {nx, ny, nz, overlap, fn, touching}.
template <int W>
DEMCAL_INLINE void one_pair(const double *in, double *out) {
  const Normal<W> g =
      in[11] > 0.0
          ? normal_part<W, true>(lane0<W>(in[0]), lane0<W>(in[1]), lane0<W>(in[2]), lane0<W>(in[3]),
                                 lane0<W>(in[4]), lane0<W>(in[5]), lane0<W>(in[6]), lane0<W>(in[7]),
                                 lane0<W>(in[8]), lane0<W>(in[9]), in[10], in[11])
          : normal_part<W, false>(lane0<W>(in[0]), lane0<W>(in[1]), lane0<W>(in[2]),
                                  lane0<W>(in[3]), lane0<W>(in[4]), lane0<W>(in[5]),
                                  lane0<W>(in[6]), lane0<W>(in[7]), lane0<W>(in[8]),
                                  lane0<W>(in[9]), in[10], in[11]);
  out[0] = g.nx[0];
  out[1] = g.ny[0];
  out[2] = g.nz[0];
  out[3] = g.ov[0];
  out[4] = g.fn[0];
  out[5] = g.touch[0] ? 1.0 : 0.0;
}

// Whether any lane of m is set. The mask goes through a select into
// doubles (−1 or 0) and one test instruction: read lane by lane, GCC
// rebuilds the comparison behind m with one scalar compare per lane.
template <int W>
DEMCAL_INLINE bool any(typename Simd<W>::M m) {
  using D = typename Simd<W>::D;
  const D zero{};
  const D v = select<W>(m, zero - 1.0, zero);
#if defined(DEMCAL_X86_64) && defined(__clang__)
  // Clang rejects a 256- or 512-bit asm operand in the baseline target
  // (simd.hpp, vsqrt): test the 128-bit halves.
  bool set = false;
  for (int k = 0; k < W; k += 2) {
    const Simd<2>::D half{v[k], v[k + 1]};
    set = set || _mm_movemask_pd(reinterpret_cast<__m128d>(half)) != 0;
  }
  return set;
#elif defined(DEMCAL_X86_64)
  if constexpr (W == 8) {
    unsigned char k;
    asm("vptestmq %1, %1, %0" : "=k"(k) : "v"(v));
    return k != 0;
  } else if constexpr (W == 4) {
    int bits;
    asm("vmovmskpd %1, %0" : "=r"(bits) : "x"(v));
    return bits != 0;
  } else {
    return _mm_movemask_pd(reinterpret_cast<__m128d>(v)) != 0;
  }
#else
  bool r = false;
  for (int l = 0; l < W; ++l) r = r || v[l] != 0.0;
  return r;
#endif
}

// The history's turning scale A = sqrt(|h|²/|p|²)/(1 + c²) (file
// comment) from y = 1/A² computed without a division: near 1 (|y − 1| <
// 1e-4, a contact that turned little in the step: the usual case) the
// Taylor polynomial 1 − e/2 + 3e²/8 − 5e³/16 of (1 + e)^(-1/2), whose
// truncation error 35e⁴/128 < 3e-17 is below half an ulp of 1; elsewhere
// the exact form from |p|² itself, 0 where p = 0. Lane by lane, the value
// depends on that lane's inputs alone.
template <int W>
DEMCAL_INLINE typename Simd<W>::D turn_scale(typename Simd<W>::D y, typename Simd<W>::D mag2,
                                             typename Simd<W>::D px, typename Simd<W>::D py,
                                             typename Simd<W>::D pz, typename Simd<W>::D t) {
  using D = typename Simd<W>::D;
  const D zero{}, one = zero + 1.0;
  const D e = y - 1.0;
  const D series = 1.0 + e * (-0.5 + e * (0.375 + e * -0.3125));
  // Far: every lane not near 1, NaN included (y = 0·∞ where |h|² < 1e-308,
  // so that 1/|h|² overflowed, and |h|² − hn² is 0): the exact form there.
  const typename Simd<W>::M near = e * e < 1e-8;
  const typename Simd<W>::M far = select<W>(near, zero, one) > zero;
  if (!any<W>(far)) return series;
  const D p2 = px * px + py * py + pz * pz;
  const typename Simd<W>::M turnable = p2 > zero;
  const D z = select<W>(turnable, mag2, one) / select<W>(turnable, p2 * t * t, one);
  return select<W>(far, select<W>(turnable, vsqrt(z), zero), series);
}

// Three components of one vector on W lanes.
template <int W>
struct Vec3 {
  typename Simd<W>::D x, y, z;
};

// The trial tangential force of a touching contact (file comment): its
// history h turned with it over the step — projected onto the contact
// plane (normal n) and rescaled to its former length, then twisted about n
// by the spin sum s (Cayley form, c = Δt·n·s/4 from half_dt = Δt/2), one
// scale A = sqrt(|h|²/|p|²)/(1 + c²) for both — plus the increment kt·Δt·
// v_t (kdt = kt·Δt). mag2 = |h|², held = mag2 > 0, inv_mag2 = 1/|h|² (1
// where not held). The turn and the increment stay one expression, so that
// a compiler that contracts only within one (Clang) rounds as before.
template <int W>
DEMCAL_INLINE Vec3<W> trial_history(Vec3<W> n, Vec3<W> s, Vec3<W> h, typename Simd<W>::D mag2,
                                    typename Simd<W>::M held, typename Simd<W>::D inv_mag2,
                                    double half_dt, double kdt, Vec3<W> vt) {
  using D = typename Simd<W>::D;
  const D one = D{} + 1.0;
  const D hn = h.x * n.x + h.y * n.y + h.z * n.z;
  const D px = h.x - hn * n.x, py = h.y - hn * n.y, pz = h.z - hn * n.z;
  const D c = half_dt * 0.5 * (n.x * s.x + n.y * s.y + n.z * s.z);
  const D c2 = c * c, t = 1.0 + c2;
  // 1/A² = |p|²(1 + c²)²/|h|² with |p|² = |h|² − hn² (|n| = 1): no
  // division on the chain (1/|h|² came with the load), and A by the
  // series of y^(-1/2) near 1; where a lane is far from 1, the exact
  // form (turn_scale). Lanes without history take y = 1 (p = 0 there,
  // so A does not matter).
  const D y = select<W>(held, (mag2 - hn * hn) * (t * t * inv_mag2), one);
  const D A = turn_scale<W>(y, mag2, px, py, pz, t);
  const D s1 = 1.0 - c2, s2 = 2.0 * c;
  return {A * (px * s1 + (n.y * pz - n.z * py) * s2) + kdt * vt.x,
          A * (py * s1 + (n.z * px - n.x * pz) * s2) + kdt * vt.y,
          A * (pz * s1 + (n.x * py - n.y * px) * s2) + kdt * vt.z};
}

// Coulomb's cap on a tangential force h (|h|² = h2) of the touching lanes:
// false when no touching lane slides (|h| ≤ cap = μ·fn in all of them);
// else cut = cap/|h| where one slides and 1 elsewhere, and the slip work
// cap·(|h| − cap) of the sliding lanes added to slid (file comment). The
// root and the division only then: the common slot skips both.
template <int W>
DEMCAL_INLINE bool coulomb_cut(typename Simd<W>::M touch, typename Simd<W>::D h2,
                               typename Simd<W>::D cap, typename Simd<W>::D &slid,
                               typename Simd<W>::D &cut) {
  using D = typename Simd<W>::D;
  const D zero{}, one = zero + 1.0;
  const typename Simd<W>::M sliding = select<W>(touch, h2, zero) > cap * cap;
  if (!any<W>(sliding)) return false;
  const D mag = vsqrt(h2);
  cut = select<W>(sliding, cap / select<W>(sliding, mag, one), one);
  slid += select<W>(sliding, cap * (mag - cap), zero);
  return true;
}

// A sum kept lane by lane over groups of 8 lanes (8 wall candidates) on
// any path's width W: one W-wide part per W lanes, added up by
// detail::lane_sum, so that every path gives the same bits.
template <int W>
struct BlockLanes {
  typename Simd<W>::D part[kBlock / W] = {};
  DEMCAL_INLINE double total() const {
    double l[kBlock];
    for (int q = 0; q < kBlock / W; ++q) store<W>(l + q * W, part[q]);
    return detail::lane_sum(l);
  }
};

struct SumArgs {
  const int *__restrict mirror_block;
  const int *__restrict mirror_term;      // places of the mirrored pair terms
  const unsigned char *__restrict fused;  // blocks the pair pass summed already
  const double *__restrict pfx, *__restrict pfy, *__restrict pfz;
  const double *__restrict ptx, *__restrict pty, *__restrict ptz;
  double *__restrict fx, *__restrict fy, *__restrict fz;
  double *__restrict tx, *__restrict ty, *__restrict tz;
};

// Adds to each particle j of blocks [b0, b1) what it receives from its pairs
// (i, j), i < j, in increasing i: −(force on i) and the torque on j.
// (A: SumArgs, or PairArgs when fused into the pair pass, so that the
// arrays are reached through the same restrict pointers.)
template <int W, Gather G, class A>
DEMCAL_INLINE double sum_blocks(const A &a, int b0, int b1) {
  using D = typename Simd<W>::D;
  for (int b = b0; b < b1; ++b) {
    const int s0 = a.mirror_block[b], s1 = a.mirror_block[b + 1];
    if (s0 == s1) continue;
    for (int sub = 0; sub < kBlock; sub += W) {
      const int i0 = kBlock * b + sub;
      D fx = load<W>(a.fx + i0), fy = load<W>(a.fy + i0), fz = load<W>(a.fz + i0);
      D tx = load<W>(a.tx + i0), ty = load<W>(a.ty + i0), tz = load<W>(a.tz + i0);
      for (int s = s0 + sub; s < s1; s += kBlock) {
        const int *S = a.mirror_term + s;
        fx -= gather<W, G>(a.pfx, S);
        fy -= gather<W, G>(a.pfy, S);
        fz -= gather<W, G>(a.pfz, S);
        tx += gather<W, G>(a.ptx, S);
        ty += gather<W, G>(a.pty, S);
        tz += gather<W, G>(a.ptz, S);
      }
      store<W>(a.fx + i0, fx);
      store<W>(a.fy + i0, fy);
      store<W>(a.fz + i0, fz);
      store<W>(a.tx + i0, tx);
      store<W>(a.ty + i0, ty);
      store<W>(a.tz + i0, tz);
    }
  }
  return 0.0;
}

// Pairs of blocks [b0, b1) (half list: each pair once, from i < j): each
// particle's force and torque summed over its own slots, written (not
// added), and per slot the pair's force on i and torque on j for the sum
// pass; and each block's mirrored sums right after its pairs where this
// pass wrote all of its mirrored slots (with one thread, every block; the
// same sums in the same order as the sum pass, which does the others).
// Returns the largest overlap/min(r_i, r_j).
// Where the pair pass sums the mirrored terms (see PairArgs).
enum FuseSums : int {
  kFuseOwn = 1,  // threads: the blocks this pass completes, the rest after
  kFuseAll = 2,  // one thread: every block, right after its pairs
};

template <int W, Gather G, bool kDamped, int kFuse>
DEMCAL_INLINE double pair_blocks(const PairArgs &a, int b0, int b1) {
  using D = typename Simd<W>::D;
  using M = typename Simd<W>::M;
  const D zero{}, one = zero + 1.0;
  D mo = zero;
  const double kn = a.kn, kdt = a.kdt, half_dt = a.half_dt, mu = a.mu;
  for (int b = b0; b < b1; ++b) {
    const int s0 = a.block_slot[b], s1 = a.block_slot[b + 1];
    const int t0 = a.term_block[b] - s0;  // slot s's pair terms at t0 + s
    for (int sub = 0; sub < kBlock; sub += W) {
      const int i0 = kBlock * b + sub;
      // This sub-block's lanes, into block_* after the slots.
      D released = zero, slid = zero, power = zero;
      const D xi = load<W>(a.x + i0), yi = load<W>(a.y + i0), zi = load<W>(a.z + i0);
      const D vxi = load<W>(a.vx + i0), vyi = load<W>(a.vy + i0), vzi = load<W>(a.vz + i0);
      const D wxi = load<W>(a.wx + i0), wyi = load<W>(a.wy + i0), wzi = load<W>(a.wz + i0);
      const D ri = load<W>(a.r + i0), iri = load<W>(a.inv_r + i0);
      D mi = zero;
      if constexpr (kDamped) mi = load<W>(a.m + i0);
      D fx = zero, fy = zero, fz = zero, tx = zero, ty = zero, tz = zero;
      // The neighbours' positions are gathered one slot-vector ahead: they
      // start the law's longest chain (d², its root, 1/|d|), and issued a
      // slot-vector early the gathers no longer wait behind that chain in
      // the scheduler (1.05-1.08x on Intel's AVX-512 path with hardware
      // gathers at 256-4 000 spheres; AVX2 at par on Intel, 1.01-1.04x on
      // AMD Zen 5; only the positions: gathering the velocities ahead too
      // lost 1.03-1.04x). Not on the AVX-512 path with emulated gathers,
      // where ahead lost 1.05-1.06x on Zen 5 (performance.md, 2026-12-06).
      // Either way the same values, so the same bits.
      constexpr bool kAhead = !(W == 8 && G == Gather::kEmulated);
      D gx = zero, gy = zero, gz = zero;
      if (kAhead && s0 + sub < s1) {
        const int *J = a.slot_j + s0 + sub;
        gx = gather<W, G>(a.x, J), gy = gather<W, G>(a.y, J), gz = gather<W, G>(a.z, J);
      }
      for (int s = s0 + sub; s < s1; s += kBlock) {
        const int *J = a.slot_j + s;
        const D rj = load<W>(a.slot_r + s);
        if constexpr (!kAhead)
          gx = gather<W, G>(a.x, J), gy = gather<W, G>(a.y, J), gz = gather<W, G>(a.z, J);
        const D dx = gx - xi, dy = gy - yi, dz = gz - zi;
        if (kAhead && s + kBlock < s1) {
          const int *next = J + kBlock;
          gx = gather<W, G>(a.x, next), gy = gather<W, G>(a.y, next), gz = gather<W, G>(a.z, next);
        }
        const D dvx = gather<W, G>(a.vx, J) - vxi, dvy = gather<W, G>(a.vy, J) - vyi,
                dvz = gather<W, G>(a.vz, J) - vzi;
        D mj = zero;
        if constexpr (kDamped) mj = gather<W, G>(a.m, J);
        const Normal<W> g =
            normal_part<W, kDamped>(dx, dy, dz, ri, rj, dvx, dvy, dvz, mi, mj, kn, a.beta2);
        const M touch = g.touch;
        if constexpr (kDamped) power += g.power;
        const D hx0 = load<W>(a.hx + s), hy0 = load<W>(a.hy + s), hz0 = load<W>(a.hz + s);
        const D mag2 = hx0 * hx0 + hy0 * hy0 + hz0 * hz0;
        const M held = mag2 > zero;
        const D inv_mag2 = one / select<W>(held, mag2, one);
        if (!any<W>(touch)) {  // no lane touches: histories released, no force
          released += mag2;
          for (double *p : {a.hx, a.hy, a.hz}) store<W>(p + s, zero);
          for (double *p : {a.pfx, a.pfy, a.pfz, a.ptx, a.pty, a.ptz}) store<W>(p + t0 + s, zero);
          continue;
        }
        const D nx = g.nx, ny = g.ny, nz = g.nz, ov = g.ov, fn = g.fn;
        const D ai = ri - 0.5 * ov, aj = rj - 0.5 * ov;
        const D wxj = gather<W, G>(a.wx, J), wyj = gather<W, G>(a.wy, J),
                wzj = gather<W, G>(a.wz, J);
        // a_i·ω_i + a_j·ω_j, and the spin sum of the twist.
        const D sx = wxi + wxj, sy = wyi + wyj, sz = wzi + wzj;
        const D rx = ai * wxi + aj * wxj;
        const D ry = ai * wyi + aj * wyj;
        const D rz = ai * wzi + aj * wzj;
        // v_rel = v_j − v_i − (a_i ω_i + a_j ω_j) × n; v_t its tangential part.
        const D ux = dvx - (ry * nz - rz * ny);
        const D uy = dvy - (rz * nx - rx * nz);
        const D uz = dvz - (rx * ny - ry * nx);
        const D un = ux * nx + uy * ny + uz * nz;
        const D vtx = ux - un * nx, vty = uy - un * ny, vtz = uz - un * nz;
        const Vec3<W> trial = trial_history<W>({nx, ny, nz}, {sx, sy, sz}, {hx0, hy0, hz0}, mag2,
                                               held, inv_mag2, half_dt, kdt, {vtx, vty, vtz});
        D hx = trial.x, hy = trial.y, hz = trial.z;
        // Coulomb: |h| ≤ μ·fn. The root and the division only when a
        // touching lane slides (else cut = 1 in every lane that counts).
        const D cap = mu * fn, h2 = hx * hx + hy * hy + hz * hz;
        if (D cut; coulomb_cut<W>(touch, h2, cap, slid, cut)) {
          hx *= cut;
          hy *= cut;
          hz *= cut;
        }
        released += select<W>(touch, zero, mag2);
        hx = select<W>(touch, hx, zero);
        hy = select<W>(touch, hy, zero);
        hz = select<W>(touch, hz, zero);
        store<W>(a.hx + s, hx);
        store<W>(a.hy + s, hy);
        store<W>(a.hz + s, hz);
        // Force on i: −fn·n + h (on j its opposite); torques a_i·n × h on
        // i and a_j·n × h on j.
        const D qx = hx - fn * nx, qy = hy - fn * ny, qz = hz - fn * nz;
        const D cx = ny * hz - nz * hy, cy = nz * hx - nx * hz, cz = nx * hy - ny * hx;
        fx += qx;
        fy += qy;
        fz += qz;
        tx += ai * cx;
        ty += ai * cy;
        tz += ai * cz;
        store<W>(a.pfx + t0 + s, qx);
        store<W>(a.pfy + t0 + s, qy);
        store<W>(a.pfz + t0 + s, qz);
        store<W>(a.ptx + t0 + s, aj * cx);
        store<W>(a.pty + t0 + s, aj * cy);
        store<W>(a.ptz + t0 + s, aj * cz);
        // overlap/min(r_i, r_j) (ov ≥ 0 where touching: the product is
        // monotone, the maximum of the two ratios exactly).
        const D irj = load<W>(a.slot_ir + s);
        const D ovr = select<W>(touch, ov * (iri > irj ? iri : irj), zero);
        mo = mo > ovr ? mo : ovr;
      }
      store<W>(a.fx + i0, fx);
      store<W>(a.fy + i0, fy);
      store<W>(a.fz + i0, fz);
      store<W>(a.tx + i0, tx);
      store<W>(a.ty + i0, ty);
      store<W>(a.tz + i0, tz);
      store<W>(a.block_released + i0, released);
      store<W>(a.block_slid + i0, slid);
      if constexpr (kDamped) store<W>(a.block_power + i0, power);
    }
    // Block b's mirrored slots all belong to blocks in [src_block[b], b]
    // (i < j): if this pass did those, its sums are complete now, the pair
    // terms still in cache.
    if constexpr (kFuse == kFuseAll) {
      sum_blocks<W, G>(a, b, b + 1);
    } else {
      const bool complete = a.src_block[b] >= b0;
      a.fused[b] = complete;
      if (complete) sum_blocks<W, G>(a, b, b + 1);
    }
  }
  return hmax<W>(mo);
}

struct WallArgs {
  const int *__restrict idx;  // the wall's candidates, padded with the ghost to blocks of 8
  int count;                  // candidates
  // Per candidate: history components along u and v, normal force.
  double *__restrict hu, *__restrict hv, *__restrict fn;
  // Particle arrays along the wall's axis a and the other two, u and v.
  const double *__restrict pa, *__restrict r, *__restrict m;
  const double *__restrict va, *__restrict vu, *__restrict vv;
  const double *__restrict wu, *__restrict wv;
  double *__restrict fa, *__restrict fu, *__restrict fv, *__restrict tu, *__restrict tv;
  double sign, position, velocity;  // inward normal g = sign·e_a; the wall's
  double kn, kdt, mu, beta2;        // wall kn, kt·Δt, μ; beta2 = 2·contact damping ratio
};

// One wall's contacts, W candidates at a time (gathered by index; their
// histories are contiguous), added to the particles' forces and torques.
// The law of the file comment written along the wall's axis a and the two
// others u = a + 1, v = a + 2 (cyclic): with g = σ·e_a (σ = ±1) and the
// arm −dist·g, ω × g = σ·(ω_v, −ω_u) on (u, v) and g × h = σ·(−h_v, h_u),
// so the relative velocity's tangential part is (σ·dist·ω_v − v_u, −v_v −
// σ·dist·ω_u), the force σ·fn·e_a + h and the torque σ·dist·(h_v, −h_u).
// The history's component along a stays 0 (its increment is the normal
// part of a tangential vector, exactly 0), so it is never read. out =
// {spheres' force on the wall −Σf along a, u, v; contacts; Σ|h|² of
// contacts that opened; Σ cap·(|h_trial| − cap) of sliding ones; the
// largest overlap/r; the dashpots' power Σ (fe − fn)·v_n}, each summed over the list in 8 lanes,
// then over the lanes by detail::lane_sum: one order whatever the thread count and the path's
// width.
template <int W, Gather G, bool kFriction>
DEMCAL_INLINE void wall_contacts(const WallArgs &a, double *out) {
  using D = typename Simd<W>::D;
  using M = typename Simd<W>::M;
  const D zero{}, one = zero + 1.0;
  D lane;
  for (int l = 0; l < W; ++l) lane[l] = l;
  // The sums by 8 candidates, W at a time (BlockLanes): the same bits on
  // every path. The list is padded to a multiple of 8 (with the ghost,
  // histories 0), so every group of 8 is read whole; unrolled, each part
  // stays in registers.
  BlockLanes<W> sum_fa, sum_fu, sum_fv, sum_count, sum_released, sum_slid, sum_power;
  D mo = zero;
  const double sg = a.sign;
  for (int k8 = 0; k8 < a.count; k8 += kBlock)
#pragma GCC unroll 4
    for (int q = 0; q < kBlock / W; ++q) {
      const int k = k8 + q * W;
      D &wfa = sum_fa.part[q], &wfu = sum_fu.part[q], &wfv = sum_fv.part[q];
      D &count = sum_count.part[q], &released = sum_released.part[q], &slid = sum_slid.part[q];
      D &power = sum_power.part[q];
      const int *J = a.idx + k;
      const M valid = lane < static_cast<double>(a.count - k);
      const D r = gather<W, G>(a.r, J);
      const D dist = (gather<W, G>(a.pa, J) - a.position) * sg;
      // (Masks combined through selects and one compare each: GCC rebuilds
      // a mask made with & lane by lane on the AVX-512 path.)
      const D ov = select<W>(valid, r - dist, zero - one);
      const M touch = ov > zero;
      const D hu0 = load<W>(a.hu + k), hv0 = load<W>(a.hv + k);
      if (!any<W>(touch)) {  // histories released (the padding holds 0)
        released += hu0 * hu0 + hv0 * hv0;
        store<W>(a.hu + k, zero);
        store<W>(a.hv + k, zero);
        store<W>(a.fn + k, zero);
        continue;
      }
      released += select<W>(touch, zero, hu0 * hu0 + hv0 * hv0);
      const D ratio = select<W>(touch, ov / select<W>(touch, r, one), zero);
      mo = mo > ratio ? mo : ratio;
      D fn = law::elastic_normal_force(a.kn, ov);
      if (a.beta2 > 0.0) {
        const D vn = (gather<W, G>(a.va, J) - a.velocity) * sg;  // leaving the wall > 0
        const D fe = fn;
        fn = law::damped_normal_force(fe, a.beta2, vsqrt(a.kn * gather<W, G>(a.m, J)), vn);
        power += select<W>(touch, law::dashpot_power(fe, fn, vn), zero);
      }
      fn = select<W>(touch, fn, zero);
      if constexpr (!kFriction) {
        // A frictionless wall (μ = 0): Coulomb's cap is 0, so the full
        // evaluation below cuts every trial history to 0 with no slip work
        // (cap·(|h| − cap) = 0): only the normal force is left.
        store<W>(a.hu + k, zero);
        store<W>(a.hv + k, zero);
        store<W>(a.fn + k, fn);
        const D fa = sg * fn;
        for (int l = 0; l < W; ++l) a.fa[J[l]] += fa[l];
        wfa -= fa;
        count += select<W>(touch, one, zero);
        continue;
      }
      const D sd = sg * dist;
      const D dvu = sd * gather<W, G>(a.wv, J) - gather<W, G>(a.vu, J);
      const D dvv = (zero - gather<W, G>(a.vv, J)) - sd * gather<W, G>(a.wu, J);
      D hu = hu0 + a.kdt * dvu, hv = hv0 + a.kdt * dvv;
      const D cap = a.mu * fn, h2 = hu * hu + hv * hv;
      if (D cut; coulomb_cut<W>(touch, h2, cap, slid, cut)) {
        hu *= cut;
        hv *= cut;
      }
      hu = select<W>(touch, hu, zero);
      hv = select<W>(touch, hv, zero);
      store<W>(a.hu + k, hu);
      store<W>(a.hv + k, hv);
      store<W>(a.fn + k, fn);
      const D fa = sg * fn, tu = select<W>(touch, sd * hv, zero),
              tv = select<W>(touch, sd * hu, zero);
      // Each candidate once per list (the padding adds zeros to the ghost).
      for (int l = 0; l < W; ++l) {
        const int i = J[l];
        a.fa[i] += fa[l];
        a.fu[i] += hu[l];
        a.fv[i] += hv[l];
        a.tu[i] += tu[l];
        a.tv[i] -= tv[l];
      }
      wfa -= fa;
      wfu -= hu;
      wfv -= hv;
      count += select<W>(touch, one, zero);
    }
  out[0] = sum_fa.total();
  out[1] = sum_fu.total();
  out[2] = sum_fv.total();
  out[3] = sum_count.total();
  out[4] = sum_released.total();
  out[5] = sum_slid.total();
  out[6] = hmax<W>(mo);
  out[7] = sum_power.total();
}

struct IntegrateArgs {
  double *__restrict x, *__restrict y, *__restrict z;
  double *__restrict vx, *__restrict vy, *__restrict vz;
  double *__restrict wx, *__restrict wy, *__restrict wz;
  const double *__restrict fx, *__restrict fy, *__restrict fz;
  const double *__restrict tx, *__restrict ty, *__restrict tz;
  const double *__restrict ca_t, *__restrict cb_t, *__restrict ca_r, *__restrict cb_r;
  const double *__restrict d_t, *__restrict d_r;
  const double *__restrict x_built, *__restrict y_built, *__restrict z_built;
  double *__restrict block_lost;
  double dt;
};

// Central difference with global damping for blocks [b0, b1); writes each
// block's damping loss Σ D·|v̄|²/4 and returns the largest squared
// displacement since the last neighbour-list build.
template <int W, bool kRotation>
DEMCAL_INLINE double integrate_blocks(const IntegrateArgs &a, int b0, int b1) {
  using D = typename Simd<W>::D;
  D md = D{};
  const double dt = a.dt;
  for (int b = b0; b < b1; ++b) {
    for (int i = kBlock * b; i < kBlock * (b + 1); i += W) {
      const D cat = load<W>(a.ca_t + i), cbt = load<W>(a.cb_t + i);
      const D ux = load<W>(a.vx + i), uy = load<W>(a.vy + i), uz = load<W>(a.vz + i);
      const D vx = cat * ux + cbt * load<W>(a.fx + i);
      const D vy = cat * uy + cbt * load<W>(a.fy + i);
      const D vz = cat * uz + cbt * load<W>(a.fz + i);
      const D bx = ux + vx, by = uy + vy, bz = uz + vz;
      D lost = 0.25 * load<W>(a.d_t + i) * (bx * bx + by * by + bz * bz);
      const D x = load<W>(a.x + i) + vx * dt, y = load<W>(a.y + i) + vy * dt,
              z = load<W>(a.z + i) + vz * dt;
      store<W>(a.vx + i, vx);
      store<W>(a.vy + i, vy);
      store<W>(a.vz + i, vz);
      store<W>(a.x + i, x);
      store<W>(a.y + i, y);
      store<W>(a.z + i, z);
      if constexpr (kRotation) {
        const D car = load<W>(a.ca_r + i), cbr = load<W>(a.cb_r + i);
        const D oxu = load<W>(a.wx + i), oyu = load<W>(a.wy + i), ozu = load<W>(a.wz + i);
        const D ox = car * oxu + cbr * load<W>(a.tx + i);
        const D oy = car * oyu + cbr * load<W>(a.ty + i);
        const D oz = car * ozu + cbr * load<W>(a.tz + i);
        const D ex = oxu + ox, ey = oyu + oy, ez = ozu + oz;
        lost += 0.25 * load<W>(a.d_r + i) * (ex * ex + ey * ey + ez * ez);
        store<W>(a.wx + i, ox);
        store<W>(a.wy + i, oy);
        store<W>(a.wz + i, oz);
      }
      const D dx = x - load<W>(a.x_built + i), dy = y - load<W>(a.y_built + i),
              dz = z - load<W>(a.z_built + i);
      const D d2 = dx * dx + dy * dy + dz * dz;
      md = d2 > md ? d2 : md;
      store<W>(a.block_lost + i, lost);
    }
  }
  return hmax<W>(md);
}

// ---------------------------------------------------------------- dispatch

using PairFn = double (*)(const PairArgs &, int, int);
using SumFn = double (*)(const SumArgs &, int, int);
using IntegrateFn = double (*)(const IntegrateArgs &, int, int);
using WallFn = void (*)(const WallArgs &, double *);

struct Kernels {
  PairFn pairs, pairs_damped;      // one thread: every block's sums fused
  PairFn pairs_t, pairs_damped_t;  // threads: the blocks a pass completes
  SumFn sums;
  IntegrateFn integrate, integrate_locked;
  void (*one_pair)(const double *, double *);
  WallFn walls;
};

// The threaded pair pass sums the blocks it completes on every path. Before
// the pair terms had their ring (term_ring.hpp), that cost the AVX2 path
// 0.93x at 97 556 spheres on 2 threads (2026-12-02), so AVX2 and SSE2 left
// every sum to the sum pass; with the ring it gains 1.16x on AVX2 (5
// alternating rounds, 2026-12-05, reports/performance.md).
#define DEMCAL_SPHERE_KERNELS(SUFFIX, TARGET, W, G)                                              \
  TARGET double pairs_##SUFFIX(const PairArgs &a, int b0, int b1) {                              \
    return pair_blocks<W, G, false, kFuseAll>(a, b0, b1);                                        \
  }                                                                                              \
  TARGET double pairs_damped_##SUFFIX(const PairArgs &a, int b0, int b1) {                       \
    return pair_blocks<W, G, true, kFuseAll>(a, b0, b1);                                         \
  }                                                                                              \
  TARGET double pairs_t_##SUFFIX(const PairArgs &a, int b0, int b1) {                            \
    return pair_blocks<W, G, false, kFuseOwn>(a, b0, b1);                                        \
  }                                                                                              \
  TARGET double pairs_damped_t_##SUFFIX(const PairArgs &a, int b0, int b1) {                     \
    return pair_blocks<W, G, true, kFuseOwn>(a, b0, b1);                                         \
  }                                                                                              \
  TARGET double sums_##SUFFIX(const SumArgs &a, int b0, int b1) {                                \
    for (int b = b0; b < b1; ++b)                                                                \
      if (!a.fused[b]) sum_blocks<W, G, SumArgs>(a, b, b + 1);                                   \
    return 0.0;                                                                                  \
  }                                                                                              \
  TARGET double integrate_##SUFFIX(const IntegrateArgs &a, int b0, int b1) {                     \
    return integrate_blocks<W, true>(a, b0, b1);                                                 \
  }                                                                                              \
  TARGET double integrate_locked_##SUFFIX(const IntegrateArgs &a, int b0, int b1) {              \
    return integrate_blocks<W, false>(a, b0, b1);                                                \
  }                                                                                              \
  TARGET void one_pair_##SUFFIX(const double *in, double *out) { one_pair<W>(in, out); }         \
  TARGET void walls_##SUFFIX(const WallArgs &a, double *out) {                                   \
    if (a.mu > 0.0)                                                                              \
      wall_contacts<W, G, true>(a, out);                                                         \
    else                                                                                         \
      wall_contacts<W, G, false>(a, out);                                                        \
  }                                                                                              \
  constexpr Kernels kKernels_##SUFFIX{                                                           \
      pairs_##SUFFIX, pairs_damped_##SUFFIX, pairs_t_##SUFFIX,          pairs_damped_t_##SUFFIX, \
      sums_##SUFFIX,  integrate_##SUFFIX,    integrate_locked_##SUFFIX, one_pair_##SUFFIX,       \
      walls_##SUFFIX};

#define DEMCAL_NO_TARGET
DEMCAL_SPHERE_KERNELS(sse2, DEMCAL_NO_TARGET, 2, Gather::kEmulated)
#ifdef DEMCAL_X86_64
DEMCAL_SPHERE_KERNELS(avx2, DEMCAL_V3, 4, Gather::kEmulated)
DEMCAL_SPHERE_KERNELS(avx512, DEMCAL_V4, 8, Gather::kEmulated)
#if !defined(__clang__)
DEMCAL_SPHERE_KERNELS(avx512_hw, DEMCAL_V4, 8, Gather::kHardware)
#endif
#endif

// The path and the way to gather the 2D kernel chose (kernel_simd() and
// kernel_gather(): CPU, DEMCAL_SIMD and DEMCAL_GATHER).
const Kernels &kernels() {
  static const Kernels chosen = [] {
#ifdef DEMCAL_X86_64
    const char *name = kernel_simd();
#if !defined(__clang__)
    if (std::strcmp(kernel_gather(), "hardware") == 0) return kKernels_avx512_hw;
#endif
    if (std::strcmp(name, "avx512") == 0) return kKernels_avx512;
    if (std::strcmp(name, "avx2") == 0) return kKernels_avx2;
#endif
    return kKernels_sse2;
  }();
  return chosen;
}

}  // namespace

double SphereWorldImpl::pair_pass(int b0, int b1) {
  // Frictionless spheres (μ = 0) carry no tangential spring: the Coulomb
  // cap would cut it to 0 anyway, but it compares squares, and a trial |h|²
  // that underflows to 0 would let a (tiny) tangential force through.
  const double kdt =
      material_.particle.friction > 0.0 ? material_.particle.kt * integration_.dt : 0.0;
  const PairArgs a{block_slot_.data(),
                   slot_j_.data(),
                   hx_.data(),
                   hy_.data(),
                   hz_.data(),
                   slot_r_.data(),
                   slot_ir_.data(),
                   pfx_.data(),
                   pfy_.data(),
                   pfz_.data(),
                   ptx_.data(),
                   pty_.data(),
                   ptz_.data(),
                   x_.data(),
                   y_.data(),
                   z_.data(),
                   vx_.data(),
                   vy_.data(),
                   vz_.data(),
                   wx_.data(),
                   wy_.data(),
                   wz_.data(),
                   r_.data(),
                   inv_r_.data(),
                   m_.data(),
                   fx_.data(),
                   fy_.data(),
                   fz_.data(),
                   tx_.data(),
                   ty_.data(),
                   tz_.data(),
                   block_released_.data(),
                   block_slid_.data(),
                   block_power_.data(),
                   material_.particle.kn,
                   kdt,
                   0.5 * integration_.dt,
                   material_.particle.friction,
                   2.0 * material_.contact_damping_ratio,
                   term_block_.data(),
                   mirror_block_.data(),
                   mirror_term_.data(),
                   mirror_src_block_.data(),
                   block_fused_.data()};
  const Kernels &k = kernels();
  const bool damped = material_.contact_damping_ratio > 0.0;
  if (active_threads() <= 1) return damped ? k.pairs_damped(a, b0, b1) : k.pairs(a, b0, b1);
  return damped ? k.pairs_damped_t(a, b0, b1) : k.pairs_t(a, b0, b1);
}

double SphereWorldImpl::sum_pass(int b0, int b1) {
  const SumArgs a{mirror_block_.data(), mirror_term_.data(), block_fused_.data(), pfx_.data(),
                  pfy_.data(),          pfz_.data(),         ptx_.data(),         pty_.data(),
                  ptz_.data(),          fx_.data(),          fy_.data(),          fz_.data(),
                  tx_.data(),           ty_.data(),          tz_.data()};
  return kernels().sums(a, b0, b1);
}

double SphereWorldImpl::integrate_pass(int b0, int b1) {
  const IntegrateArgs a{x_.data(),          y_.data(),       z_.data(),       vx_.data(),
                        vy_.data(),         vz_.data(),      wx_.data(),      wy_.data(),
                        wz_.data(),         fx_.data(),      fy_.data(),      fz_.data(),
                        tx_.data(),         ty_.data(),      tz_.data(),      ca_t_.data(),
                        cb_t_.data(),       ca_r_.data(),    cb_r_.data(),    d_t_.data(),
                        d_r_.data(),        x_built_.data(), y_built_.data(), z_built_.data(),
                        block_lost_.data(), integration_.dt};
  const Kernels &k = kernels();
  return integration_.lock_rotation ? k.integrate_locked(a, b0, b1) : k.integrate(a, b0, b1);
}

double SphereWorldImpl::wall_distance(int s, int i) const {
  const double *pos[3] = {x_.data(), y_.data(), z_.data()};
  const double sign = (s % 2 == 0) ? 1.0 : -1.0;
  return (pos[s / 2][i] - walls_[s].position) * sign;
}

SphereWorldImpl::PairGeometry SphereWorldImpl::pair_geometry(int i, int j) const {
  // The pair pass's normal_part, one lane on the same SIMD path.
  const double in[12] = {
      x_[j] - x_[i], y_[j] - y_[i],   z_[j] - z_[i],         r_[i],
      r_[j],         vx_[j] - vx_[i], vy_[j] - vy_[i],       vz_[j] - vz_[i],
      m_[i],         m_[j],           material_.particle.kn, 2.0 * material_.contact_damping_ratio};
  double out[6];
  kernels().one_pair(in, out);
  PairGeometry p{};
  p.touching = out[5] != 0.0;
  if (!p.touching) return p;
  p.n = V3(out[0], out[1], out[2]);
  p.overlap = out[3];
  p.fn = out[4];
  return p;
}

void SphereWorldImpl::wall_pass() {
  const double kdt = material_.wall.kt * integration_.dt;
  const double compliance = material_.wall.kt > 0.0 ? 1.0 / material_.wall.kt : 0.0;
  const double *pos[3] = {x_.data(), y_.data(), z_.data()};
  const double *vel[3] = {vx_.data(), vy_.data(), vz_.data()};
  const double *spin[3] = {wx_.data(), wy_.data(), wz_.data()};
  double *force[3] = {fx_.data(), fy_.data(), fz_.data()};
  double *torque[3] = {tx_.data(), ty_.data(), tz_.data()};
  double max_overlap = 0.0, released = 0.0, slid = 0.0, power = 0.0;
  const Kernels &k = kernels();
  for (int s = 0; s < 6; ++s) {
    SphereWall &wall = walls_[s];
    const int ax = s / 2, u = (ax + 1) % 3, v = (ax + 2) % 3;
    Array *h[3] = {&wall_hx_[s], &wall_hy_[s], &wall_hz_[s]};
    const WallArgs a{wall_gather_[s].data(),
                     static_cast<int>(wall_candidates_[s].size()),
                     h[u]->data(),
                     h[v]->data(),
                     wall_fn_[s].data(),
                     pos[ax],
                     r_.data(),
                     m_.data(),
                     vel[ax],
                     vel[u],
                     vel[v],
                     spin[u],
                     spin[v],
                     force[ax],
                     force[u],
                     force[v],
                     torque[u],
                     torque[v],
                     (s % 2 == 0) ? 1.0 : -1.0,
                     wall.position,
                     wall.velocity,
                     material_.wall.kn,
                     kdt,
                     material_.wall.friction,
                     2.0 * material_.contact_damping_ratio};
    double out[8];
    k.walls(a, out);
    wall.force = V3::Zero();
    wall.force[ax] = out[0];
    wall.force[u] = out[1];
    wall.force[v] = out[2];
    wall.contacts = static_cast<int>(out[3]);
    released += out[4];
    slid += out[5];
    max_overlap = std::max(max_overlap, out[6]);
    power += out[7];
  }
  max_overlap_ratio_seen_ = std::max(max_overlap_ratio_seen_, max_overlap);
  friction_dissipated_ += released * (0.5 * compliance) + slid * compliance;
  dashpot_power_ += power;
}

void SphereWorldImpl::compute_forces() {
  // The sums fused into the pair pass, block by block, where a thread's
  // own pairs complete them (one thread: all; the same sums, same order);
  // the others in a second pass once all pairs are done.
  max_overlap_ratio_seen_ = run_pass(&SphereWorldImpl::pair_pass, pair_bounds_);
  if (active_threads() > 1) run_pass(&SphereWorldImpl::sum_pass, particle_bounds_);
  // Friction's losses, lane by lane over the blocks in a fixed order (every
  // pair counted once; detail::block_lanes_sum).
  const double kt = material_.particle.kt;
  if (kt > 0.0) {
    const double released = detail::block_lanes_sum(block_released_.data(), nblocks_);
    const double slid = detail::block_lanes_sum(block_slid_.data(), nblocks_);
    friction_dissipated_ += released * (0.5 / kt) + slid / kt;
  }
  // The contact dashpots' power of these forces, booked by step() over the
  // step that applies them (the walls' share added by wall_pass).
  dashpot_power_ = material_.contact_damping_ratio > 0.0
                       ? detail::block_lanes_sum(block_power_.data(), nblocks_)
                       : 0.0;
  wall_pass();
}

}  // namespace demcal
