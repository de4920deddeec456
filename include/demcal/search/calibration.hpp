// Automatic calibration (README.md "Commands", ARCHITECTURE.md): NLopt searches the algorithmic
// parameters for the cheapest run (fewest steps) that passes every
// criterion of the scoring module; a convergence certificate (Nstep
// doubled) confirms the answer stopped moving.
//
// API shape after Ceres Solver: CalibrationOptions with documented
// defaults in, CalibrationSummary with BriefReport()/FullReport() out.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/trial_runner.hpp"

namespace demcal {

/// The search strategies (CalibrationOptions::strategy documents each).
enum class Strategy { model, cobyla, auglag, penalty, direct };
/// Every strategy, in the order the CLI lists them.
inline constexpr Strategy kStrategies[] = {Strategy::model, Strategy::cobyla, Strategy::auglag,
                                           Strategy::penalty, Strategy::direct};
std::string to_string(Strategy strategy);
/// The strategy named `name`; an unknown name throws InputError naming
/// `option` (e.g. "--strategy") and the valid names.
Strategy parse_strategy(std::string_view name, const std::string& option = "strategy");

/// Why a trial was run: its `phase` in trials.jsonl and the reports.
enum class TrialPhase {
  search,            ///< a search trial
  search_tightened,  ///< a search with tightened tolerances after a failed certificate
  verify,            ///< the model strategy verifying its prediction
  certificate,       ///< the convergence certificate (Nstep and 2·Nstep)
  baseline,          ///< the paper's recipe (evidence)
  reference,         ///< the converged reference (evidence)
  steps_search,      ///< the smallest passing Nstep at fixed multipliers (upscaling)
};
/// The name written to trials.jsonl ("search-tightened", "steps-search", …).
std::string to_string(TrialPhase phase);
/// The phase named `name`; an unknown name throws InputError naming
/// `source` and `field`.
TrialPhase parse_trial_phase(std::string_view name, const std::string& source,
                             const std::string& field = "phase");

/// Nstep rounded to four significant digits (0.1 % of the loading rate,
/// what the searches resolve), at least 10.
int64_t round_steps(double steps);

/// Search space (all bounds inclusive):
///   α = Δt/Δt_crit in [dt_ratio_min, dt_ratio_safety · α_stable], α_stable
///     from the stiffnesses of the consolidated state (never beyond it; the
///     lower bound falls to half the upper one where the upper one is
///     below dt_ratio_min, dt_ratio_lower());
///   log10 Nstep in [log10 steps_min, log10 steps_max];
///   ζ_t in [damping_min, damping_max], ζ_r in [0, damping_max].
/// Mass scaling stays at the config's value (1 by default).
struct CalibrationOptions {
  /// model (default, see reports/optimizers.md): BOBYQA over (α, ζ_t, ζ_r)
  ///   on the smallest passing Nstep predicted from one trial by the 1/Nstep
  ///   decay of the rate-driven criteria, then verified by trials;
  /// cobyla: COBYLA on log10(Nstep) with the criteria as constraints
  ///   log(value/tolerance) ≤ 0;
  /// auglag: AUGLAG around BOBYQA with the same constraints;
  /// penalty: SBPLX on log10(Nstep) + 10·Σ max(0, log(value/tolerance));
  /// direct: a short DIRECT-L global phase on the penalty, then COBYLA.
  Strategy strategy = Strategy::model;
  /// search trials (the certificate comes on top)
  int max_trials = CalibrationSpec{}.max_trials;
  int jobs = 0;  ///< parallel trials; 0: one per core
  /// peak accuracy target (Richardson estimate)
  double accuracy = CalibrationSpec{}.accuracy;
  Tolerances tolerances;                   ///< criteria every accepted run meets
  uint64_t seed = CalibrationSpec{}.seed;  ///< stochastic parts (start perturbations)
  double dt_ratio_min = 0.02;
  double dt_ratio_safety = 0.95;  ///< fraction of the estimated stable α
  double damping_min = 0.05;
  double damping_max = 4.0;
  int64_t steps_min = 0;  ///< 0: 50 per particle
  int64_t steps_max = 0;  ///< 0: 20000 per particle
  /// Stop a trial as soon as it has certainly failed (a running lower
  /// bound of a criterion is beyond early_stop_factor × its tolerance).
  bool early_stop = true;
  double early_stop_factor = 3.0;
  std::string trials_path;  ///< trials.jsonl: appended per trial; "" = none
  bool resume = false;      ///< read trials_path first and reuse its trials
  /// Progress callback (trial finished); may be empty.
  std::function<void(const std::string&)> progress;
  /// Set by the caller (e.g. a SIGINT handler) to stop cleanly: running
  /// trials are abandoned at their next monitoring point and not recorded,
  /// no new trial starts, and calibrate() returns with `interrupted` set.
  /// Every finished trial is already in trials_path, so `resume` continues.
  /// May be null.
  const std::atomic<bool>* stop = nullptr;

