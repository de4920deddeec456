// Contact law (DESIGN.md §2): linear normal spring kn·δ; incremental
// tangential spring kt capped by Coulomb μ·Fn. The tangential force is kept
// as a scalar along the contact tangent t = (−n_y, n_x), so it turns with the
// contact as the pair rolls around itself.
//
// Contact point: x^c = x_i + (r_i − δ/2)·n, the middle of the overlap. The
// same lever arms enter the torques and the stress, so a moment-free particle
// contributes a symmetric term to σ exactly.
#include <algorithm>
#include <cmath>

#include "demcal/world.hpp"

namespace demcal {

namespace {

struct WallGeometry {
  double nx, ny;  // inward unit normal
};
constexpr WallGeometry kWallGeometry[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};

}  // namespace

void World::compute_forces() {
  const int n = size();
  std::fill(fx_.begin(), fx_.end(), 0.0);
  std::fill(fy_.begin(), fy_.end(), 0.0);
  std::fill(tq_.begin(), tq_.end(), 0.0);
  const double dt = integration_.dt;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  const double mu = material_.particle.friction;
  const double beta = material_.contact_damping_ratio;
  double max_overlap = 0.0;

  const size_t np = pair_i_.size();
  for (size_t k = 0; k < np; ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const double dx = x_[j] - x_[i], dy = y_[j] - y_[i];
    const double d2 = dx * dx + dy * dy;
    const double rsum = r_[i] + r_[j];
    if (d2 >= rsum * rsum) {
      pair_ft_[k] = 0.0;
      pair_fn_[k] = 0.0;
      continue;
    }
    const double d = std::sqrt(d2);
    const double nx = dx / d, ny = dy / d;
    const double tx = -ny, ty = nx;
    const double overlap = rsum - d;
    const double ai = r_[i] - 0.5 * overlap, aj = r_[j] - 0.5 * overlap;
    max_overlap = std::max(max_overlap, overlap / std::min(r_[i], r_[j]));
    const double dvx = vx_[j] - vx_[i], dvy = vy_[j] - vy_[i];
    double fn = kn * overlap;
    if (beta > 0.0) {
      const double meff = m_[i] * m_[j] / (m_[i] + m_[j]);
      const double vn = dvx * nx + dvy * ny;  // > 0 when separating
      fn = std::max(0.0, fn - beta * 2.0 * std::sqrt(kn * meff) * vn);
    }
    // Tangential velocity of j's contact point relative to i's.
    const double vt = dvx * tx + dvy * ty - omega_[j] * aj - omega_[i] * ai;
    double ft = pair_ft_[k] + kt * vt * dt;
    const double cap = mu * fn;
    ft = std::clamp(ft, -cap, cap);
    pair_ft_[k] = ft;
    pair_fn_[k] = fn;
    pair_nx_[k] = nx;
    pair_ny_[k] = ny;
    // Force on i: −fn·n + ft·t; on j the opposite.
    const double fxi = -fn * nx + ft * tx, fyi = -fn * ny + ft * ty;
    fx_[i] += fxi;
    fy_[i] += fyi;
    fx_[j] -= fxi;
    fy_[j] -= fyi;
    tq_[i] += ai * ft;
    tq_[j] += aj * ft;
  }

  // Walls. Contact point on the wall line; lever arm = distance to the wall.
  const double kw = material_.wall.kn, ktw = material_.wall.kt, muw = material_.wall.friction;
  for (int s = 0; s < 4; ++s) {
    Wall& wall = walls_[s];
    const auto g = kWallGeometry[s];
    const double tx = -g.ny, ty = g.nx;
    const bool vertical = (s == kLeft || s == kRight);
    const double wvx = vertical ? wall.velocity : 0.0, wvy = vertical ? 0.0 : wall.velocity;
    double wfx = 0.0, wfy = 0.0;
    int count = 0;
    double* hist = wall_ft_[s].data();
    double* hist_fn = wall_fn_[s].data();
    for (int i : wall_candidates_[s]) {
      // Signed distance from the wall line to the centre, along the inward normal.
      const double dist =
          vertical ? (x_[i] - wall.position) * g.nx : (y_[i] - wall.position) * g.ny;
      const double overlap = r_[i] - dist;
      if (overlap <= 0.0) {
        hist[i] = 0.0;
        hist_fn[i] = 0.0;
        continue;
      }
      ++count;
      max_overlap = std::max(max_overlap, overlap / r_[i]);
      double fn = kw * overlap;
      const double dvx = wvx - vx_[i], dvy = wvy - vy_[i];  // wall relative to particle
      if (beta > 0.0) {
        const double vn = -(dvx * g.nx + dvy * g.ny);  // particle leaving the wall > 0
        fn = std::max(0.0, fn - beta * 2.0 * std::sqrt(kw * m_[i]) * vn);
      }
      // Particle contact point moves with v − ω·dist·t (arm = −dist·n).
      const double vt = dvx * tx + dvy * ty + omega_[i] * dist;
      double ft = hist[i] + ktw * vt * dt;
      const double cap = muw * fn;
      ft = std::clamp(ft, -cap, cap);
      hist[i] = ft;
      hist_fn[i] = fn;
      const double fxi = fn * g.nx + ft * tx, fyi = fn * g.ny + ft * ty;
      fx_[i] += fxi;
      fy_[i] += fyi;
      tq_[i] += -dist * ft;
      wfx -= fxi;
      wfy -= fyi;
    }
    wall.force = Eigen::Vector2d(wfx, wfy);
    wall.contacts = count;
  }
  (void)n;
  max_overlap_ratio_seen_ = max_overlap;
}

}  // namespace demcal
