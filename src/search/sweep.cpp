#include "demcal/search/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <mutex>
#include <numeric>
#include <sstream>

#include "demcal/io/format.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/search/parallel.hpp"

namespace demcal {

namespace {

/// Scientific notation with `digits` decimals ("1.2e+05"): the atlas's
/// compact cells (io/format.hpp's sci() switches to plain numbers).
std::string scientific(double v, int digits = 2) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << v;
  return s.str();
}

int64_t scaled_steps(int64_t steps, double factor) {
  return std::max<int64_t>(1, std::llround(static_cast<double>(steps) * factor));
}

}  // namespace

std::vector<SweepCase> atlas_cases(const AlgorithmSpec& b, double alpha_stable, bool grid) {
  std::vector<SweepCase> out;
  auto same = [](const AlgorithmSpec& x, const AlgorithmSpec& y) {
    return x.steps == y.steps && std::abs(x.dt_ratio - y.dt_ratio) < 1e-12 &&
           std::abs(x.damping_ratio_translation - y.damping_ratio_translation) < 1e-12 &&
           std::abs(x.damping_ratio_rotation - y.damping_ratio_rotation) < 1e-12 &&
           std::abs(x.mass_scaling - y.mass_scaling) < 1e-12 && x.lock_rotation == y.lock_rotation;
  };
  auto add = [&](std::string name, std::string group, std::string change, std::string expected,
                 AlgorithmSpec a) {
    // A grid point that repeats an earlier case is not run twice.
    if (group == "grid")
      for (const auto& c : out)
        if (same(c.algorithm, a)) return;
    out.push_back({std::move(name), std::move(group), std::move(change), std::move(expected), a});
  };
  add("benchmark", "benchmark", "none", "quasi-static", b);

  // The paper's one-at-a-time cases (Tu & Andrade 2008; the table of
  // signatures and what our kernel shows: reports/signature-atlas.md §5).
  {
    AlgorithmSpec a = b;
    a.steps = scaled_steps(b.steps, 1.0 / 6.0);
    add("steps_x1_6", "atlas", "Nstep x1/6", "gap b_yy != s_yy, peak over-predicted", a);
    a = b;
    a.steps = scaled_steps(b.steps, 33.0);
    add("steps_x33", "atlas", "Nstep x33",
        "zigzag shared by b_yy and s_yy; strength under-predicted", a);
    a = b;
    a.dt_ratio = b.dt_ratio * 0.1;
    add("dt_x0.1", "atlas", "dt x0.1 (same Nstep: loading 10x faster)",
        "gap without oscillation, peak over-predicted", a);
    a = b;
    a.dt_ratio = b.dt_ratio * 1.5;
    add("dt_x1.5", "atlas", "dt x1.5 (same Nstep)",
        "heavy oscillation, s_xy and s_yx large and opposite", a);
    a = b;
    a.damping_ratio_translation = b.damping_ratio_translation * 0.7;
    add("zeta_t_x0.7", "atlas", "D_t x0.7", "noise, b != s, strength under-predicted, s_xy = s_yx",
        a);
    a = b;
    a.damping_ratio_translation = b.damping_ratio_translation * 4.3;
    add("zeta_t_x4.3", "atlas", "D_t x4.3",
        "no oscillation, gap, perfectly plastic post-peak, moment imbalance", a);
    a = b;
    a.damping_ratio_rotation = 0.0;
    add("zeta_r_x0", "atlas", "D_r = 0", "usually acceptable; post-peak differs", a);
    a = b;
    a.damping_ratio_rotation = b.damping_ratio_rotation * 2.0;
    add("zeta_r_x2", "atlas", "D_r x2", "s_xy != s_yx, strength under-predicted", a);
    for (double f : {1e4, 1e8}) {
      // Mass scaled at the benchmark's absolute Δt (α is relative to the
      // scaled Δt_crit), no damping: the loading is sqrt(f) times faster
      // against the particles' own time scale.
      a = b;
      a.mass_scaling = b.mass_scaling * f;
      a.dt_ratio = b.dt_ratio / std::sqrt(f);
      a.damping_ratio_translation = 0.0;
      a.damping_ratio_rotation = 0.0;
      const bool small = f < 1e6;
      add(small ? "mass_1e4_undamped" : "mass_1e8_undamped", "atlas",
          std::string("mass scaling ") + (small ? "1e4" : "1e8") + ", no damping, same dt",
          "normal stresses unrealistically large, b and s follow different trends", a);
    }
  }
  // Convergence ladder (with steps_x33).
  for (int f : {2, 4, 8, 16}) {
    AlgorithmSpec a = b;
    a.steps = b.steps * f;
    add("steps_x" + std::to_string(f), "convergence", "Nstep x" + std::to_string(f), "", a);
  }
  // α scan at the benchmark's loading time.
  if (alpha_stable > 0.0) {
    for (double frac : {0.25, 0.5, 0.75, 0.9, 1.0, 1.05, 1.1, 1.2, 1.35, 1.5}) {
      AlgorithmSpec a = b;
      a.dt_ratio = std::round(frac * alpha_stable * 1000.0) / 1000.0;
      if (std::abs(a.dt_ratio - b.dt_ratio) < 1e-3) continue;
      a.steps = scaled_steps(b.steps, b.dt_ratio / a.dt_ratio);
      add("alpha_" + fixed(a.dt_ratio, 3), "alpha_scan",
          "alpha = " + fixed(a.dt_ratio, 3) + " (" + fixed(frac, 2) +
              " alpha_stable), same loading time",
          "", a);
    }
  }
  if (grid) {
    // Around the paper's start point: Nstep against both dampings.
    for (double fs : {0.25, 0.5, 1.0, 2.0})
      for (double zt : {0.0, 0.3, 1.0})
        for (double zr : {0.0, 0.3, 1.0, 3.0}) {
          AlgorithmSpec a = b;
          a.steps = scaled_steps(b.steps, fs);
          a.damping_ratio_translation = zt;
          a.damping_ratio_rotation = zr;
          std::ostringstream name, change;
          name << "grid_n" << fixed(fs, 2) << "_zt" << fixed(zt, 1) << "_zr" << fixed(zr, 1);
          change << "Nstep x" << fs << ", zeta_t " << zt << ", zeta_r " << zr;
          add(name.str(), "grid", change.str(), "", a);
        }
    // Where a search for the cheapest passing run goes: α near its limit,
    // little damping.
    if (alpha_stable > 0.0) {
      const double alpha = std::round(0.9 * alpha_stable * 100.0) / 100.0;
      for (double fs : {0.25, 0.5, 1.0, 2.0})
        for (double zt : {0.0, 0.1, 0.3})
          for (double zr : {0.0, 0.1}) {
            AlgorithmSpec a = b;
            a.steps = scaled_steps(b.steps, fs);
            a.dt_ratio = alpha;
            a.damping_ratio_translation = zt;
            a.damping_ratio_rotation = zr;
            std::ostringstream name, change;
            name << "grid_n" << fixed(fs, 2) << "_a" << fixed(alpha, 2) << "_zt" << fixed(zt, 1)
                 << "_zr" << fixed(zr, 1);
            change << "Nstep x" << fs << ", alpha " << alpha << ", zeta_t " << zt << ", zeta_r "
                   << zr;
            add(name.str(), "grid", change.str(), "", a);
          }
    }
    for (double fs : {0.5, 1.0, 2.0})
      for (double alpha : {0.1, 0.25}) {
        AlgorithmSpec a = b;
        a.steps = scaled_steps(b.steps, fs);
        a.dt_ratio = alpha;
        std::ostringstream name, change;
        name << "grid_n" << fixed(fs, 2) << "_alpha" << fixed(alpha, 2);
        change << "Nstep x" << fs << ", alpha " << alpha;
        add(name.str(), "grid", change.str(), "", a);
      }
  }
  return out;
}