  /// The options a config's calibration block asks for (max_trials,
  /// accuracy, seed); everything else at its default.
  static CalibrationOptions from(const CalibrationSpec& spec);
  /// The same for a whole config, with the tolerances of its dimension
  /// (default_tolerances(): the 3D ones for a triaxial scene).
  static CalibrationOptions from(const SceneConfig& config);
};

/// One finished trial, as stored in trials.jsonl: which trial, why it ran,
/// what it ran and how it scored, plus what the run took.
struct TrialRecord {
  int id = 0;
  TrialPhase phase = TrialPhase::search;
  AlgorithmSpec params;
  /// Read back from trials.jsonl, the score lacks only what the file does
  /// not keep: the diagnosis beyond its message (the search and the report
  /// need no more).
  Score score;
  int64_t steps_run = 0;  ///< fewer than params.steps when the run stopped early
  double wall_time_s = 0.0;
};
/// The one JSON form of a trial (a line of trials.jsonl, the evidence and
/// scaling files) and its inverse; errors name `source`. The keys are those
/// of every earlier version, so old files resume.
nlohmann::json to_json(const TrialRecord& record);
TrialRecord trial_from_json(const nlohmann::json& j, const std::string& source);
/// A trial (id 0, phase search) from its parameters, score and run.
TrialRecord trial_record(const AlgorithmSpec& params, const Score& score, const LoadingResult& run);
/// A trial's peak error against a reference peak (peak_error_of()), or
/// nothing for a run without a valid peak (stopped early, diverged).
std::optional<double> peak_error(const TrialRecord& trial, double reference_peak);

///
/// In 3D the certificate has a third level, Nstep halved (run beside 2N, so
/// it adds no wall time): under the 1/N law |P(N/2) − P(N)| is the error of
/// P(N) itself, as 2·|P(N) − P(2N)| is, so both read the same when the law
/// holds; a random 3D REV's peak does not yet follow it between N and 2N
/// (reports/atlas-3d.md: a 0.08 % change, 1.07 % off at 8N), and the
/// estimate is the larger of the two.
struct Certificate {
  int64_t steps = 0;
  double peak = 0.0, peak_doubled = 0.0;
  double steps_doubled_peak_change = 0.0;  ///< |P(N) − P(2N)|/|P(2N)|
  /// The estimated error of P(N): 2·change (Richardson, 1/N decay); in 3D
  /// the larger of that and steps_halved_peak_change.
  double richardson_error = 0.0;
  /// 3D only: P(N/2) and |P(N/2) − P(N)|/|P(N)|.
  std::optional<double> peak_halved, steps_halved_peak_change;
  bool passed = false;
};
/// The certificate as params.json records it.
nlohmann::json to_json(const Certificate& certificate);

struct CalibrationSummary {
  bool success = false;      ///< a passing, certified parameter set was found
  bool interrupted = false;  ///< options.stop was set: the result is incomplete
  std::string message;
  AlgorithmSpec best;
  TrialRecord best_trial;
  Certificate certificate;
  double dt_ratio_stable = 0.0;     ///< the bound the search respected
  std::vector<TrialRecord> trials;  ///< every trial, in id order
  int trials_run = 0, trials_reused = 0;
  double wall_time_s = 0.0;
  Strategy strategy = CalibrationOptions{}.strategy;  ///< options.strategy
  int dimension = 2;  ///< of the scene calibrated (TrialRunner::dimension())

  /// best_trial is a trial that ran: the cheapest passing one, certified
  /// or not (the evidence runs rerun it, the report marks it). False when
  /// no trial passed: best_trial is then default-constructed, with no
  /// particle-steps.
  bool has_best_trial() const { return best_trial.score.particle_steps > 0.0; }
  /// best and best_trial hold a trial that passed every criterion (the
  /// cheapest; certified when success). False when no trial passed: best
  /// is then the default AlgorithmSpec, never run, and params.json holds
  /// no parameters. (A summary built by hand with success set has one,
  /// though its best_trial may be left default.)
  bool has_best() const { return success || has_best_trial(); }

