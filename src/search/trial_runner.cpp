#include "demcal/search/trial_runner.hpp"

#include <optional>

#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/search/calibration.hpp"

namespace demcal {

double BiaxialRunner::stable_dt_ratio(const AlgorithmSpec& base) const {
  return estimated_stable_dt_ratio(state_, base);
}

TrialRun BiaxialRunner::run(const AlgorithmSpec& params, const Tolerances& tolerances,
                            bool early_stop, double early_stop_factor,
                            const std::atomic<bool>* stop) const {
  const TrialRecord r =
      run_trial(config_, state_, params, tolerances, early_stop, early_stop_factor, nullptr, stop);
  return {r.score, r.steps_run, r.wall_time_s};
}

double TriaxialRunner::stable_dt_ratio(const AlgorithmSpec& base) const {
  return estimated_stable_dt_ratio(state_, base);
}

TrialRun TriaxialRunner::run(const AlgorithmSpec& params, const Tolerances& tolerances,
                             bool early_stop, double early_stop_factor,
                             const std::atomic<bool>* stop) const {
  return run(params, tolerances, early_stop, early_stop_factor, stop, nullptr);
}

TrialRun TriaxialRunner::run(const AlgorithmSpec& params, const Tolerances& tolerances,
                             bool early_stop, double early_stop_factor,
                             const std::atomic<bool>* stop, TriaxialResult* run_out) const {
  const double s3 = config_.test.lateral_stress;
  // Early stop: only once the trial has certainly failed (scoring's bounds).
  std::optional<TriaxialEarlyFailure> failure;
  if (early_stop) failure.emplace(tolerances, early_stop_factor, config_.test.monitor_points, s3);
  TriaxialMonitor monitor;
  if (stop || failure) {
    monitor = [&](const TriaxialPoint& p) {
      if (stop && stop->load(std::memory_order_relaxed)) return false;
      return !(failure && failure->add(p));
    };
  }
  TriaxialResult run = run_triaxial_loading(state_, config_.test, params, monitor);
  TrialRun out{score_triaxial_run(run, s3, tolerances), run.steps_run, run.wall_time_s};
  if (run_out) *run_out = std::move(run);
  return out;
}

}  // namespace demcal