ConvergedReference converged_reference(std::vector<std::pair<int64_t, double>> peaks,
                                       double tolerance) {
  ConvergedReference ref;
  ref.tolerance = tolerance;
  std::sort(peaks.begin(), peaks.end());
  for (size_t i = 0; i < peaks.size(); ++i) {
    ConvergedReference::Rung r{peaks[i].first, peaks[i].second, 0.0};
    if (i > 0) {
      r.richardson = richardson_limit(static_cast<double>(peaks[i - 1].first), peaks[i - 1].second,
                                      static_cast<double>(peaks[i].first), peaks[i].second);
    }
    ref.ladder.push_back(r);
  }
  if (ref.ladder.empty()) return ref;
  if (ref.ladder.size() == 1) {
    ref.peak_stress_yy = ref.ladder[0].peak_stress_yy;
    return ref;
  }
  const auto& last = ref.ladder.back();
  const auto& prev = ref.ladder[ref.ladder.size() - 2];
  ref.peak_stress_yy = last.richardson;
  ref.last_change = std::abs(last.peak_stress_yy - prev.peak_stress_yy) /
                    std::max(std::abs(last.peak_stress_yy), 1e-300);
  ref.converged = ref.last_change < tolerance;
  return ref;
}

namespace {

struct NamedMeasure {
  const char* name;
  double (*get)(const Criteria&);
};

const NamedMeasure kCriteria[4] = {
    {"force_balance", [](const Criteria& c) { return c.force_balance; }},
    {"moment_balance", [](const Criteria& c) { return c.moment_balance; }},
    {"servo", [](const Criteria& c) { return c.servo; }},
    {"oscillation", [](const Criteria& c) { return c.oscillation; }},
};

// Other measures whose power to certify accuracy alone is reported.
const NamedMeasure kOtherMeasures[] = {
    {"force_balance_paper", [](const Criteria& c) { return c.force_balance_paper; }},
    {"force_balance_xx", [](const Criteria& c) { return c.force_balance_xx; }},
    {"force_balance_yy", [](const Criteria& c) { return c.force_balance_yy; }},
    {"force_balance_shear", [](const Criteria& c) { return c.force_balance_shear; }},
    {"force_balance_xx_rms", [](const Criteria& c) { return c.force_balance_xx_rms; }},
    {"force_balance_whole", [](const Criteria& c) { return c.force_balance_whole; }},
    {"interior_lateral", [](const Criteria& c) { return c.interior_lateral; }},
    {"servo_rms", [](const Criteria& c) { return c.servo_rms; }},
    {"zigzag", [](const Criteria& c) { return c.zigzag; }},
    {"unbalanced_force_ratio_max", [](const Criteria& c) { return c.unbalanced_force_ratio_max; }},
    {"kinetic_energy_ratio_max", [](const Criteria& c) { return c.kinetic_energy_ratio_max; }},
};

double tolerance_of(const Tolerances& t, int i) {
  switch (i) {
    case 0:
      return t.force_balance;
    case 1:
      return t.moment_balance;
    case 2:
      return t.servo;
    default:
      return t.oscillation;
  }
}

bool scored(const SweepCaseResult& r) {
  return !r.score.diverged && r.score.complete && r.score.criteria.peak_error.has_value();
}

void compute_evidence(SweepResult& res) {
  const double inf = std::numeric_limits<double>::infinity();
  res.evidence.clear();
  res.false_passes = res.false_rejects = 0;
  for (int i = 0; i < 4; ++i) {
    CriterionEvidence e;
    e.name = kCriteria[i].name;
    e.tolerance = tolerance_of(res.tolerances, i);
    e.safe_alone = e.safe_joint = inf;
    for (const auto& r : res.cases) {
      if (!scored(r) || r.accurate) continue;
      const double v = kCriteria[i].get(r.score.criteria);
      e.safe_alone = std::min(e.safe_alone, v);
      bool others_pass = true, others_all = true;
      for (int j = 0; j < 4; ++j) {
        if (j == i) continue;
        const bool ok = kCriteria[j].get(r.score.criteria) <= tolerance_of(res.tolerances, j);
        others_pass = others_pass && ok;
        others_all = others_all && ok;
      }
      if (others_pass) e.safe_joint = std::min(e.safe_joint, v);
      if (others_all && v > e.tolerance) ++e.binding;
    }
    res.evidence.push_back(e);
  }
  for (const auto& m : kOtherMeasures) {
    CriterionEvidence e;
    e.name = m.name;
    e.safe_alone = e.safe_joint = inf;
    for (const auto& r : res.cases)
      if (scored(r) && !r.accurate) e.safe_alone = std::min(e.safe_alone, m.get(r.score.criteria));
    res.evidence.push_back(e);
  }
  res.worst_passed_error = res.worst_paper_form_error = 0.0;
  for (const auto& r : res.cases) {
    if (!scored(r)) continue;
    const double e = std::abs(*r.score.criteria.peak_error);
    if (r.score.passed) res.worst_passed_error = std::max(res.worst_passed_error, e);
    if (r.score.criteria.force_balance_paper <= 0.02)
      res.worst_paper_form_error = std::max(res.worst_paper_form_error, e);
    if (r.score.passed && !r.accurate) ++res.false_passes;
    if (!r.score.passed && r.accurate) ++res.false_rejects;
  }
}

}  // namespace

