// The contact laws, written once (private to the kernel).
//
// Particle–particle and particle–wall contacts share one law:
//   normal     fn = max(0, kn·δ − c·v_n),  c = 2ζ·sqrt(kn·m_eff)
//              (m_eff: reduced_mass, kernel/particle_scales.hpp; m_i at a wall)
//              (v_n > 0 when the contact opens; the dashpot never pulls)
//   tangential ft = clamp(ft_prev + kt·Δu_t, −μ·fn, μ·fn)
//   energy     ½·fe²/kn in the normal spring (fe = kn·δ, the elastic part
//              alone), ½·ft²/kt in the tangential one
//   dissipated by the dashpot: (fe − fn)·v_n ≥ 0 (per unit time)
//
// Every user evaluates the law through these functions: the SIMD force pass
// (contact.cpp, with V a GCC vector of doubles), the scalar re-evaluation
// for measures and views (World::pair_state), the walls, the energy ledger
// (energy_balance.cpp), the stress measure (stress.cpp) and the stability
// estimate (stability.cpp); the sphere kernel's springs' energy too
// (sphere_stress.cpp, sphere_energy_balance.cpp). The operations and their order are part of the
// law: the SIMD pass and the scalar paths must give the same bits.
#pragma once

#include <algorithm>
#include <cmath>

#include "demcal/kernel/particle_scales.hpp"  // reduced_mass

// The templates are always inlined: no SIMD vector crosses a call boundary,
// so the ABI note about passing AVX vectors does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace demcal::law {

#define DEMCAL_LAW inline __attribute__((always_inline))

/// Inward unit normals of the walls, indexed by WallSide (left, right,
/// bottom, top).
constexpr double kWallNormal[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};

/// γ_max = max 2ζ_c·sqrt(m_eff/kn) of the contact dashpots over `contacts`
/// (each with i, j — j < 0 a wall, m_eff the particle's mass — and kn), for
/// the stable-step estimates of both kernels (stability.cpp's file
/// comment); 0 without dashpots.
template <class Contacts, class Masses>
double dashpot_gamma_max(const Contacts& contacts, const Masses& m, double zeta_c) {
  double gamma = 0.0;
  if (zeta_c > 0.0)
    for (const auto& c : contacts) {
      const double m_eff = c.j >= 0 ? reduced_mass(m[c.i], m[c.j]) : m[c.i];
      gamma = std::max(gamma, 2.0 * zeta_c * std::sqrt(m_eff / c.kn));
    }
  return gamma;
}

/// The elastic normal force kn·δ (δ > 0: overlap).
template <class V>
DEMCAL_LAW V elastic_normal_force(double kn, V overlap) {
  return kn * overlap;
}

/// The normal force with the contact dashpot: fe − 2ζ·sqrt(kn·m_eff)·v_n,
/// never below 0. `two_zeta` is 2·contact_damping_ratio, `sqrt_kn_meff`
/// sqrt(kn·m_eff) (the caller's square root: the SIMD pass has its own).
template <class V>
DEMCAL_LAW V damped_normal_force(V fn_elastic, double two_zeta, V sqrt_kn_meff, V vn) {
  const V fn = fn_elastic - two_zeta * sqrt_kn_meff * vn;
  const V zero{};
  return fn > zero ? fn : zero;
}

/// Coulomb's cap on the trial tangential force: clamp to [−cap, cap].
template <class V>
DEMCAL_LAW V coulomb_clamp(V ft, V cap) {
  ft = ft < -cap ? -cap : ft;
  return ft > cap ? cap : ft;
}

/// Energy ½·|f|²/k stored in a linear spring carrying a force of squared
/// magnitude f2 (0 for k = 0: no spring); the sphere kernel's tangential
/// spring holds a 3-vector.
DEMCAL_LAW double spring_energy_squared(double force2, double stiffness) {
  return stiffness > 0.0 ? 0.5 * force2 / stiffness : 0.0;
}

/// Energy ½·f²/k stored in a linear spring carrying force f (0 for k = 0:
/// no spring).
DEMCAL_LAW double spring_energy(double force, double stiffness) {
  return spring_energy_squared(force * force, stiffness);
}

/// Power taken by the dashpot: (fe − fn)·v_n, the force it removed from the
/// spring times the opening speed (≥ 0; with the clamp at fn = 0 it is
/// fe·v_n: the spring's energy released without work).
template <class V>
DEMCAL_LAW V dashpot_power(V fn_elastic, V fn, V vn) {
  return (fn_elastic - fn) * vn;
}

#undef DEMCAL_LAW

}  // namespace demcal::law

#pragma GCC diagnostic pop
