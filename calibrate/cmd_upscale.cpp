// `demcal upscale PARAMS.json --particles N | --prototype FILE`: the REV's
// calibrated parameters for a prototype named after the calibration.
// Multipliers unchanged, Nstep by the scaling law, Δt and damping from the
// prototype's own particles. Also the config resolution that `verify` and
// `export` share.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string_view>

#include "commands.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace fs = std::filesystem;

namespace {

/// A params.json and the config it is applied to are of one dimension:
/// 3D parameters (spheres, triaxial) on a 2D scene or the reverse would be
/// upscaled with the wrong particle scales.
SceneConfig same_dimension(SceneConfig config, const nlohmann::json& params,
                           const std::string& path) {
  const int d = params_dimension(params);
  if (config.dimension != d)
    throw InputError(path, "dimension",
                     "is " + std::to_string(d) + (d == 3 ? " (spheres)" : " (disks)") +
                         ", but the config " + config.source + " is " +
                         std::to_string(config.dimension) +
                         "D: give the config the parameters were calibrated on");
  return config;
}

}  // namespace

void check_calibrated(const std::string& path, bool allow_failed, const char* command) {
  // The JSON only (its other faults are the command's to name, in its order).
  const nlohmann::json params = parse_config_json(read_text_file(path), path);
  // Not an object, or no "success": the reader names it (after rev).
  if (!params.is_object() || !params.contains("success")) return;
  if (!allow_failed) return require_calibrated(params, path);
  // A "success" missing or not true or false is refused, --allow-failed or not.
  if (calibration_succeeded(params, path)) return;
  // No parameters at all (rev null): the reader refuses it, no warning first.
  if (params.contains("rev") && params["rev"].is_null()) return;
  std::cerr << "demcal " << command << ": warning: " << path
            << ": success is false: the calibration failed, and its parameters are not "
               "certified; used because of --allow-failed\n";
}

namespace {

/// "material" of "material.kn=1e9" (or of "material={...}").
std::string set_section(const std::string& set) {
  return set.substr(0, std::min(set.find('.'), set.find('=')));
}

std::string scene_of(const nlohmann::json& j) {
  const auto s = j.find("scene");
  return s != j.end() && s->is_string() ? s->get<std::string>() : std::string();
}

/// Whether `--set` gives a value to one of the algorithm keys a params.json
/// command never runs (the rev's parameters are, upscaled): all but
/// lock_rotation, which is the consolidation's. A mistyped key or a --set
/// without a value is not one of them: the config's reader refuses it.
bool set_without_effect(const std::string& set) {
  for (const char* key :
       {"dt_ratio", "steps", "damping_ratio_translation", "damping_ratio_rotation", "mass_scaling"})
    if (set.rfind(std::string("algorithm.") + key + "=", 0) == 0) return true;
  return false;
}

}  // namespace

void check_params_options(const UpscaledParamsOptions& o, const char* command) {
  // A key given twice is bad input whatever the key: a command-line
  // mistake, known before any file is read, said first (a failed
  // params.json's error, or its --allow-failed warning, came before it);
  // before the warnings on the --sets, and before params_scene drops the
  // ones without effect.
  require_distinct_set_keys(o.sets);
  check_calibrated(o.params, o.allow_failed, command);
  const nlohmann::json params = read_params_file(o.params);
  const bool upscale = std::string_view(command) == "upscale";
  const std::string scene = scene_of(params);
  if (const auto stored = config_from_params(params, o.params)) {
    // README: the config is params.json's own when it has one; --config is
    // for a params.json without. upscale writes that config back as the
    // record of its result; verify and export run what they are given, and
    // say it (a deck of another scene with these multipliers is a use).
    if (!o.config.empty()) {
      const SceneConfig given = same_dimension(load_config(o.config), params, o.params);
      if (to_json(given) != to_json(*stored)) {
        const std::string what = "--config " + o.config + " (scene " + given.name +
                                 ") is not the config " + o.params +
                                 " was calibrated on and carries (scene " + stored->name + ")";
        if (upscale)
          throw InputError(o.params, "config",
                           what +
                               ", which upscale applies and records: drop --config (it is for "
                               "a params.json without a config)");
        std::cerr << "demcal " << command << ": warning: " << what
                  << "; its parameters are applied to " << given.name
                  << ", where they are not certified\n";
      }
    }
    if (!o.sets.empty()) {
      if (upscale)
        throw InputError("--set " + o.sets.front(), "",
                         "upscale applies the calibration to the config " + o.params +
                             " carries (scene " + stored->name +
                             ") and records it unchanged: its multipliers were calibrated for "
                             "that material and test, and the prototype is chosen by "
                             "--particles or --prototype; for another material or test, "
                             "calibrate again with --set");
      for (const std::string& set : o.sets) {
        const std::string section = set_section(set);
        if (section == "material" || section == "test")
          std::cerr << "demcal " << command << ": warning: --set " << set << " changes the "
                    << section << " " << o.params
                    << " was calibrated for: its parameters are not certified for it\n";
      }
    }
  }
  // The three run params.json's rev upscaled, never the config's calibrated
  // algorithm keys (its lock_rotation is the consolidation's: used).
  for (const std::string& set : o.sets)
    if (set_without_effect(set))
      std::cerr << "demcal " << command << ": warning: --set " << set
                << " has no effect: the algorithm parameters are " << o.params
                << "'s rev, upscaled\n";
  // A law measured on another scene: said, with both scenes.
  if (!o.law.empty()) {
    const std::string law_scene = scene_of(read_json_file(o.law));
    if (!law_scene.empty() && !scene.empty() && law_scene != scene)
      std::cerr << "demcal " << command << ": note: " << o.law << " is the law measured on scene "
                << law_scene << ", and " << o.params << " was calibrated on scene " << scene
                << "\n";
  }
}