namespace {

/// Runs one case of a scene: fills r.run, r.score (against no reference:
/// the peak error is added once the reference is known), r.planes (3D) and
/// r.identity_residual. Thread-safe.
using CaseRunner = std::function<void(SweepCaseResult& r)>;

/// The sweep, whatever the dimension: `res` holds the scene's description.
SweepResult sweep_cases(SweepResult res, const std::vector<SweepCase>& cases,
                        const SweepSettings& settings, const CaseRunner& run_case) {
  const auto t0 = std::chrono::steady_clock::now();
  res.accuracy = settings.accuracy;
  res.tolerances = settings.tolerances;
  res.cases.resize(cases.size());
  for (size_t i = 0; i < cases.size(); ++i) res.cases[i].spec = cases[i];

  // Longest first: the pool then ends with short trials.
  std::vector<size_t> order(cases.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return cases[a].algorithm.steps > cases[b].algorithm.steps;
  });
  const int jobs =
      std::clamp(resolve_jobs(settings.jobs), 1, std::max(1, static_cast<int>(cases.size())));
  res.jobs = jobs;
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  for_each_parallel(static_cast<int>(order.size()), jobs, [&](int k) {
    SweepCaseResult& r = res.cases[order[k]];
    run_case(r);
    const int finished = ++done;
    if (settings.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      settings.progress(finished, static_cast<int>(order.size()), r.spec.name, r.run.wall_time_s);
    }
  });

