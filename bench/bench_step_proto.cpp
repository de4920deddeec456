// Prototype step loops, to put numbers on the recommendations of
// reports/performance.md. NOT the kernel: a stand-alone re-implementation of
// one step (integrate, neighbour-list validity check, particle–particle
// forces) on the state of a pre-loaded bench scene (bench_scene.hpp), in
// three forms:
//
//   Baseline  — the kernel's current structure (SoA arrays, pair list sorted
//               by i, scatter of forces to i and j, three divisions per pair,
//               contact normal stored per pair, separate passes for
//               integrate / displacement check / force zeroing).
//   Flat      — the Baseline's flat pair loop with the cheap fixes only
//               (__restrict local pointers, one division per pair, overlap
//               maximum as a length, no per-pair normal stored, one fused
//               particle pass).
//   FlatRsqrt — Flat with 1/d from the AVX-512 rsqrt14 estimate refined by two
//               Newton steps (no sqrt, no division: the divider is free).
//   Scalar    — same physics, restructured: particle state in one 48-byte
//               record (x, y, vx, vy, ω, r), CSR half list (i's force summed
//               in registers, written once), one division per pair, maximum
//               overlap tracked as a length (one division per step), no
//               per-pair normal stored, integrate + displacement check +
//               force zeroing fused into one pass.
//   TwoPass   — pass 1 computes per-pair forces branch-free over the pair
//               arrays (explicit AVX2/FMA, four pairs at a time with gathers,
//               when the CPU has it; scalar otherwise), pass 2 gathers each
//               particle's forces from its incident pairs (CSR, no scatter)
//               and integrates it in the same loop.
//
// Walls: the scene's four frictionless walls (normal force only: with μ_w = 0
// the kernel's wall tangential force is identically 0), the top one moving,
// acting on the particles that were within the skin of a wall at the start.
// The neighbour list is never rebuilt (the kernel rebuilds about once per
// 10^4–10^5 steps here); the counter list_expired_steps says if it should have
// been. All forms are checked against each other on the first
// evaluation; the counter contacts (particle pairs in contact at the end)
// shows the packing stayed loaded. Rates: particle_steps/s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <immintrin.h>
#include <memory>
#include <numbers>
#include <vector>

#include "bench_scene.hpp"

