// The formulas both kernels' measures and stable-step estimates end with,
// written once (private to src/kernel): the sums each kernel's measure()
// gathers contact by contact and particle by particle, and Measures and
// SphereMeasures from them (stress.cpp, sphere_stress.cpp); a
// StabilityEstimate from a linearised contact network, its steps and ratios
// from its ω² (stability.cpp, sphere_stability.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"  // stable_step
#include "demcal/kernel/world.hpp"            // StabilityEstimate
#include "tridiagonal.hpp"                    // lanczos_max_eigenvalue

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

/// What a kernel's measure() sums over its contacts in D dimensions: V·σ and
/// V·b (tension positive, origin of b at the box centre), the contact
/// forces' magnitudes and their number, and the springs' energy (which the
/// kernel adds itself: the contacts' energy does not need a force).
template <int D>
struct ContactSums {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  Mat sigma = Mat::Zero(), b = Mat::Zero();
  double force = 0.0, elastic = 0.0;
  int pairs = 0, walls = 0;

  /// A particle pair: `branch` x^j − x^i, `f` the force on i (the two
  /// particles' terms of σ add up to branch ⊗ f wherever the contact sits).
  void add_pair(const Vec& branch, const Vec& f) {
    sigma += branch * f.transpose();
    force += f.norm();
    ++pairs;
  }
  /// A wall contact: `arm` from the particle's centre to the contact point,
  /// `xc` the contact point from the box centre, `f` the wall's force on the
  /// particle.
  void add_wall(const Vec& arm, const Vec& xc, const Vec& f) {
    sigma += arm * f.transpose();
    b += xc * f.transpose();
    force += f.norm();
    ++walls;
  }
};

/// What a kernel's measure() sums over its `n` particles: the kinetic
/// energies, the net forces' magnitudes, the diameters.
struct ParticleSums {
  double ke_translation = 0.0, ke_rotation = 0.0, net_force = 0.0, diameter = 0.0;
};

/// Measures (2D) or SphereMeasures (3D) `out`, its volume set by the
/// caller, from its sums over `n` particles; `rho` the scaled density, `strain_rate` for the
/// inertial number. The mean pressure is −tr(σ)/D.
template <class M, int D>
void set_measures(M& out, const ContactSums<D>& contacts, const ParticleSums& particles, int n,
                  double strain_rate, double rho) {
  out.homogenized_stress = contacts.sigma / out.volume;
  out.boundary_stress = contacts.b / out.volume;
  out.elastic_energy = contacts.elastic;
  out.particle_contacts = contacts.pairs;
  out.wall_contacts = contacts.walls;
  out.kinetic_energy_translation = particles.ke_translation;
  out.kinetic_energy_rotation = particles.ke_rotation;
  out.unbalanced_force_ratio = unbalanced_force_ratio(particles.net_force, n, contacts.force,
                                                      contacts.pairs + contacts.walls);
  out.mean_pressure = -out.homogenized_stress.trace() / D;
  out.coordination_number = coordination_number(out.particle_contacts, n);
  out.inertial_number = inertial_number(strain_rate, particles.diameter, n, rho, out.mean_pressure);
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

/// The stable-step estimate of a kernel's linearised contact network
/// `contacts` (its LinearContact: i, j, kn; stability.cpp's file comment)
/// over `n` particles of masses `m` and moments of inertia `inertia`, of
/// `dofs_per_particle` dofs each, the first `translation_dofs` of them
/// translations. The kernel gives its Gershgorin bound
/// `gershgorin(contacts, ism, isi, rotation)` and its y = A·x,
/// `apply(contacts, ism, isi, rotation, x, y)` (ism, isi: 1/sqrt of the
/// masses and of the moments of inertia), and the contact dashpots' γ_max
/// `gamma` (law::dashpot_gamma_max: each pair's normal dashpot, a wall's
/// with the particle's mass). ω²_max is the Lanczos value with the rotations
/// coupled unless they are locked (`rotation` false); the steps come from
/// it, the Gershgorin bound and the translational Lanczos value.
template <class Contacts, class Masses, class Gershgorin, class Apply>
StabilityEstimate network_stability(const Contacts& contacts, const Masses& m,
                                    const Masses& inertia, int n, int dofs_per_particle,
                                    int translation_dofs, bool rotation, int iterations,
                                    const Gershgorin& gershgorin, const Apply& apply, double gamma,
                                    double dt_crit) {
  std::vector<double> ism(n), isi(n);
  for (int p = 0; p < n; ++p) {
    ism[p] = 1.0 / std::sqrt(m[p]);
    isi[p] = 1.0 / std::sqrt(inertia[p]);
  }
  auto lanczos = [&](bool rot) {
    if (contacts.empty()) return 0.0;
    return lanczos_max_eigenvalue(n, dofs_per_particle, translation_dofs, rot, iterations,
                                  [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
                                    apply(contacts, ism, isi, rot, x, y);
                                  });
  };
  StabilityEstimate est;
  est.omega2_gershgorin = gershgorin(contacts, ism, isi, rotation);
  est.omega2_max = lanczos(rotation);
  set_stable_steps(est, lanczos(false), gamma, dt_crit);
  return est;
}

}  // namespace demcal::detail
