// One trial, whatever the dimension: what the calibration's search needs of
// a scene. A runner holds the consolidated state (the biaxial disks or the
// triaxial spheres) and the config; run() loads a copy with one set of
// algorithmic parameters and scores it (the 2D scoring, or its 3D form in
// triaxial_scoring.hpp), with the early stop and the caller's stop flag.
// The search (calibration.hpp) sees only this interface.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"

namespace demcal {

/// What one trial gives the search.
struct TrialRun {
  /// The criteria (criteria.peak_stress_yy: the axial peak, b_yy in 2D,
  /// b_zz in 3D), verdict, completeness, divergence, particle-steps planned.
  Score score;
  int64_t steps_run = 0;  ///< fewer than params.steps when the run stopped
  double wall_time_s = 0.0;
};

class TrialRunner {
 public:
  virtual ~TrialRunner() = default;
  /// 2 (disks, biaxial test) or 3 (spheres, triaxial test).
  virtual int dimension() const = 0;
  virtual int64_t particles() const = 0;
  /// The stable α of the consolidated contact network at `base`'s mass
  /// scaling (the search never proposes a step beyond it).
  virtual double stable_dt_ratio(const AlgorithmSpec& base) const = 0;
  /// Load a copy of the consolidated state with `params` and score it.
  /// `early_stop`: stop once the trial has certainly failed (a running lower
  /// bound of a criterion beyond early_stop_factor × its tolerance). With
  /// `stop` set during the run, the run ends at its next monitoring point
  /// and the score is incomplete. Thread-safe: trials run in parallel.
  virtual TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool early_stop,
                       double early_stop_factor, const std::atomic<bool>* stop) const = 0;
};

/// The biaxial test on a consolidated disk sample (run_trial()).
class BiaxialRunner final : public TrialRunner {
 public:
  BiaxialRunner(const SceneConfig& config, const ConsolidatedState& state)
      : config_(config), state_(state) {}
  int dimension() const override { return 2; }
  int64_t particles() const override { return state_.world.size(); }
  double stable_dt_ratio(const AlgorithmSpec& base) const override;
  TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool early_stop,
               double early_stop_factor, const std::atomic<bool>* stop) const override;

 private:
  const SceneConfig& config_;
  const ConsolidatedState& state_;
};

/// The same parameters, exactly (every member): the same run.
bool same_params(const AlgorithmSpec& a, const AlgorithmSpec& b);

/// A passing trial's run as the search ran it (TriaxialRunner::keep_passing_runs()):
/// its series and the world at its monitored peak (the first most
/// compressive b_zz), what the report would otherwise rerun.
struct KeptTriaxialRun {
  AlgorithmSpec params;  ///< as run (rounded by the search)
  TriaxialResult run;
  std::optional<SphereWorld> peak_world;
};

/// The triaxial test on a consolidated sphere sample: run_triaxial_loading()
/// scored by score_triaxial_run(), early stop by TriaxialEarlyFailure.
class TriaxialRunner final : public TrialRunner {
 public:
  TriaxialRunner(const SceneConfig& config, const TriaxialState& state)
      : config_(config), state_(state) {}
  int dimension() const override { return 3; }
  int64_t particles() const override { return state_.world.size(); }
  double stable_dt_ratio(const AlgorithmSpec& base) const override;
  TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool early_stop,
               double early_stop_factor, const std::atomic<bool>* stop) const override;
  /// The same, with the run itself (its series) for the caller.
  TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool early_stop,
               double early_stop_factor, const std::atomic<bool>* stop,
               TriaxialResult* run_out) const;

  /// Keep the run of every trial that passes, complete (set before the
  /// search): the calibration's result is one of them, and kept_run() gives
  /// it to the report without a rerun. Costs a copy of the world at each new
  /// running peak of every trial, and the memory of the passing ones.
  void keep_passing_runs(bool keep) { keep_ = keep; }
  /// The kept run of a trial run with exactly `params`, if any.
  std::optional<KeptTriaxialRun> kept_run(const AlgorithmSpec& params) const;

 private:
  const SceneConfig& config_;
  const TriaxialState& state_;
  bool keep_ = false;
  mutable std::mutex kept_mutex_;
  mutable std::vector<KeptTriaxialRun> kept_;
};

}  // namespace demcal
