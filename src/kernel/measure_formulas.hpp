// The formulas both kernels' measures and stable-step estimates end with,
// written once (private to src/kernel): the scalar ratios of Measures and
// SphereMeasures from the sums each kernel's measure() gathers
// (stress.cpp, sphere_stress.cpp), and the steps and ratios of a
// StabilityEstimate from its ω² (stability.cpp, sphere_stability.cpp).
#pragma once

#include <algorithm>
#include <cmath>

#include "demcal/kernel/particle_scales.hpp"  // stable_step
#include "demcal/kernel/world.hpp"            // StabilityEstimate

namespace demcal::detail {

/// mean|F_net| / mean|f_contact|: `sum_net` the particles' net forces'
/// magnitudes summed over `n` particles, `sum_contact` the contact forces'
/// over `contacts` contacts (pairs and walls); 0 without either.
inline double unbalanced_force_ratio(double sum_net, int n, double sum_contact, int contacts) {
  const double mean_contact = contacts ? sum_contact / contacts : 0.0;
  return (n && mean_contact > 0.0) ? (sum_net / n) / mean_contact : 0.0;
}

/// 2·contacts / particles (particle–particle contacts; 0 without particles).
inline double coordination_number(int particle_contacts, int n) {
  return n ? 2.0 * particle_contacts / n : 0.0;
}

/// I = |ε̇|·d·sqrt(ρ/p): `sum_d` the diameters summed over `n` particles,
/// ρ the (scaled) density, p the mean pressure; 0 unless p > 0.
inline double inertial_number(double strain_rate, double sum_d, int n, double rho, double p) {
  if (!(n && p > 0.0)) return 0.0;
  return std::abs(strain_rate) * (sum_d / n) * std::sqrt(rho / p);
}

/// The steps of `est` from its ω² (omega2_max, omega2_gershgorin, set by the
/// caller) and the translational ω², with the contact dashpots' γ_max
/// (stable_step), and their ratios to dt_crit (none if dt_crit ≤ 0).
inline void set_stable_steps(StabilityEstimate& est, double omega2_translation, double gamma,
                             double dt_crit) {
  auto step_for = [gamma](double w2) { return stable_step(w2, gamma); };
  est.dt_stable = step_for(est.omega2_max);
  est.dt_stable_gershgorin = step_for(est.omega2_gershgorin);
  if (dt_crit > 0.0) {
    est.dt_ratio_stable = est.dt_stable / dt_crit;
    est.dt_ratio_stable_gershgorin = est.dt_stable_gershgorin / dt_crit;
    est.dt_ratio_stable_translation = step_for(omega2_translation) / dt_crit;
  }
}

}  // namespace demcal::detail