  // The reference: benchmark, convergence ladder, ×33.
  std::vector<std::pair<int64_t, double>> peaks;
  for (const auto& r : res.cases) {
    const bool ladder =
        r.spec.group == "benchmark" || r.spec.group == "convergence" || r.spec.name == "steps_x33";
    if (!ladder || r.run.diverged || r.run.steps_run != r.run.steps_planned) continue;
    peaks.emplace_back(r.spec.algorithm.steps, r.score.criteria.peak_stress_yy);
  }
  res.reference = converged_reference(peaks);
  const std::optional<double> ref =
      peaks.empty() ? std::nullopt : std::optional<double>(res.reference.peak_stress_yy);
  for (auto& r : res.cases) {
    Criteria& c = r.score.criteria;
    // As compute_criteria() sets it: for every run that has a (compressive) peak.
    if (c.peak_stress_yy < 0.0) c.peak_error = peak_error_of(c.peak_stress_yy, ref);
    if (res.analytical_peak && c.peak_stress_yy < 0.0)
      r.peak_error_analytical =
          (*res.analytical_peak - c.peak_stress_yy) / std::abs(*res.analytical_peak);
    r.accurate = c.peak_error && std::abs(*c.peak_error) <= settings.accuracy;
  }
  compute_evidence(res);
  res.wall_time_s = seconds_since(t0);
  return res;
}

template <class Run>
SweepRun sweep_run(const Run& run, std::string series) {
  return {run.diverged,      run.divergence,     run.divergence_step, run.steps_run,
          run.steps_planned, run.integration.dt, run.wall_time_s,     std::move(series)};
}

/// What a sweep records of its scene and sample, disks and spheres alike.
SweepResult sweep_of(const SceneConfig& config, int dimension, int particles,
                     const ConsolidationRecord& consolidation) {
  SweepResult res;
  res.scene = config.name;
  res.dimension = dimension;
  res.particles = particles;
  res.benchmark = config.algorithm;
  res.lateral_stress = config.test.lateral_stress;
  res.consolidation = consolidation;
  return res;
}

}  // namespace

namespace {

/// A case's series.csv metadata (`demcal score` reads it: the case's
/// criteria and verdict).
template <class Run>
SeriesMetadata sweep_metadata(const SceneConfig& config, const Run& run) {
  SeriesMetadata m = series_metadata(config.name, config.test, run);
  m.writer = "demcal sweep";
  return m;
}

}  // namespace

SweepResult run_sweep(const SceneConfig& config, const ConsolidatedState& state,
                      const std::vector<SweepCase>& cases, const SweepSettings& settings) {
  SweepResult res = sweep_of(config, 2, state.world.size(), consolidation_record(state));
  res.analytical_peak = analytical_peak_stress(config);
  res.alpha_stable = state.world.stability_estimate().dt_ratio_stable;
  const double s3 = config.test.lateral_stress;
  return sweep_cases(std::move(res), cases, settings, [&](SweepCaseResult& r) {
    const ConsolidatedState local = state;  // each trial its own copy
    World final_state = local.world;
    const LoadingResult run = run_loading(local, config.test, r.spec.algorithm, {}, &final_state);
    r.score = score_run(run, s3, settings.tolerances);
    r.identity_residual = gap_identity_residual(final_state);
    r.run = sweep_run(run, series_csv(sweep_metadata(config, run), run.series));
  });
}

