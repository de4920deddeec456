// The energy ledger of the divergence check.
//
// A time step beyond the stable one does not always blow up: when the
// unstable mode (on the hexagonal REVs, the rotational one) makes contacts
// slide, or damping takes its energy away, it settles into a bounded rattle
// that the kinetic-energy and overlap checks never see (measured on
// hex_10x10: stable at α = 0.29, a rattle from α = 0.295 to 0.45, blow-up
// only beyond; the estimate from the stiffnesses is 0.292). Such a run
// creates energy, step after step. For the continuous system
//
//   E(t) − E(0) = W_walls − D_damping − D_friction,  both D ≥ 0,
//
// so E − E(0) − W + D_damping ≥ D_friction ≥ 0 by physics, and anything
// above 0 is energy the integrator made. Friction is left out on purpose:
// its rate |ft·vt| sampled at one step over-counts on vibrating contacts
// (an undamped stable run read as creating energy), while leaving it out
// only makes the reading a lower bound. Rates are sampled every
// KernelOptions::energy_check_interval steps and integrated with the
// trapezoidal rule. Measured readings of stable runs (hex 5×5, 10×10,
// 20×20, random 400; ζ from 0 to 4; 10³ to 10⁵ steps) stay below 0.012;
// rattles pass 0.1 within a few hundred to a few thousand steps.
#include <algorithm>
#include <cmath>

#include "demcal/kernel/world.hpp"

namespace demcal {

namespace {

// Inward unit normals of the walls (left, right, bottom, top), as in contact.cpp.
constexpr double kWallNormal[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};

}  // namespace

World::EnergySample World::energy_sample() const {
  EnergySample e;
  const int n = size();
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  const double beta2 = 2.0 * material_.contact_damping_ratio;
  const bool rotation = !integration_.lock_rotation;

  // Kinetic energy and global (mass-proportional) damping: D_t|v|² + D_r ω²,
  // with the coefficients of update_damping_coefficients().
  for (int i = 0; i < n; ++i) {
    const double v2 = vx_[i] * vx_[i] + vy_[i] * vy_[i];
    const double w2 = rotation ? omega_[i] * omega_[i] : 0.0;
    e.energy += 0.5 * (m_[i] * v2 + inertia_[i] * w2);
    const double dt_coef = integration_.damping_ratio_translation * 2.0 * std::sqrt(kn * m_[i]);
    const double dr_coef =
        integration_.damping_ratio_rotation * 2.0 * std::sqrt(kt * r_[i] * r_[i] * inertia_[i]);
    e.power_lost += dt_coef * v2 + dr_coef * w2;
  }

  // Pairs: spring energy and contact damping (the non-elastic part of fn
  // times the separation speed), with the contact law's formulas (contact.cpp).
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const int i = pair_i_[k], j = pair_j_[k];
    const double dx = x_[j] - x_[i], dy = y_[j] - y_[i];
    const double d2 = dx * dx + dy * dy;
    const double rs = r_[i] + r_[j];
    if (!(d2 < rs * rs)) continue;
    const double d = std::sqrt(d2);
    const double nx = dx / d, ny = dy / d;
    const double ov = rs - d;
    const double dvx = vx_[j] - vx_[i], dvy = vy_[j] - vy_[i];
    const double vn = dvx * nx + dvy * ny;  // > 0 when separating
    const double fn_elastic = kn * ov;
    double fn = fn_elastic;
    if (beta2 > 0.0) {
      const double meff = m_[i] * m_[j] / (m_[i] + m_[j]);
      fn = std::max(0.0, fn - beta2 * std::sqrt(kn * meff) * vn);
    }
    const double ft = slot_ft_[pair_slot_[k]];
    e.elastic += 0.5 * fn_elastic * ov + (kt > 0.0 ? 0.5 * ft * ft / kt : 0.0);
    e.power_lost += (fn_elastic - fn) * vn;
  }

  // Walls: spring energy, the work rate of the moving walls and their
  // contact damping (wall_pass's formulas).
  const double kw = material_.wall.kn, ktw = material_.wall.kt;
  const double beta = material_.contact_damping_ratio;
  for (int s = 0; s < 4; ++s) {
    const Wall& wall = walls_[s];
    const double gx = kWallNormal[s][0], gy = kWallNormal[s][1];
    const bool vertical = (s == kLeft || s == kRight);
    const double wvx = vertical ? wall.velocity : 0.0, wvy = vertical ? 0.0 : wall.velocity;
    // wall.force is the particles' force on the wall; the wall's on them is −force.
    e.power_in -= (vertical ? wall.force.x() : wall.force.y()) * wall.velocity;
    for (int i : wall_candidates_[s]) {
      const double dist = vertical ? (x_[i] - wall.position) * gx : (y_[i] - wall.position) * gy;
      const double ov = r_[i] - dist;
      if (ov <= 0.0) continue;
      const double dvx = wvx - vx_[i], dvy = wvy - vy_[i];
      const double vn = -(dvx * gx + dvy * gy);  // particle leaving the wall > 0
      const double fn_elastic = kw * ov;
      const double fn = wall_fn_[s][i];
      const double ft = wall_ft_[s][i];
      e.elastic += 0.5 * fn_elastic * ov + (ktw > 0.0 ? 0.5 * ft * ft / ktw : 0.0);
      if (beta > 0.0) e.power_lost += (fn_elastic - fn) * vn;
    }
  }
  e.energy += e.elastic;
  return e;
}

bool World::ledger_due() const {
  return !ledger_.started || steps_ - ledger_.step >= std::max(1, options_.energy_check_interval);
}

bool World::ledger_record(const EnergySample& e) {
  Ledger& l = ledger_;
  if (!l.started) {
    l = {};
    l.started = true;
    l.step = steps_;
    l.energy0 = e.energy;
    l.power_in = e.power_in;
    l.power_lost = e.power_lost;
    return false;
  }
  const double h = static_cast<double>(steps_ - l.step) * integration_.dt;
  l.work += 0.5 * (l.power_in + e.power_in) * h;
  l.lost += 0.5 * (l.power_lost + e.power_lost) * h;
  l.power_in = e.power_in;
  l.power_lost = e.power_lost;
  l.step = steps_;
  const double created = e.energy - l.energy0 - l.work + l.lost;
  const double scale = l.energy0 + std::abs(l.work) + l.lost;
  l.created = scale > 0.0 ? created / scale : 0.0;
  if (std::isfinite(l.created) && l.created <= options_.max_energy_created) return false;
  divergence_ = Divergence::kEnergyCreated;
  return true;
}

}  // namespace demcal
