#include "demcal/search/evidence.hpp"

#include <algorithm>
#include <functional>
#include <utility>

#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/search/parallel.hpp"

namespace demcal {

AssemblyPicture picture_of(const World& world) {
  AssemblyPicture p;
  const int n = world.size();
  p.x.assign(world.x().begin(), world.x().end());
  p.y.assign(world.y().begin(), world.y().end());
  p.r.assign(world.radius().begin(), world.radius().end());
  p.rotation.assign(world.rotation().begin(), world.rotation().end());
  p.left = world.wall(kLeft).position;
  p.right = world.wall(kRight).position;
  p.bottom = world.wall(kBottom).position;
  p.top = world.wall(kTop).position;
  for (const auto& c : world.contacts()) {
    if (c.fn <= 0.0) continue;
    p.forces.push_back({p.x[c.i], p.y[c.i], p.x[c.j], p.y[c.j], c.fn, false});
  }
  // Wall contacts: linear law on the overlap with each wall. The kernel
  // keeps its per-particle wall forces private; with the default (zero)
  // contact damping they are exactly kn·overlap.
  const double kn = world.material().wall.kn;
  for (int i = 0; i < n; ++i) {
    const double x = p.x[i], y = p.y[i], r = p.r[i];
    const double d[4] = {r - (x - p.left), r - (p.right - x), r - (y - p.bottom), r - (p.top - y)};
    const double cx[4] = {p.left, p.right, x, x}, cy[4] = {y, y, p.bottom, p.top};
    for (int w = 0; w < 4; ++w)
      if (d[w] > 0.0) p.forces.push_back({x, y, cx[w], cy[w], kn * d[w], true});
  }
  return p;
}

namespace {

/// The result rerun up to the monitoring point of its peak, drawn there.
std::optional<AssemblyPicture> picture_at_peak(const SceneConfig& config,
                                               const ConsolidatedState& state,
                                               const ReportRun& best) {
  const auto& series = best.run.series;
  if (series.empty()) return std::nullopt;
  const Peak peak = find_peak(series);
  if (peak.index < 0) return std::nullopt;
  const int64_t peak_step = series[peak.index].step;
  World world = state.world;
  if (peak_step > 0)
    run_loading(
        state, config.test, best.params, [&](const MonitorPoint& p) { return p.step < peak_step; },
        &world);
  AssemblyPicture picture = picture_of(world);
  picture.step = peak_step;
  picture.steps = best.params.steps;
  picture.strain_yy = series[peak.index].strain_yy;
  picture.stress_yy = peak.stress_yy;
  return picture;
}

}  // namespace

ResultRuns rerun_start_and_result(const SceneConfig& config, const ConsolidatedState& state,
                                  const AlgorithmSpec& start, const CalibrationSummary& summary,
                                  const Tolerances& tolerances, int jobs) {
  const double s3 = config.test.lateral_stress;
  auto one = [&](const std::string& label, const AlgorithmSpec& p) {
    ReportRun r;
    r.label = label;
    r.params = p;
    r.run = run_loading(state, config.test, p);
    r.score = score_run(r.run, s3, tolerances);
    return r;
  };
  ResultRuns out;
  const bool have_best = summary.has_best_trial();
  run_parallel({[&] { out.start = one("start point", start); },
                [&] {
                  if (have_best)
                    out.best = one(summary.success ? "calibrated" : "best found", summary.best);
                }},
               jobs);
  if (out.best) out.picture = picture_at_peak(config, state, *out.best);
  return out;
}

SpherePicture picture_of(const SphereWorld& world) {
  SpherePicture p;
  const int n = world.size();
  p.x.assign(world.x().begin(), world.x().end());
  p.y.assign(world.y().begin(), world.y().end());
  p.z.assign(world.z().begin(), world.z().end());
  p.r.assign(world.radius().begin(), world.radius().end());
  p.force.assign(static_cast<size_t>(n), 0.0);
  for (int a = 0; a < 3; ++a) {
    p.lo[a] = world.wall(static_cast<SphereWallSide>(2 * a)).position;
    p.hi[a] = world.wall(static_cast<SphereWallSide>(2 * a + 1)).position;
  }
  for (const auto& c : world.contacts()) {
    if (c.fn <= 0.0) continue;
    p.force[c.i] += c.fn;
    p.force[c.j] += c.fn;
  }
  // Wall contacts: kn·overlap, as in the 2D picture_of().
  const double kn = world.material().wall.kn;
  for (int i = 0; i < n; ++i) {
    const double c[3] = {p.x[i], p.y[i], p.z[i]};
    for (int a = 0; a < 3; ++a)
      p.force[i] += kn * (std::max(0.0, p.r[i] - (c[a] - p.lo[a])) +
                          std::max(0.0, p.r[i] - (p.hi[a] - c[a])));
  }
  return p;
}

ReportRun3D report_run(const SceneConfig& config, const TriaxialState& state,
                       const std::string& label, const AlgorithmSpec& params,
                       const Tolerances& tolerances, const std::atomic<bool>* stop) {
  ReportRun3D r;
  r.label = label;
  r.params = params;
  TriaxialMonitor monitor;
  if (stop)
    monitor = [stop](const TriaxialPoint&) { return !stop->load(std::memory_order_relaxed); };
  r.run = run_triaxial_loading(state, config.test, params, monitor);
  r.score = score_triaxial_run(r.run, config.test.lateral_stress, tolerances);
  return r;
}

ResultRuns3D rerun_start_and_result(const SceneConfig& config, const TriaxialState& state,
                                    const AlgorithmSpec& start, const CalibrationSummary& summary,
                                    const Tolerances& tolerances, int jobs, KnownRuns3D known) {
  ResultRuns3D out;
  const bool have_best = summary.has_best_trial();
  const std::string best_label = summary.success ? "calibrated" : "best found";
  // What already ran, when it ran exactly these parameters to the end.
  const auto whole = [](const TriaxialResult& run) { return !run.stopped_early; };
  if (known.start && same_params(known.start->params, start) && whole(known.start->run)) {
    out.start = std::move(known.start);
    out.start->label = "start point";
  }
  if (have_best && known.best && same_params(known.best->params, summary.best) &&
      whole(known.best->run) && !known.best->run.series.empty() && known.best->peak_world) {
    ReportRun3D r;
    r.label = best_label;
    r.params = summary.best;
    r.run = std::move(known.best->run);
    r.score = score_triaxial_run(r.run, config.test.lateral_stress, tolerances);
    out.best = std::move(r);
  }
  std::vector<std::function<void()>> runs;
  if (!out.start)
    runs.push_back(
        [&] { out.start = report_run(config, state, "start point", start, tolerances); });
  const bool rerun_best = have_best && !out.best;
  if (rerun_best)
    runs.push_back(
        [&] { out.best = report_run(config, state, best_label, summary.best, tolerances); });
  run_parallel(runs, jobs);
  if (!out.best || out.best->run.series.empty()) return out;
  // The world at the monitoring point of the result's peak: kept by the
  // search, or the result once more, up to that point.
  const auto& series = out.best->run.series;
  const auto peak =
      std::min_element(series.begin(), series.end(),
                       [](const auto& a, const auto& b) { return a.b(2, 2) < b.b(2, 2); });
  const int64_t peak_step = peak->step;
  SphereWorld world = state.world;
  if (!rerun_best && peak_step > 0)
    world = std::move(*known.best->peak_world);
  else if (peak_step > 0)
    run_triaxial_loading(
        state, config.test, out.best->params,
        [&](const TriaxialPoint& p) { return p.step < peak_step; }, &world);
  SpherePicture picture = picture_of(world);
  picture.step = peak_step;
  picture.steps = out.best->params.steps;
  picture.strain_zz = peak->strain_zz;
  picture.stress_zz = peak->b(2, 2);
  out.picture = std::move(picture);
  out.world = std::move(world);
  return out;
}

namespace {

/// The reference's levels: the result's multipliers at 8× and 16× its Nstep.
std::pair<AlgorithmSpec, AlgorithmSpec> reference_levels(const AlgorithmSpec& best) {
  AlgorithmSpec coarse = best, fine = best;
  coarse.steps = kReferenceCoarse * best.steps;
  fine.steps = kReferenceFine * best.steps;
  return {coarse, fine};
}

/// The two runs made into the reference (phases, ids, Richardson limit).
void finish_reference(ReferenceEvidence& out) {
  out.coarse.phase = out.fine.phase = TrialPhase::reference;
  out.coarse.id = 0;
  out.fine.id = 1;
  // Nstep in units of the result's: only the ratio matters, and with
  // powers of two the limit is exactly 2·P(16N) − P(8N).
  out.peak = richardson_limit(kReferenceCoarse, out.coarse.score.criteria.peak_stress_yy,
                              kReferenceFine, out.fine.score.criteria.peak_stress_yy);
}

}  // namespace

ReferenceEvidence run_refined_reference(const SceneConfig& config, const ConsolidatedState& state,
                                        const AlgorithmSpec& best, const Tolerances& tolerances,
                                        int jobs) {
  ReferenceEvidence out;
  // Named copies, not a structured binding: clang 14 cannot capture one.
  const auto levels = reference_levels(best);
  const AlgorithmSpec& coarse = levels.first;
  const AlgorithmSpec& fine = levels.second;
  LoadingResult fine_run;
  run_parallel(
      {[&] { out.fine = run_trial(config, state, fine, tolerances, false, 3.0, &fine_run); },
       [&] { out.coarse = run_trial(config, state, coarse, tolerances); }},
      jobs);
  out.fine_series = std::move(fine_run.series);
  finish_reference(out);
  return out;
}

ReferenceEvidence run_refined_reference(const TrialRunner& runner, const AlgorithmSpec& best,
                                        const Tolerances& tolerances, int jobs) {
  ReferenceEvidence out;
  // Named copies, not a structured binding: clang 14 cannot capture one.
  const auto levels = reference_levels(best);
  const AlgorithmSpec& coarse = levels.first;
  const AlgorithmSpec& fine = levels.second;
  run_parallel({[&] { out.fine = run_trial(runner, fine, tolerances); },
                [&] { out.coarse = run_trial(runner, coarse, tolerances); }},
               jobs);
  finish_reference(out);
  return out;
}

}  // namespace demcal