namespace {

struct State0 {
  // The scene after pre-load, flattened.
  int n = 0;
  double dt = 0, kn = 0, kt = 0, mu = 0, skin = 0, r_min = 0;
  std::vector<double> x, y, vx, vy, th, om, r, ca_t, cb_t, ca_r, cb_r;
  std::vector<int> pi, pj;  // half list, i < j, sorted by (i, j)
  std::vector<double> ft;   // tangential history per pair
  // Walls: left, right, bottom, top positions; top velocity; stiffness.
  double wall[4] = {0, 0, 0, 0}, vtop = 0, kw = 0;
  std::vector<uint8_t> wall_mask;  // bit s: particle is a candidate of wall s
  std::vector<int> cand[4];
};

// Normal force of the frictionless walls on one particle (mask = candidate
// walls). Adds to (fx, fy).
inline void wall_force(const double* wall, double kw, uint8_t mask, double x, double y, double r,
                       double& fx, double& fy) {
  if (mask & 1) fx += kw * std::max(0.0, r - (x - wall[0]));
  if (mask & 2) fx -= kw * std::max(0.0, r - (wall[1] - x));
  if (mask & 4) fy += kw * std::max(0.0, r - (y - wall[2]));
  if (mask & 8) fy -= kw * std::max(0.0, r - (wall[3] - y));
}

State0 make_state(int side) {
  auto scene = demcal_bench::hex_scene(side, side);
  auto w = demcal_bench::make_compression_world(scene);
  w->step(std::clamp<int64_t>(20'000'000 / w->size(), 200, 2000));
  State0 s;
  s.n = w->size();
  s.dt = w->integration().dt;
  s.kn = scene.material.particle.kn;
  s.kt = scene.material.particle.kt;
  s.mu = scene.material.particle.friction;
  s.x.assign(w->x().begin(), w->x().end());
  s.y.assign(w->y().begin(), w->y().end());
  s.vx.assign(w->vx().begin(), w->vx().end());
  s.vy.assign(w->vy().begin(), w->vy().end());
  s.th.assign(w->rotation().begin(), w->rotation().end());
  s.om.assign(w->omega().begin(), w->omega().end());
  s.r.assign(w->radius().begin(), w->radius().end());
  s.r_min = *std::min_element(s.r.begin(), s.r.end());
  s.skin = w->options().skin_ratio * s.r_min;
  for (int k = 0; k < 4; ++k) s.wall[k] = w->wall(static_cast<demcal::WallSide>(k)).position;
  s.vtop = w->wall(demcal::kTop).velocity;
  s.kw = scene.material.wall.kn;
  s.wall_mask.assign(s.n, 0);
  for (int i = 0; i < s.n; ++i) {
    const double gaps[4] = {s.x[i] - s.r[i] - s.wall[0], s.wall[1] - s.x[i] - s.r[i],
                            s.y[i] - s.r[i] - s.wall[2], s.wall[3] - s.y[i] - s.r[i]};
    for (int k = 0; k < 4; ++k)
      if (gaps[k] < s.skin) {
        s.wall_mask[i] |= static_cast<uint8_t>(1u << k);
        s.cand[k].push_back(i);
      }
  }
  // Integration coefficients as in solver.cpp (ζ_t = ζ_r = 1).
  for (int i = 0; i < s.n; ++i) {
    const double m = w->mass()[i], I = 0.5 * m * s.r[i] * s.r[i];
    const double c = 2.0 * std::sqrt(s.kn * m) * s.dt / (2.0 * m);
    s.ca_t.push_back((1 - c) / (1 + c));
    s.cb_t.push_back(s.dt / m / (1 + c));
    const double cr = 2.0 * std::sqrt(s.kt * s.r[i] * s.r[i] * I) * s.dt / (2.0 * I);
    s.ca_r.push_back((1 - cr) / (1 + cr));
    s.cb_r.push_back(s.dt / I / (1 + cr));
  }
  // Half neighbour list with skin (brute force over a grid is not needed for
  // a one-off: use a simple cell sort).
  const double cell = 2.0 * *std::max_element(s.r.begin(), s.r.end()) + s.skin;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (int i = 0; i < s.n; ++i) {
    x0 = std::min(x0, s.x[i]);
    y0 = std::min(y0, s.y[i]);
    x1 = std::max(x1, s.x[i]);
    y1 = std::max(y1, s.y[i]);
  }
  const int ncx = std::max(1, static_cast<int>((x1 - x0) / cell) + 1);
  const int ncy = std::max(1, static_cast<int>((y1 - y0) / cell) + 1);
  std::vector<std::vector<int>> cells(static_cast<size_t>(ncx) * ncy);
  auto cx = [&](int i) { return std::min(ncx - 1, static_cast<int>((s.x[i] - x0) / cell)); };
  auto cy = [&](int i) { return std::min(ncy - 1, static_cast<int>((s.y[i] - y0) / cell)); };
  for (int i = 0; i < s.n; ++i) cells[cy(i) * ncx + cx(i)].push_back(i);
  // Tangential history from the world's active contacts.
  std::vector<std::pair<int64_t, double>> hist;
  for (const auto& c : w->contacts())
    hist.push_back({static_cast<int64_t>(c.i) * s.n + c.j, c.ft});
  std::sort(hist.begin(), hist.end());
  for (int i = 0; i < s.n; ++i) {
    std::vector<int> js;
    for (int ddy = -1; ddy <= 1; ++ddy)
      for (int ddx = -1; ddx <= 1; ++ddx) {
        const int xx = cx(i) + ddx, yy = cy(i) + ddy;
        if (xx < 0 || yy < 0 || xx >= ncx || yy >= ncy) continue;
        for (int j : cells[yy * ncx + xx]) {
          if (j <= i) continue;
          const double dx = s.x[j] - s.x[i], dy = s.y[j] - s.y[i];
          const double cut = s.r[i] + s.r[j] + s.skin;
          if (dx * dx + dy * dy < cut * cut) js.push_back(j);
        }
      }
    std::sort(js.begin(), js.end());
    for (int j : js) {
      s.pi.push_back(i);
      s.pj.push_back(j);
      const int64_t key = static_cast<int64_t>(i) * s.n + j;
      auto it = std::lower_bound(hist.begin(), hist.end(), std::make_pair(key, -1e300));
      s.ft.push_back(it != hist.end() && it->first == key ? it->second : 0.0);
    }
  }
  return s;
}

// ---------------------------------------------------------------- Baseline
struct Baseline {
  State0 s;
  std::vector<double> fx, fy, tq, fn, nx, ny, xb, yb;
  double max_overlap = 0;
  explicit Baseline(const State0& st) : s(st) {
    fx.assign(s.n, 0);
    fy.assign(s.n, 0);
    tq.assign(s.n, 0);
    fn.assign(s.pi.size(), 0);
    nx.assign(s.pi.size(), 0);
    ny.assign(s.pi.size(), 0);
    xb = s.x;
    yb = s.y;
  }
  void forces() {
    std::fill(fx.begin(), fx.end(), 0.0);
    std::fill(fy.begin(), fy.end(), 0.0);
    std::fill(tq.begin(), tq.end(), 0.0);
    double mo = 0;
    const double dt = s.dt, kn = s.kn, kt = s.kt, mu = s.mu;
    for (size_t k = 0; k < s.pi.size(); ++k) {
      const int i = s.pi[k], j = s.pj[k];
      const double dx = s.x[j] - s.x[i], dy = s.y[j] - s.y[i];
      const double d2 = dx * dx + dy * dy, rsum = s.r[i] + s.r[j];
      if (d2 >= rsum * rsum) {
        s.ft[k] = 0;
        fn[k] = 0;
        continue;
      }
      const double d = std::sqrt(d2);
      const double ex = dx / d, ey = dy / d, tx = -ey, ty = ex;
      const double ov = rsum - d;
      const double ai = s.r[i] - 0.5 * ov, aj = s.r[j] - 0.5 * ov;
      mo = std::max(mo, ov / std::min(s.r[i], s.r[j]));
      const double dvx = s.vx[j] - s.vx[i], dvy = s.vy[j] - s.vy[i];
      const double f = kn * ov;
      const double vt = dvx * tx + dvy * ty - s.om[j] * aj - s.om[i] * ai;
      double t = s.ft[k] + kt * vt * dt;
      const double cap = mu * f;
      t = std::clamp(t, -cap, cap);
      s.ft[k] = t;
      fn[k] = f;
      nx[k] = ex;
      ny[k] = ey;
      const double fxi = -f * ex + t * tx, fyi = -f * ey + t * ty;
      fx[i] += fxi;
      fy[i] += fyi;
      fx[j] -= fxi;
      fy[j] -= fyi;
      tq[i] += ai * t;
      tq[j] += aj * t;
    }
    // Walls: one loop per wall over its candidates, as in the kernel.
    for (int w = 0; w < 4; ++w) {
      const uint8_t bit = static_cast<uint8_t>(1u << w);
      for (int i : s.cand[w]) wall_force(s.wall, s.kw, bit, s.x[i], s.y[i], s.r[i], fx[i], fy[i]);
    }
    max_overlap = mo;
  }
  bool step() {
    for (int i = 0; i < s.n; ++i) {
      s.vx[i] = s.ca_t[i] * s.vx[i] + s.cb_t[i] * fx[i];
      s.vy[i] = s.ca_t[i] * s.vy[i] + s.cb_t[i] * fy[i];
      s.x[i] += s.vx[i] * s.dt;
      s.y[i] += s.vy[i] * s.dt;
    }
    for (int i = 0; i < s.n; ++i) {
      s.om[i] = s.ca_r[i] * s.om[i] + s.cb_r[i] * tq[i];
      s.th[i] += s.om[i] * s.dt;
    }
    s.wall[3] += s.vtop * s.dt;
    double md2 = 0;
    for (int i = 0; i < s.n; ++i) {
      const double dx = s.x[i] - xb[i], dy = s.y[i] - yb[i];
      md2 = std::max(md2, dx * dx + dy * dy);
    }
    forces();
    return 2.0 * std::sqrt(md2) < s.skin;  // list still valid
  }
  int contacts() const {
    int c = 0;
    for (size_t k = 0; k < s.pi.size(); ++k) {
      const int i = s.pi[k], j = s.pj[k];
      const double dx = s.x[j] - s.x[i], dy = s.y[j] - s.y[i], rs = s.r[i] + s.r[j];
      c += dx * dx + dy * dy < rs * rs;
    }
    return c;
  }
};

// ---------------------------------------------------------------- Flat
// The Baseline's loop structure (SoA, one flat loop over the sorted half
// list, scatter to i and j) with the cheap fixes only: data pointers in
// __restrict locals, one division per pair (1/d), maximum overlap tracked as
// a length, no per-pair normal / normal force stored, integrate + rotation +
// displacement check + force zeroing in one pass.
// 1/sqrt(d2) without the divider: AVX-512 rsqrt14 estimate (14 bits) and two
// Newton steps (≈ full double precision).
__attribute__((target("avx512f"))) inline double inv_sqrt_nr(double d2) {
  const __m128d v = _mm_set_sd(d2);
  double y = _mm_cvtsd_f64(_mm_rsqrt14_sd(v, v));
  const double h = 0.5 * d2;
  y = y * (1.5 - h * y * y);
  y = y * (1.5 - h * y * y);
  return y;
}

template <bool kRsqrt>
struct FlatT {
  State0 s;
  std::vector<double> fx, fy, tq, xb, yb;
  double max_overlap = 0;
  explicit FlatT(const State0& st) : s(st) {
    fx.assign(s.n, 0);
    fy.assign(s.n, 0);
    tq.assign(s.n, 0);
    xb = s.x;
    yb = s.y;
  }
  __attribute__((always_inline)) inline void forces_body() {
    const int* __restrict I = s.pi.data();
    const int* __restrict J = s.pj.data();
    const double *__restrict X = s.x.data(), *__restrict Y = s.y.data(), *__restrict R = s.r.data();
    const double *__restrict VX = s.vx.data(), *__restrict VY = s.vy.data();
    const double* __restrict OM = s.om.data();
    double* __restrict T = s.ft.data();
    double *__restrict FX = fx.data(), *__restrict FY = fy.data(), *__restrict TQ = tq.data();
    const double kn = s.kn, mu = s.mu, kdt = s.kt * s.dt;
    double mo = 0;
    const size_t np = s.pi.size();
    for (size_t k = 0; k < np; ++k) {
      const int i = I[k], j = J[k];
      const double dx = X[j] - X[i], dy = Y[j] - Y[i];
      const double d2 = dx * dx + dy * dy, rsum = R[i] + R[j];
      if (d2 >= rsum * rsum) {
        T[k] = 0;
        continue;
      }
      double d, inv;
      if constexpr (kRsqrt) {
        inv = inv_sqrt_nr(d2);
        d = d2 * inv;
      } else {
        d = std::sqrt(d2);
        inv = 1.0 / d;
      }
      const double ex = dx * inv, ey = dy * inv;
      const double ov = rsum - d;
      const double ai = R[i] - 0.5 * ov, aj = R[j] - 0.5 * ov;
      mo = std::max(mo, ov);
      const double f = kn * ov;
      const double vt = -(VX[j] - VX[i]) * ey + (VY[j] - VY[i]) * ex - OM[j] * aj - OM[i] * ai;
      const double cap = mu * f;
      const double t = std::min(std::max(T[k] + kdt * vt, -cap), cap);
      T[k] = t;
      const double fxi = -f * ex - t * ey, fyi = -f * ey + t * ex;
      FX[i] += fxi;
      FY[i] += fyi;
      FX[j] -= fxi;
      FY[j] -= fyi;
      TQ[i] += ai * t;
      TQ[j] += aj * t;
    }
    for (int w = 0; w < 4; ++w) {
      const uint8_t bit = static_cast<uint8_t>(1u << w);
      for (int i : s.cand[w]) wall_force(s.wall, s.kw, bit, X[i], Y[i], R[i], FX[i], FY[i]);
    }
    max_overlap = mo / s.r_min;
  }
  void forces() {
    if constexpr (kRsqrt) forces_avx512();
    else forces_body();
  }
  __attribute__((target("avx512f"))) void forces_avx512() { forces_body(); }
  bool step() {
    double *__restrict X = s.x.data(), *__restrict Y = s.y.data(), *__restrict TH = s.th.data();
    double *__restrict VX = s.vx.data(), *__restrict VY = s.vy.data(), *__restrict OM = s.om.data();
    double *__restrict FX = fx.data(), *__restrict FY = fy.data(), *__restrict TQ = tq.data();
    const double *__restrict CAT = s.ca_t.data(), *__restrict CBT = s.cb_t.data();
    const double *__restrict CAR = s.ca_r.data(), *__restrict CBR = s.cb_r.data();
    const double *__restrict XB = xb.data(), *__restrict YB = yb.data();
    const double dt = s.dt;
    double md2 = 0;
    for (int i = 0; i < s.n; ++i) {
      VX[i] = CAT[i] * VX[i] + CBT[i] * FX[i];
      VY[i] = CAT[i] * VY[i] + CBT[i] * FY[i];
      OM[i] = CAR[i] * OM[i] + CBR[i] * TQ[i];
      X[i] += VX[i] * dt;
      Y[i] += VY[i] * dt;
      TH[i] += OM[i] * dt;
      FX[i] = FY[i] = TQ[i] = 0.0;
      const double dx = X[i] - XB[i], dy = Y[i] - YB[i];
      md2 = std::max(md2, dx * dx + dy * dy);
    }
    s.wall[3] += s.vtop * dt;
    forces();
    return 2.0 * std::sqrt(md2) < s.skin;
  }
  int contacts() const {
    int c = 0;
    for (size_t k = 0; k < s.pi.size(); ++k) {
      const int i = s.pi[k], j = s.pj[k];
      const double dx = s.x[j] - s.x[i], dy = s.y[j] - s.y[i], rs = s.r[i] + s.r[j];
      c += dx * dx + dy * dy < rs * rs;
    }
    return c;
  }
};
using Flat = FlatT<false>;
using FlatRsqrt = FlatT<true>;

// ---------------------------------------------------------------- Scalar
struct alignas(16) Particle {
  double x, y, vx, vy, om, r;
};
struct Coef {
  double ca_t, cb_t, ca_r, cb_r;
};

struct Scalar {
  int n;
  double dt, kn, kt, mu, skin, r_min;
  std::vector<Particle> p;
  std::vector<Coef> c;
  std::vector<double> th, xb, yb;
  std::vector<double> f;  // fx, fy, tq interleaved (3 per particle)
  std::vector<int> start, nbr;
  std::vector<double> ft;
  double wall[4], vtop, kw;
  std::vector<uint8_t> mask;
  double max_overlap = 0;
  explicit Scalar(const State0& s)
      : n(s.n), dt(s.dt), kn(s.kn), kt(s.kt), mu(s.mu), skin(s.skin), r_min(s.r_min),
        wall{s.wall[0], s.wall[1], s.wall[2], s.wall[3]}, vtop(s.vtop), kw(s.kw),
        mask(s.wall_mask) {
    for (int i = 0; i < n; ++i) {
      p.push_back({s.x[i], s.y[i], s.vx[i], s.vy[i], s.om[i], s.r[i]});
      c.push_back({s.ca_t[i], s.cb_t[i], s.ca_r[i], s.cb_r[i]});
    }
    th = s.th;
    xb = s.x;
    yb = s.y;
    f.assign(3 * static_cast<size_t>(n), 0.0);
    start.assign(n + 1, 0);
    for (int i : s.pi) ++start[i + 1];
    for (int i = 0; i < n; ++i) start[i + 1] += start[i];
    nbr = s.pj;
    ft = s.ft;
  }
  void forces() {
    Particle* __restrict P = p.data();
    double* __restrict F = f.data();
    double* __restrict T = ft.data();
    const int* __restrict S = start.data();
    const int* __restrict J = nbr.data();
    const double kdt = kt * dt;
    double mo = 0;
    for (int i = 0; i < n; ++i) {
      const Particle a = P[i];
      double sx = 0, sy = 0, st = 0;
      if (mask[i]) wall_force(wall, kw, mask[i], a.x, a.y, a.r, sx, sy);
      for (int k = S[i]; k < S[i + 1]; ++k) {
        const Particle& b = P[J[k]];
        const double dx = b.x - a.x, dy = b.y - a.y;
        const double d2 = dx * dx + dy * dy, rsum = a.r + b.r;
        if (d2 >= rsum * rsum) {
          T[k] = 0;
          continue;
        }
        const double d = std::sqrt(d2), inv = 1.0 / d;
        const double ex = dx * inv, ey = dy * inv;
        const double ov = rsum - d;
        const double ai = a.r - 0.5 * ov, aj = b.r - 0.5 * ov;
        mo = std::max(mo, ov);
        const double fn = kn * ov;
        const double vt = -(b.vx - a.vx) * ey + (b.vy - a.vy) * ex - b.om * aj - a.om * ai;
        const double cap = mu * fn;
        const double t = std::clamp(T[k] + kdt * vt, -cap, cap);
        T[k] = t;
        const double fxi = -fn * ex - t * ey, fyi = -fn * ey + t * ex;
        sx += fxi;
        sy += fyi;
        st += ai * t;
        double* fj = F + 3 * static_cast<size_t>(J[k]);
        fj[0] -= fxi;
        fj[1] -= fyi;
        fj[2] += aj * t;
      }
      F[3 * i] += sx;
      F[3 * i + 1] += sy;
      F[3 * i + 2] += st;
    }
    max_overlap = mo / r_min;
  }
  bool step() {
    Particle* __restrict P = p.data();
    double* __restrict F = f.data();
    const Coef* __restrict C = c.data();
    wall[3] += vtop * dt;
    double md2 = 0;
    for (int i = 0; i < n; ++i) {
      Particle& a = P[i];
      a.vx = C[i].ca_t * a.vx + C[i].cb_t * F[3 * i];
      a.vy = C[i].ca_t * a.vy + C[i].cb_t * F[3 * i + 1];
      a.om = C[i].ca_r * a.om + C[i].cb_r * F[3 * i + 2];
      a.x += a.vx * dt;
      a.y += a.vy * dt;
      th[i] += a.om * dt;
      F[3 * i] = F[3 * i + 1] = F[3 * i + 2] = 0.0;
      const double dx = a.x - xb[i], dy = a.y - yb[i];
      md2 = std::max(md2, dx * dx + dy * dy);
    }
    forces();
    return 2.0 * std::sqrt(md2) < skin;
  }
  int contacts() const {
    int cnt = 0;
    for (int i = 0; i < n; ++i)
      for (int k = start[i]; k < start[i + 1]; ++k) {
        const Particle &a = p[i], &b = p[nbr[k]];
        const double dx = b.x - a.x, dy = b.y - a.y, rs = a.r + b.r;
        cnt += dx * dx + dy * dy < rs * rs;
      }
    return cnt;
  }
};

// ---------------------------------------------------------------- TwoPass
struct TwoPass {
  int n;
  size_t np;
  double dt, kn, kt, mu, skin, r_min;
  std::vector<double> x, y, vx, vy, om, th, r, xb, yb;
  std::vector<Coef> c;
  std::vector<int> pi, pj;
  std::vector<double> ft, pfx, pfy, pti, ptj;  // per-pair outputs
  // Incident pairs per particle: as first member (+) and as second (−).
  std::vector<int> s1, l1, s2, l2;
  double wall[4], vtop, kw;
  std::vector<uint8_t> mask;
  double max_overlap = 0;
  explicit TwoPass(const State0& s)
      : n(s.n), np(s.pi.size()), dt(s.dt), kn(s.kn), kt(s.kt), mu(s.mu), skin(s.skin),
        r_min(s.r_min), wall{s.wall[0], s.wall[1], s.wall[2], s.wall[3]}, vtop(s.vtop),
        kw(s.kw), mask(s.wall_mask) {
    x = s.x;
    y = s.y;
    vx = s.vx;
    vy = s.vy;
    om = s.om;
    th = s.th;
    r = s.r;
    xb = s.x;
    yb = s.y;
    for (int i = 0; i < n; ++i) c.push_back({s.ca_t[i], s.cb_t[i], s.ca_r[i], s.cb_r[i]});
    pi = s.pi;
    pj = s.pj;
    ft = s.ft;
    pfx.assign(np, 0);
    pfy.assign(np, 0);
    pti.assign(np, 0);
    ptj.assign(np, 0);
    s1.assign(n + 1, 0);
    s2.assign(n + 1, 0);
    for (size_t k = 0; k < np; ++k) {
      ++s1[pi[k] + 1];
      ++s2[pj[k] + 1];
    }
    for (int i = 0; i < n; ++i) {
      s1[i + 1] += s1[i];
      s2[i + 1] += s2[i];
    }
    l1.resize(np);
    l2.resize(np);
    std::vector<int> o1(s1.begin(), s1.end() - 1), o2(s2.begin(), s2.end() - 1);
    for (size_t k = 0; k < np; ++k) {
      l1[o1[pi[k]]++] = static_cast<int>(k);
      l2[o2[pj[k]]++] = static_cast<int>(k);
    }
  }
  // Pass 1: branch-free per-pair forces (scalar form; the AVX2 form below
  // does the same four pairs at a time with gathers).
  double pair_pass_scalar(size_t k0 = 0) {
    const int* __restrict I = pi.data();
    const int* __restrict J = pj.data();
    const double *__restrict X = x.data(), *__restrict Y = y.data(), *__restrict R = r.data();
    const double *__restrict VX = vx.data(), *__restrict VY = vy.data(), *__restrict OM = om.data();
    double* __restrict T = ft.data();
    double *__restrict FX = pfx.data(), *__restrict FY = pfy.data();
    double *__restrict TI = pti.data(), *__restrict TJ = ptj.data();
    const double kdt = kt * dt;
    double mo = 0;
    for (size_t k = k0; k < np; ++k) {
      const int i = I[k], j = J[k];
      const double dx = X[j] - X[i], dy = Y[j] - Y[i];
      const double d2 = dx * dx + dy * dy, rsum = R[i] + R[j];
      const double d = std::sqrt(d2);
      const double inv = 1.0 / d;
      const double ov = std::max(rsum - d, 0.0);  // 0 when apart: every force 0
      const double ex = dx * inv, ey = dy * inv;
      const double ai = R[i] - 0.5 * ov, aj = R[j] - 0.5 * ov;
      mo = std::max(mo, ov);
      const double fn = kn * ov;
      const double vt = -(VX[j] - VX[i]) * ey + (VY[j] - VY[i]) * ex - OM[j] * aj - OM[i] * ai;
      const double cap = mu * fn;
      const double t = std::min(std::max(T[k] + kdt * vt, -cap), cap);  // 0 when apart
      T[k] = t;
      FX[k] = -fn * ex - t * ey;
      FY[k] = -fn * ey + t * ex;
      TI[k] = ai * t;
      TJ[k] = aj * t;
    }
    return mo;
  }
// GCC 12 warns about the undefined source operand of its own gather intrinsic.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  __attribute__((target("avx2,fma"))) double pair_pass_avx2() {
    const int* __restrict I = pi.data();
    const int* __restrict J = pj.data();
    const double *__restrict X = x.data(), *__restrict Y = y.data(), *__restrict R = r.data();
    const double *__restrict VX = vx.data(), *__restrict VY = vy.data(), *__restrict OM = om.data();
    double* __restrict T = ft.data();
    double *__restrict FX = pfx.data(), *__restrict FY = pfy.data();
    double *__restrict TI = pti.data(), *__restrict TJ = ptj.data();
    const __m256d zero = _mm256_setzero_pd(), half = _mm256_set1_pd(0.5),
                  one = _mm256_set1_pd(1.0), vkn = _mm256_set1_pd(kn), vmu = _mm256_set1_pd(mu),
                  vkdt = _mm256_set1_pd(kt * dt);
    __m256d vmo = zero;
    size_t k = 0;
    for (; k + 4 <= np; k += 4) {
      const __m128i vi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(I + k));
      const __m128i vj = _mm_loadu_si128(reinterpret_cast<const __m128i*>(J + k));
      const __m256d dx = _mm256_sub_pd(_mm256_i32gather_pd(X, vj, 8), _mm256_i32gather_pd(X, vi, 8));
      const __m256d dy = _mm256_sub_pd(_mm256_i32gather_pd(Y, vj, 8), _mm256_i32gather_pd(Y, vi, 8));
      const __m256d ri = _mm256_i32gather_pd(R, vi, 8), rj = _mm256_i32gather_pd(R, vj, 8);
      const __m256d d = _mm256_sqrt_pd(_mm256_fmadd_pd(dx, dx, _mm256_mul_pd(dy, dy)));
      const __m256d inv = _mm256_div_pd(one, d);
      const __m256d ov = _mm256_max_pd(_mm256_sub_pd(_mm256_add_pd(ri, rj), d), zero);
      const __m256d ex = _mm256_mul_pd(dx, inv), ey = _mm256_mul_pd(dy, inv);
      const __m256d ai = _mm256_fnmadd_pd(half, ov, ri), aj = _mm256_fnmadd_pd(half, ov, rj);
      vmo = _mm256_max_pd(vmo, ov);
      const __m256d fn = _mm256_mul_pd(vkn, ov);
      const __m256d dvx = _mm256_sub_pd(_mm256_i32gather_pd(VX, vj, 8), _mm256_i32gather_pd(VX, vi, 8));
      const __m256d dvy = _mm256_sub_pd(_mm256_i32gather_pd(VY, vj, 8), _mm256_i32gather_pd(VY, vi, 8));
      const __m256d omi = _mm256_i32gather_pd(OM, vi, 8), omj = _mm256_i32gather_pd(OM, vj, 8);
      // vt = −dvx·ey + dvy·ex − ω_j·a_j − ω_i·a_i
      __m256d vt = _mm256_fmsub_pd(dvy, ex, _mm256_mul_pd(dvx, ey));
      vt = _mm256_fnmadd_pd(omj, aj, vt);
      vt = _mm256_fnmadd_pd(omi, ai, vt);
      const __m256d cap = _mm256_mul_pd(vmu, fn);
      const __m256d ncap = _mm256_sub_pd(zero, cap);
      __m256d t = _mm256_fmadd_pd(vkdt, vt, _mm256_loadu_pd(T + k));
      t = _mm256_min_pd(_mm256_max_pd(t, ncap), cap);
      _mm256_storeu_pd(T + k, t);
      // FX = −fn·ex − t·ey, FY = −fn·ey + t·ex
      _mm256_storeu_pd(FX + k, _mm256_fnmadd_pd(fn, ex, _mm256_mul_pd(_mm256_sub_pd(zero, t), ey)));
      _mm256_storeu_pd(FY + k, _mm256_fmsub_pd(t, ex, _mm256_mul_pd(fn, ey)));
      _mm256_storeu_pd(TI + k, _mm256_mul_pd(ai, t));
      _mm256_storeu_pd(TJ + k, _mm256_mul_pd(aj, t));
    }
    alignas(32) double m4[4];
    _mm256_store_pd(m4, vmo);
    const double mo = std::max({m4[0], m4[1], m4[2], m4[3]});
    return std::max(mo, pair_pass_scalar(k));
  }
