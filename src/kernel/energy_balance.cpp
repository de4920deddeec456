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
// only makes the reading a lower bound. The rates of the walls' work and of
// the global damping are sampled every KernelOptions::energy_check_interval
// steps and integrated with the trapezoidal rule; the contact dashpots'
// dissipation lives in contact vibrations a few steps long, which such
// samples would alias, so it is summed every step (WorldImpl::dashpot_power). Measured readings of
// stable runs (hex 5×5, 10×10, 20×20, random 400; ζ from 0 to 4; 10³ to 10⁵ steps) stay below
// 0.012; rattles pass 0.1 within a few hundred to a few thousand steps.
#include <algorithm>
#include <cmath>

#include "contact_law.hpp"
#include "divergence.hpp"
#include "world_impl.hpp"

namespace demcal {

WorldImpl::EnergySample WorldImpl::energy_sample() const {
  EnergySample e;
  const int n = size();
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  const bool rotation = !integration_.lock_rotation;

  // Kinetic energy and global (mass-proportional) damping: D_t|v|² + D_r ω²,
  // with the coefficients of update_damping_coefficients().
  for (int i = 0; i < n; ++i) {
    const double v2 = vx_[i] * vx_[i] + vy_[i] * vy_[i];
    const double w2 = rotation ? omega_[i] * omega_[i] : 0.0;
    e.energy += 0.5 * (m_[i] * v2 + inertia_[i] * w2);
    const double dt_coef =
        integration_.damping_ratio_translation * critical_damping_translation(kn, m_[i]);
    const double dr_coef =
        integration_.damping_ratio_rotation * critical_damping_rotation(kt, r_[i], inertia_[i]);
    e.power_lost += dt_coef * v2 + dr_coef * w2;
  }

  // Pairs: the energy of both springs, by the contact law (contact_law.hpp).
  // (The contact dashpots' dissipation is summed every step: dashpot_power().)
  for (size_t k = 0; k < pair_i_.size(); ++k) {
    const PairState p = pair_state(pair_i_[k], pair_j_[k]);
    if (!p.touching) continue;
    e.elastic +=
        law::spring_energy(p.fn_elastic, kn) + law::spring_energy(slot_ft_[pair_slot_[k]], kt);
  }

  // Walls: spring energy.
  const double kw = material_.wall.kn, ktw = material_.wall.kt;
  for (int s = 0; s < 4; ++s) {
    const Wall& wall = walls_[s];
    const double gx = law::kWallNormal[s][0], gy = law::kWallNormal[s][1];
    const bool vertical = (s == kLeft || s == kRight);
    for (int i : wall_candidates_[s]) {
      const double dist = vertical ? (x_[i] - wall.position) * gx : (y_[i] - wall.position) * gy;
      const double ov = r_[i] - dist;
      if (ov <= 0.0) continue;
      e.elastic += law::spring_energy(law::elastic_normal_force(kw, ov), kw) +
                   law::spring_energy(wall_ft_[s][i], ktw);
    }
  }
  e.power_in = wall_power();
  e.energy += e.elastic;
  return e;
}
double WorldImpl::wall_power() const {
  double power = 0.0;
  for (int s = 0; s < 4; ++s) {
    const Wall& wall = walls_[s];
    const bool vertical = (s == kLeft || s == kRight);
    // wall.force is the particles' force on the wall; the wall's on them is −force.
    power -= (vertical ? wall.force.x() : wall.force.y()) * wall.velocity;
  }
  return power;
}

bool WorldImpl::ledger_record(const EnergySample& e) {
  Ledger& l = ledger_;
  if (detail::ledger_start(l, steps_, e.energy)) {
    l.power_in = e.power_in;
    l.power_lost = e.power_lost;
    return false;
  }
  const double h = static_cast<double>(steps_ - l.step) * integration_.dt;
  l.work += 0.5 * (l.power_in + e.power_in) * h;
  l.lost += 0.5 * (l.power_lost + e.power_lost) * h;
  l.power_in = e.power_in;
  l.power_lost = e.power_lost;
  return detail::ledger_read(l, steps_, e.energy, l.work, l.lost + l.dashpot, options_,
                             divergence_);
}

}  // namespace demcal
