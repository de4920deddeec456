#include "demcal/upscaling/params_file.hpp"

#include <cmath>
#include <string_view>

#include "demcal/io/files.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/io/quoted_json.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/upscaling/upscaling.hpp"

namespace demcal {

nlohmann::json read_params_file(const std::string& path) {
  return parse_params_text(read_text_file(path), path);  // a folder, a loop: one clear error
}

void require_calibrated(const nlohmann::json& params, const std::string& path) {
  const auto success = params.is_object() ? params.find("success") : params.end();
  if (success == params.end() || *success != false) return;
  std::string why;
  if (const auto m = params.find("message"); m != params.end() && m->is_string())
    why = " (" + quoted_value(m->get<std::string>(), 200) + ")";
  // --allow-failed helps only where there are parameters (rev not null).
  const auto rev = params.find("rev");
  const bool has_parameters = rev != params.end() && !rev->is_null();
  throw InputError(path, "success",
                   "is false: the calibration failed" + why +
                       "; re-run demcal calibrate with more trials (--max-trials)" +
                       (has_parameters ? std::string(", or pass --allow-failed to use its "
                                                     "uncertified parameters anyway")
                                       : std::string()));
}

nlohmann::json parse_params_text(std::string_view text, const std::string& path) {
  // The config's JSON reader: every nlohmann error (1e999 is out_of_range,
  // not a parse error) an InputError with its line, duplicate keys refused.
  const nlohmann::json params = parse_config_json(text, path);
  if (!params.is_object()) throw InputError(path, "", "must be a JSON object (a params.json)");
  // A calibration in which no trial passed has no parameters (params_file).
  if (const auto rev = params.find("rev"); rev != params.end() && rev->is_null())
    throw InputError(path, "rev",
                     "is null: the calibration found no passing trial, so there are no "
                     "parameters to use; re-run demcal calibrate with more trials (--max-trials)");
  const RevParams rev = rev_params_from_json(params, path);  // the values used first: named first
  // The stable step the calibration measured on the REV bounds its α, as
  // it bounds `demcal run`'s (a params.json edited beyond it is refused).
  if (const auto stable = params.find("dt_ratio_stable");
      stable != params.end() && stable->is_number() && stable->get<double>() > 0.0)
    require_stable_dt_ratio(rev.params.dt_ratio, stable->get<double>(), path, "rev.dt_ratio",
                            "the stable dt_ratio this params.json records as dt_ratio_stable; "
                            "use a smaller value, or calibrate again");
  const auto schema = params.find("schema");
  if (schema == params.end() || !schema->is_string() || *schema != kParamsSchema)
    throw InputError(
        path, "schema",
        std::string("must be \"") + kParamsSchema + "\" (a demcal params.json), got " +
            (schema == params.end() ? "nothing"
                                    : quoted_value(schema->is_string() ? schema->get<std::string>()
                                                                       : schema->dump())));
  const auto version = params.find("version");
  if (version != params.end()) {
    const bool plain = version->is_string() && !version->get<std::string>().empty() &&
                       version->get<std::string>().size() <= 40 &&
                       version->get<std::string>().find_first_not_of(
                           "0123456789.+-abcdefghijklm"
                           "nopqrstuvwxyz") == std::string::npos;
    if (!plain)
      throw InputError(path, "version",
                       "must be a demcal version string, got " + quoted_json(*version));
  }
  if (const auto d = params.find("dimension"); d != params.end())
    json_integer(*d, 2, 3, path, "dimension");
  if (params.contains("prototype") && params["prototype"].is_object() &&
      params["prototype"].contains("particles")) {
    particle_count(params["prototype"]["particles"], 1, path, "prototype.particles");
  }
  return params;
}

int params_dimension(const nlohmann::json& params) {
  // parse_params_text has checked it: 2 or 3 when present.
  const auto d = params.find("dimension");
  return d != params.end() ? static_cast<int>(json_integer(*d, 2, 3)) : 2;
}

double particle_steps_run(const std::vector<TrialRecord>& trials, int64_t particles) {
  double sum = 0.0;
  for (const auto& t : trials) sum += static_cast<double>(t.steps_run);
  return sum * static_cast<double>(particles);
}

namespace {

// What params.json holds in 2D and 3D alike: the scene, the outcome, the
// criteria and certificate of the calibrated run, the search's figures and
// provenance. (nlohmann::json sorts the keys: the order here is free.)
nlohmann::json calibration_record(const SceneConfig& config, int64_t n_rev,
                                  const CalibrationOptions& options,
                                  const CalibrationSummary& summary) {
  return {{"scene", config.name},
          {"success", summary.success},
          {"message", summary.message},
          {"config", to_json(config)},
          {"criteria", to_json(summary.best_trial.score.criteria)},
          {"tolerances", to_json(options.tolerances)},
          {"accuracy", options.accuracy},
          {"certificate", to_json(summary.certificate)},
          {"dt_ratio_stable", summary.dt_ratio_stable},
          {"strategy", to_string(summary.strategy)},
          {"trials", static_cast<int>(summary.trials.size())},
          {"particle_steps_run", particle_steps_run(summary.trials, n_rev)},
          {"seed", config.calibration.seed},
          {"config_sha256", sha256_hex(config.text)},
          {"version", DEMCAL_VERSION}};
}

/// No trial passed: there is no parameter set, and none is written (a
/// default or a failed trial's values would be taken for a result). rev,
/// prototype, criteria and certificate are null; success is false and the
/// message says why.
void without_parameters(nlohmann::json& params) {
  for (const char* key : {"rev", "prototype", "criteria", "certificate"}) params[key] = nullptr;
}

}  // namespace

nlohmann::json params_file(const SceneConfig& config, const ConsolidatedState& state,
                           const CalibrationOptions& options, const CalibrationSummary& summary) {
  const int64_t n_rev = state.world.size();
  const int64_t n_proto = config.prototype.particles > 0 ? config.prototype.particles : n_rev;
  nlohmann::json params = calibration_record(config, n_rev, options, summary);
  params["schema"] = kParamsSchema;
  if (summary.has_best()) {
    params["rev"] = param_block(summary.best, particle_scales(state.world.radius(), config.material,
                                                              summary.best.mass_scaling));
    // Δt and damping recomputed from the prototype's own particles.
    params["prototype"] = prototype_block(config, summary.best, n_rev);
  } else {
    without_parameters(params);
  }
  params["upscaling"] = upscaling_block(n_rev, n_proto);
  if (auto a = analytical_peak_stress(config)) params["analytical_peak_stress_yy"] = *a;
  return params;
}

nlohmann::json params_file(const SceneConfig& config, const TriaxialState& state,
                           const CalibrationOptions& options, const CalibrationSummary& summary) {
  const int64_t n_rev = state.world.size();
  const ScalingLaw law = default_law(3);
  nlohmann::json params = calibration_record(config, n_rev, options, summary);
  params["schema"] = kParamsSchema;
  params["dimension"] = 3;
  params["test"] = "triaxial";
  if (summary.has_best()) {
    params["rev"] =
        param_block(summary.best, sphere_scales(state.world, config.material, summary.best));
    // Δt and damping recomputed from the prototype's own spheres; Nstep by
    // the default 3D law (N^(2/3); `demcal upscale --law` applies another).
    params["prototype"] = prototype_block(config, summary.best, n_rev, law);
    const int64_t n_proto = json_integer(params["prototype"].at("particles"), 1);
    params["upscaling"] = upscaling_block(n_rev, n_proto, law);
  } else {
    without_parameters(params);
    params["upscaling"] = upscaling_block(n_rev, n_rev, law);
  }
  params["axial_component"] = kTriaxialCriteriaNames;
  if (auto a = analytical_peak_ratio_3d(config))
    params["analytical_peak_stress_yy"] = -*a * config.test.lateral_stress;
  return params;
}

nlohmann::json peak_error_json(const TrialRecord& t, double reference_peak) {
  const std::optional<double> error = peak_error(t, reference_peak);
  return error ? nlohmann::json(*error) : nlohmann::json(nullptr);
}

nlohmann::json evidence_block(const CalibrationEvidence& e, const TrialRecord& best) {
  const BaselineResult& baseline = e.baseline;
  nlohmann::json b{{"passed", baseline.passed},
                   {"start_steps", e.baseline_start_steps},
                   {"trials", static_cast<int>(baseline.trials.size())},
                   {"particle_steps_total", baseline.particle_steps_total}};
  if (baseline.passed) {
    const TrialRecord& last = baseline.trials.back();
    b["steps"] = baseline.params.steps;
    b["particle_steps"] = last.score.particle_steps;
    b["peak_stress_yy"] = last.score.criteria.peak_stress_yy;
    b["peak_error"] = peak_error_json(last, e.reference.peak);
  }
  return {{"reference",
           {{"law", "Richardson, error proportional to 1/Nstep: 2 P(16 Nstep) - P(8 Nstep)"},
            {"steps_8x", e.reference.coarse.params.steps},
            {"peak_stress_yy_8x", e.reference.coarse.score.criteria.peak_stress_yy},
            {"steps_16x", e.reference.fine.params.steps},
            {"peak_stress_yy_16x", e.reference.fine.score.criteria.peak_stress_yy},
            {"peak_stress_yy", e.reference.peak},
            {"calibrated_peak_error", peak_error_json(best, e.reference.peak)}}},
          {"baseline", b}};
}

std::string evidence_lines(const CalibrationEvidence& e) {
  std::string lines;
  auto add = [&](const TrialRecord& t) {
    nlohmann::json j = to_json(t);
    j["peak_error"] = peak_error_json(t, e.reference.peak);
    lines += j.dump() + "\n";
  };
  add(e.reference.coarse);
  add(e.reference.fine);
  for (const auto& t : e.baseline.trials) add(t);
  return lines;
}

}  // namespace demcal