#pragma GCC diagnostic pop

  // Pass 2: per particle, gather the forces of its pairs, integrate.
  double gather_integrate() {
    const int *__restrict S1 = s1.data(), *__restrict L1 = l1.data();
    const int *__restrict S2 = s2.data(), *__restrict L2 = l2.data();
    const double *__restrict FX = pfx.data(), *__restrict FY = pfy.data();
    const double *__restrict TI = pti.data(), *__restrict TJ = ptj.data();
    const Coef* __restrict C = c.data();
    double md2 = 0;
    for (int i = 0; i < n; ++i) {
      double sx = 0, sy = 0, st = 0;
      for (int e = S1[i]; e < S1[i + 1]; ++e) {
        const int k = L1[e];
        sx += FX[k];
        sy += FY[k];
        st += TI[k];
      }
      for (int e = S2[i]; e < S2[i + 1]; ++e) {
        const int k = L2[e];
        sx -= FX[k];
        sy -= FY[k];
        st += TJ[k];
      }
      if (mask[i]) wall_force(wall, kw, mask[i], x[i], y[i], r[i], sx, sy);
      vx[i] = C[i].ca_t * vx[i] + C[i].cb_t * sx;
      vy[i] = C[i].ca_t * vy[i] + C[i].cb_t * sy;
      om[i] = C[i].ca_r * om[i] + C[i].cb_r * st;
      x[i] += vx[i] * dt;
      y[i] += vy[i] * dt;
      th[i] += om[i] * dt;
      const double dx = x[i] - xb[i], dy = y[i] - yb[i];
      md2 = std::max(md2, dx * dx + dy * dy);
    }
    wall[3] += vtop * dt;
    return md2;
  }
  bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  void forces() { max_overlap = (avx2 ? pair_pass_avx2() : pair_pass_scalar()) / r_min; }
  bool step() {
    const double md2 = gather_integrate();
    forces();
    return 2.0 * std::sqrt(md2) < skin;
  }
  int contacts() const {
    int c = 0;
    for (size_t k = 0; k < np; ++k) {
      const int i = pi[k], j = pj[k];
      const double dx = x[j] - x[i], dy = y[j] - y[i], rs = r[i] + r[j];
      c += dx * dx + dy * dy < rs * rs;
    }
    return c;
  }
  // Net forces (for the cross-check).
  void net(std::vector<double>& fx, std::vector<double>& fy, std::vector<double>& tq) const {
    fx.assign(n, 0);
    fy.assign(n, 0);
    tq.assign(n, 0);
    for (size_t k = 0; k < np; ++k) {
      fx[pi[k]] += pfx[k];
      fy[pi[k]] += pfy[k];
      tq[pi[k]] += pti[k];
      fx[pj[k]] -= pfx[k];
      fy[pj[k]] -= pfy[k];
      tq[pj[k]] += ptj[k];
    }
    for (int i = 0; i < n; ++i)
      if (mask[i]) wall_force(wall, kw, mask[i], x[i], y[i], r[i], fx[i], fy[i]);
  }
};

