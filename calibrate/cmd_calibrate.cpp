// `demcal calibrate`: the main job. Writes DIR/params.json (deterministic:
// the same config and seed give the same bytes, whatever --jobs or
// --resume), DIR/run.json (this invocation: wall time, jobs, trials run and
// reused), DIR/trials.jsonl (appended per trial, so --resume loses nothing)
// and the report, DIR/report.html and DIR/report.md (3D: and DIR/final.vtk,
// the calibrated run at its peak, when output.vtk); with --evidence also
// DIR/evidence.jsonl (the paper-recipe baseline and the reference runs).
// 3D: the report's runs are not rerun after the search: the result's series
// and world at its peak are kept from the search's own run of it, and the
// start point runs beside the search when --jobs > 1 (on the core the search
// leaves idle while it verifies or certifies one run at a time).
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
#include <future>
#include <iostream>
#include <optional>
#include <string_view>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/report/report.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/evidence.hpp"
#include "demcal/search/parallel.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "resume_key.hpp"
#include "shell_word.hpp"
#include "stop_signal.hpp"

namespace demcal::cli {

namespace {

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
  return shell_command(args);
}

/// run.json: what varies between invocations (kept out of params.json).
/// Its schema is its own: `demcal run`'s summary.json is "demcal.run/1".
nlohmann::json run_record(double wall_time_s, const CalibrationSummary& summary,
                          const ConsolidationRecord& consolidation, int jobs, bool resumed) {
  nlohmann::json j{{"schema", "demcal.calibration-run/1"},
                   {"wall_time_s", wall_time_s},
                   {"calibration_wall_time_s", summary.wall_time_s},
                   {"jobs", jobs},
                   {"resumed", resumed},
                   {"trials_run", summary.trials_run},
                   {"trials_reused", summary.trials_reused},
                   {"kernel_simd", kernel_simd()},
                   {"version", DEMCAL_VERSION}};
  add_consolidation_flat(j, consolidation);
  return j;
}

/// DIR/resume.json: what the trials of DIR/trials.jsonl were run with.
/// Written when a calibration starts afresh; --resume reuses the trials only
/// when everything that changes a trial's outcome or the search is the same
/// (the config as given with its --set, the REV's particle file,
/// --accuracy, --strategy, demcal's version and build: add_build).
/// --max-trials, --jobs and --evidence do not change a trial, nor does the
/// prototype's file (read again after the search).
nlohmann::json resume_key(const SceneConfig& config, const Strategy strategy) {
  nlohmann::json key{{"schema", "demcal.resume/1"},
                     {"config_sha256", sha256_hex(config.text)},
                     {"accuracy", config.calibration.accuracy},
                     {"strategy", to_string(strategy)}};
  if (config.assembly.type == "file")
    add_file_digest(key, "assembly_file_sha256", config, "assembly.file", config.assembly.file);
  add_build(key);
  return key;
}

/// --resume into `dir`: the trials there must come from the same settings,
/// or the result would be another calibration's (one error, exit 2,
/// nothing changed).
void require_same_trials(const std::string& dir, const nlohmann::json& key) {
  require_same_run(dir, key, "the trials in " + dir + "/trials.jsonl",
                   "config, --set, particle file, --accuracy, --strategy and demcal build",
                   "calibrate afresh without --resume (or into another -o)");
}

/// The consolidated REV of either dimension, made once.
struct Consolidated {
  std::optional<ConsolidatedState> disks;  ///< 2D: biaxial
  std::optional<TriaxialState> spheres;    ///< 3D: triaxial
  int64_t particles = 0;
  ConsolidationRecord record;  ///< its steps and time (a cache read's when from_cache)
};

/// The report's start point (3D), run beside the search when there is more
/// than one job: it depends only on the consolidated REV (the search's
/// first start, search_start()), and the search leaves a core idle for long
/// stretches (its verification runs one trial at a time, the certificate's
/// doubled run outlasts its halved one). Abandoned at its next monitoring
/// point when the command returns without taking it (a stop, an error).
class StartPointBeside {
 public:
  StartPointBeside(const SceneConfig& config, const TriaxialState& state,
                   const CalibrationOptions& options) {
    future_ = std::async(std::launch::async, [&config, &state, options, this] {
      const AlgorithmSpec start =
          start_point(config, state.world.size(),
                      dt_ratio_max(options, estimated_stable_dt_ratio(state, config.algorithm)));
      return report_run(config, state, "start point", start, options.tolerances, &abandon_);
    });
  }
  StartPointBeside(const StartPointBeside&) = delete;
  StartPointBeside& operator=(const StartPointBeside&) = delete;
  ~StartPointBeside() {
    abandon_ = true;
    if (future_.valid()) future_.wait();
  }
  /// The run, once finished (rethrows its error).
  ReportRun3D take() { return future_.get(); }