SweepResult run_sweep(const SceneConfig& config, const TriaxialState& state,
                      const std::vector<SweepCase>& cases, const SweepSettings& settings) {
  SweepResult res = sweep_of(config, 3, state.world.size(), consolidation_record(state));
  const double s3 = config.test.lateral_stress;
  if (const auto ratio = analytical_peak_ratio_3d(config)) res.analytical_peak = -*ratio * s3;
  res.alpha_stable = estimated_stable_dt_ratio(state, config.algorithm);
  return sweep_cases(std::move(res), cases, settings, [&](SweepCaseResult& r) {
    SphereWorld final_state = state.world;
    const TriaxialResult run =
        run_triaxial_loading(state, config.test, r.spec.algorithm, {}, &final_state);
    r.score = score_triaxial_run(run, s3, settings.tolerances);
    r.planes = compute_triaxial_criteria(run, s3);
    r.identity_residual = gap_identity_residual(final_state);
    r.run = sweep_run(run, series_csv(sweep_metadata(config, run), run.series));
  });
}

namespace {
/// A case's parameters and the absolute Δt they gave.
nlohmann::json params_with_dt(const AlgorithmSpec& params, double dt) {
  nlohmann::json j = to_json(params);
  j["dt"] = dt;
  return j;
}
}  // namespace

nlohmann::json to_json(const SweepResult& res) {
  using nlohmann::json;
  json cases = json::array();
  for (const auto& r : res.cases) {
    json c{{"name", r.spec.name},
           {"group", r.spec.group},
           {"change", r.spec.change},
           {"expected", r.spec.expected},
           {"params", params_with_dt(r.spec.algorithm, r.run.dt)},
           {"criteria", to_json(r.score.criteria)},
           {"peak_ratio", -r.score.criteria.peak_stress_yy / res.lateral_stress},
           {"passed", r.score.passed},
           {"accurate", r.accurate},
           {"diverged", r.run.diverged},
           {"steps_run", r.run.steps_run},
           {"objective", objective(r.score, res.tolerances)},
           {"diagnosis", to_json(r.score.diagnosis)},
           {"identity_residual", r.identity_residual},
           {"wall_time_s", r.run.wall_time_s},
           {"series", "series/" + r.spec.name + ".csv"}};
    if (r.run.diverged) c["divergence"] = to_string(r.run.divergence);
    if (r.peak_error_analytical) c["peak_error_analytical"] = *r.peak_error_analytical;
    if (r.planes)
      c["planes"] = {{"xz", to_json(r.planes->xz)},
                     {"yz", to_json(r.planes->yz)},
                     {"xy", to_json(r.planes->xy)},
                     {"servo_walls", r.planes->servo_walls}};
    cases.push_back(c);
  }
  json ladder = json::array();
  for (const auto& rung : res.reference.ladder)
    ladder.push_back({{"steps", rung.steps},
                      {"peak_stress_yy", rung.peak_stress_yy},
                      {"richardson", rung.richardson}});
  json evidence = json::array();
  for (const auto& e : res.evidence) {
    auto finite_or_null = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    json j{{"name", e.name}, {"safe_alone", finite_or_null(e.safe_alone)}};
    if (e.tolerance > 0.0) {
      j["tolerance"] = e.tolerance;
      j["safe_joint"] = finite_or_null(e.safe_joint);
      j["binding"] = e.binding;
    }
    evidence.push_back(j);
  }
  json j{{"schema", "demcal.sweep/1"},
         {"scene", res.scene},
         {"dimension", res.dimension},
         {"particles", res.particles},
         {"benchmark", to_json(res.benchmark)},
         {"alpha_stable", res.alpha_stable},
         {"lateral_stress", res.lateral_stress},
         {"reference",
          {{"peak_stress_yy", res.reference.peak_stress_yy},
           {"ratio", -res.reference.peak_stress_yy / res.lateral_stress},
           {"converged", res.reference.converged},
           {"last_change", res.reference.last_change},
           {"tolerance", res.reference.tolerance},
           {"ladder", ladder}}},
         {"accuracy", res.accuracy},
         {"tolerances", to_json(res.tolerances)},
         {"false_passes", res.false_passes},
         {"false_rejects", res.false_rejects},
         {"worst_passed_error", res.worst_passed_error},
         {"worst_paper_form_error", res.worst_paper_form_error},
         {"evidence", evidence},
         {"cases", cases},
         {"consolidation", consolidation_json(res.consolidation)},
         {"consolidation_time_s", res.consolidation.wall_time_s},
         {"wall_time_s", res.wall_time_s},
         {"jobs", res.jobs}};
  if (res.analytical_peak)
    j["analytical_peak"] = {{"stress_yy", *res.analytical_peak},
                            {"ratio", -*res.analytical_peak / res.lateral_stress}};
  return j;
}

namespace {

std::string pct(std::optional<double> v) { return v ? signed_pct(*v, 1) : "–"; }

std::string compact(double v) {
  if (v == 0.0) return "0";
  if (!std::isfinite(v)) return "∞";
  return scientific(v, 1);
}

}  // namespace