// Cross-check: the three forms give the same forces on the first evaluation
// (with dt = 0 the tangential increment is not applied twice).
bool cross_check(const State0& s0, double& err) {
  State0 s = s0;
  s.dt = 0.0;
  Baseline b(s);
  Flat fl(s);
  Scalar sc(s);
  TwoPass tp(s);
  b.forces();
  fl.forces();
  sc.forces();
  tp.forces();
  std::vector<double> fx, fy, tq;
  tp.net(fx, fy, tq);
  double scale = 0;
  err = 0;
  for (int i = 0; i < s.n; ++i) {
    scale = std::max({scale, std::abs(b.fx[i]), std::abs(b.fy[i])});
    err = std::max({err, std::abs(b.fx[i] - fl.fx[i]), std::abs(b.fy[i] - fl.fy[i]),
                    std::abs(b.tq[i] - fl.tq[i]) / s.r_min});
    err = std::max({err, std::abs(b.fx[i] - sc.f[3 * i]), std::abs(b.fy[i] - sc.f[3 * i + 1]),
                    std::abs(b.fx[i] - fx[i]), std::abs(b.fy[i] - fy[i])});
    err = std::max({err, std::abs(b.tq[i] - sc.f[3 * i + 2]) / s.r_min,
                    std::abs(b.tq[i] - tq[i]) / s.r_min});
  }
  err /= std::max(scale, 1e-300);
  return err < 1e-9;
}

