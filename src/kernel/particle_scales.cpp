#include "demcal/kernel/particle_scales.hpp"

#include <algorithm>

namespace demcal {

ParticleScales particle_scales(std::span<const double> radii, const Material& material,
                               double mass_scaling) {
  ParticleScales s;
  s.particles = static_cast<int64_t>(radii.size());
  if (radii.empty()) return s;
  const double kn = material.particle.kn, kt = material.particle.kt;
  const double areal_density = disk_areal_density(material, mass_scaling);
  s.radius_min = *std::min_element(radii.begin(), radii.end());
  s.radius_max = *std::max_element(radii.begin(), radii.end());
  double sum_r = 0.0, sum_m = 0.0, sum_dt = 0.0, sum_dr = 0.0;
  for (double r : radii) {
    const double m = disk_mass(areal_density, r);
    sum_r += r;
    sum_m += m;
    sum_dt += critical_damping_translation(kn, m);
    sum_dr += critical_damping_rotation(kt, r, disk_inertia(m, r));
  }
  const double n = static_cast<double>(radii.size());
  s.radius_mean = sum_r / n;
  s.mass_mean = sum_m / n;
  // The lightest disk is the smallest one.
  s.mass_min = disk_mass(areal_density, s.radius_min);
  s.dt_crit = critical_time_step(s.mass_min, kn);
  s.damping_translation_crit = critical_damping_translation(kn, s.mass_min);
  s.damping_rotation_crit = critical_damping_rotation_of_disk(kt, s.radius_min, s.mass_min);
  s.damping_translation_crit_mean = sum_dt / n;
  s.damping_rotation_crit_mean = sum_dr / n;
  return s;
}

}  // namespace demcal