namespace {

/// atlas.md's table of every case, group by group (bold: beyond its
/// tolerance); 3D adds the per-axis and per-plane columns.
void atlas_case_tables(std::ostream& md, const SweepResult& res) {
  const double s3 = res.lateral_stress;
  const bool three_d = res.dimension == 3;
  auto bold = [](double v, double tol) { return v > tol ? "**" + compact(v) + "**" : compact(v); };
  const std::vector<std::string> groups = {"benchmark", "atlas", "convergence", "alpha_scan",
                                           "grid"};
  for (const auto& g : groups) {
    bool any = false;
    for (const auto& r : res.cases) any = any || r.spec.group == g;
    if (!any) continue;
    md << "\n## " << g << "\n\n";
    if (three_d)
      md << "| case | change | peak s1/s3 | err vs ref | FB | FB x | FB y | FB z | FB sh | paper | "
            "MB | MB xz | MB yz | MB xy | servo | osc | zig | soft | rot | pass | diagnosis | "
            "signature |\n"
         << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
            "---:|---:|---|---|---|\n";
    else
      md << "| case | change | peak s1/s3 | err vs ref | FB | FB xx | FB yy | FB sh | paper | MB | "
            "servo | osc | zig | soft | pass | diagnosis | signature |\n"
         << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---|\n";
    for (const auto& r : res.cases) {
      if (r.spec.group != g) continue;
      const Criteria& c = r.score.criteria;
      const Tolerances& t = res.tolerances;
      md << "| " << r.spec.name << " | " << r.spec.change << " | ";
      if (r.run.diverged) {
        md << "diverged (" << to_string(r.run.divergence) << ", step " << r.run.divergence_step
           << ") |";
        for (int k = 0; k < (three_d ? 16 : 11); ++k) md << " – |";
        md << " fail | " << r.score.diagnosis.parameter << " " << r.score.diagnosis.direction
           << " | " << r.score.diagnosis.signature << " |\n";
        continue;
      }
      md << fixed(-c.peak_stress_yy / s3, 3) << " | " << pct(c.peak_error) << " | "
         << bold(c.force_balance, t.force_balance) << " | ";
      if (three_d && r.planes) {
        const TriaxialCriteria& p = *r.planes;
        md << compact(p.xz.force_balance_xx) << " | " << compact(p.yz.force_balance_xx) << " | "
           << compact(c.force_balance_yy) << " | " << compact(c.force_balance_shear) << " | "
           << compact(c.force_balance_paper) << " | " << bold(c.moment_balance, t.moment_balance)
           << " | " << compact(p.xz.moment_balance) << " | " << compact(p.yz.moment_balance)
           << " | " << compact(p.xy.moment_balance) << " | ";
      } else {
        md << compact(c.force_balance_xx) << " | " << compact(c.force_balance_yy) << " | "
           << compact(c.force_balance_shear) << " | " << compact(c.force_balance_paper) << " | "
           << bold(c.moment_balance, t.moment_balance) << " | ";
      }
      md << bold(c.servo, t.servo) << " | " << bold(c.oscillation, t.oscillation) << " | "
         << compact(c.zigzag) << " | " << compact(c.post_peak_softening) << " | ";
      if (three_d) md << fixed(c.rotational_energy_share, 2) << " | ";
      md << (r.score.passed ? "pass" : "fail") << (r.accurate ? "" : " (inacc.)") << " | "
         << r.score.diagnosis.parameter << " " << r.score.diagnosis.direction << " ("
         << fixed(r.score.diagnosis.confidence, 2) << ") | " << r.score.diagnosis.signature
         << " |\n";
    }
  }
}

/// atlas.md: each criterion against the peak error, the finished trials
/// binned by value/tolerance.
void atlas_criterion_bins(std::ostream& md, const SweepResult& res) {
  const double edges[] = {0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 10.0, 1e300};
  const char* labels[] = {"<= 0.25", "0.25-0.5", "0.5-1", "1-2", "2-4", "4-10", "> 10"};
  md << "\n### Each criterion against the peak error\n\n"
     << "Finished trials binned by criterion value / tolerance; each cell: trials, largest "
        "|peak error|.\n\n| value/tolerance |";
  for (int i = 0; i < 4; ++i) md << " " << kCriteria[i].name << " |";
  md << "\n|---|---:|---:|---:|---:|\n";
  for (int b = 0; b < 7; ++b) {
    md << "| " << labels[b] << " |";
    for (int i = 0; i < 4; ++i) {
      int n = 0;
      double worst = 0.0;
      for (const auto& r : res.cases) {
        if (!scored(r)) continue;
        const double x = kCriteria[i].get(r.score.criteria) / tolerance_of(res.tolerances, i);
        if (x > edges[b] && x <= edges[b + 1]) {
          ++n;
          worst = std::max(worst, std::abs(*r.score.criteria.peak_error));
        }
      }
      if (b == 0)
        for (const auto& r : res.cases)
          if (scored(r) && kCriteria[i].get(r.score.criteria) == 0.0) ++n;
      md << " " << n << (n ? ", " + fixed(100.0 * worst, 1) + " %" : "") << " |";
    }
    md << "\n";
  }
}

}  // namespace