std::optional<SceneConfig> params_scene(const nlohmann::json& params, const std::string& path,
                                        const std::string& config_path,
                                        const std::vector<std::string>& all_sets) {
  // A --set without effect (warned about) is not applied either: a value
  // the config would refuse (steps below test.monitor_points) is then no
  // error blamed on a key the command does not use.
  std::vector<std::string> sets;
  for (const std::string& set : all_sets)
    if (!set_without_effect(set)) sets.push_back(set);
  // 2D and 3D configs alike (the commands dispatch on config.dimension).
  if (!config_path.empty()) return same_dimension(load_config(config_path, sets), params, path);
  if (auto c = config_from_params(params, path)) {
    if (c->dimension != params_dimension(params)) same_dimension(*c, params, path);
    if (sets.empty()) return c;
    nlohmann::json j = to_json(*c);
    return parse_config_with_overrides(j, sets, path + ": config");
  }
  // A params.json of the embedded default scene needs no config.
  const SceneConfig def = default_config();
  if (params.is_object() && params.value("scene", std::string()) == def.name) {
    if (sets.empty()) return def;
    nlohmann::json j = to_json(def);
    return parse_config_with_overrides(j, sets, def.source);
  }
  return std::nullopt;
}

SceneConfig required_scene(const nlohmann::json& params, const std::string& path,
                           const std::string& config, const std::vector<std::string>& sets) {
  auto scene = params_scene(params, path, config, sets);
  if (!scene)
    throw InputError(
        path, "config",
        "no scene config inside; pass --config CONFIG (the scene it was calibrated on)");
  return *scene;
}

NamedPrototype named_prototype(const nlohmann::json& params, const std::string& params_path,
                               const std::string& file, int64_t particles) {
  if (!file.empty() || particles != 0 || !params.contains("prototype") ||
      !params["prototype"].is_object())
    return {file, particles};
  const auto& p = params["prototype"];
  if (p.contains("source") && p["source"].contains("file"))
    return {p["source"]["file"].get<std::string>(), 0};
  if (p.contains("particles"))  // checked by read_params_file: 1 to kMaxParticles
    return {"", json_integer(p["particles"], 1, kMaxParticles),
            CountOrigin{params_path, "prototype.particles"}};
  return {file, particles};
}

