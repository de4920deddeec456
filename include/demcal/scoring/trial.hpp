// One trial of a scene: the consolidated state loaded with one set of
// algorithmic parameters, scored, summarised. Shared by `demcal run`, the
// sweep and the calibration.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scoring/scoring.hpp"

namespace demcal {

/// The analytical peak b_yy (negative) of a hexagonal scene's walled sample,
/// or nothing for other assemblies.
std::optional<double> analytical_peak_stress(const SceneConfig& config);

/// The algorithm block as params JSON: multipliers and absolute values.
nlohmann::json params_json(const AlgorithmSpec& algorithm, const Integration& integration,
                           const ReferenceScales& scales);

/// Particle-steps per wall-clock second, the cost rate every summary
/// reports (0 when no time was measured).
inline double particle_steps_per_second(double particles, double steps, double wall_time_s) {
  return wall_time_s > 0 ? particles * steps / wall_time_s : 0.0;
}

/// summary.json of a run (`demcal run`, README.md "Commands").
nlohmann::json run_summary(const SceneConfig& config, const LoadingResult& run, const Score& score);

}  // namespace demcal
