// `demcal scaling`: the proof of the upscaling law (issue #6 §3). A family
// of scenes that differ only in size is calibrated at every size up to
// --calibrate-max; Nstep is fitted against N (linear: slope, intercept, R²;
// power: exponent), the multipliers' spread across sizes is measured, the
// smallest passing Nstep at FIXED multipliers (the largest REV's) is found
// at every size, and the law is checked forward: the largest size is run
// with the REV's multipliers and Nstep upscaled from it, and scored.
// Writes DIR/scaling.md and DIR/scaling.json; per-size work (trials,
// results) goes to --work and is reused with --resume.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "commands.hpp"
#include "demcal/io/format.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json algo_json(const AlgorithmSpec& p) {
  return {{"dt_ratio", p.dt_ratio},
          {"steps", p.steps},
          {"damping_ratio_translation", p.damping_ratio_translation},
          {"damping_ratio_rotation", p.damping_ratio_rotation},
          {"mass_scaling", p.mass_scaling}};
}

AlgorithmSpec algo_from(const json& j, AlgorithmSpec base) {
  base.dt_ratio = j.at("dt_ratio").get<double>();
  base.steps = j.at("steps").get<int64_t>();
  base.damping_ratio_translation = j.at("damping_ratio_translation").get<double>();
  base.damping_ratio_rotation = j.at("damping_ratio_rotation").get<double>();
  base.mass_scaling = j.at("mass_scaling").get<double>();
  return base;
}

json trial_json(const TrialRecord& t) {
  return {{"params", algo_json(t.params)},
          {"passed", t.passed},
          {"diverged", t.diverged},
          {"worst_excess", t.worst_excess},
          {"force_balance", t.criteria.force_balance},
          {"moment_balance", t.criteria.moment_balance},
          {"servo", t.criteria.servo},
          {"oscillation", t.criteria.oscillation},
          {"peak_stress_yy", t.criteria.peak_stress_yy},
          {"particle_steps", t.particle_steps},
          {"wall_time_s", t.wall_time_s},
          {"diagnosis", t.diagnosis}};
}

std::string fmt(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}
std::string pct(double v, int digits = 3) { return fmt(100.0 * v, digits) + " %"; }

std::vector<int64_t> parse_sizes(const std::string& text) {
  std::vector<int64_t> sizes;
  std::stringstream s(text);
  for (std::string f; std::getline(s, f, ',');) {
    char* end = nullptr;
    const long long v = std::strtoll(f.c_str(), &end, 10);
    if (f.empty() || *end != '\0' || v < 4 || v > 10000000)
      throw InputError("--sizes", "",
                       "expected particle counts >= 4 separated by commas, got \"" + text + "\"");
    sizes.push_back(v);
  }
  std::sort(sizes.begin(), sizes.end());
  sizes.erase(std::unique(sizes.begin(), sizes.end()), sizes.end());
  if (sizes.size() < 2) throw InputError("--sizes", "", "needs at least two sizes");
  return sizes;
}

struct SizeResult {
  int64_t requested = 0, particles = 0;
  bool calibrated = false, success = false;
  AlgorithmSpec best;
  double richardson = 0.0, peak = 0.0;
  int trials = 0;
  double wall_time_s = 0.0, consolidation_s = 0.0;
  int64_t consolidation_steps = 0;
  // The smallest passing Nstep at the reference multipliers.
  bool fixed_found = false;
  int64_t fixed_steps = 0;
  TrialRecord fixed;
  std::vector<TrialRecord> fixed_trials;
  double fixed_wall_time_s = 0.0;
  json to_json() const {
    json j{{"requested", requested},
           {"particles", particles},
           {"calibrated", calibrated},
           {"consolidation_steps", consolidation_steps},
           {"consolidation_wall_time_s", consolidation_s}};
    if (calibrated)
      j.update({{"success", success},
                {"best", algo_json(best)},
                {"steps_per_particle", static_cast<double>(best.steps) / particles},
                {"richardson_error", richardson},
                {"peak_stress_yy", peak},
                {"trials", trials},
                {"wall_time_s", wall_time_s}});
    if (!fixed_trials.empty()) {
      json runs = json::array();
      for (const auto& t : fixed_trials) runs.push_back(trial_json(t));
      j["fixed_multipliers"] = {{"found", fixed_found},
                                {"steps", fixed_steps},
                                {"best", fixed_found ? trial_json(fixed) : json()},
                                {"runs", runs},
                                {"wall_time_s", fixed_wall_time_s}};
    }
    return j;
  }
};

