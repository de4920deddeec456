// Test support: a params.json as `demcal calibrate` writes it (params_file,
// the one writer, so a fixture cannot drift from the real format), for the
// tests of the commands that read one (upscale, verify, export, scaling
// --law).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "support/files.hpp"

namespace demcal::test {

/// params.json of the REV `state` (a ConsolidatedState or a TriaxialState,
/// consolidated from `config`) calibrated to `best`; `rev_peak` the REV's
/// peak as the calibration recorded it. dt_ratio_stable is the stable step
/// calibrate records (its runner's estimate, BiaxialRunner/TriaxialRunner).
template <class State>
nlohmann::json calibrated_params(const SceneConfig& config, const State& state,
                                 const AlgorithmSpec& best,
                                 std::optional<double> rev_peak = std::nullopt) {
  CalibrationSummary summary;
  summary.success = true;
  summary.best = best;
  summary.best_trial.params = best;
  if (rev_peak) summary.best_trial.score.criteria.peak_stress_yy = *rev_peak;
  summary.dimension = std::is_same_v<State, TriaxialState> ? 3 : 2;
  summary.dt_ratio_stable = estimated_stable_dt_ratio(state, config.algorithm);
  return params_file(config, state, CalibrationOptions::from(config.calibration), summary);
}

/// DIR/params.json of the default scene (default_config(), hex_10x10; its
/// REV consolidated afresh, no cache) calibrated to `best`; returns its path.
inline std::string write_default_scene_params(const std::filesystem::path& dir,
                                              const AlgorithmSpec& best) {
  const SceneConfig config = default_config();
  const ConsolidatedState state = consolidate(config, make_assembly(config), std::string());
  return write_text(dir / "params.json", calibrated_params(config, state, best).dump(2));
}

}  // namespace demcal::test
