// `demcal calibrate`: the main job. Writes DIR/params.json and
// DIR/trials.jsonl (appended per trial, so --resume loses nothing).
#include <filesystem>
#include <iostream>
#include <thread>

#include "commands.hpp"
#include "demcal/biaxial.hpp"
#include "demcal/calibration.hpp"
#include "demcal/output.hpp"
#include "demcal/packing.hpp"
#include "demcal/trial.hpp"

namespace demcal::cli {

namespace {

nlohmann::json param_block(const AlgorithmSpec& p, const ReferenceScales& s, int64_t particles) {
  const double dt = p.dt_ratio * s.dt_crit;
  return {{"particles", particles},
          {"dt", dt},
          {"dt_ratio", p.dt_ratio},
          {"dt_crit", s.dt_crit},
          {"steps", p.steps},
          {"damping_translation", p.damping_ratio_translation * s.damping_translation_crit},
          {"damping_ratio_translation", p.damping_ratio_translation},
          {"damping_rotation", p.damping_ratio_rotation * s.damping_rotation_crit},
          {"damping_ratio_rotation", p.damping_ratio_rotation},
          {"mass_scaling", p.mass_scaling}};
}

}  // namespace

int cmd_calibrate(const CalibrateOptions& o) {
  SceneConfig config = load_scene(o.config, o.sets);
  if (o.max_trials > 0) config.calibration.max_trials = o.max_trials;
  if (o.accuracy > 0) config.calibration.accuracy = o.accuracy;
  if (o.accuracy < 0 || o.accuracy >= 1)
    throw InputError("--accuracy", "", "must be a fraction in (0, 1), e.g. 0.02");
  const std::string dir = o.out_dir.empty() ? "demcal-" + config.name : o.out_dir;
  const std::string trials_path = dir + "/trials.jsonl";
  if (o.resume && !std::filesystem::exists(trials_path))
    throw InputError(trials_path, "", "--resume needs the trials.jsonl of an earlier run");

  Assembly assembly = make_assembly(config);
  std::cerr << "demcal: consolidating " << assembly.size() << " particles of " << config.name
            << " to sigma3 = " << config.test.lateral_stress << " Pa\n";
  const ConsolidatedState state = consolidate(config, assembly);
  std::cerr << "demcal: consolidated in " << state.steps << " steps (" << state.wall_time_s
            << " s)\n";

  make_output_dir(dir);
  if (!o.resume) std::filesystem::remove(trials_path);

  CalibrationOptions options;
  options.strategy = o.strategy;
  options.max_trials = config.calibration.max_trials;
  options.jobs = o.jobs;
  options.accuracy = config.calibration.accuracy;
  options.seed = config.calibration.seed;
  options.trials_path = trials_path;
  options.resume = o.resume;
  if (!o.quiet) options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  const CalibrationSummary summary = calibrate(config, state, options);

  const ReferenceScales scales = [&] {
    World w = state.world;
    Integration in;
    in.mass_scaling = summary.best.mass_scaling;
    w.set_integration(in);
    return w.reference_scales();
  }();
  const int64_t n_rev = state.world.size();
  const int64_t n_proto = config.prototype.particles > 0 ? config.prototype.particles : n_rev;
  AlgorithmSpec proto = summary.best;
  // Tu & Andrade: Nstep grows linearly with the particle count; the
  // multipliers do not depend on size.
  proto.steps =
      static_cast<int64_t>(std::llround(static_cast<double>(summary.best.steps) *
                                        static_cast<double>(n_proto) / static_cast<double>(n_rev)));

  nlohmann::json params{
      {"schema", "demcal.params/1"},
      {"scene", config.name},
      {"success", summary.success},
      {"message", summary.message},
      {"rev", param_block(summary.best, scales, n_rev)},
      {"prototype", param_block(proto, scales, n_proto)},
      {"upscaling", {{"law", "linear"}, {"factor", static_cast<double>(n_proto) / n_rev}}},
      {"criteria", to_json(summary.best_trial.criteria)},
      {"tolerances", to_json(options.tolerances)},
      {"accuracy", options.accuracy},
      {"certificate",
       {{"steps", summary.certificate.steps},
        {"peak_stress_yy", summary.certificate.peak},
        {"peak_stress_yy_steps_doubled", summary.certificate.peak_doubled},
        {"steps_doubled_peak_change", summary.certificate.steps_doubled_peak_change},
        {"richardson_error", summary.certificate.richardson_error},
        {"passed", summary.certificate.passed}}},
      {"dt_ratio_stable", summary.dt_ratio_stable},
      {"strategy", summary.strategy},
      {"trials", static_cast<int>(summary.trials.size())},
      {"wall_time_s", summary.wall_time_s},
      {"seed", config.calibration.seed},
      {"config_sha256", sha256_hex(config.text)},
      {"version", DEMCAL_VERSION}};
  if (auto a = analytical_peak_stress(config)) params["analytical_peak_stress_yy"] = *a;
  write_file_atomic(dir + "/params.json", params.dump(2) + "\n");

  std::cout << summary.BriefReport() << "  wrote " << dir << "/params.json, " << dir
            << "/trials.jsonl\n";
  return summary.success ? 0 : 1;
}

}  // namespace demcal::cli
