#include "demcal/scoring/trial.hpp"

#include <cmath>
#include <limits>

#include "demcal/io/json_integer.hpp"
#include "demcal/scene/packing.hpp"

namespace demcal {

std::optional<double> analytical_peak_stress(const SceneConfig& config) {
  if (config.assembly.type != "hexagonal") return std::nullopt;
  const double ratio = hexagonal_peak_ratio_walled(config.material.particle.friction,
                                                   config.assembly.columns, config.assembly.rows);
  if (!std::isfinite(ratio)) return std::nullopt;
  return -ratio * config.test.lateral_stress;
}

nlohmann::json params_json(const AlgorithmSpec& a, const Integration& in,
                           const ReferenceScales& s) {
  // Damping is per particle (same ratio for all); the absolute values are
  // given for the lightest particle, the one that also sets Δt_crit.
  nlohmann::json j = to_json(a);
  j.update({{"dt", in.dt},
            {"dt_crit", s.dt_crit},
            {"damping_translation", a.damping_ratio_translation * s.damping_translation_crit},
            {"damping_translation_crit", s.damping_translation_crit},
            {"damping_rotation", a.damping_ratio_rotation * s.damping_rotation_crit},
            {"damping_rotation_crit", s.damping_rotation_crit}});
  return j;
}

nlohmann::json run_summary(const SceneConfig& config, const LoadingResult& run,
                           const Score& score) {
  using nlohmann::json;
  const auto analytical = analytical_peak_stress(config);
  json criteria = to_json(score.criteria);
  json j{{"schema", "demcal.run/1"},
         {"scene", config.name},
         {"criteria", criteria},
         {"passed", score.passed},
         {"diagnosis", to_json(score.diagnosis)},
         {"peak",
          {{"stress_yy", score.criteria.peak_stress_yy},
           {"strain_yy", score.criteria.peak_strain_yy},
           {"ratio", -score.criteria.peak_stress_yy / config.test.lateral_stress}}}};
  j.update(run_account_json(config.algorithm, run));
  if (analytical) {
    j["analytical_peak"] = {
        {"stress_yy", *analytical},
        {"ratio", -*analytical / config.test.lateral_stress},
        {"ratio_periodic", hexagonal_peak_ratio(config.material.particle.friction)},
        {"note",
         "walled-box value; rotation-locked sliding mechanism (reports/hexagonal-peaks.md)"}};
  }
  return j;
}

void add_consolidation_flat(nlohmann::json& into, const ConsolidationRecord& record) {
  const nlohmann::json block = consolidation_json(record);  // (items() of a temporary dangles)
  for (const auto& item : block.items()) into["consolidation_" + item.key()] = item.value();
}

ConsolidationRecord consolidation_flat_from_json(const nlohmann::json& block,
                                                 const std::string& file,
                                                 const std::string& where) {
  ConsolidationRecord r;
  if (block.contains("consolidation_steps"))
    r.steps = json_integer(block.at("consolidation_steps"), 0, std::numeric_limits<int64_t>::max(),
                           file, where + "consolidation_steps");
  if (const auto t = block.find("consolidation_wall_time_s"); t != block.end()) {
    if (!t->is_number())
      throw InputError(file, where + "consolidation_wall_time_s",
                       "must be a number, got " + t->dump());
    r.wall_time_s = t->get<double>();
  }
  if (const auto c = block.find("consolidation_from_cache"); c != block.end()) {
    if (!c->is_boolean())
      throw InputError(file, where + "consolidation_from_cache",
                       "must be true or false, got " + c->dump());
    r.from_cache = c->get<bool>();
  }
  return r;
}

}  // namespace demcal