ScalingLaw resolve_law(const nlohmann::json& params, const std::string& params_path,
                       const std::string& law_path, double exponent) {
  if (exponent > 0.0) {
    if (exponent > 3.0) throw InputError("--exponent", "", "must be in (0, 3]");
    ScalingLaw law;
    law.exponent = exponent;
    law.source = "--exponent";
    return law;
  }
  if (!law_path.empty()) {
    const nlohmann::json j = read_json_file(law_path);
    if (!j.contains("law")) throw InputError(law_path, "law", "missing (not a scaling.json?)");
    // A law measured on disks is not one for spheres, nor the reverse.
    const int law_dim =
        j.contains("dimension")
            ? static_cast<int>(json_integer(j["dimension"], 2, 3, law_path, "dimension"))
            : 2;
    if (law_dim != params_dimension(params))
      throw InputError(law_path, "dimension",
                       "a law measured in " + std::to_string(law_dim) + "D, but " + params_path +
                           " is " + std::to_string(params_dimension(params)) +
                           "D: pass the scaling.json of a study in its dimension");
    ScalingLaw law = scaling_law_from_json(j["law"], law_path);
    law.source = law_path + ": " + law.source;
    return law;
  }
  if (params.contains("upscaling") && params["upscaling"].is_object() &&
      params["upscaling"].contains("exponent"))
    return scaling_law_from_json(params["upscaling"], params_path + ": upscaling");
  return default_law(params_dimension(params));
}

void print_prototype_notes(const char* command, int64_t asked, int64_t n_rev, int64_t n_proto,
                           const ScalingLaw& law) {
  if (asked > 0 && asked != n_proto)
    std::cerr << "demcal " << command << ": note: " << asked << " particles asked for, " << n_proto
              << " made: the scene's generator makes whole samples of the config's "
              << "shape (lattice cells, rows)\n";
  const std::string note = below_rev_note(n_rev, n_proto, law);
  if (!note.empty()) std::cerr << "demcal " << command << ": note: " << note << "\n";
}

int cmd_upscale(const UpscaleOptions& o) {
  const nlohmann::json params = read_params_file(o.params);
  const RevParams rev = rev_params_from_json(params, o.params);
  if (o.particles < 0) throw InputError("--particles", "", "must be positive");
  if (o.particles == 0 && o.prototype.empty())
    throw InputError("--particles", "", "give the prototype's particle count or --prototype FILE");
  // The destination is checked before the prototype is made (its folders
  // are made as verify's and export's are).
  if (!o.output.empty() && o.output != "-") check_output_file(o.output);
  const ScalingLaw law = resolve_law(params, o.params, o.law, o.exponent);
  const auto config = params_scene(params, o.params, o.config, o.sets);

  nlohmann::json block;
  int64_t n_proto = 0;
  if (config) {
    // Named absolutely in the params.json written (its prototype.source.file),
    // like the config's files: verify and export read it from any folder.
    const std::string file = o.prototype.empty() ? "" : fs::absolute(o.prototype).string();
    block = prototype_block(*config, rev.params, rev.particles, law, o.particles, file);
    n_proto = json_integer(block.at("particles"), 1);
  } else {
    if (!o.prototype.empty())
      throw InputError(o.params, "config",
                       "no scene config inside; pass --config CONFIG to read a prototype file");
    // No config: the prototype is taken to have the REV's particle sizes
    // (same smallest particle, same masses): Δt and damping carry over.
    n_proto = o.particles;
    ParticleScales s = rev.scales;
    s.particles = n_proto;
    block = param_block(upscale(rev.params, rev.particles, n_proto, law), s);
    for (const char* k : {"radius_min", "radius_max", "radius_mean", "mass_min", "mass_mean",
                          "damping_translation_mean", "damping_rotation_mean"})
      block.erase(k);
    block["source"] = {
        {"kind", "count"},
        {"description", std::to_string(n_proto) + " particles assumed to have the REV's size "
                                                  "distribution (no config: pass --config for the "
                                                  "generator's own particles)"}};
  }
  nlohmann::json out = params;
  out["prototype"] = block;
  out["upscaling"] = upscaling_block(rev.particles, n_proto, law);
  print_prototype_notes("upscale", o.prototype.empty() ? o.particles : 0, rev.particles, n_proto,
                        law);
  const std::string text = out.dump(2) + "\n";
  // Which law scaled Nstep, on stderr whatever the output (the user must
  // know which law, measured or default, and its source).
  std::cerr << "demcal upscale: Nstep by the " << law.name() << " law (exponent " << law.exponent
            << "; " << law.source << ")\n";
  if (o.output.empty() || o.output == "-") {
    std::cout << text;
  } else {
    write_output_file(o.output, text);
    std::cerr << "demcal upscale: " << n_proto
              << (params_dimension(params) == 3 ? " spheres, " : " particles, ") << block["steps"]
              << " steps, dt " << block["dt"] << " s; wrote " << o.output << "\n";
  }
  return 0;
}

}  // namespace demcal::cli
