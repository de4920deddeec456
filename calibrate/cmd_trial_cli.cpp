// Command-line registration of check, run, sweep, calibrate, stability and
// score: the commands on the REV and on a monitoring series, kept out of
// main.cpp as the upscaling commands are (cmd_upscaling_cli.cpp).
#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/search/calibration.hpp"
#include "option_checks.hpp"

namespace demcal::cli {
namespace {

/// check and run: one scene, one trial.
struct TrialOptions {
  std::string config, out_dir;
  std::vector<std::string> sets;
  bool allow_unstable = false;
  double progress_every_s = kProgressEverySeconds;
};

std::string strategy_names() {
  std::string names;
  for (Strategy s : kStrategies) names += (names.empty() ? "" : ", ") + to_string(s);
  return names;
}

void add_calibrate_options(CLI::App* calibrate, CalibrateOptions& cal) {
  add_scene_options(calibrate, cal.config, cal.sets);
  calibrate->add_option("-o,--output", cal.out_dir, "output folder (default demcal-NAME)")
      ->check(non_empty_path());
  calibrate->add_option("-j,--jobs", cal.jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));
  calibrate
      ->add_option("--max-trials", cal.max_trials,
                   "the search's trials at most, from 12 (default: config, 80); verification "
                   "and the certificate come on top")
      ->check(whole_number(kMinSearchTrials, kMaxTrials, kMinSearchTrialsWhy));
  calibrate
      ->add_option("--accuracy", cal.accuracy,
                   "peak accuracy target (default: the config's calibration.accuracy, 0.02)")
      ->check(real_between(0.0, 1.0));
  calibrate->add_option("--strategy", cal.strategy, "search strategy: " + strategy_names());
  calibrate->add_flag("--resume", cal.resume, "continue from DIR/trials.jsonl");
  calibrate->add_flag("-q,--quiet", cal.quiet, "no progress lines on stderr");
  add_progress_option(calibrate, cal.progress_every_s);
  calibrate->add_flag("--evidence", cal.evidence,
                      "also run the paper-recipe baseline and a converged reference (8x and 16x "
                      "Nstep) so the report shows every trial's peak error");
}

void add_stability_options(CLI::App* stability, StabilityOptions& stab) {
  add_scene_options(stability, stab.config, stab.sets);
  stability
      ->add_option("-o,--output", stab.out_dir, "output folder (default demcal-stability-NAME)")
      ->check(non_empty_path());
  add_progress_option(stability, stab.progress_every_s);
  stability->add_option("-j,--jobs", stab.scan.jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));
  stability
      ->add_option("--from", stab.scan.from, "first rung, x the estimated stable dt_ratio (0.5)")
      ->check(real_above(0.0, 100.0));
  stability->add_option("--to", stab.scan.to, "last rung, x the estimated stable dt_ratio (2)")
      ->check(real_above(0.0, 100.0));
  stability->add_option("--points", stab.scan.points, "rungs of the ladder (16)")
      ->check(CLI::Range(2, 1000));
  // Fewer steps than this cannot show a divergence: the energy ledger is
  // sampled every energy_check_interval steps, and a step past the stable
  // one needs a few thousand steps to create energy beyond the threshold
  // (KernelOptions in demcal/kernel/world.hpp); 100 steps called 2x the
  // stable step "stable".
  const int interval = KernelOptions{}.energy_check_interval;
  stability->add_option("--steps", stab.scan.steps, "loading steps per trial (20000)")
      ->check(whole_number(16LL * interval, 1'000'000'000,
                           "fewer steps cannot show a divergence: the energy ledger is sampled "
                           "every " +
                               std::to_string(interval) + " steps"));
}

void add_score_options(CLI::App* score, ScoreOptions& options) {
  score
      ->add_option("file", options.file,
                   "series file (e.g. the LAMMPS deck's NAME.series.csv, or demcal run's)")
      ->required();
  score
      ->add_option("--lateral-stress", options.lateral_stress,
                   "sigma3 in Pa, if the file has no '# lateral_stress = ' line")
      ->check(real_above(kLateralStress.lo, kLateralStress.hi));
  score
      ->add_option("--reference-peak", options.reference_peak,
                   "a reference peak |sigma_yy| (3D: |sigma_zz|) in Pa to report the peak error "
                   "against (default: the file's '# reference_peak = ' line, if any)")
      ->check(real_above(kReferencePeak.lo, kReferencePeak.hi));
  score->add_option("-o,--output", options.out_dir, "output folder (default demcal-score-STEM)")
      ->check(non_empty_path());
}

}  // namespace

std::function<int()> add_trial_commands(CLI::App& app) {
  auto one = std::make_shared<TrialOptions>();
  auto* check = app.add_subcommand("check", "validate a config and print the derived scales");
  add_scene_options(check, one->config, one->sets);
  add_progress_option(check, one->progress_every_s);

  auto* run = app.add_subcommand("run", "run one trial and print its criteria");
  add_scene_options(run, one->config, one->sets);
  run->add_option("-o,--output", one->out_dir, "output folder (default demcal-run-NAME)")
      ->check(non_empty_path());
  run->add_flag("--allow-unstable", one->allow_unstable,
                "run a dt_ratio beyond the estimated stable step (to watch it diverge)");
  add_progress_option(run, one->progress_every_s);

  auto sw = std::make_shared<SweepOptions>();
  auto* sweep =
      app.add_subcommand("sweep", "the signature atlas: one parameter out of bounds at a time");
  add_scene_options(sweep, sw->config, sw->sets);
  sweep->add_option("-o,--output", sw->out_dir, "output folder (default demcal-sweep-NAME)")
      ->check(non_empty_path());
  add_progress_option(sweep, sw->progress_every_s);
  sweep->add_option("-j,--jobs", sw->jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));

  auto cal = std::make_shared<CalibrateOptions>();
  auto* calibrate = app.add_subcommand("calibrate", "calibrate dt, steps and damping on the REV");
  add_calibrate_options(calibrate, *cal);

  auto stab = std::make_shared<StabilityOptions>();
  auto* stability = app.add_subcommand(
      "stability", "find the time step at which the REV diverges and compare it with the estimate");
  add_stability_options(stability, *stab);

  auto sc = std::make_shared<ScoreOptions>();
  auto* score = app.add_subcommand(
      "score",
      "criteria, verdict and diagnosis of a monitoring series (CSV: another engine's, or demcal "
      "run's)");
  add_score_options(score, *sc);

  return [=]() -> int {
    if (check->parsed()) return cmd_check(one->config, one->sets, one->progress_every_s);
    if (run->parsed())
      return cmd_run(one->config, one->sets, one->out_dir, one->allow_unstable,
                     one->progress_every_s);
    if (sweep->parsed()) return cmd_sweep(*sw);
    if (calibrate->parsed()) return cmd_calibrate(*cal);
    if (stability->parsed()) return cmd_stability(*stab);
    if (score->parsed()) return cmd_score(*sc);
    return -1;
  };
}

}  // namespace demcal::cli