std::string atlas_markdown(const SweepResult& res) {
  std::ostringstream md;
  const double s3 = res.lateral_stress;
  const bool three_d = res.dimension == 3;
  md << "# Signature atlas: " << res.scene << "\n\n"
     << res.particles << (three_d ? " spheres, triaxial test (z axial)" : " particles")
     << ". Benchmark: alpha " << res.benchmark.dt_ratio << ", Nstep " << res.benchmark.steps
     << ", zeta_t " << res.benchmark.damping_ratio_translation << ", zeta_r "
     << res.benchmark.damping_ratio_rotation << ", mass scaling " << res.benchmark.mass_scaling
     << ". Stable alpha (rotation coupled) " << fixed(res.alpha_stable, 3) << ".\n\n";
  md << "Converged quasi-static peak sigma1/sigma3 = "
     << fixed(-res.reference.peak_stress_yy / s3, 4) << " (Richardson, Nstep ladder; last "
     << "doubling changed the peak by " << fixed(100.0 * res.reference.last_change, 2) << " %, "
     << (res.reference.converged ? "converged" : "NOT converged") << ")";
  if (res.analytical_peak)
    md << (three_d ? "; analytical (walled FCC, Thornton 1979, rotation locked) "
                   : "; analytical (walled box, rotation locked) ")
       << fixed(-*res.analytical_peak / s3, 4);
  md << ".\n\n| Nstep | peak sigma1/sigma3 | Richardson with previous |\n|---:|---:|---:|\n";
  for (const auto& r : res.reference.ladder)
    md << "| " << r.steps << " | " << fixed(-r.peak_stress_yy / s3, 4) << " | "
       << (r.richardson != 0.0 ? fixed(-r.richardson / s3, 4) : "–") << " |\n";

  md << "\nTolerances: force balance " << res.tolerances.force_balance << ", moment balance "
     << res.tolerances.moment_balance << ", servo " << res.tolerances.servo << ", oscillation "
     << res.tolerances.oscillation << "; accuracy target " << 100.0 * res.accuracy << " %.\n\n";
  md << "Columns: FB = force balance (max |trend| of b−σ; xx, yy, shear), paper = "
        "RMS(b_yy−σ_yy)/RMS(b_yy), MB = moment balance RMS(σxy−σyx)/σ3, servo = max |trend| of "
        "the lateral wall stress error, osc = noise of b−σ, zig = noise b_yy and σ_yy share, "
        "soft = post-peak softening. Values above tolerance in **bold**.\n\n";
  if (three_d)
    md << "3D: FB, MB, servo and osc are the combined criteria (scoring/triaxial_scoring.hpp: "
          "each the largest over the xz, yz and xy planes, servo over the four lateral walls "
          "too); FB x, FB y = lateral gaps (b−σ)/σ3 on x and y, FB z = axial gap on |b_zz|, "
          "FB sh = largest symmetric shear gap of the three planes, MB xz/yz/xy = moment balance "
          "per plane, rot = median KE_rot/KE. paper and zig are those of b_zz, σ_zz.\n\n";
  atlas_case_tables(md, res);
  md << "\n## Tolerance evidence\n\n"
     << "Over the " << std::count_if(res.cases.begin(), res.cases.end(), scored)
     << " finished trials: a trial is accurate when |peak error| <= " << 100.0 * res.accuracy
     << " %. safe alone = smallest value among inaccurate trials (a tolerance below it certifies "
        "accuracy by this measure alone); safe joint = the same among inaccurate trials that pass "
        "the other three criteria; binding = inaccurate trials rejected by this criterion "
        "only.\n\n"
     << "False passes (passed, inaccurate): " << res.false_passes
     << "; false rejects (accurate, failed): " << res.false_rejects
     << ". Largest |peak error| of a passing trial: " << fixed(100.0 * res.worst_passed_error, 2)
     << " %. For comparison, the paper's form alone (RMS(b_yy−σ_yy)/RMS(b_yy) <= 2 %) passes "
        "trials up to "
     << fixed(100.0 * res.worst_paper_form_error, 1) << " % off.\n\n"
     << "| measure | tolerance | safe alone | safe joint | binding |\n|---|---:|---:|---:|---:|\n";
  for (const auto& e : res.evidence) {
    md << "| " << e.name << " | " << (e.tolerance > 0.0 ? compact(e.tolerance) : "–") << " | "
       << compact(e.safe_alone) << " | " << (e.tolerance > 0.0 ? compact(e.safe_joint) : "–")
       << " | " << (e.tolerance > 0.0 ? std::to_string(e.binding) : "–") << " |\n";
  }
  atlas_criterion_bins(md, res);
  md << "\nDiagnoses in words:\n\n";
  for (const auto& r : res.cases) {
    if (r.spec.group != "benchmark" && r.spec.group != "atlas") continue;
    md << "- **" << r.spec.name << "** (" << r.spec.change << "; paper: " << r.spec.expected
       << "): " << r.score.diagnosis.message << "\n";
  }
  md << "\nSweep wall time " << fixed(res.wall_time_s, 1) << " s on " << res.jobs
     << " threads (consolidation "
     << (res.consolidation.from_cache ? "read from the cache in " : "")
     << fixed(res.consolidation.wall_time_s, 1) << " s, once).\n";
  return md.str();
}

