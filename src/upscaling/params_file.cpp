#include "demcal/upscaling/params_file.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
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

namespace {

/// How a params.json key is checked (check_keys): its JSON type as
/// demcal writes it.
enum class Kind { kString, kBoolean, kNumber, kCount, kObject, kObjectOrNull };

struct KeyRule {
  const char* key;
  Kind kind;
};

// The top-level keys of every params.json demcal has written (params_file,
// upscale, calibrate --evidence; wall_time_s in the first ones, 2026-11-22)
// and their types. schema, version, success, dt_ratio_stable, dimension and
// rev are checked in full before (parse_params_text); the nested blocks
// other than rev, prototype and upscaling (criteria, certificate, evidence,
// config: parse_config) are not checked here.
constexpr KeyRule kTopKeys[] = {{"scene", Kind::kString},
                                {"message", Kind::kString},
                                {"config", Kind::kObject},
                                {"criteria", Kind::kObjectOrNull},
                                {"tolerances", Kind::kObject},
                                {"accuracy", Kind::kNumber},
                                {"certificate", Kind::kObjectOrNull},
                                {"strategy", Kind::kString},
                                {"trials", Kind::kCount},
                                {"particle_steps_run", Kind::kNumber},
                                {"seed", Kind::kCount},
                                {"config_sha256", Kind::kString},
                                {"test", Kind::kString},
                                {"axial_component", Kind::kString},
                                {"evidence", Kind::kObject},
                                {"analytical_peak_stress_yy", Kind::kNumber},
                                {"wall_time_s", Kind::kNumber},
                                {"schema", Kind::kString},
                                {"version", Kind::kString},
                                {"success", Kind::kBoolean},
                                {"dt_ratio_stable", Kind::kNumber},
                                {"dimension", Kind::kCount},
                                {"rev", Kind::kObject},
                                {"prototype", Kind::kObject},
                                {"upscaling", Kind::kObject}};

// A parameter block (param_block): rev, and prototype with its "source".
constexpr KeyRule kBlockKeys[] = {{"dt_ratio", Kind::kNumber},
                                  {"steps", Kind::kCount},
                                  {"damping_ratio_translation", Kind::kNumber},
                                  {"damping_ratio_rotation", Kind::kNumber},
                                  {"mass_scaling", Kind::kNumber},
                                  {"particles", Kind::kCount},
                                  {"dt", Kind::kNumber},
                                  {"dt_crit", Kind::kNumber},
                                  {"damping_translation", Kind::kNumber},
                                  {"damping_rotation", Kind::kNumber},
                                  {"damping_translation_mean", Kind::kNumber},
                                  {"damping_rotation_mean", Kind::kNumber},
                                  {"damping_translation_crit", Kind::kNumber},
                                  {"damping_rotation_crit", Kind::kNumber},
                                  {"radius_min", Kind::kNumber},
                                  {"radius_max", Kind::kNumber},
                                  {"radius_mean", Kind::kNumber},
                                  {"mass_min", Kind::kNumber},
                                  {"mass_mean", Kind::kNumber},
                                  {"duration", Kind::kNumber}};
constexpr KeyRule kSourceKeys[] = {
    {"kind", Kind::kString}, {"description", Kind::kString}, {"file", Kind::kString}};
// upscaling_block.
constexpr KeyRule kUpscalingKeys[] = {{"law", Kind::kString},
                                      {"exponent", Kind::kNumber},
                                      {"factor", Kind::kNumber},
                                      {"particles_rev", Kind::kCount},
                                      {"particles_prototype", Kind::kCount},
                                      {"source", Kind::kString},
                                      {"formula", Kind::kString}};

/// A key as written, or quoted when it is long or holds control characters.
std::string shown_key(const std::string& key) {
  const bool plain = key.size() <= 80 && std::none_of(key.begin(), key.end(), [](char c) {
                       return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
                     });
  return plain ? key : quoted_value(key);
}

void check_value(const nlohmann::json& v, Kind kind, const std::string& path,
                 const std::string& field) {
  switch (kind) {
    case Kind::kString:
      if (!v.is_string()) throw InputError(path, field, "must be a string, got " + quoted_json(v));
      return;
    case Kind::kBoolean:
      if (!v.is_boolean())
        throw InputError(path, field, "must be true or false, got " + quoted_json(v));
      return;
    case Kind::kNumber:
      if (!v.is_number()) throw InputError(path, field, "must be a number, got " + quoted_json(v));
      if (!std::isfinite(v.get<double>()))
        throw InputError(path, field, "must be finite, got " + v.dump());
      return;
    case Kind::kCount:
      json_integer(v, 0, std::numeric_limits<int64_t>::max(), path, field);
      return;
    case Kind::kObjectOrNull:
      if (v.is_null()) return;
      [[fallthrough]];
    case Kind::kObject:
      if (!v.is_object()) throw InputError(path, field, "must be an object, got " + quoted_json(v));
      return;
  }
}

/// Every key of `object` is one of `rules` and of its type; `where` is the
/// object's field ("" for the top level, "rev").
template <size_t N>
void check_keys(const nlohmann::json& object, const KeyRule (&rules)[N], const std::string& path,
                const std::string& where) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    const std::string field = (where.empty() ? "" : where + ".") + shown_key(it.key());
    const auto rule = std::find_if(std::begin(rules), std::end(rules),
                                   [&](const KeyRule& r) { return it.key() == r.key; });
    if (rule == std::end(rules))
      throw InputError(path, field, "unknown key (not one a demcal params.json holds)");
    check_value(it.value(), rule->kind, path, field);
  }
}

