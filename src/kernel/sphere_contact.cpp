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
// Walls: the inward normal g is fixed and the wall does not rotate, so a
// wall history stays in the wall plane with no turning; the contact point is
// the foot of the centre on the plane (lever arm −dist·g).
#include <algorithm>
#include <cmath>

#include "demcal/kernel/sphere_world.hpp"

namespace demcal {

namespace {
using V3 = Eigen::Vector3d;

/// Turn a tangential history h onto the plane normal to the unit vector n
/// (projection rescaled to the former length), then about n by `twist`.
V3 turn_history(const V3& h, const V3& n, double twist) {
  const double mag2 = h.squaredNorm();
  if (mag2 == 0.0) return h;
  V3 p = h - h.dot(n) * n;
  const double p2 = p.squaredNorm();
  if (p2 == 0.0) return V3::Zero();  // h along the new normal: no direction left
  p *= std::sqrt(mag2 / p2);
  if (twist != 0.0) {
    // Rotation about n by 2·atan(twist/2) (Cayley form: exactly a rotation,
    // length kept, the angle off by twist³/12 — far below the O(ΩΔt)² per
    // step of the scheme — and no trigonometric call per contact).
    const double c = 0.5 * twist, q = 1.0 / (1.0 + c * c);
    p = p * ((1.0 - c * c) * q) + n.cross(p) * (2.0 * c * q);
  }
  return p;
}
}  // namespace

double SphereWorld::wall_distance(int s, int i) const {
  const double* pos[3] = {x_.data(), y_.data(), z_.data()};
  const double sign = (s % 2 == 0) ? 1.0 : -1.0;
  return (pos[s / 2][i] - walls_[s].position) * sign;
}

SphereWorld::PairGeometry SphereWorld::pair_geometry(int i, int j) const {
  PairGeometry p{};
  const V3 d(x_[j] - x_[i], y_[j] - y_[i], z_[j] - z_[i]);
  const double d2 = d.squaredNorm();
  const double rs = r_[i] + r_[j];
  p.touching = d2 < rs * rs;
  if (!p.touching) return p;
  const double dist = std::sqrt(d2);
  p.n = d / dist;
  p.overlap = rs - dist;
  const double kn = material_.particle.kn;
  double fn = kn * p.overlap;
  const double beta2 = 2.0 * material_.contact_damping_ratio;
  if (beta2 > 0.0) {
    const double meff = m_[i] * m_[j] / (m_[i] + m_[j]);
    const V3 dv(vx_[j] - vx_[i], vy_[j] - vy_[i], vz_[j] - vz_[i]);
    fn = std::max(0.0, fn - beta2 * std::sqrt(kn * meff) * dv.dot(p.n));
  }
  p.fn = fn;
  return p;
}

// flatten: pair_geometry (shared with the energy ledger) inlined here, the
// hot loop (it was a call per neighbour, a sixth of the step).
[[gnu::flatten]] void SphereWorld::pair_forces() {
  const double dt = integration_.dt;
  const double kt = material_.particle.kt, kdt = kt * dt, mu = material_.particle.friction;
  const double compliance = kt > 0.0 ? 1.0 / kt : 0.0, half_compliance = 0.5 * compliance;
  double max_overlap = 0.0, released = 0.0, slid = 0.0;
  for (int i = 0; i < n_; ++i) {
    const V3 vi(vx_[i], vy_[i], vz_[i]), wi(wx_[i], wy_[i], wz_[i]);
    V3 fi(fx_[i], fy_[i], fz_[i]), ti(tx_[i], ty_[i], tz_[i]);
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const int j = nbr_j_[k];
      const PairGeometry g = pair_geometry(i, j);
      if (!g.touching) {
        released += hx_[k] * hx_[k] + hy_[k] * hy_[k] + hz_[k] * hz_[k];
        hx_[k] = hy_[k] = hz_[k] = 0.0;
        continue;
      }
      const V3& n = g.n;
      const double ai = r_[i] - 0.5 * g.overlap, aj = r_[j] - 0.5 * g.overlap;
      const V3 wj(wx_[j], wy_[j], wz_[j]);
      const V3 vrel = V3(vx_[j], vy_[j], vz_[j]) - vi - (ai * wi + aj * wj).cross(n);
      const V3 vt = vrel - vrel.dot(n) * n;
      V3 h = turn_history(V3(hx_[k], hy_[k], hz_[k]), n, 0.5 * dt * n.dot(wi + wj));
      h += kdt * vt;
      const double cap = mu * g.fn, h2 = h.squaredNorm();
      if (h2 > cap * cap) {
        const double mag = std::sqrt(h2);
        slid += cap * (mag - cap);
        h *= cap / mag;
      }
      hx_[k] = h.x();
      hy_[k] = h.y();
      hz_[k] = h.z();
      const V3 f = -g.fn * n + h;  // on i
      const V3 nxh = n.cross(h);
      fi += f;
      ti += ai * nxh;
      fx_[j] -= f.x();
      fy_[j] -= f.y();
      fz_[j] -= f.z();
      tx_[j] += aj * nxh.x();
      ty_[j] += aj * nxh.y();
      tz_[j] += aj * nxh.z();
      max_overlap = std::max(max_overlap, g.overlap / std::min(r_[i], r_[j]));
    }
    fx_[i] = fi.x();
    fy_[i] = fi.y();
    fz_[i] = fi.z();
    tx_[i] = ti.x();
    ty_[i] = ti.y();
    tz_[i] = ti.z();
  }
  max_overlap_ratio_seen_ = max_overlap;
  friction_dissipated_ += released * half_compliance + slid * compliance;
}

