// Test support: a 3D params.json as `demcal calibrate` writes it, for the
// tests of the commands that read one (upscale, verify, scaling --law).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/calibration.hpp"
#include "support/calibrated_params.hpp"

namespace demcal::test {

/// params.json of the REV `state` (consolidated from `config`) calibrated to
/// `best`; `rev_peak` the REV's peak as the calibration recorded it.
inline nlohmann::json params_3d(const SceneConfig& config, const TriaxialState& state,
                                const AlgorithmSpec& best,
                                std::optional<double> rev_peak = std::nullopt) {
  return calibrated_params(config, state, best, rev_peak);
}

}  // namespace demcal::test