/// A parameter block (rev, prototype; check_keys made it an object): its
/// keys, and the prototype's source.
void check_block(const nlohmann::json& params, const std::string& key, const std::string& path) {
  const auto block = params.find(key);
  if (block == params.end()) return;
  nlohmann::json numbers = *block;
  if (key == "prototype" && block->contains("source")) {
    check_value(block->at("source"), Kind::kObject, path, "prototype.source");
    check_keys(block->at("source"), kSourceKeys, path, "prototype.source");
    numbers.erase("source");
  }
  check_keys(numbers, kBlockKeys, path, key);
}

}  // namespace

bool calibration_succeeded(const nlohmann::json& params, const std::string& path) {
  const auto success = params.find("success");
  if (success == params.end())
    throw InputError(path, "success",
                     "missing: every params.json demcal writes says whether its calibration "
                     "succeeded (true or false)");
  check_value(*success, Kind::kBoolean, path, "success");
  return success->get<bool>();
}

void require_calibrated(const nlohmann::json& params, const std::string& path) {
  if (calibration_succeeded(params, path)) return;
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

std::optional<std::string> uncertified_reason(const nlohmann::json& params) {
  const auto ok = params.find("success");
  if (ok == params.end() || *ok != false) return std::nullopt;
  const auto why = params.find("message");
  return why != params.end() && why->is_string() ? why->get<std::string>() : std::string();
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
  calibration_succeeded(params, path);  // true or false (whether it may be used: the command's)
  // The stable step the calibration measured on the REV bounds its α, as
  // it bounds `demcal run`'s (a params.json edited beyond it is refused).
  // Every params.json demcal writes records it: without it, or not a
  // number, the bound would be off.
  const auto stable = params.find("dt_ratio_stable");
  if (stable == params.end())
    throw InputError(path, "dt_ratio_stable",
                     "missing: every params.json demcal writes records the stable dt_ratio "
                     "that bounds rev.dt_ratio");
  check_value(*stable, Kind::kNumber, path, "dt_ratio_stable");
  if (!(stable->get<double>() > 0.0))
    throw InputError(path, "dt_ratio_stable", "must be > 0, got " + stable->dump());
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
  // Every other key: one demcal writes, of the type it writes (a typo, or
  // a value of the wrong type, is not taken for a setting that applies).
  check_keys(params, kTopKeys, path, "");
  check_block(params, "rev", path);
  check_block(params, "prototype", path);
  if (const auto up = params.find("upscaling"); up != params.end())
    check_keys(*up, kUpscalingKeys, path, "upscaling");
  if (params.contains("prototype") && params["prototype"].contains("particles")) {
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
  int64_t n_proto = config.prototype.particles > 0 ? config.prototype.particles : n_rev;
  nlohmann::json params = calibration_record(config, n_rev, options, summary);
  params["schema"] = kParamsSchema;
  if (summary.has_best()) {
    params["rev"] = param_block(summary.best, particle_scales(state.world.radius(), config.material,
                                                              summary.best.mass_scaling));
    // Δt and damping recomputed from the prototype's own particles; the
    // upscaling block counts them too (a prototype file's, not the config's
    // prototype.particles, 0 there), as in 3D.
    params["prototype"] = prototype_block(config, summary.best, n_rev);
    n_proto = json_integer(params["prototype"].at("particles"), 1);
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
