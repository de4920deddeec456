// Test support: a 3D params.json as `demcal calibrate` writes it, for the
// tests of the commands that read one (upscale, verify, scaling --law).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/upscaling/params_file.hpp"

namespace demcal::test {

/// params.json of the REV `state` (consolidated from `config`) calibrated to
/// `best`; `rev_peak` the REV's peak as the calibration recorded it.
inline nlohmann::json params_3d(const SceneConfig& config, const TriaxialState& state,
                                const AlgorithmSpec& best,
                                std::optional<double> rev_peak = std::nullopt) {
  CalibrationSummary summary;
  summary.success = true;
  summary.best = best;
  summary.best_trial.params = best;
  if (rev_peak) summary.best_trial.score.criteria.peak_stress_yy = *rev_peak;
  summary.dimension = 3;
  // The stable step calibrate records (its runner's, TriaxialRunner).
  summary.dt_ratio_stable = estimated_stable_dt_ratio(state, config.algorithm);
  return params_file(config, state, CalibrationOptions::from(config.calibration), summary);
}

}  // namespace demcal::test