std::string evidence_csv(const SweepResult& res) {
  std::ostringstream s;
  s << std::setprecision(6);
  s << "name,group,dt_ratio,steps,zeta_t,zeta_r,mass_scaling,diverged,peak_ratio,peak_error,"
       "passed,accurate,force_balance,force_balance_paper,force_balance_xx,force_balance_yy,"
       "force_balance_shear,force_balance_xx_rms,force_balance_whole,moment_balance,moment_balance_"
       "trend,"
       "moment_noise,servo,servo_rms,interior_lateral,oscillation,zigzag,post_peak_softening,"
       "plateau_spread,unbalanced_force_ratio_max,kinetic_energy_ratio_max,diagnosis";
  if (res.dimension == 3)
    s << ",force_balance_x,force_balance_y,force_balance_z_xz,force_balance_z_yz,"
         "force_balance_shear_xz,force_balance_shear_yz,force_balance_shear_xy,moment_balance_xz,"
         "moment_balance_yz,moment_balance_xy,servo_xmin,servo_xmax,servo_ymin,servo_ymax,"
         "rotational_energy_share";
  s << '\n';
  for (const auto& r : res.cases) {
    const Criteria& c = r.score.criteria;
    const AlgorithmSpec& a = r.spec.algorithm;
    s << r.spec.name << ',' << r.spec.group << ',' << a.dt_ratio << ',' << a.steps << ','
      << a.damping_ratio_translation << ',' << a.damping_ratio_rotation << ',' << a.mass_scaling
      << ',' << (r.run.diverged ? 1 : 0) << ',' << -c.peak_stress_yy / res.lateral_stress << ','
      << (c.peak_error ? *c.peak_error : std::nan("")) << ',' << (r.score.passed ? 1 : 0) << ','
      << (r.accurate ? 1 : 0) << ',' << c.force_balance << ',' << c.force_balance_paper << ','
      << c.force_balance_xx << ',' << c.force_balance_yy << ',' << c.force_balance_shear << ','
      << c.force_balance_xx_rms << ',' << c.force_balance_whole << ',' << c.moment_balance << ','
      << c.moment_balance_trend << ',' << c.moment_noise << ',' << c.servo << ',' << c.servo_rms
      << ',' << c.interior_lateral << ',' << c.oscillation << ',' << c.zigzag << ','
      << c.post_peak_softening << ',' << c.plateau_spread << ',' << c.unbalanced_force_ratio_max
      << ',' << c.kinetic_energy_ratio_max << ',' << r.score.diagnosis.parameter << '_'
      << r.score.diagnosis.direction;
    if (r.planes) {
      const TriaxialCriteria& p = *r.planes;
      s << ',' << p.xz.force_balance_xx << ',' << p.yz.force_balance_xx << ','
        << p.xz.force_balance_yy << ',' << p.yz.force_balance_yy << ',' << p.xz.force_balance_shear
        << ',' << p.yz.force_balance_shear << ',' << p.xy.force_balance_shear << ','
        << p.xz.moment_balance << ',' << p.yz.moment_balance << ',' << p.xy.moment_balance;
      for (double w : p.servo_walls) s << ',' << w;
      s << ',' << c.rotational_energy_share;
    }
    s << '\n';
  }
  return s.str();
}

}  // namespace demcal
