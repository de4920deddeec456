// The reference scales of a disk assembly, in one place: every layer that
// needs a disk's mass, its critical time step or its critical damping calls
// these functions (the kernel for its own particles, the scene for Δt, the
// upscaling for a prototype it never builds).
//
//   disk mass          m = f_ms·ρ·t·π·r²   (a cylinder of thickness t)
//   inertia            I = m·r²/2
//   sphere mass        m = f_ms·ρ·(4/3)·π·r³,  I = (2/5)·m·r²
//   critical step      Δt_crit = 2·sqrt(m_min/kn)
//   critical damping   D_t^crit = 2·sqrt(kn·m),  D_r^crit = 2·sqrt(kt·r²·I)
//   reduced mass       m_eff = m_i·m_j/(m_i + m_j) of a contact
//
// The order of the floating-point operations is part of the contract: the
// kernel integrates with these masses, and the calibration's outputs quote
// these numbers, so every caller must get the same bits.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

#include "demcal/kernel/material.hpp"

namespace demcal {

/// f_ms·ρ·t [kg/m²]: the mass of the unit disk area (times π·r² in disk_mass).
inline double disk_areal_density(const Material& material, double mass_scaling) {
  return material.density * material.thickness * mass_scaling;
}
/// m = (f_ms·ρ·t)·π·r² [kg], with areal_density from disk_areal_density().
inline double disk_mass(double areal_density, double radius) {
  return areal_density * std::numbers::pi * radius * radius;
}
/// I = m·r²/2 [kg·m²] of a uniform disk.
inline double disk_inertia(double mass, double radius) { return 0.5 * mass * radius * radius; }
/// m = (f_ms·ρ)·(4/3)·π·r³ [kg] of a sphere, `density` = f_ms·ρ.
inline double sphere_mass(double density, double radius) {
  return density * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}
/// I = (2/5)·m·r² [kg·m²] of a uniform sphere.
inline double sphere_inertia(double mass, double radius) { return 0.4 * mass * radius * radius; }
/// m_eff = m_i·m_j/(m_i + m_j) [kg]: the reduced mass of a pair of
/// particles, a contact's effective mass (against a wall: m_i). Its one
/// home: the kernels' contact laws (with V a GCC vector of doubles in their
/// SIMD passes, hence a template, always inlined) and the engine decks'
/// dashpots compute it here, in this order.
/// (Always inlined: no vector crosses a call boundary, so GCC's note on
/// the ABI of AVX vector arguments does not apply.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
template <class V>
inline __attribute__((always_inline)) V reduced_mass(V mi, V mj) {
  return mi * mj / (mi + mj);
}
#pragma GCC diagnostic pop
/// Δt_crit = 2·sqrt(m/kn) [s]: twice the inverse angular frequency of a
/// mass on one spring.
inline double critical_time_step(double mass, double kn) { return 2.0 * std::sqrt(mass / kn); }
/// D_t^crit = 2·sqrt(kn·m) [N·s/m].
inline double critical_damping_translation(double kn, double mass) {
  return 2.0 * std::sqrt(kn * mass);
}
/// D_r^crit = 2·sqrt(kt·r²·I) [N·m·s].
inline double critical_damping_rotation(double kt, double radius, double inertia) {
  return 2.0 * std::sqrt(kt * radius * radius * inertia);
}

/// f = sqrt(1 + ζ²) − ζ: the factor by which an explicit dashpot of ratio ζ
/// (of the critical value) shrinks the stable step of a mass on a spring,
/// ω·Δt < 2f. Explicit: the drag comes from the lagging velocity, i.e.
/// x_{n+1} − 2x_n + x_{n−1} = −Ω²x_n − 2ζΩ(x_n − x_{n−1}), Ω = ω·Δt, whose
/// characteristic z² + (Ω² + 2ζΩ − 2)z + 1 − 2ζΩ = 0 has its root z = −1 at
/// Ω = 2f. Two users: the kernel's contact dashpots (stability.cpp, the
/// consolidation step in biaxial.cpp), and LAMMPS' and LIGGGHTS' fix viscous,
/// which the export runs at α·f for Nstep/f steps (demcal's global damping
/// is semi-implicit, f = 1). Written as 1/(sqrt(1 + ζ²) + ζ), which loses no
/// digits at large ζ.
inline double dashpot_step_factor(double zeta) {
  return 1.0 / (std::sqrt(1.0 + zeta * zeta) + zeta);
}

/// The stable step of the fastest mode, ω² its squared frequency, with
/// contact dashpots of at most γ_max = max 2ζ_c·sqrt(m_eff/k) over the
/// contacts (0 without them): a mode of frequency ω then carries at most ζ =
/// γ_max·ω/2, so Δt < 2/ω·dashpot_step_factor(ζ) (kernel/stability.cpp).
/// Infinite for ω² ≤ 0 (no contact: no limit from the springs). Both
/// kernels' estimates.
inline double stable_step(double omega2, double gamma_max) {
  if (!(omega2 > 0.0)) return std::numeric_limits<double>::infinity();
  const double omega = std::sqrt(omega2);
  if (gamma_max == 0.0) return 2.0 / omega;
  return 2.0 / omega * dashpot_step_factor(0.5 * gamma_max * omega);
}

/// D_r^crit of a disk of mass m, with the inertia m·r²/2 written out:
/// 2·sqrt(kt·r²·(m/2)·r²). The same value as critical_damping_rotation(kt,
/// r, disk_inertia(m, r)) up to the last bit; this order is the one the
/// quoted scales (params.json) have always been computed in.
inline double critical_damping_rotation_of_disk(double kt, double radius, double mass) {
  return 2.0 * std::sqrt(kt * radius * radius * 0.5 * mass * radius * radius);
}

/// The reference scales of an assembly, from its radii alone (no contact
/// network needed): what fixes the absolute Δt, D_t and D_r. Damping is
/// applied per particle (every particle gets the same ratio); the critical
/// values are quoted for the lightest particle and as the mean over all.
struct ParticleScales {
  int64_t particles = 0;
  double radius_min = 0.0, radius_max = 0.0, radius_mean = 0.0;
  double mass_min = 0.0, mass_mean = 0.0;      ///< scaled by f_ms [kg]
  double dt_crit = 0.0;                        ///< 2·sqrt(m_min/kn) [s]
  double damping_translation_crit = 0.0;       ///< 2·sqrt(kn·m_min) [N·s/m]
  double damping_rotation_crit = 0.0;          ///< 2·sqrt(kt·r²·I) of the lightest [N·m·s]
  double damping_translation_crit_mean = 0.0;  ///< mean over the particles
  double damping_rotation_crit_mean = 0.0;
};
/// The kernel's name for the same record (World::reference_scales()).
using ReferenceScales = ParticleScales;

/// Scales of a set of radii for a material and a mass scaling f_ms.
ParticleScales particle_scales(std::span<const double> radii, const Material& material,
                               double mass_scaling = 1.0);

}  // namespace demcal