  /// The search's first start as it ran (rounded): the report's start point.
  static AlgorithmSpec start_point(const SceneConfig& config, int64_t particles,
                                   double dt_ratio_max) {
    return rounded_params(search_start(config.algorithm, particles, dt_ratio_max));
  }

 private:
  std::atomic<bool> abandon_{false};
  std::future<ReportRun3D> future_;
};

/// What one invocation works on: the config with the flags applied, where
/// it writes, and the key of its trials.
struct Invocation {
  SceneConfig config;
  bool three_d = false;
  Strategy strategy{};
  std::string dir, trials_path;
  nlohmann::json key;  ///< resume_key()
};

/// The config and flags checked before anything runs: bad input fails here
/// (exit 2), before the consolidation's seconds.
Invocation prepare(const CalibrateOptions& o) {
  Invocation v;
  // 2D scenes as every command loads them; 3D (spheres, triaxial test) too.
  v.config = load_config(o.config, o.sets);
  SceneConfig& config = v.config;
  v.three_d = config.dimension == 3;
  if (o.max_trials > 0) config.calibration.max_trials = o.max_trials;
  require_calibration_budget(config);  // --max-trials is checked at parse time
  if (o.accuracy > 0) config.calibration.accuracy = o.accuracy;
  if (o.accuracy < 0 || o.accuracy >= 1)
    throw InputError("--accuracy", "", "must be a fraction in (0, 1), e.g. 0.02");
  v.strategy = parse_strategy(o.strategy, "--strategy");
  require_prototype(config);  // read again after the search, for params.json
  v.dir = o.out_dir.empty() ? "demcal-" + config.name : o.out_dir;
  v.trials_path = v.dir + "/trials.jsonl";
  OutputFolder::check(v.dir);  // an unwritable -o fails now, not after the search
  if (o.resume && !std::filesystem::exists(v.trials_path))
    throw InputError(v.trials_path, "", "--resume needs the trials.jsonl of an earlier run");
  v.key = resume_key(config, v.strategy);
  if (o.resume) {
    require_readable_file(v.trials_path);  // a folder named trials.jsonl: one line
    require_same_trials(v.dir, v.key);     // before the consolidation's seconds
  }
  return v;
}

/// The consolidated REV: disks (biaxial) or spheres (triaxial), cached.
/// "consolidating ..." is said only when it consolidates (not before a
/// cache read), then its steps and time (print_consolidation_time: a cache
/// read's labelled).
Consolidated consolidate_rev(const CalibrateOptions& o, const SceneConfig& config, bool three_d) {
  Consolidated c;
  auto announce = [&](int64_t size, const char* what) {
    return [&o, &config, three_d, size, what] {
      if (!o.quiet)
        std::cerr << "demcal: consolidating " << size << " " << what << " of " << config.name
                  << " to sigma3 = " << config.test.lateral_stress << " Pa"
                  << (three_d ? " (3D, triaxial)" : "") << "\n";
    };
  };
  auto account = [&](const auto& state) {
    c.particles = state.world.size();
    c.record = consolidation_record(state);
  };
  // Progress lines (--progress, every 2 s) as run, sweep and export print
  // them, unless -q.
  ConsolidationOptions co;
  if (!o.quiet) co.progress = consolidation_progress(o.progress_every_s);
  if (three_d) {
    const SphereAssembly assembly = make_sphere_assembly(config);
    account(c.spheres.emplace(
        consolidate_announced(config, assembly, co, announce(assembly.size(), "spheres"))));
  } else {
    Assembly assembly = make_assembly(config);
    account(c.disks.emplace(
        consolidate_announced(config, assembly, co, announce(assembly.size(), "particles"))));
  }
  if (!o.quiet) {
    std::cerr << "demcal: consolidated in " << c.record.steps << " steps (";
    print_consolidation_time(std::cerr, c.record.wall_time_s, c.record.from_cache);
    std::cerr << ")\n";
  }
  return c;
}

/// The output folder made ready under its lock: a --resume checked once
/// more, a fresh start's trials and key replaced. An earlier calibration's
/// results stay until this one's replace them (write_results): a stop or a
/// failure before that leaves them as they were.
void ready_output_folder(const CalibrateOptions& o, const Invocation& v) {
  const std::string& dir = v.dir;
  if (o.resume) {
    require_same_trials(dir, v.key);  // unchanged since the check in prepare()?
    // A damaged trials.jsonl stops the run before anything is removed.
    read_trials_text(read_text_file(v.trials_path), v.trials_path);
  }
  remove_stale_temporaries(dir);
  if (!o.resume) {
    require_regular_file_target(v.trials_path);
    std::filesystem::remove(v.trials_path);
    write_resume_key(dir, v.key);
  }
}

/// The --evidence runs: the paper's recipe done mechanically (α = 0.2,
/// ζ = 1, Nstep doubled from the search's size-based start until it passes)
/// and a converged reference from the calibrated multipliers. 2D and 3D
/// alike through the scene's trial runner; 2D keeps the reference's fine
/// series for the report's panels.
struct Evidence {
  std::optional<BaselineResult> baseline;
  std::optional<ReferenceEvidence> reference;
  std::string lines;     ///< evidence.jsonl, written with params.json
  nlohmann::json block;  ///< params.json's "evidence"
};

Evidence run_evidence(const SceneConfig& config, const Consolidated& rev, const TrialRunner& runner,
                      const CalibrationSummary& summary, const CalibrationOptions& options,
                      int jobs) {
  Evidence e;
  const int64_t start_steps = kStartStepsPerParticle * rev.particles;
  auto run_baseline = [&] {
    e.baseline = paper_recipe_baseline(runner, config.algorithm, options.tolerances, start_steps);
  };
  auto run_reference = [&] {
    e.reference =
        rev.disks ? run_refined_reference(config, *rev.disks, summary.best, options.tolerances, 1)
                  : run_refined_reference(runner, summary.best, options.tolerances, 1);
  };
  run_parallel({run_baseline, run_reference}, jobs);
  const CalibrationEvidence evidence{*e.reference, *e.baseline, start_steps};
  e.lines = demcal::evidence_lines(evidence);
  e.block = evidence_block(evidence, summary.best_trial);
  return e;
}

/// The report's input from the calibration, before the reruns.
ReportInput report_input(const CalibrateOptions& o, const Invocation& v, int64_t n_rev,
                         const nlohmann::json& params, const CalibrationSummary& summary,
                         const CalibrationOptions& options) {
  const SceneConfig& config = v.config;
  ReportInput in;
  in.scene = config.name;
  in.command = reproduce_command(o, config, v.dir);
  in.params = params;
  in.summary = summary;
  in.tolerances = options.tolerances;
  in.accuracy = options.accuracy;
  in.lateral_stress = config.test.lateral_stress;
  in.dt_ratio_max = dt_ratio_max(options, summary.dt_ratio_stable);
  in.particles = n_rev;
  if (v.three_d) {
    // 3D: the prototype is what params.json's prototype block says (the
    // report shows it); the analytical peak is params.json's.
    in.prototype_particles = n_rev;
    if (params.contains("analytical_peak_stress_yy"))
      in.analytical_peak = params["analytical_peak_stress_yy"].get<double>();
  } else {
    // The prototype params.json's prototype block counts (a prototype
    // file's, a generator's made count), as its upscaling block does.
    const auto proto = params.find("prototype");
    in.prototype_particles =
        proto != params.end() && proto->is_object() ? proto->at("particles").get<int64_t>() : n_rev;
    in.analytical_peak = analytical_peak_stress(config);
  }
  return in;
}

/// The report: the start point and the result rerun with their series, the
/// picture at the peak (3D: and final.vtk of that state, when output.vtk),
/// then plots and text. Returns the files written, for the closing line
/// ("" when the report failed: a warning, not a failure).
std::string write_report(const CalibrateOptions& o, const Invocation& v, const Consolidated& rev,
                         const nlohmann::json& params, const CalibrationSummary& summary,
                         const CalibrationOptions& options, Evidence evidence, int jobs,
                         KnownRuns3D known) {
  const SceneConfig& config = v.config;
  const std::string& dir = v.dir;
  try {
    const auto t0 = std::chrono::steady_clock::now();
    ReportInput in = report_input(o, v, rev.particles, params, summary, options);
    in.baseline = std::move(evidence.baseline);
    in.reference = std::move(evidence.reference);
    // The search's first start, as it ran.
    const AlgorithmSpec start =
        StartPointBeside::start_point(config, rev.particles, in.dt_ratio_max);
    // A stop now: finish, the runs are done.
    std::string vtk;
    if (v.three_d) {
      ResultRuns3D runs = rerun_start_and_result(config, *rev.spheres, start, summary,
                                                 in.tolerances, jobs, std::move(known));
      if (runs.world && config.output.vtk) {
        vtk = world_vtk(*runs.world, "demcal " + config.name + " calibrated, at the peak");
        in.vtk_file = "final.vtk";
      }
      attach_runs(in, std::move(runs));
    } else {
      attach_runs(in,
                  rerun_start_and_result(config, *rev.disks, start, summary, in.tolerances, jobs));
    }
    const auto t1 = std::chrono::steady_clock::now();
    const Report report = make_report(in);
    OutputFolder out(dir);  // the renderings of one report, together
    out.write("report.html", report.html);
    out.write("report.md", report.markdown);
    if (!vtk.empty()) out.write("final.vtk", vtk);
    out.commit();
    if (!o.quiet)
      std::cerr << "demcal: report: reruns " << std::chrono::duration<double>(t1 - t0).count()
                << " s, writing " << seconds_since(t1) << " s; " << report.plot_status << "\n";
    return ", " + dir + "/report.html, " + dir + "/report.md" +
           (vtk.empty() ? "" : ", " + dir + "/final.vtk");
  } catch (const std::exception& e) {
    std::cerr << "demcal: warning: the report was not written: " << e.what() << "\n";
    return "";
  }
}

/// params.json, run.json and evidence.jsonl of one calibration replace
/// those of an earlier one together. The earlier one's other results go in
/// the same commit, whether or not this one writes them again (its report
/// comes next and may fail; an evidence.jsonl of an earlier --evidence run
/// that this one does not redo), so nothing of it passes for this run's.
/// Not a refusal of a non-empty folder: --resume and a recalibration into
/// the same -o are how the folder is meant to be used, and the user's own
/// files in it stay — so final.vtk, which `demcal run` writes too, goes only
/// where an earlier calibration's run.json says it was that calibration's
/// (a 3D report's final.vtk stayed beside a 2D one).
void write_results(const std::string& dir, const nlohmann::json& params,
                   const std::string& evidence_lines, const std::string& run_json) {
  const bool earlier_calibration = std::filesystem::exists(dir + "/run.json");
  OutputFolder out(dir);
  if (!evidence_lines.empty())
    out.write("evidence.jsonl", evidence_lines);
  else
    out.retire("evidence.jsonl");
  out.write("params.json", params.dump(2) + "\n");
  out.write("run.json", run_json);
  for (const char* name : {"report.html", "report.md"}) out.retire(name);
  if (earlier_calibration) out.retire("final.vtk");
  out.commit();
}

/// The search's options from the config and the flags.
CalibrationOptions search_options(const CalibrateOptions& o, const Invocation& v,
                                  const StopOnSignal& stop) {
  CalibrationOptions options = CalibrationOptions::from(v.config);
  options.strategy = v.strategy;
  options.jobs = o.jobs;
  options.trials_path = v.trials_path;
  options.resume = o.resume;
  if (!o.quiet) options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  options.stop = &stop.flag();
  return options;
}

}  // namespace