json fit_json(const LinearFit& lin, const LinearFit& pw) {
  return {{"linear", {{"slope", lin.slope}, {"intercept", lin.intercept}, {"r2", lin.r2}}},
          {"power",
           {{"exponent", pw.slope}, {"coefficient", std::exp(pw.intercept)}, {"r2_log", pw.r2}}}};
}

struct Spread {
  double mean = 0, min = 0, max = 0, relative = 0;
};
Spread spread_of(const std::vector<double>& v) {
  Spread s;
  if (v.empty()) return s;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  s.relative = s.mean > 0 ? (s.max - s.min) / s.mean : 0.0;
  return s;
}

}  // namespace

int cmd_scaling(const ScalingOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  SceneConfig config = load_scene(o.config, o.sets);
  if (o.max_trials > 0) config.calibration.max_trials = o.max_trials;
  const std::vector<int64_t> sizes = parse_sizes(o.sizes);
  const int64_t calibrate_max = o.calibrate_max > 0 ? o.calibrate_max : 400;
  std::vector<int64_t> calibrated_sizes, forward_sizes;
  for (int64_t n : sizes) (n <= calibrate_max ? calibrated_sizes : forward_sizes).push_back(n);
  if (calibrated_sizes.size() < 2)
    throw InputError(
        "--sizes", "",
        "needs at least two sizes <= --calibrate-max (" + std::to_string(calibrate_max) + ")");
  const int64_t forward_size = sizes.back();
  // The REV the law is carried from: the largest calibrated size below the
  // largest size.
  int64_t ref_size = 0;
  for (int64_t n : calibrated_sizes)
    if (n < forward_size) ref_size = n;
  if (ref_size == 0) throw InputError("--sizes", "", "needs a calibrated size below the largest");

  // The family: resized generators, or REVs cut from the prototype file.
  const bool from_file = config.assembly.type == "file";
  Assembly file_prototype;
  if (from_file) {
    file_prototype = read_particle_file(config.prototype.file.empty() ? config.assembly.file
                                                                      : config.prototype.file);
    if (file_prototype.size() < forward_size)
      throw InputError(
          "--sizes", "",
          "the prototype file has only " + std::to_string(file_prototype.size()) + " particles");
  }
  auto scene_for = [&](int64_t n) { return from_file ? config : scene_of_size(config, n); };

  const std::string work = o.work_dir.empty() ? "demcal-scaling-" + config.name : o.work_dir;
  const std::string out_dir = o.out_dir.empty() ? "reports" : o.out_dir;
  make_output_dir(work);
  make_output_dir(out_dir);
  auto log = [&](const std::string& line) {
    if (!o.quiet) std::cerr << "demcal scaling: " << line << "\n";
  };
  log("family: " +
      (from_file ? "REVs cut from a " + std::to_string(file_prototype.size()) + "-particle file"
                 : config.assembly.type + " generator of " + config.name) +
      "; sizes " + o.sizes + "; calibrated up to " + std::to_string(calibrate_max) +
      "; the REV whose multipliers are carried: " + std::to_string(ref_size));

  // Consolidated states. A size that is not calibrated keeps its
  // consolidated packing in the work folder, so that --resume re-settles a
  // dense file in a few thousand steps instead of compressing a gas again.
  std::map<int64_t, ConsolidatedState> states;
  auto state_for = [&](int64_t n) -> const ConsolidatedState& {
    auto it = states.find(n);
    if (it != states.end()) return it->second;
    const std::string cache = work + "/size-" + std::to_string(n) + "/consolidated.csv";
    const bool cached = o.resume && n > calibrate_max && fs::exists(cache);
    const Assembly a = cached      ? read_particle_file(cache)
                       : from_file ? cut_rev(file_prototype, n)
                                   : make_assembly(scene_of_size(config, n));
    log("consolidating " + std::to_string(a.size()) + " particles (size " + std::to_string(n) +
        (cached ? ", from " + cache : std::string()) + ")");
    auto [pos, _] = states.emplace(n, consolidate(scene_for(n), a));
    log("  consolidated in " + std::to_string(pos->second.steps) + " steps, " +
        fmt(pos->second.wall_time_s, 3) + " s");
    if (n > calibrate_max && !cached) {
      make_output_dir(work + "/size-" + std::to_string(n));
      write_file_atomic(cache, particle_csv(assembly_of(pos->second.world)));
    }
    return pos->second;
  };

  // 1. Calibrate every size up to calibrate_max (reused with --resume).
  std::map<int64_t, SizeResult> results;
  for (int64_t n : calibrated_sizes) {
    const std::string dir = work + "/size-" + std::to_string(n);
    const std::string result_path = dir + "/result.json";
    SizeResult r;
    r.requested = n;
    if (o.resume && fs::exists(result_path)) {
      std::ifstream in(result_path);
      const json j = json::parse(in);
      r.particles = j.at("particles").get<int64_t>();
      r.calibrated = true;
      r.success = j.at("success").get<bool>();
      r.best = algo_from(j.at("best"), config.algorithm);
      r.richardson = j.at("richardson_error").get<double>();
      r.peak = j.at("peak_stress_yy").get<double>();
      r.trials = j.at("trials").get<int>();
      r.wall_time_s = j.at("wall_time_s").get<double>();
      r.consolidation_steps = j.value("consolidation_steps", int64_t{0});
      r.consolidation_s = j.value("consolidation_wall_time_s", 0.0);
      log("size " + std::to_string(n) + ": reusing " + result_path);
      results[n] = r;
      continue;
    }
    make_output_dir(dir);
    const ConsolidatedState& state = state_for(n);
    r.particles = state.world.size();
    r.consolidation_steps = state.steps;
    r.consolidation_s = state.wall_time_s;
    CalibrationOptions co;
    co.max_trials = config.calibration.max_trials;
    co.jobs = o.jobs;
    co.accuracy = config.calibration.accuracy;
    co.seed = config.calibration.seed;
    co.trials_path = dir + "/trials.jsonl";
    fs::remove(co.trials_path);
    if (!o.quiet)
      co.progress = [n](const std::string& line) {
        std::cerr << "demcal scaling: size " << n << ": " << line << "\n";
      };
    const CalibrationSummary s = calibrate(scene_for(n), state, co);
    r.calibrated = true;
    r.success = s.success;
    r.best = s.best;
    r.richardson = s.certificate.richardson_error;
    r.peak = s.certificate.peak;
    r.trials = static_cast<int>(s.trials.size());
    r.wall_time_s = s.wall_time_s;
    write_file_atomic(result_path, r.to_json().dump(2) + "\n");
    log("size " + std::to_string(n) + ": " + (s.success ? "calibrated" : "FAILED") + ", steps " +
        std::to_string(s.best.steps) + ", alpha " + fmt(s.best.dt_ratio) + ", zeta_t " +
        fmt(s.best.damping_ratio_translation) + ", zeta_r " + fmt(s.best.damping_ratio_rotation) +
        " (" + fmt(s.wall_time_s, 3) + " s)");
    results[n] = r;
  }
  const SizeResult ref = results.at(ref_size);
  if (!ref.success)
    throw std::runtime_error("the REV (size " + std::to_string(ref_size) +
                             ") did not calibrate: no multipliers to carry (see " + work + ")");

  // 2. The smallest passing Nstep at the REV's multipliers, at every size.
  // At a size beyond the calibrated ones the search starts at the linear
  // prediction: that first run is the forward check of the linear law.
  const Tolerances tolerances;
  std::map<int64_t, TrialRecord> forward_linear;
  for (int64_t n : sizes) {
    SizeResult& r = results[n];
    r.requested = n;
    if (n == ref_size) {
      r.fixed_found = true;
      r.fixed_steps = r.best.steps;
      continue;
    }
    const std::string dir = work + "/size-" + std::to_string(n);
    const std::string fixed_path = dir + "/fixed.json";
    if (o.resume && fs::exists(fixed_path)) {
      std::ifstream in(fixed_path);
      const json j = json::parse(in);
      r.particles = j.at("particles").get<int64_t>();
      r.fixed_found = j.at("found").get<bool>();
      r.fixed_steps = j.at("steps").get<int64_t>();
      r.fixed_wall_time_s = j.value("wall_time_s", 0.0);
      for (const auto& t : j.at("runs")) {
        TrialRecord tr;
        tr.params = algo_from(t.at("params"), config.algorithm);
        tr.passed = t.at("passed").get<bool>();
        tr.diverged = t.at("diverged").get<bool>();
        tr.worst_excess = t.at("worst_excess").get<double>();
        tr.criteria.force_balance = t.at("force_balance").get<double>();
        tr.criteria.moment_balance = t.at("moment_balance").get<double>();
        tr.criteria.servo = t.at("servo").get<double>();
        tr.criteria.oscillation = t.at("oscillation").get<double>();
        tr.criteria.peak_stress_yy = t.at("peak_stress_yy").get<double>();
        tr.particle_steps = t.at("particle_steps").get<double>();
        tr.wall_time_s = t.at("wall_time_s").get<double>();
        tr.diagnosis = t.at("diagnosis").get<std::string>();
        r.fixed_trials.push_back(tr);
        if (tr.passed && tr.params.steps == r.fixed_steps) r.fixed = tr;
      }
      log("size " + std::to_string(n) + ": reusing " + fixed_path);
    } else {
      make_output_dir(dir);
      const ConsolidatedState& state = state_for(n);
      r.particles = state.world.size();
      const AlgorithmSpec start = upscale(ref.best, ref.particles, r.particles);
      log("size " + std::to_string(r.particles) +
          ": smallest passing Nstep at the REV's multipliers, from the linear prediction " +
          std::to_string(start.steps) + " (" +
          fmt(static_cast<double>(start.steps) * r.particles, 3) + " particle-steps)");
      const auto t0 = std::chrono::steady_clock::now();
      const StepSearch search = smallest_passing_steps(scene_for(n), state, start, tolerances);
      r.fixed_found = search.found;
      r.fixed_steps = search.found ? search.best.params.steps : 0;
      r.fixed = search.best;
      r.fixed_trials = search.trials;
      r.fixed_wall_time_s = seconds_since(t0);
      json fixed = r.to_json()["fixed_multipliers"];
      fixed["particles"] = r.particles;
      write_file_atomic(fixed_path, fixed.dump(2) + "\n");
      for (const auto& t : search.trials)
        log("  " + std::to_string(t.params.steps) + " steps: " + (t.passed ? "pass" : "fail") +
            " (worst " + fmt(t.worst_excess, 3) + "x tol), " + fmt(t.wall_time_s, 3) + " s");
    }
    if (n > calibrate_max && !r.fixed_trials.empty()) forward_linear[n] = r.fixed_trials.front();
  }

  // 3. Fits. The calibrated Nstep over the sizes that calibrated; Nstep at
  // fixed multipliers over all sizes and over the REV and larger (the
  // representative sizes: the law is carried upward from the REV).
  std::vector<double> n_cal, steps_cal, n_fix, steps_fix, n_rep, steps_rep;
  std::vector<double> alphas, zetas_t, zetas_r;
  for (int64_t n : calibrated_sizes) {
    const SizeResult& r = results[n];
    if (!r.success) continue;
    n_cal.push_back(static_cast<double>(r.particles));
    steps_cal.push_back(static_cast<double>(r.best.steps));
    alphas.push_back(r.best.dt_ratio);
    zetas_t.push_back(r.best.damping_ratio_translation);
    zetas_r.push_back(r.best.damping_ratio_rotation);
  }
  for (int64_t n : sizes) {
    const SizeResult& r = results[n];
    if (!r.fixed_found) continue;
    n_fix.push_back(static_cast<double>(r.particles));
    steps_fix.push_back(static_cast<double>(r.fixed_steps));
    if (n >= ref_size) {
      n_rep.push_back(static_cast<double>(r.particles));
      steps_rep.push_back(static_cast<double>(r.fixed_steps));
    }
  }
  const LinearFit lin_cal = fit_linear(n_cal, steps_cal), pow_cal = fit_power(n_cal, steps_cal);
  const LinearFit lin_fix = fit_linear(n_fix, steps_fix), pow_fix = fit_power(n_fix, steps_fix);
  const LinearFit lin_rep = fit_linear(n_rep, steps_rep), pow_rep = fit_power(n_rep, steps_rep);
  ScalingLaw measured;
  measured.exponent = n_rep.size() >= 2 ? pow_rep.slope : 1.0;
  measured.source = "demcal scaling " + config.name + ": smallest passing Nstep at the " +
                    std::to_string(ref.particles) + "-particle REV's multipliers, sizes >= REV";
  // Linear when the measured exponent is within 0.1 of 1; a smaller one
  // means the linear law spends steps for nothing, a larger one that it
  // falls short.
  const bool linear_holds = std::abs(measured.exponent - 1.0) <= 0.1;
  const Spread s_alpha = spread_of(alphas), s_zt = spread_of(zetas_t), s_zr = spread_of(zetas_r);

  // 4. Forward check at the largest size: the linear law's run (the first
  // of the search) against a reference with twice its steps.
  const double accuracy = config.calibration.accuracy;
  const bool have_forward = forward_linear.count(forward_size) > 0;
  TrialRecord linear_run, reference;
  double linear_peak_error = 0.0;
  if (have_forward) {
    linear_run = forward_linear[forward_size];
    const std::string ref_path = work + "/size-" + std::to_string(forward_size) + "/reference.json";
    AlgorithmSpec ref_params = linear_run.params;
    ref_params.steps = 2 * linear_run.params.steps;
    if (o.resume && fs::exists(ref_path)) {
      std::ifstream in(ref_path);
      const json j = json::parse(in);
      reference.params = algo_from(j.at("params"), config.algorithm);
      reference.passed = j.at("passed").get<bool>();
      reference.worst_excess = j.at("worst_excess").get<double>();
      reference.criteria.force_balance = j.at("force_balance").get<double>();
      reference.criteria.servo = j.at("servo").get<double>();
      reference.criteria.peak_stress_yy = j.at("peak_stress_yy").get<double>();
      reference.wall_time_s = j.at("wall_time_s").get<double>();
    } else {
      log("forward reference at " + std::to_string(forward_size) + ": " +
          std::to_string(ref_params.steps) + " steps");
      reference =
          run_trial(scene_for(forward_size), state_for(forward_size), ref_params, tolerances);
      write_file_atomic(ref_path, trial_json(reference).dump(2) + "\n");
    }
    const double ref_peak = reference.criteria.peak_stress_yy;
    linear_peak_error = ref_peak != 0.0
                            ? (std::abs(linear_run.criteria.peak_stress_yy) - std::abs(ref_peak)) /
                                  std::abs(ref_peak)
                            : 0.0;
  }
  const bool forward_ok =
      have_forward && linear_run.passed && std::abs(linear_peak_error) <= accuracy;
  // The law upscaling uses: linear while the forward check confirms it (a
  // smaller measured exponent would save steps, but it was fitted on the
  // forward size itself and has no independent check here); the measured
  // exponent when the linear law falls short.
  const ScalingLaw chosen = forward_ok || measured.exponent <= 1.0 ? ScalingLaw{} : measured;
  const SizeResult& fwd = results[forward_size];

  // 5. Outputs.
  json sizes_json = json::array();
  for (int64_t n : sizes) sizes_json.push_back(results[n].to_json());
  auto spread_json = [](const Spread& s) {
    return json{{"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"relative", s.relative}};
  };
  const json report{
      {"schema", "demcal.scaling/1"},
      {"scene", config.name},
      {"family", from_file ? "REVs cut from a particle file" : config.assembly.type + " generator"},
      {"sizes", sizes},
      {"calibrate_max", calibrate_max},
      {"results", sizes_json},
      {"fit_calibrated", fit_json(lin_cal, pow_cal)},
      {"fit_fixed_multipliers_all", fit_json(lin_fix, pow_fix)},
      {"fit_fixed_multipliers_from_rev", fit_json(lin_rep, pow_rep)},
      {"reference_rev", {{"particles", ref.particles}, {"params", algo_json(ref.best)}}},
      {"multiplier_spread",
       {{"dt_ratio", spread_json(s_alpha)},
        {"damping_ratio_translation", spread_json(s_zt)},
        {"damping_ratio_rotation", spread_json(s_zr)}}},
      {"measured_law", to_json(measured)},
      {"law", to_json(chosen)},
      {"linear_holds", linear_holds},
      {"forward",
       {{"particles", fwd.particles},
        {"from_rev", ref.particles},
        {"linear", have_forward ? trial_json(linear_run) : json()},
        {"reference", have_forward ? trial_json(reference) : json()},
        {"peak_error_vs_reference", linear_peak_error},
        {"accuracy", accuracy},
        {"passed", forward_ok}}},
      {"tolerances", to_json(tolerances)},
      {"wall_time_s", seconds_since(t_start)},
      {"config", to_json(config)},
      {"version", DEMCAL_VERSION}};

  std::ostringstream md;
  md << "# Upscaling law: Nstep against the particle count\n\n"
     << "Generated by `demcal scaling` (demcal " << DEMCAL_VERSION << ") on scene `" << config.name
     << "`: a family of "
     << (from_file ? "REVs cut from the prototype file"
                   : "`" + config.assembly.type + "` assemblies")
     << " that differ only in size (same material, test, distribution"
     << (config.assembly.type == "random" ? " and seed" : "") << "). Sizes " << o.sizes
     << "; calibrated up to " << calibrate_max << " particles; default tolerances (force balance "
     << tolerances.force_balance << ", moment balance " << tolerances.moment_balance << ", servo "
     << tolerances.servo << ", oscillation " << tolerances.oscillation << "); accuracy target "
     << pct(accuracy, 2) << ". Wall time of this invocation " << fmt(seconds_since(t_start), 3)
     << " s on a shared 2-core machine" << (o.resume ? " (finished sizes reused)" : "")
     << ". Machine-readable: `scaling.json`.\n\n";
  md << "## 1. Calibration at each size\n\n"
     << "| N | Nstep | Nstep/N | α | ζ_t | ζ_r | certified | Richardson error | trials | wall time "
        "|\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (int64_t n : calibrated_sizes) {
    const SizeResult& r = results[n];
    md << "| " << r.particles << " | " << r.best.steps << " | "
       << fmt(static_cast<double>(r.best.steps) / r.particles, 4) << " | "
       << fmt(r.best.dt_ratio, 3) << " | " << fmt(r.best.damping_ratio_translation, 3) << " | "
       << fmt(r.best.damping_ratio_rotation, 3) << " | "
       << (r.success ? "yes" : "**no** (best trial shown, not passing)") << " | "
       << (r.success ? pct(r.richardson, 2) : "–") << " | " << r.trials << " | "
       << fmt(r.wall_time_s, 3) << " s |\n";
  }
  md << "\nFit of the calibrated Nstep against N (" << n_cal.size()
     << " calibrated sizes): linear Nstep = " << fmt(lin_cal.slope, 5) << "·N + "
     << fmt(lin_cal.intercept, 5) << " (R² = " << fmt(lin_cal.r2, 4) << "); power Nstep ∝ N^"
     << fmt(pow_cal.slope, 3) << " (R² in log space " << fmt(pow_cal.r2, 4) << ").\n\n"
     << "Spread of the multipliers across the calibrated sizes ((max − min)/mean): α "
     << fmt(s_alpha.min, 3) << "–" << fmt(s_alpha.max, 3) << " (" << pct(s_alpha.relative, 3)
     << "), ζ_t " << fmt(s_zt.min, 3) << "–" << fmt(s_zt.max, 3) << " (" << pct(s_zt.relative, 3)
     << "), ζ_r " << fmt(s_zr.min, 3) << "–" << fmt(s_zr.max, 3) << " (" << pct(s_zr.relative, 3)
     << ").\n\n"
     << "The search returns the cheapest passing point; where the cost is flat in a multiplier,\n"
     << "that multiplier wanders between sizes without meaning, and the calibrated Nstep moves\n"
     << "with it. Whether the REV's multipliers carry over is therefore tested directly: they\n"
     << "are held fixed and the smallest passing Nstep is searched at every size.\n\n";
  md << "## 2. Nstep at fixed multipliers (the " << ref.particles << "-particle REV's: α "
     << fmt(ref.best.dt_ratio, 4) << ", ζ_t " << fmt(ref.best.damping_ratio_translation, 4)
     << ", ζ_r " << fmt(ref.best.damping_ratio_rotation, 4) << ")\n\n"
     << "| N | smallest passing Nstep | Nstep/N | linear prediction from the REV | found / "
        "predicted | runs |\n"
     << "|---|---|---|---|---|---|\n";
  for (int64_t n : sizes) {
    const SizeResult& r = results[n];
    const int64_t pred = upscale_steps(ref.best.steps, ref.particles, r.particles);
    md << "| " << r.particles << (n == ref_size ? " (REV)" : "") << " | "
       << (r.fixed_found ? std::to_string(r.fixed_steps) : "none") << " | "
       << (r.fixed_found ? fmt(static_cast<double>(r.fixed_steps) / r.particles, 4) : "–") << " | "
       << pred << " | " << (r.fixed_found ? fmt(static_cast<double>(r.fixed_steps) / pred, 3) : "–")
       << " | "
       << (n == ref_size ? std::string("calibration") : std::to_string(r.fixed_trials.size()))
       << " |\n";
  }
  md << "\nFrom the REV up (" << n_rep.size() << " sizes): linear Nstep = " << fmt(lin_rep.slope, 5)
     << "·N + " << fmt(lin_rep.intercept, 5) << " (R² = " << fmt(lin_rep.r2, 4)
     << "), power Nstep ∝ N^" << fmt(pow_rep.slope, 3) << ". Over all " << n_fix.size()
     << " sizes: linear " << fmt(lin_fix.slope, 5) << "·N + " << fmt(lin_fix.intercept, 5)
     << " (R² = " << fmt(lin_fix.r2, 4) << "), power N^" << fmt(pow_fix.slope, 3)
     << ". Below the REV the samples are not representative (a few\n"
     << "particles per wall): their Nstep says nothing about larger samples, which is why the law\n"
     << "is measured from the REV up.\n\n";
  md << "## 3. Forward check: " << fwd.particles << " particles, Nstep upscaled linearly from the "
     << ref.particles << "-particle REV\n\n";
  if (have_forward) {
    md << "The REV's multipliers unchanged, Nstep = " << ref.best.steps << " × " << fwd.particles
       << "/" << ref.particles << " = " << linear_run.params.steps
       << "; scored with the same criteria; the reference is the same run with twice the steps.\n\n"
       << "| run | Nstep | passes | worst criterion / tolerance | force balance | servo | peak "
          "σ_yy | peak vs reference | wall time |\n"
       << "|---|---|---|---|---|---|---|---|---|\n";
    auto row = [&](const std::string& label, const TrialRecord& t, const std::string& err) {
      md << "| " << label << " | " << t.params.steps << " | " << (t.passed ? "yes" : "**no**")
         << " | " << fmt(t.worst_excess, 3) << " | " << fmt(t.criteria.force_balance, 3) << " | "
         << fmt(t.criteria.servo, 3) << " | " << fmt(t.criteria.peak_stress_yy, 5) << " Pa | "
         << err << " | " << fmt(t.wall_time_s, 3) << " s |\n";
    };
    row("linear law", linear_run, pct(linear_peak_error, 3));
    row("reference (2×)", reference, "–");
    md << "\n";
  } else {
    md << "No size beyond --calibrate-max: no forward check.\n\n";
  }
  md << "## 4. Verdict\n\n"
     << "- Forward check of the linear law (Tu & Andrade) at " << fwd.particles
     << " particles: " << (forward_ok ? "**passed**" : "**failed**") << " (criteria "
     << (linear_run.passed ? "met" : "not met") << ", peak " << pct(linear_peak_error, 3)
     << " from the reference, target ±" << pct(accuracy, 2) << ").\n"
     << "- Measured at fixed multipliers from the REV up: Nstep ∝ N^" << fmt(measured.exponent, 3)
     << ". ";
  if (linear_holds)
    md << "Within 0.1 of 1: the linear law holds for our kernel on this family.\n";
  else if (measured.exponent < 1.0)
    md << "Below 1: on this family the linear law is conservative (the forward run passed\n"
          "  with room to spare); the measured exponent would save steps, but it is fitted on\n"
          "  the forward size itself, so it has no independent check here.\n";
  else
    md << "Above 1: the linear law falls short on this family.\n";
  md << "- Upscaling uses: **"
     << (chosen.name() == "linear" ? std::string("the linear law")
                                   : "Nstep ∝ N^" + fmt(chosen.exponent, 3))
     << "** (`law` in scaling.json, read by `demcal upscale|verify|export --law scaling.json`); "
     << (chosen.name() == "linear" && measured.exponent < 0.9
             ? "`--exponent " + fmt(measured.exponent, 3) +
                   "` applies the measured one at the user's risk (check it with `demcal verify`)."
             : std::string("the forward check above is its evidence."))
     << "\n";

  write_file_atomic(out_dir + "/scaling.json", report.dump(2) + "\n");
  write_file_atomic(out_dir + "/scaling.md", md.str());
  std::cout << "calibrated fit: slope " << fmt(lin_cal.slope, 5) << ", intercept "
            << fmt(lin_cal.intercept, 5) << ", R2 " << fmt(lin_cal.r2, 4)
            << "; fixed multipliers from the REV up: exponent " << fmt(measured.exponent, 3)
            << " (law " << chosen.name() << "); forward check of the linear law at "
            << fwd.particles << ": " << (forward_ok ? "passed" : "FAILED") << "\n  wrote "
            << out_dir << "/scaling.md, " << out_dir << "/scaling.json\n";
  return forward_ok ? 0 : 1;
}

}  // namespace demcal::cli
