// The energy ledger of the sphere kernel's divergence check, the same
// bookkeeping as the 2D kernel's (energy_balance.cpp explains it): for the
// continuous system E(t) − E(0) = W_walls − D_damping − D_friction, so the
// reading E − E(0) − W + D_damping + D_friction is 0 up to the scheme's
// error, and a reading above KernelOptions::max_energy_created of the energy
// scale is energy the integrator made (a step beyond the stable one).
// Friction's loss is booked as the tangential spring energy given up to the
// Coulomb cap or at opening, summed every step (sphere_contact.cpp); left
// out (as the 2D ledger does), it reads as a deficit that hides created
// energy. The global damping's loss is summed every step, exactly
// (SphereWorldImpl::integrate), and so is the work of the moving walls
// (SphereWorldImpl::book_wall_work: sampled, it missed collisions shorter than
// the interval, and a wall throwing a resting sphere read as energy
// created), and so is the contact dashpots' loss, at the forces each step
// applies (SphereWorldImpl::step, as the 2D ledger does: sampled every
// energy_check_interval steps and integrated by the trapezoidal rule, a
// damped collision that began just before a sample booked the dashpot's
// initial power c·v² over the whole interval, and a lone bounce at
// α = 0.002 stopped as "energy created"). (Sampling the global damping
// too, as the 2D ledger does, overestimates the loss many times over when
// the kinetic energy decays within a sampling interval — a free sphere at
// ζ = 0.7, α = 0.1 read as creating energy.)
#include <algorithm>
#include <cmath>

#include "contact_law.hpp"
#include "divergence.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

SphereWorldImpl::EnergySample SphereWorldImpl::energy_sample() const {
  EnergySample e;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  const bool rotation = !integration_.lock_rotation;

  for (int i = 0; i < n_; ++i) {
    const double v2 = vx_[i] * vx_[i] + vy_[i] * vy_[i] + vz_[i] * vz_[i];
    const double w2 = rotation ? wx_[i] * wx_[i] + wy_[i] * wy_[i] + wz_[i] * wz_[i] : 0.0;
    e.energy += 0.5 * (m_[i] * v2 + inertia_[i] * w2);
  }

  // Pairs: the energy of both springs (the dashpots' loss is booked every
  // step: dashpot_dissipated_).
  for (int i = 0; i < n_; ++i)
    for (int k = nbr_start_[i]; k < nbr_start_[i + 1]; ++k) {
      const PairGeometry g = pair_geometry(i, nbr_j_[k]);
      if (!g.touching) continue;
      const double h2 = pair_history(k).squaredNorm();
      e.elastic += law::spring_energy(law::elastic_normal_force(kn, g.overlap), kn) +
                   law::spring_energy_squared(h2, kt);
    }

  // Walls: the energy of both springs.
  const double kw = material_.wall.kn, ktw = material_.wall.kt;
  for (int s = 0; s < 6; ++s)
    for (size_t k = 0; k < wall_candidates_[s].size(); ++k) {
      const double ov = r_[wall_candidates_[s][k]] - wall_distance(s, wall_candidates_[s][k]);
      if (ov <= 0.0) continue;
      const double h2 = wall_hx_[s][k] * wall_hx_[s][k] + wall_hy_[s][k] * wall_hy_[s][k] +
                        wall_hz_[s][k] * wall_hz_[s][k];
      e.elastic += law::spring_energy(law::elastic_normal_force(kw, ov), kw) +
                   law::spring_energy_squared(h2, ktw);
    }
  e.energy += e.elastic;
  return e;
}

bool SphereWorldImpl::ledger_record(const EnergySample& e) {
  Ledger& l = ledger_;
  if (detail::ledger_start(l, steps_, e.energy)) {
    damping_dissipated_ = 0.0;
    dashpot_dissipated_ = 0.0;
    wall_work_ = 0.0;
    friction_dissipated_ = 0.0;
    return false;
  }
  const double lost = damping_dissipated_ + friction_dissipated_ + dashpot_dissipated_;
  return detail::ledger_read(l, steps_, e.energy, wall_work_, lost, options_, divergence_);
}

}  // namespace demcal
