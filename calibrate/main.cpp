// The demcal program: a thin command line over the library. Each
// subcommand lives in its own cmd_*.cpp.
#include <CLI/CLI.hpp>
#include <iostream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/search/calibration.hpp"
#include "option_checks.hpp"

namespace {

/// `text` with every byte outside printable ASCII (a control character, a
/// byte of 0x80 and above) shown as \xNN: the kernel's message on a
/// DEMCAL_SIMD it cannot honour quotes the environment's value as it is,
/// and the one-line error must stay one readable line.
std::string printable(std::string_view text) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace demcal::cli;
  // Exit statuses: 0 ok, 1 the computation failed, 2 bad input.
  constexpr int kBadInput = 2;
  CLI::App app{
      "demcal: calibrate the algorithmic parameters (dt, steps, damping) of quasi-static "
      "DEM runs"};
  app.require_subcommand(1);
  std::string config_path, out_dir;
  std::vector<std::string> sets;

  auto* check = app.add_subcommand("check", "validate a config and print the derived scales");
  check->add_option("config", config_path, "scene config (JSON); default: the embedded one");
  check->add_option("--set", sets, "override a key: section.key=value");

  auto* run = app.add_subcommand("run", "run one trial and print its criteria");
  run->add_option("config", config_path, "scene config (JSON); default: the embedded one");
  run->add_option("--set", sets, "override a key: section.key=value (repeatable)");
  run->add_option("-o,--output", out_dir, "output folder (default demcal-run-NAME)");
  bool allow_unstable = false;
  run->add_flag("--allow-unstable", allow_unstable,
                "run a dt_ratio beyond the estimated stable step (to watch it diverge)");

  SweepOptions sweep_options;
  auto* sweep =
      app.add_subcommand("sweep", "the signature atlas: one parameter out of bounds at a time");
  sweep->add_option("config", sweep_options.config,
                    "scene config (JSON); default: the embedded one");
  sweep->add_option("--set", sweep_options.sets, "override a key: section.key=value (repeatable)");
  sweep->add_option("-o,--output", sweep_options.out_dir,
                    "output folder (default demcal-sweep-NAME)");
  sweep->add_option("-j,--jobs", sweep_options.jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));

  CalibrateOptions cal;
  auto* calibrate = app.add_subcommand("calibrate", "calibrate dt, steps and damping on the REV");
  calibrate->add_option("config", cal.config, "scene config (JSON); default: the embedded one");
  calibrate->add_option("--set", cal.sets, "override a key: section.key=value (repeatable)");
  calibrate->add_option("-o,--output", cal.out_dir, "output folder (default demcal-NAME)");
  calibrate->add_option("-j,--jobs", cal.jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));
  calibrate->add_option("--max-trials", cal.max_trials, "search trials (default: config, 80)")
      ->check(whole_number(1, kMaxTrials));
  calibrate->add_option("--accuracy", cal.accuracy, "peak accuracy target (default 0.02)")
      ->check(real_between(0.0, 1.0));
  std::string strategies;
  for (demcal::Strategy s : demcal::kStrategies)
    strategies += (strategies.empty() ? "" : ", ") + demcal::to_string(s);
  calibrate->add_option("--strategy", cal.strategy, "search strategy: " + strategies);
  calibrate->add_flag("--resume", cal.resume, "continue from DIR/trials.jsonl");
  calibrate->add_flag("-q,--quiet", cal.quiet, "no progress lines on stderr");
  calibrate->add_flag("--evidence", cal.evidence,
                      "also run the paper-recipe baseline and a converged reference (8x and 16x "
                      "Nstep) so the report shows every trial's peak error");

  StabilityOptions stab;
  auto* stability = app.add_subcommand(
      "stability", "find the time step at which the REV diverges and compare it with the estimate");
  stability->add_option("config", stab.config, "scene config (JSON); default: the embedded one");
  stability->add_option("--set", stab.sets, "override a key: section.key=value (repeatable)");
  stability->add_option("-o,--output", stab.out_dir,
                        "output folder (default demcal-stability-NAME)");
  stability->add_option("-j,--jobs", stab.jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));
  stability->add_option("--from", stab.from, "first rung, x the estimated stable dt_ratio (0.5)")
      ->check(real_above(0.0, 100.0));
  stability->add_option("--to", stab.to, "last rung, x the estimated stable dt_ratio (2)")
      ->check(real_above(0.0, 100.0));
  stability->add_option("--points", stab.points, "rungs of the ladder (16)")
      ->check(CLI::Range(2, 1000));
  // Fewer steps than this cannot show a divergence: the energy ledger is
  // sampled every energy_check_interval steps, and a step past the stable
  // one needs a few thousand steps to create energy beyond the threshold
  // (KernelOptions in demcal/kernel/world.hpp); 100 steps called 2x the
  // stable step "stable".
  constexpr int64_t kMinStabilitySteps = 16LL * demcal::KernelOptions{}.energy_check_interval;
  stability->add_option("--steps", stab.steps, "loading steps per trial (20000)")
      ->check(whole_number(kMinStabilitySteps, 1'000'000'000,
                           "fewer steps cannot show a divergence: the energy ledger is sampled "
                           "every " +
                               std::to_string(demcal::KernelOptions{}.energy_check_interval) +
                               " steps"));

  ScoreOptions score_options;
  auto* score = app.add_subcommand(
      "score",
      "criteria, verdict and diagnosis of a monitoring series (CSV: another engine's, or demcal "
      "run's)");
  score
      ->add_option("file", score_options.file,
                   "series file (e.g. the LAMMPS deck's series.csv, or demcal run's)")
      ->required();
  score
      ->add_option("--lateral-stress", score_options.lateral_stress,
                   "sigma3 in Pa, if the file has no '# lateral_stress = ' line")
      ->check(real_above(0.0, 1e12));
  score
      ->add_option("--reference-peak", score_options.reference_peak,
                   "a reference peak |sigma_yy| (3D: |sigma_zz|) in Pa to report the peak error "
                   "against (default: the file's '# reference_peak = ' line, if any)")
      ->check(real_above(0.0, 1e15));
  score->add_option("-o,--output", score_options.out_dir,
                    "output folder (default demcal-score-STEM)");

  const auto run_upscaling = add_upscaling_commands(app);  // upscale, verify, scaling, export, rev

  // A first word that is neither an option nor a command: name it (CLI11
  // says only that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      known |= sub->get_name() == word;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "demcal: error: unknown command " << demcal::quoted_value(word)
                << "; the commands are " << names << " (see --help)\n";
      return kBadInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; a usage error is bad input: one line, 2.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::cerr << "demcal: error: " << e.what() << " (see --help)\n";
    return kBadInput;
  }
  try {
    // A DEMCAL_SIMD the kernel cannot honour is bad input, found before a
    // command reads or writes anything.
    try {
      demcal::kernel_simd();
    } catch (const std::invalid_argument& e) {
      throw demcal::InputError("environment", "", printable(e.what()));
    }
    if (check->parsed()) return cmd_check(config_path, sets);
    if (run->parsed()) return cmd_run(config_path, sets, out_dir, allow_unstable);
    if (sweep->parsed()) return cmd_sweep(sweep_options);
    if (calibrate->parsed()) return cmd_calibrate(cal);
    if (stability->parsed()) return cmd_stability(stab);
    if (score->parsed()) return cmd_score(score_options);
    if (const int status = run_upscaling(); status >= 0) return status;
  } catch (const demcal::InputError& e) {
    std::cerr << "demcal: error: " << e.what() << "\n";
    return kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "demcal: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
