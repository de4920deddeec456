// `demcal calibrate`: the main job. Writes DIR/params.json (deterministic:
// the same config and seed give the same bytes, whatever --jobs or
// --resume), DIR/run.json (this invocation: wall time, jobs, trials run and
// reused), DIR/trials.jsonl (appended per trial, so --resume loses nothing)
// and the report, DIR/report.html and DIR/report.md; with --evidence also
// DIR/evidence.jsonl (the paper-recipe baseline and the reference runs).
// SIGINT/SIGTERM stop it cleanly after consolidation, exit status 128 +
// signal: finished trials stay in trials.jsonl; during the search or the
// evidence runs nothing else is written; once params.json (and run.json)
// are written, the report is skipped if its reruns have not started, or
// finished if they have.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string_view>

#include "commands.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/report/report.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/parallel.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "stop_signal.hpp"

namespace demcal::cli {

namespace {

/// Shell-quoted for display: the user copies it into a shell.
std::string shell_word(const std::string& w) {
  const bool plain = !w.empty() && std::all_of(w.begin(), w.end(), [](unsigned char c) {
    return std::isalnum(c) || std::string_view("_./=:,+-@%").find(c) != std::string_view::npos;
  });
  if (plain) return w;
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string reproduce_command(const CalibrateOptions& o, const SceneConfig& config,
                              const std::string& dir) {
  std::vector<std::string> args{"demcal", "calibrate"};
  if (!o.config.empty()) args.push_back(o.config);
  for (const auto& s : o.sets) {
    args.push_back("--set");
    args.push_back(s);
  }
  args.insert(args.end(), {"-o", dir, "--max-trials", std::to_string(config.calibration.max_trials),
                           "--accuracy", nlohmann::json(config.calibration.accuracy).dump(),
                           "--strategy", o.strategy});
  if (o.evidence) args.push_back("--evidence");
  std::string out;
  for (const auto& a : args) {
    if (!out.empty()) out += ' ';
    out += shell_word(a);
  }
  return out;
}

/// run.json: what varies between invocations (kept out of params.json).
nlohmann::json run_record(double wall_time_s, const CalibrationSummary& summary,
                          double consolidation_wall_time_s, bool consolidation_from_cache, int jobs,
                          bool resumed) {
  return {{"schema", "demcal.run/1"},
          {"wall_time_s", wall_time_s},
          {"calibration_wall_time_s", summary.wall_time_s},
          {"consolidation_wall_time_s", consolidation_wall_time_s},
          {"consolidation_from_cache", consolidation_from_cache},
          {"jobs", jobs},
          {"resumed", resumed},
          {"trials_run", summary.trials_run},
          {"trials_reused", summary.trials_reused},
          {"kernel_simd", kernel_simd()},
          {"version", DEMCAL_VERSION}};
}

/// DIR/resume.json: what the trials of DIR/trials.jsonl were run with.
/// Written when a calibration starts afresh; --resume reuses the trials only
/// when everything that changes a trial's outcome or the search is the same
/// (the config as given with its --set, --accuracy, --strategy, demcal's
/// version). --max-trials, --jobs and --evidence do not change a trial.
nlohmann::json resume_key(const SceneConfig& config, const Strategy strategy) {
  return {{"schema", "demcal.resume/1"},
          {"config_sha256", sha256_hex(config.text)},
          {"accuracy", config.calibration.accuracy},
          {"strategy", to_string(strategy)},
          {"version", DEMCAL_VERSION}};
}

/// --resume into `dir`: the trials there must come from the same settings,
/// or the result would be another calibration's (one error, exit 2,
/// nothing changed).
void require_same_run(const std::string& dir, const nlohmann::json& key) {
  const std::string path = dir + "/resume.json";
  const char* fresh = "calibrate afresh without --resume (or into another -o)";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(path, "",
                     std::string("missing: the trials in this folder cannot be matched to their "
                                 "settings (an older demcal or not a calibration); ") +
                         fresh);
  nlohmann::json stored;
  try {
    stored = parse_config_json(read_text_file(path), path);
  } catch (const InputError& e) {
    throw InputError(path, "", std::string(e.what()) + "; " + fresh);
  }
  const auto shown = [](const nlohmann::json& v) {
    return v.is_string() ? quoted_value(v.get<std::string>()) : quoted_value(v.dump());
  };
  for (const auto& [name, value] : key.items())
    if (!stored.is_object() || !stored.contains(name) || stored[name] != value)
      throw InputError(path, name,
                       "the trials in " + dir + "/trials.jsonl were run with " +
                           (stored.is_object() && stored.contains(name) ? shown(stored[name])
                                                                        : std::string("nothing")) +
                           ", this run has " + shown(value) +
                           "; --resume reuses only trials of the same config, --set, --accuracy, "
                           "--strategy and demcal version: " +
                           fresh);
}

/// The report: the start point and the result rerun with their series, the
/// picture at the peak, then plots and text. Returns the files written, for
/// the closing line ("" when the report failed: a warning, not a failure).
std::string write_report(const CalibrateOptions& o, const SceneConfig& config,
                         const ConsolidatedState& state, const std::string& dir,
                         const nlohmann::json& params, const CalibrationSummary& summary,
                         const CalibrationOptions& options, std::optional<BaselineResult> baseline,
                         std::optional<ReferenceEvidence> reference, int jobs) {
  const int64_t n_rev = state.world.size();
  try {
    const auto t0 = std::chrono::steady_clock::now();
    ReportInput in;
    in.scene = config.name;
    in.command = reproduce_command(o, config, dir);
    in.params = params;
    in.summary = summary;
    in.tolerances = options.tolerances;
    in.accuracy = options.accuracy;
    in.lateral_stress = config.test.lateral_stress;
    in.dt_ratio_max = dt_ratio_max(options, summary.dt_ratio_stable);
    in.particles = n_rev;
    in.prototype_particles = config.prototype.particles > 0 ? config.prototype.particles : n_rev;
    in.analytical_peak = analytical_peak_stress(config);
    in.baseline = std::move(baseline);
    in.reference = std::move(reference);
    // The search's first start, as it ran.
    const AlgorithmSpec start =
        rounded_params(search_start(config.algorithm, n_rev, in.dt_ratio_max));
    // A stop now: finish, the runs are done.
    attach_runs(in, rerun_start_and_result(config, state, start, summary, in.tolerances, jobs));
    const auto t1 = std::chrono::steady_clock::now();
    const Report report = make_report(in);
    OutputFolder out(dir);  // the two renderings of one report, together
    out.write("report.html", report.html);
    out.write("report.md", report.markdown);
    out.commit();
    if (!o.quiet)
      std::cerr << "demcal: report: reruns " << std::chrono::duration<double>(t1 - t0).count()
                << " s, writing " << seconds_since(t1) << " s; " << report.plot_status << "\n";
    return ", " + dir + "/report.html, " + dir + "/report.md";
  } catch (const std::exception& e) {
    std::cerr << "demcal: warning: the report was not written: " << e.what() << "\n";
    return "";
  }
}

}  // namespace

int cmd_calibrate(const CalibrateOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  // 2D scenes as every command loads them; 3D (spheres, triaxial test) too.
  SceneConfig config = load_config(o.config, o.sets);
  const bool three_d = config.dimension == 3;
  if (o.max_trials > 0) config.calibration.max_trials = o.max_trials;
  if (o.accuracy > 0) config.calibration.accuracy = o.accuracy;
  if (o.accuracy < 0 || o.accuracy >= 1)
    throw InputError("--accuracy", "", "must be a fraction in (0, 1), e.g. 0.02");
  const Strategy strategy = parse_strategy(o.strategy, "--strategy");
  const std::string dir = o.out_dir.empty() ? "demcal-" + config.name : o.out_dir;
  const std::string trials_path = dir + "/trials.jsonl";
  OutputFolder::check(dir);  // an unwritable -o fails now, not after the search
  if (o.resume && !std::filesystem::exists(trials_path))
    throw InputError(trials_path, "", "--resume needs the trials.jsonl of an earlier run");
  const nlohmann::json key = resume_key(config, strategy);
  if (o.resume) {
    require_readable_file(trials_path);  // a folder named trials.jsonl: one line
    require_same_run(dir, key);          // before the consolidation's seconds
  }

  // The consolidated REV: disks (biaxial, cached) or spheres (triaxial).
  std::optional<ConsolidatedState> state2;
  std::optional<TriaxialState> state3;
  int64_t n_rev = 0;
  int64_t consolidation_steps = 0;
  double consolidation_wall_time_s = 0.0;
  bool from_cache = false;
  if (three_d) {
    const SphereAssembly assembly = make_sphere_assembly(config);
    if (!o.quiet)
      std::cerr << "demcal: consolidating " << assembly.size() << " spheres of " << config.name
                << " to sigma3 = " << config.test.lateral_stress << " Pa (3D, triaxial)\n";
    state3.emplace(consolidate_triaxial(config, assembly));
    n_rev = state3->world.size();
    consolidation_steps = state3->steps;
    consolidation_wall_time_s = state3->wall_time_s;
  } else {
    Assembly assembly = make_assembly(config);
    if (!o.quiet)
      std::cerr << "demcal: consolidating " << assembly.size() << " particles of " << config.name
                << " to sigma3 = " << config.test.lateral_stress << " Pa\n";
    state2.emplace(consolidate(config, assembly));
    n_rev = state2->world.size();
    consolidation_steps = state2->steps;
    consolidation_wall_time_s = state2->wall_time_s;
    from_cache = state2->from_cache;
  }
  if (!o.quiet)
    std::cerr << "demcal: consolidated in " << consolidation_steps << " steps ("
              << (from_cache ? "read from the consolidation cache"
                             : std::to_string(consolidation_wall_time_s) + " s")
              << ")\n";

  // From here on a signal stops cleanly (consolidation writes nothing, so
  // the default action is fine before).
  const StopOnSignal stop;
  make_output_dir(dir);
  // Held to the end: a second calibration into this folder stops here,
  // before it changes anything.
  const FolderLock lock(dir);
  if (o.resume) {
    require_same_run(dir, key);  // unchanged since the check above?
    // A damaged trials.jsonl stops the run before anything is removed.
    read_trials_text(read_text_file(trials_path), trials_path);
  }
  remove_stale_temporaries(dir);
  if (!o.resume) {
    require_regular_file_target(trials_path);
    std::filesystem::remove(trials_path);
    write_file_atomic(dir + "/resume.json", key.dump(2) + "\n");
  }
  // Results of an earlier run in this folder would not match the trials
  // from here on; they are rewritten at the end.
  for (const char* name : {"params.json", "run.json", "report.html", "report.md", "evidence.jsonl"})
    std::filesystem::remove(dir + "/" + name);

  CalibrationOptions options = CalibrationOptions::from(config);
  options.strategy = strategy;
  options.jobs = o.jobs;
  options.trials_path = trials_path;
  options.resume = o.resume;
  if (!o.quiet) options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  options.stop = &stop.flag();
  const CalibrationSummary summary =
      three_d ? calibrate(config, *state3, options) : calibrate(config, *state2, options);
  const auto interrupted = [&](const std::string& what) {
    std::cerr << "demcal: interrupted" << what << "; " << summary.trials.size()
              << " finished trials are in " << trials_path << ". Continue with:\n  "
              << reproduce_command(o, config, dir) << " --resume\n";
    return stop.exit_status();
  };
  if (summary.interrupted) return interrupted("");

  nlohmann::json params = three_d ? params_file(config, *state3, options, summary)
                                  : params_file(config, *state2, options, summary);

  const bool have_best = summary.best_trial.score.particle_steps > 0.0;
  const int jobs = resolve_jobs(o.jobs);
  auto say = [&](const std::string& line) {
    if (!o.quiet) std::cerr << "demcal: " << line << "\n";
  };

  // --evidence: the paper's recipe done mechanically (α = 0.2, ζ = 1,
  // Nstep doubled from the search's size-based start until it passes) and a
  // converged reference from the calibrated multipliers.
  std::optional<BaselineResult> baseline;
  std::optional<ReferenceEvidence> reference;
  std::string evidence_lines;  // evidence.jsonl, written with params.json
  if (o.evidence && have_best && three_d)
    say("--evidence: the paper-recipe baseline and the converged reference are 2D only for now "
        "(issue #18); skipped for this 3D scene");
  if (o.evidence && have_best && !three_d) {
    say("evidence: paper-recipe baseline and converged reference (8x, 16x Nstep = " +
        std::to_string(16 * summary.best.steps) + ")");
    auto run_baseline = [&] {
      baseline = paper_recipe_baseline(config, *state2, options.tolerances,
                                       kStartStepsPerParticle * n_rev);
    };
    auto run_reference = [&] {
      reference = run_refined_reference(config, *state2, summary.best, options.tolerances, 1);
    };
    run_parallel({run_baseline, run_reference}, jobs);
    const CalibrationEvidence evidence{*reference, *baseline, kStartStepsPerParticle * n_rev};
    evidence_lines = demcal::evidence_lines(evidence);
    params["evidence"] = evidence_block(evidence, summary.best_trial);
  }
  // The evidence and report runs do not poll the flag (seconds on a REV):
  // a stop asked for during them takes effect here.
  if (stop.stopped()) return interrupted(" during the evidence runs (nothing written)");
  // What varies between invocations stays out of params.json (run.json).
  // Written with params.json, and again after the report with the total.
  const auto run_json = [&] {
    return run_record(seconds_since(t_start), summary, consolidation_wall_time_s, from_cache, jobs,
                      o.resume)
               .dump(2) +
           "\n";
  };
  {
    // params.json, run.json and evidence.jsonl of one calibration replace
    // those of an earlier one together (an evidence.jsonl of an earlier
    // --evidence run that this one does not redo goes with them).
    OutputFolder out(dir);
    if (!evidence_lines.empty())
      out.write("evidence.jsonl", evidence_lines);
    else
      out.retire("evidence.jsonl");
    out.write("params.json", params.dump(2) + "\n");
    out.write("run.json", run_json());
    out.commit();
  }
  const auto write_run_json = [&] { write_file_atomic(dir + "/run.json", run_json()); };
  if (stop.stopped())
    return interrupted(
        " before the report (params.json and run.json are written; --resume reuses every trial "
        "and writes the report)");

  std::string report_note;
  if (three_d) {
    // The 3D report (panels, picture) is not written yet: said, not crashed.
    std::cerr << "demcal: note: no report for 3D scenes yet (issue #18, report part); params.json "
                 "and trials.jsonl hold the result\n";
  } else {
    report_note = write_report(o, config, *state2, dir, params, summary, options,
                               std::move(baseline), std::move(reference), jobs);
  }

  write_run_json();
  std::cout << summary.BriefReport() << "  wrote " << dir << "/params.json, " << dir
            << "/run.json, " << dir << "/trials.jsonl" << report_note
            << (o.evidence && have_best && !three_d ? ", " + dir + "/evidence.jsonl" : "") << "\n";
  if (stop.stopped()) {
    std::cerr << "demcal: interrupted after the last run; every output was written\n";
    return stop.exit_status();
  }
  return summary.success ? 0 : 1;
}

}  // namespace demcal::cli
