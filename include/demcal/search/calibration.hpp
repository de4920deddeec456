// Automatic calibration (DESIGN.md §4–§7): NLopt searches the algorithmic
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
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scoring/scoring.hpp"

namespace demcal {

/// Search space (all bounds inclusive):
///   α = Δt/Δt_crit in [dt_ratio_min, dt_ratio_safety · α_stable], α_stable
///     from the stiffnesses of the consolidated state (never beyond it);
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
  std::string strategy = "model";
  int max_trials = 80;     ///< search trials (the certificate comes on top)
  int jobs = 0;            ///< parallel trials; 0: one per core
  double accuracy = 0.02;  ///< peak accuracy target (Richardson estimate)
  Tolerances tolerances;   ///< criteria every accepted run meets
  uint64_t seed = 1;       ///< stochastic parts (start perturbations)
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
};

/// One finished trial, as stored in trials.jsonl.
struct TrialRecord {
  int id = 0;
  std::string phase;  ///< search, certificate, baseline, reference
  AlgorithmSpec params;
  Criteria criteria;
  /// to_json(criteria) as written to trials.jsonl; a resumed trial keeps the
  /// stored object, so its params.json is the same as an uninterrupted run's.
  nlohmann::json criteria_json;
  bool passed = false, diverged = false, complete = true;
  double worst_excess = 0.0;
  int64_t steps_run = 0;
  double particle_steps = 0.0;  ///< cost
  double wall_time_s = 0.0;
  std::string diagnosis;
};
nlohmann::json to_json(const TrialRecord& record);
TrialRecord trial_from_json(const nlohmann::json& j, const std::string& source);

struct Certificate {
  int64_t steps = 0;
  double peak = 0.0, peak_doubled = 0.0;
  double steps_doubled_peak_change = 0.0;  ///< |P(N) − P(2N)|/|P(2N)|
  double richardson_error = 0.0;           ///< 2·change: error of P(N) for 1/N decay
  bool passed = false;
};

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
  std::string strategy;

  std::string BriefReport() const;
  std::string FullReport() const;
};

/// Calibrate on a consolidated REV. Deterministic for a given config,
/// options and seed, whatever `jobs` is.
CalibrationSummary calibrate(const SceneConfig& config, const ConsolidatedState& state,
                             const CalibrationOptions& options);

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

/// Run one trial and score it (no cache, no file).
/// With `stop` set during the run, the run ends at its next monitoring
/// point and the record is incomplete (check *stop before using it).
TrialRecord run_trial(const SceneConfig& config, const ConsolidatedState& state,
                      const AlgorithmSpec& params, const Tolerances& tolerances,
                      bool early_stop = false, double early_stop_factor = 3.0,
                      LoadingResult* run_out = nullptr, const std::atomic<bool>* stop = nullptr);

}  // namespace demcal
