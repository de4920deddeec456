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
  // Kept runs: the world at the first most compressive b_zz so far, as
  // rerun_start_and_result() finds the peak.
  std::optional<SphereWorld> peak_world;
  double peak = 0.0;
  TriaxialWorldObserver observe;
  if (keep_) {
    observe = [&](const TriaxialPoint& p, const SphereWorld& world) {
      if (peak_world && !(p.b(2, 2) < peak)) return;
      peak = p.b(2, 2);
      peak_world.emplace(world);
    };
  }
  TriaxialResult run =
      run_triaxial_loading(state_, config_.test, params, monitor, nullptr, observe);
  TrialRun out{score_triaxial_run(run, s3, tolerances), run.steps_run, run.wall_time_s};
  if (keep_ && out.score.passed && out.score.complete) {
    const std::lock_guard<std::mutex> lock(kept_mutex_);
    kept_.push_back({params, run, std::move(peak_world)});
  }
  if (run_out) *run_out = std::move(run);
  return out;
}

bool same_params(const AlgorithmSpec& a, const AlgorithmSpec& b) {
  return a.dt_ratio == b.dt_ratio && a.steps == b.steps &&
         a.damping_ratio_translation == b.damping_ratio_translation &&
         a.damping_ratio_rotation == b.damping_ratio_rotation && a.mass_scaling == b.mass_scaling &&
         a.lock_rotation == b.lock_rotation;
}

std::optional<KeptTriaxialRun> TriaxialRunner::kept_run(const AlgorithmSpec& params) const {
  const std::lock_guard<std::mutex> lock(kept_mutex_);
  for (const auto& k : kept_)
    if (same_params(k.params, params)) return k;
  return std::nullopt;
}

}  // namespace demcal