template <class Impl>
void run(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const State0 s0 = make_state(side);
  double err = 0;
  if (!cross_check(s0, err)) {
    char msg[128];
    std::snprintf(msg, sizeof msg, "prototypes disagree: relative error %.3g", err);
    state.SkipWithError(msg);
    return;
  }
  // Restart from the pre-loaded state (outside the timing) every kMaxSteps
  // steps: the list is never rebuilt, so stay well inside its validity.
  constexpr int64_t kMaxSteps = 20'000;
  auto impl = std::make_unique<Impl>(s0);
  impl->forces();
  const int64_t chunk = std::min<int64_t>(kMaxSteps, std::max<int64_t>(32, 4'000'000 / s0.n));
  int64_t steps = 0, invalid = 0, since = 0;
  for (auto _ : state) {
    if (since + chunk > kMaxSteps) {
      state.PauseTiming();
      impl = std::make_unique<Impl>(s0);
      impl->forces();
      since = 0;
      state.ResumeTiming();
    }
    for (int64_t k = 0; k < chunk; ++k) invalid += impl->step() ? 0 : 1;
    steps += chunk;
    since += chunk;
  }
  benchmark::DoNotOptimize(impl->max_overlap);
  state.counters["contacts"] = static_cast<double>(impl->contacts());
  state.counters["particle_steps/s"] = benchmark::Counter(
      static_cast<double>(s0.n) * static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["pairs/particle"] = static_cast<double>(s0.pi.size()) / s0.n;
  state.counters["list_expired_steps"] = static_cast<double>(invalid);
}

void BM_ProtoBaseline(benchmark::State& st) { run<Baseline>(st); }
void BM_ProtoFlat(benchmark::State& st) { run<Flat>(st); }
void BM_ProtoFlatRsqrt(benchmark::State& st) {
  if (!__builtin_cpu_supports("avx512f")) {
    st.SkipWithError("needs AVX-512F");
    return;
  }
  run<FlatRsqrt>(st);
}
void BM_ProtoScalar(benchmark::State& st) { run<Scalar>(st); }
void BM_ProtoTwoPass(benchmark::State& st) { run<TwoPass>(st); }
#define PROTO_ARGS \
  ArgName("side")->Arg(10)->Arg(20)->Arg(100)->Arg(316)->MinTime(1.0)->UseRealTime()->Unit(benchmark::kMillisecond)
BENCHMARK(BM_ProtoBaseline)->PROTO_ARGS;
BENCHMARK(BM_ProtoFlat)->PROTO_ARGS;
BENCHMARK(BM_ProtoFlatRsqrt)->PROTO_ARGS;
BENCHMARK(BM_ProtoScalar)->PROTO_ARGS;
BENCHMARK(BM_ProtoTwoPass)->PROTO_ARGS;

}  // namespace

BENCHMARK_MAIN();