void SphereWorld::wall_forces() {
  const double dt = integration_.dt;
  const double beta = material_.contact_damping_ratio;
  const double kw = material_.wall.kn, ktw_dt = material_.wall.kt * dt;
  const double muw = material_.wall.friction;
  const double compliance = material_.wall.kt > 0.0 ? 1.0 / material_.wall.kt : 0.0;
  const double half_compliance = 0.5 * compliance;
  double max_overlap = 0.0, released = 0.0, slid = 0.0;
  for (int s = 0; s < 6; ++s) {
    SphereWall& wall = walls_[s];
    const int axis = s / 2;
    V3 g = V3::Zero();
    g[axis] = (s % 2 == 0) ? 1.0 : -1.0;  // inward normal
    const V3 vw = wall.velocity * V3::Unit(axis);
    V3 wf = V3::Zero();
    int count = 0;
    for (int i : wall_candidates_[s]) {
      const double dist = wall_distance(s, i);
      const double overlap = r_[i] - dist;
      if (overlap <= 0.0) {
        released += wall_hx_[s][i] * wall_hx_[s][i] + wall_hy_[s][i] * wall_hy_[s][i] +
                    wall_hz_[s][i] * wall_hz_[s][i];
        wall_hx_[s][i] = wall_hy_[s][i] = wall_hz_[s][i] = 0.0;
        wall_fn_[s][i] = 0.0;
        continue;
      }
      ++count;
      max_overlap = std::max(max_overlap, overlap / r_[i]);
      // Wall relative to the particle's contact point (arm −dist·g).
      const V3 dv = vw - V3(vx_[i], vy_[i], vz_[i]) + dist * V3(wx_[i], wy_[i], wz_[i]).cross(g);
      double fn = kw * overlap;
      if (beta > 0.0) {
        const double vn = -dv.dot(g);  // particle leaving the wall > 0
        fn = std::max(0.0, fn - beta * 2.0 * std::sqrt(kw * m_[i]) * vn);
      }
      V3 h(wall_hx_[s][i], wall_hy_[s][i], wall_hz_[s][i]);
      h += ktw_dt * (dv - dv.dot(g) * g);
      const double cap = muw * fn, h2 = h.squaredNorm();
      if (h2 > cap * cap) {
        const double mag = std::sqrt(h2);
        slid += cap * (mag - cap);
        h *= cap / mag;
      }
      wall_hx_[s][i] = h.x();
      wall_hy_[s][i] = h.y();
      wall_hz_[s][i] = h.z();
      wall_fn_[s][i] = fn;
      const V3 f = fn * g + h;
      const V3 t = -dist * g.cross(h);
      fx_[i] += f.x();
      fy_[i] += f.y();
      fz_[i] += f.z();
      tx_[i] += t.x();
      ty_[i] += t.y();
      tz_[i] += t.z();
      wf -= f;
    }
    wall.force = wf;
    wall.contacts = count;
  }
  max_overlap_ratio_seen_ = std::max(max_overlap_ratio_seen_, max_overlap);
  friction_dissipated_ += released * half_compliance + slid * compliance;
}

void SphereWorld::compute_forces() {
  for (auto* a : {&fx_, &fy_, &fz_, &tx_, &ty_, &tz_}) std::fill(a->begin(), a->end(), 0.0);
  pair_forces();
  wall_forces();
}

}  // namespace demcal
