#include "demcal/search/stability_scan.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "demcal/io/format.hpp"
#include "demcal/search/parallel.hpp"

namespace demcal {

namespace {

/// The loading of one rung: `steps` steps at α, the config's damping and
/// mass scaling; only divergence matters, so few monitoring points.
template <class State, class Load>
StabilityTrial run_one(const SceneConfig& config, const State& state, double alpha, int64_t steps,
                       Load load) {
  AlgorithmSpec a = config.algorithm;
  a.dt_ratio = alpha;
  a.steps = steps;
  TestSpec test = config.test;
  test.monitor_points = std::min<int>(test.monitor_points, 20);  // only divergence matters
  const auto run = load(state, test, a);
  StabilityTrial t;
  t.dt_ratio = alpha;
  t.diverged = run.diverged;
  t.divergence = run.divergence;
  t.divergence_step = run.divergence_step;
  t.steps_run = run.steps_run;
  return t;
}

/// The scan, whatever the dimension: `out` holds the estimates, `trial(α)`
/// runs one rung.
template <class Trial>
StabilityScanResult scan(StabilityScanResult out, const StabilityScanOptions& options,
                         const Trial& trial) {
  if (!(options.from > 0.0) || !(options.to > options.from) || options.points < 2 ||
      options.steps < 1 || options.bisections < 0)
    throw std::invalid_argument("stability_scan: need 0 < from < to, points >= 2, steps >= 1");
  const auto t0 = std::chrono::steady_clock::now();
  const int jobs = resolve_jobs(options.jobs);
  out.steps = options.steps;

  std::vector<StabilityTrial> ladder(options.points);
  for_each_parallel(options.points, jobs, [&](int k) {
    const double f = options.from + (options.to - options.from) * k / (options.points - 1);
    ladder[k] = trial(f * out.dt_ratio_estimate);
  });
  out.trials = ladder;

  auto first_diverged = std::find_if(ladder.begin(), ladder.end(),
                                     [](const StabilityTrial& t) { return t.diverged; });
  if (first_diverged != ladder.end() && first_diverged != ladder.begin()) {
    double lo = std::prev(first_diverged)->dt_ratio, hi = first_diverged->dt_ratio;
    for (int b = 0; b < options.bisections; ++b) {
      StabilityTrial t = trial(0.5 * (lo + hi));
      t.bisection = true;
      (t.diverged ? hi : lo) = t.dt_ratio;
      out.trials.push_back(t);
    }
    out.dt_ratio_last_stable = lo;
    out.dt_ratio_first_diverged = hi;
    out.stable_above_limit =
        static_cast<int>(std::count_if(std::next(first_diverged), ladder.end(),
                                       [](const StabilityTrial& t) { return !t.diverged; }));
  }
  std::sort(
      out.trials.begin(), out.trials.end(),
      [](const StabilityTrial& x, const StabilityTrial& y) { return x.dt_ratio < y.dt_ratio; });
  out.wall_time_s = seconds_since(t0);
  return out;
}

/// What every scan reports besides its trials.
template <class State>
StabilityScanResult estimates(const SceneConfig& config, const State& state, int dimension) {
  StabilityScanResult out;
  out.dimension = dimension;
  out.damping_ratio_translation = config.algorithm.damping_ratio_translation;
  out.damping_ratio_rotation = config.algorithm.damping_ratio_rotation;
  out.dt_ratio_estimate = estimated_stable_dt_ratio(state, config.algorithm);
  const StabilityEstimate e = state.world.stability_estimate();
  out.dt_ratio_gershgorin = e.dt_ratio_stable_gershgorin;
  out.dt_ratio_translation = e.dt_ratio_stable_translation;
  return out;
}

}  // namespace

double StabilityScanResult::ratio() const {
  if (dt_ratio_estimate <= 0.0 || dt_ratio_first_diverged <= 0.0 || dt_ratio_last_stable <= 0.0)
    return 0.0;
  return 0.5 * (dt_ratio_last_stable + dt_ratio_first_diverged) / dt_ratio_estimate;
}

StabilityScanResult stability_scan(const SceneConfig& config, const ConsolidatedState& state,
                                   const StabilityScanOptions& options) {
  return scan(estimates(config, state, 2), options, [&](double alpha) {
    return run_one(config, state, alpha, options.steps,
                   [](const ConsolidatedState& s, const TestSpec& t, const AlgorithmSpec& a) {
                     return run_loading(s, t, a);
                   });
  });
}

StabilityScanResult stability_scan(const SceneConfig& config, const TriaxialState& state,
                                   const StabilityScanOptions& options) {
  return scan(estimates(config, state, 3), options, [&](double alpha) {
    return run_one(config, state, alpha, options.steps,
                   [](const TriaxialState& s, const TestSpec& t, const AlgorithmSpec& a) {
                     return run_triaxial_loading(s, t, a);
                   });
  });
}

nlohmann::json to_json(const StabilityScanResult& r) {
  nlohmann::json trials = nlohmann::json::array();
  for (const auto& t : r.trials) {
    nlohmann::json j{{"dt_ratio", t.dt_ratio},
                     {"diverged", t.diverged},
                     {"steps_run", t.steps_run},
                     {"bisection", t.bisection}};
    if (t.diverged) {
      j["divergence"] = to_string(t.divergence);
      j["divergence_step"] = t.divergence_step;
    }
    trials.push_back(j);
  }
  nlohmann::json j{{"schema", "demcal.stability/1"},
                   {"dimension", r.dimension},
                   {"dt_ratio_estimate", r.dt_ratio_estimate},
                   {"dt_ratio_gershgorin", r.dt_ratio_gershgorin},
                   {"dt_ratio_translation", r.dt_ratio_translation},
                   {"dt_ratio_last_stable", r.dt_ratio_last_stable},
                   {"dt_ratio_first_diverged", r.dt_ratio_first_diverged},
                   {"measured_over_estimate", r.ratio()},
                   {"stable_above_limit", r.stable_above_limit},
                   {"steps", r.steps},
                   {"damping_ratio_translation", r.damping_ratio_translation},
                   {"damping_ratio_rotation", r.damping_ratio_rotation},
                   {"trials", trials}};
  return j;
}

std::string beyond_estimate_caveat(const StabilityScanResult& r) {
  if (!(r.ratio() > 1.03)) return "";
  return "Caution: the runs between the estimate and this limit did not blow up, but they need "
         "not be stable: past the estimate an unstable mode can stay bounded by sliding contacts, "
         "a local rattle the kernel's checks (overlap, kinetic energy, energy ledger) do not see "
         "(with friction 10 such a sample's limit is the estimate). Use the estimate as the limit.";
}

std::string stability_markdown(const StabilityScanResult& r, const std::string& scene) {
  std::ostringstream s;
  s.precision(4);
  s << "# Stability scan: " << scene << "\n\n"
    << "Estimated stable alpha = dt/dt_crit from the stiffnesses (Lanczos on the consolidated "
       "contact network, "
    << (r.dimension == 3 ? "spheres, 6" : "disks, 3") << " DOF each): **" << r.dt_ratio_estimate
    << "**. Gershgorin bound " << r.dt_ratio_gershgorin << ", translation only (rotation locked) "
    << r.dt_ratio_translation << " (of the consolidated network).\n\n";
  if (r.ratio() > 0.0)
    s << "Measured: stable at alpha = " << r.dt_ratio_last_stable << ", diverged at "
      << r.dt_ratio_first_diverged << ", so the limit is " << r.ratio() << " x the estimate.\n\n";
  else if (!r.trials.empty() && r.trials.front().diverged)
    s << "Every rung diverged: the limit is below the first one (lower --from).\n\n";
  else
    s << "No rung diverged: the limit is above the last one (raise --to).\n\n";
  if (const std::string caveat = beyond_estimate_caveat(r); !caveat.empty()) s << caveat << "\n\n";
  if (r.stable_above_limit > 0)
    s << "Warning: " << r.stable_above_limit
      << " rung(s) above the first diverged one ran to the end.\n\n";
  s << "Each trial: " << r.steps << " loading steps, zeta_t " << r.damping_ratio_translation
    << ", zeta_r " << r.damping_ratio_rotation << ".\n\n"
    << "| alpha | alpha / estimate | result | divergence | step |\n|---|---|---|---|---|\n";
  for (const auto& t : r.trials) {
    s << "| " << t.dt_ratio << (t.bisection ? " (bisection)" : "") << " | "
      << t.dt_ratio / r.dt_ratio_estimate << " | " << (t.diverged ? "diverged" : "stable") << " | "
      << (t.diverged ? to_string(t.divergence) : "") << " | "
      << (t.diverged ? std::to_string(t.divergence_step) : "") << " |\n";
  }
  return s.str();
}

}  // namespace demcal
