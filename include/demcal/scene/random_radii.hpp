// Seeded random numbers of the random packings (2D disks and 3D spheres):
// one home for the radius distributions, so that a config's "uniform" or
// "lognormal" means the same for both kernels.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "demcal/scene/config.hpp"

namespace demcal::random_radii {

/// Uniform in [0, 1) from the top 53 bits: mt19937_64 is fully specified by
/// the standard, so this is the same on every platform (std::uniform_real_
/// distribution is not).
inline double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

/// Standard normal by Box–Muller; 1 − u keeps the logarithm finite.
inline double normal(std::mt19937_64& rng) {
  const double u = 1.0 - uniform01(rng), v = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
}

/// `spec.count` radii: "lognormal" with the given mean and standard
/// deviation of r (truncated at ±3 standard deviations of ln r, so that no
/// particle is absurdly small — it would set the time step — or large);
/// otherwise uniform in [radius_min, radius_max].
inline std::vector<double> sample(const AssemblySpec& spec, std::mt19937_64& rng) {
  std::vector<double> r(static_cast<size_t>(std::max(0, spec.count)));
  if (spec.distribution == "lognormal") {
    const double m = spec.radius_mean, s = spec.radius_std;
    const double s2 = std::log(1.0 + (s * s) / (m * m));
    const double mu = std::log(m) - 0.5 * s2;
    for (double& ri : r) {
      double z;
      do z = normal(rng);
      while (std::abs(z) > 3.0);
      ri = std::exp(mu + std::sqrt(s2) * z);
    }
  } else {
    for (double& ri : r)
      ri = spec.radius_min + (spec.radius_max - spec.radius_min) * uniform01(rng);
  }
  return r;
}

}  // namespace demcal::random_radii
