// One trial of a scene: the consolidated state loaded with one set of
// algorithmic parameters, scored, summarised. Shared by `demcal run`, the
// sweep and the calibration.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

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

/// A run's account in summary.json, 2D and 3D alike: particles, params
/// (params_json of `algorithm`), diverged (and the divergence's reason and
/// step), steps_run, wall_time_s, particle_steps_per_s, strain_rate.
template <class Point>
nlohmann::json run_account_json(const AlgorithmSpec& algorithm, const LoadingRun<Point>& run) {
  nlohmann::json j{{"particles", run.particles},
                   {"params", params_json(algorithm, run.integration, run.scales)},
                   {"diverged", run.diverged},
                   {"steps_run", run.steps_run},
                   {"wall_time_s", run.wall_time_s},
                   {"particle_steps_per_s",
                    particle_steps_per_second(run.particles, static_cast<double>(run.steps_run),
                                              run.wall_time_s)},
                   {"strain_rate", run.strain_rate}};
  if (run.diverged)
    j["divergence"] = {{"reason", to_string(run.divergence)}, {"step", run.divergence_step}};
  return j;
}

/// A consolidation's record, 2D and 3D alike, in summary.json (`demcal
/// run`, the "consolidation" block; a 3D run's adds the state's stress error,
/// unbalanced-force ratio and box), verify.json, rev.json and atlas.json
/// (`demcal sweep`): steps, wall_time_s, from_cache; scaling.json's sizes
/// and a calibration's run.json hold it flat (add_consolidation_flat:
/// consolidation_steps, ...). Read from the consolidation cache, the steps
/// are those the consolidation took and the wall time is the reading's.
/// `State` is a ConsolidatedState, a TriaxialState or a ConsolidationRecord.
template <class State>
nlohmann::json consolidation_json(const State& state) {
  return {
      {"steps", state.steps}, {"wall_time_s", state.wall_time_s}, {"from_cache", state.from_cache}};
}

/// A consolidation's record kept past its state (the scaling study's sizes,
/// the sweep): consolidation_json's fields, and consolidation_json of it
/// gives the same JSON as of the state.
struct ConsolidationRecord {
  int64_t steps = 0;
  double wall_time_s = 0.0;
  bool from_cache = false;
};
template <class State>
ConsolidationRecord consolidation_record(const State& state) {
  return {state.steps, state.wall_time_s, state.from_cache};
}

/// consolidation_json's keys flat, each prefixed "consolidation_"
/// (consolidation_steps, consolidation_wall_time_s,
/// consolidation_from_cache), added to `into`: scaling.json's sizes (and
/// their result.json, fixed.json) and a calibration's run.json.
void add_consolidation_flat(nlohmann::json& into, const ConsolidationRecord& record);
/// add_consolidation_flat's keys read back from `block` of `file`; a key a
/// file of an older demcal lacks is 0 / false; a key of the wrong type is
/// an InputError naming the file and `where` + the key (exit status 2).
ConsolidationRecord consolidation_flat_from_json(const nlohmann::json& block,
                                                 const std::string& file,
                                                 const std::string& where = "");

/// summary.json of a run (`demcal run`, README.md "Commands").
nlohmann::json run_summary(const SceneConfig& config, const LoadingResult& run, const Score& score);

}  // namespace demcal
