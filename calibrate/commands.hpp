// The subcommands of the demcal program, one file each. Each returns the
// exit status; bad input is thrown as demcal::InputError (exit 2).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "consolidation_progress.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/stability_scan.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace demcal::cli {

// kThreadsFrom: consolidation_progress.hpp.

/// The config's Δt (algorithm.dt_ratio) against `stable`, the dt_ratio
/// estimated from the consolidated contact network (estimated_stable_dt_ratio,
/// 2D or 3D): beyond it is bad input (InputError naming the key, exit 2), as
/// the run would diverge or rattle, unless `allow_unstable`. Checked by every
/// command that runs the config's algorithm block as given: check, run and
/// sweep (its benchmark). Not by stability (it sets its own steps, beyond the
/// limit on purpose), nor calibrate and scaling (their search starts from
/// its own Δt, below dt_ratio_max).
void require_stable_step(const SceneConfig& config, double stable, bool allow_unstable);

/// The prototype the config names (prototype.file read, prototype.particles
/// generated: prototype_assembly, 3D prototype_spheres), made now and
/// dropped. `calibrate` makes it only after the search, for params.json's
/// prototype block: a missing or malformed particle file or an impossible
/// count found there cost the whole search and failed with the folder
/// already changed. Called by calibrate before anything runs, and by check,
/// which says the config is valid.
void require_prototype(const SceneConfig& config);

/// `progress_every_s`: seconds between the consolidation's progress lines on
/// stderr (--progress).
int cmd_check(const std::string& path, const std::vector<std::string>& sets,
              double progress_every_s = kProgressEverySeconds);
/// `allow_unstable`: run a Δt beyond the estimated stable step (otherwise
/// bad input).
int cmd_run(const std::string& path, const std::vector<std::string>& sets,
            const std::string& out_dir, bool allow_unstable = false,
            double progress_every_s = kProgressEverySeconds);

struct SweepOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string out_dir;
  int jobs = 0;  ///< 0: one per core
  /// Seconds between the consolidation's progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_sweep(const SweepOptions& options);

struct CalibrateOptions {
  std::string config;  ///< "" = the embedded default
  std::vector<std::string> sets;
  std::string out_dir;
  int jobs = 0;           ///< 0: one per core
  int max_trials = 0;     ///< 0: the config's calibration.max_trials
  double accuracy = 0.0;  ///< 0: the config's calibration.accuracy
  std::string strategy = to_string(CalibrationOptions{}.strategy);
  bool resume = false;
  bool quiet = false;  ///< no progress lines (the consolidation's included)
  /// Seconds between the consolidation's progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
  /// Also run the paper-recipe baseline and a converged reference (8× and
  /// 16× Nstep) for the report's accuracy evidence (costs trials).
  bool evidence = false;
};
int cmd_calibrate(const CalibrateOptions& options);

struct StabilityOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string out_dir;
  StabilityScanOptions scan;  ///< --jobs, --from, --to, --points, --steps
  /// Seconds between the consolidation's progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_stability(const StabilityOptions& options);

/// `demcal score FILE`: another engine's monitoring series, scored.
struct ScoreOptions {
  std::string file;
  double lateral_stress = 0.0;  ///< 0: the file's "# lateral_stress"
  double reference_peak = 0.0;  ///< |b_yy| to hold the peak against (0: none)
  std::string out_dir;
};
int cmd_score(const ScoreOptions& options);

// check, run, sweep, calibrate, stability, score (cmd_trial_cli.cpp). Adds
// the subcommands to `app`; the function returned runs the one that was
// parsed, or returns -1 when none of them was.
std::function<int()> add_trial_commands(CLI::App& app);

// Issue #6: upscale, verify, scaling, export, rev (options in
// upscaling_cli.hpp). Adds the subcommands to `app`; the function returned
// runs the one that was parsed, or returns -1 when none of them was.
std::function<int()> add_upscaling_commands(CLI::App& app);

}  // namespace demcal::cli
