// The formulas both kernels' measures end with, written once (private to
// src/kernel): the scalar ratios of Measures and SphereMeasures from the
// sums each kernel's measure() gathers (stress.cpp, sphere_stress.cpp).
#pragma once

#include <cmath>

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

}  // namespace demcal::detail