int cmd_calibrate(const CalibrateOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  const Invocation v = prepare(o);
  const SceneConfig& config = v.config;
  const std::string& dir = v.dir;
  const Consolidated rev = consolidate_rev(o, config, v.three_d);

  // From here on a signal stops cleanly (consolidation writes nothing, so
  // the default action is fine before).
  const StopOnSignal stop;
  make_output_dir(dir);
  // Held to the end: a second calibration into this folder stops here,
  // before it changes anything.
  const FolderLock lock(dir);
  ready_output_folder(o, v);

  const CalibrationOptions options = search_options(o, v, stop);
  const int jobs = resolve_jobs(o.jobs);
  // 3D: the report's runs come from the search (the result's series and its
  // world at the peak, kept by the runner) and from beside it (the start
  // point on an idle core), not from reruns after it.
  std::optional<TriaxialRunner> spheres_runner;
  std::optional<StartPointBeside> start_beside;
  if (v.three_d) {
    spheres_runner.emplace(config, *rev.spheres);
    spheres_runner->keep_passing_runs(true);
    if (jobs > 1) start_beside.emplace(config, *rev.spheres, options);
  }
  const CalibrationSummary summary = v.three_d
                                         ? calibrate(*spheres_runner, config.algorithm, options)
                                         : calibrate(config, *rev.disks, options);
  if (spheres_runner) spheres_runner->keep_passing_runs(false);  // the result is kept by now
  const auto interrupted = [&](const std::string& what) {
    std::cerr << "demcal: interrupted" << what << "; " << summary.trials.size()
              << " finished trials are in " << v.trials_path << ". Continue with:\n  "
              << reproduce_command(o, config, dir) << " --resume\n";
    return stop.exit_status();
  };
  if (summary.interrupted) return interrupted("");

  nlohmann::json params = v.three_d ? params_file(config, *rev.spheres, options, summary)
                                    : params_file(config, *rev.disks, options, summary);
  const bool have_best = summary.has_best_trial();
  auto say = [&](const std::string& line) {
    if (!o.quiet) std::cerr << "demcal: " << line << "\n";
  };
  const bool evidence_runs = o.evidence && have_best;
  Evidence evidence;
  if (evidence_runs) {
    say("evidence: paper-recipe baseline and converged reference (8x, 16x Nstep = " +
        std::to_string(16 * summary.best.steps) + ")");
    std::optional<BiaxialRunner> disks_runner;
    if (rev.disks) disks_runner.emplace(config, *rev.disks);
    const TrialRunner& runner = v.three_d ? static_cast<const TrialRunner&>(*spheres_runner)
                                          : static_cast<const TrialRunner&>(*disks_runner);
    evidence = run_evidence(config, rev, runner, summary, options, jobs);
    params["evidence"] = evidence.block;
  }
  // The evidence and report runs do not poll the flag (seconds on a REV):
  // a stop asked for during them takes effect here.
  if (stop.stopped()) return interrupted(" during the evidence runs (nothing written)");
  // What varies between invocations stays out of params.json (run.json).
  // Written with params.json, and again after the report with the total.
  const auto run_json = [&] {
    return run_record(seconds_since(t_start), summary, rev.record, jobs, o.resume).dump(2) + "\n";
  };
  write_results(dir, params, evidence.lines, run_json());
  if (stop.stopped())
    return interrupted(
        " before the report (params.json and run.json are written; --resume reuses every trial "
        "and writes the report)");

  KnownRuns3D known;
  if (start_beside) {
    try {
      known.start = start_beside->take();
    } catch (const std::exception&) {  // the report reruns it (and says so if it fails again)
    }
  }
  if (spheres_runner && have_best) known.best = spheres_runner->kept_run(summary.best);
  const std::string report_note = write_report(o, v, rev, params, summary, options,
                                               std::move(evidence), jobs, std::move(known));
  write_file_atomic(dir + "/run.json", run_json());
  std::cout << summary.BriefReport() << "  wrote " << dir << "/params.json, " << dir
            << "/run.json, " << dir << "/trials.jsonl, " << dir << "/resume.json" << report_note
            << (evidence_runs ? ", " + dir + "/evidence.jsonl" : "") << "\n";
  if (stop.stopped()) {
    std::cerr << "demcal: interrupted after the last run; every output was written\n";
    return stop.exit_status();
  }
  return summary.success ? 0 : 1;
}

}  // namespace demcal::cli