  std::string BriefReport() const;
  std::string FullReport() const;
};

/// The trials of a trials.jsonl text (`path` names it in errors). Only an
/// unterminated last line is the normal trace of a kill in mid-append: it is
/// skipped, and `whole_bytes` (if given) is the length of the text without
/// it. Any other line that does not read is damage: an InputError naming
/// the line (exit 2), since rerunning the trials after it would silently
/// replace the user's.
std::vector<TrialRecord> read_trials_text(std::string_view text, const std::string& path,
                                          size_t* whole_bytes = nullptr);

/// Calibrate on a consolidated REV. Deterministic for a given config,
/// options and seed, whatever `jobs` is. The search sees the scene only
/// through `runner` (trial_runner.hpp); `base` gives what is not searched
/// (mass scaling, lock_rotation).
CalibrationSummary calibrate(const TrialRunner& runner, const AlgorithmSpec& base,
                             const CalibrationOptions& options);
/// The biaxial (2D) REV: calibrate(BiaxialRunner(config, state), config.algorithm, options).
CalibrationSummary calibrate(const SceneConfig& config, const ConsolidatedState& state,
                             const CalibrationOptions& options);
/// The triaxial (3D) REV: the same search and certificate on spheres; the
/// certificate's peak is the axial b_zz.
CalibrationSummary calibrate(const SceneConfig& config, const TriaxialState& state,
                             const CalibrationOptions& options);

/// Nstep per particle of the search's first start and of the paper-recipe
/// baseline's first run.
inline constexpr int64_t kStartStepsPerParticle = 500;
/// The search's first start point: the paper's multipliers (α = 0.2 capped
/// at `dt_ratio_max`, ζ_t = ζ_r = 1, the rest from `base`) with a
/// size-based Nstep of 500 per particle (the model strategy extrapolates
/// from there, so it need not pass).
AlgorithmSpec search_start(const AlgorithmSpec& base, int64_t particles, double dt_ratio_max);
/// `params` as a trial runs them: rounded to what the search resolves (α
/// and ζ to 1e-6, Nstep by round_steps()).
AlgorithmSpec rounded_params(const AlgorithmSpec& params);
/// The largest α the search may try: dt_ratio_safety × the estimated
/// stable α (never more, even below dt_ratio_min: a step beyond the stable
/// one diverges, and export refuses it).
double dt_ratio_max(const CalibrationOptions& options, double dt_ratio_stable);
/// The smallest α the search may try: dt_ratio_min, or half of
/// dt_ratio_max() where that is below dt_ratio_min (stiff contact
/// dashpots), so that the range is never empty.
double dt_ratio_lower(const CalibrationOptions& options, double dt_ratio_stable);

/// The paper's recipe done mechanically: α = 0.2, ζ_t = ζ_r = 1, Nstep
/// doubled from `start_steps` until every criterion passes.
struct BaselineResult {
  bool passed = false;
  AlgorithmSpec params;
  std::vector<TrialRecord> trials;
  double particle_steps_total = 0.0;
};
BaselineResult paper_recipe_baseline(const SceneConfig& config, const ConsolidatedState& state,
                                     const Tolerances& tolerances, int64_t start_steps,
                                     int max_doublings = 8);
/// The same on any scene (2D or 3D), through its trial runner; `base` gives
/// what the recipe does not set (mass scaling, lock_rotation).
BaselineResult paper_recipe_baseline(const TrialRunner& runner, const AlgorithmSpec& base,
                                     const Tolerances& tolerances, int64_t start_steps,
                                     int max_doublings = 8);
/// One whole trial (no early stop) through a runner, as a record (id 0, phase search).
/// With `stop` set during the run, the run ends at its next monitoring
/// point and the record is incomplete (check *stop before using it).
TrialRecord run_trial(const TrialRunner& runner, const AlgorithmSpec& params,
                      const Tolerances& tolerances, const std::atomic<bool>* stop = nullptr);

/// Run one trial and score it (no cache, no file).
/// With `stop` set during the run, the run ends at its next monitoring
/// point and the record is incomplete (check *stop before using it).
TrialRecord run_trial(const SceneConfig& config, const ConsolidatedState& state,
                      const AlgorithmSpec& params, const Tolerances& tolerances,
                      bool early_stop = false, double early_stop_factor = 3.0,
                      LoadingResult* run_out = nullptr, const std::atomic<bool>* stop = nullptr);

}  // namespace demcal
