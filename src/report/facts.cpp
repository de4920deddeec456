#include "facts.hpp"

#include <algorithm>
#include <cmath>

#include "demcal/io/format.hpp"
#include "demcal/io/json_integer.hpp"

namespace demcal::report {

std::string grouped(int64_t v) {
  std::string s = std::to_string(v < 0 ? -v : v), out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (i > 0 && (s.size() - i) % 3 == 0) out += ',';
    out += s[i];
  }
  return (v < 0 ? "-" : "") + out;
}

std::string kpa(double pa) { return num(pa / 1e3, 4) + " kPa"; }

std::string strain_pct(double fraction, int dimension) {
  return dimension == 3 ? num(100.0 * fraction, 3) + " %" : pct(fraction, 3);
}

std::string peak_text(const std::string& axial, double stress, double strain, int dimension) {
  if (!(stress < 0.0)) return "none (no compressive peak)";
  return kpa(stress) + " at ε_" + axial.substr(2) + " = " + strain_pct(strain, dimension);
}

std::string peak_label(const ReportFacts& f, PeakKind kind) {
  return "peak " + f.axial +
         (kind == PeakKind::every_step ? ", largest at any loading step (criteria, certificate)"
                                       : ", largest at the monitoring points (plots, picture)");
}

std::string sentence(std::string s) {
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.empty()) return s;
  if (s[0] >= 'a' && s[0] <= 'z') s[0] = static_cast<char>(s[0] - 'a' + 'A');
  if (s.back() != '.') s += '.';
  return s;
}

std::string params_text(const AlgorithmSpec& p) {
  return "α " + num(p.dt_ratio, 4) + ", Nstep " + grouped(p.steps) + ", ζ_t " +
         num(p.damping_ratio_translation, 4) + ", ζ_r " + num(p.damping_ratio_rotation, 4);
}

std::string params_gp(const AlgorithmSpec& p) {
  return "α = " + num(p.dt_ratio, 3) + ",  N_{step} = " + std::to_string(p.steps) +
         ",  ζ_t = " + num(p.damping_ratio_translation, 3) +
         ",  ζ_r = " + num(p.damping_ratio_rotation, 3);
}

std::string verdict(const TrialRecord& t) {
  if (t.score.diverged) return "diverged";
  if (!t.score.complete) return "stopped early";
  return t.score.passed ? "pass" : "FAIL";
}

namespace {

Point point_of(const ReportInput& in, bool have_best, const TrialRecord& t,
               const std::string& label) {
  const auto& S = in.summary;
  Point p;
  p.label = label;
  p.trial = &t;
  p.cost = t.score.particle_steps;
  p.seconds = t.wall_time_s;
  if (!t.score.complete && t.steps_run > 0 && t.params.steps > t.steps_run)
    p.seconds *= static_cast<double>(t.params.steps) / static_cast<double>(t.steps_run);
  if (in.reference) p.peak_error = peak_error(t, in.reference->peak);
  p.best = have_best && t.phase == S.best_trial.phase && t.id == S.best_trial.id &&
           t.params.steps == S.best_trial.params.steps;
  return p;
}

/// Nstep of the prototype: params.json's when written, else the REV's
/// scaled with the particle count.
int64_t prototype_steps(const ReportInput& in) {
  const auto& best = in.summary.best;
  int64_t steps = std::llround(static_cast<double>(best.steps) *
                               static_cast<double>(std::max(in.prototype_particles, in.particles)) /
                               static_cast<double>(in.particles));
  if (in.params.is_object() && in.params.contains("prototype") &&
      in.params["prototype"].contains("steps"))
    steps = json_integer(in.params["prototype"]["steps"], 1);
  return steps;
}

}  // namespace

std::vector<std::vector<double>> panel_rows(const std::vector<MonitorPoint>& series) {
  std::vector<std::vector<double>> rows;
  rows.reserve(series.size());
  for (const auto& p : series)
    rows.push_back({-100.0 * p.strain_yy, -p.b(1, 1) / 1e3, -p.sigma(1, 1) / 1e3,
                    p.sigma(0, 1) / 1e3, p.sigma(1, 0) / 1e3, -p.b(0, 0) / 1e3,
                    -p.sigma(0, 0) / 1e3, 100.0 * p.lateral_stress_error});
  return rows;
}

std::vector<std::vector<double>> panel_rows(const std::vector<TriaxialPoint>& series) {
  std::vector<std::vector<double>> rows;
  rows.reserve(series.size());
  for (const auto& p : series) {
    const auto& b = p.b;
    const auto& s = p.sigma;
    rows.push_back({-100.0 * p.strain_zz, -b(2, 2) / 1e3, -s(2, 2) / 1e3, -b(0, 0) / 1e3,
                    -s(0, 0) / 1e3, -b(1, 1) / 1e3, -s(1, 1) / 1e3, s(0, 1) / 1e3, s(1, 0) / 1e3,
                    s(0, 2) / 1e3, s(2, 0) / 1e3, s(1, 2) / 1e3, s(2, 1) / 1e3,
                    100.0 * p.servo_error[0], 100.0 * p.servo_error[1], 100.0 * p.servo_error[2],
                    100.0 * p.servo_error[3]});
  }
  return rows;
}

namespace {

template <class Run>
PanelRun panel_run(const Run& r, bool result) {
  PanelRun p;
  p.label = r.label;
  p.params = &r.params;
  p.score = &r.score;
  p.diverged = r.run.diverged;
  p.result = result;
  p.rows = panel_rows(r.run.series);
  return p;
}

void gather_runs(const ReportInput& in, ReportFacts& f) {
  f.runs.reserve(2);
  if (in.dimension == 3) {
    if (in.start3) f.runs.push_back(panel_run(*in.start3, false));
    if (in.best3) f.runs.push_back(panel_run(*in.best3, true));
  } else {
    if (in.start) f.runs.push_back(panel_run(*in.start, false));
    if (in.best) f.runs.push_back(panel_run(*in.best, true));
  }
  for (const auto& r : f.runs) (r.result ? f.result : f.start) = &r;
  f.have_ref_series = in.dimension != 3 && in.reference && !in.reference->fine_series.empty();
  if (f.have_ref_series) {
    f.reference.label = "Nstep ×16";
    f.reference.params = &in.reference->fine.params;
    f.reference.score = &in.reference->fine.score;
    f.reference.rows = panel_rows(in.reference->fine_series);
  }
}

}  // namespace

void gather_facts(const ReportInput& in, ReportFacts& f) {
  f.in = &in;
  f.dimension = in.dimension;
  f.axial = in.dimension == 3 ? "b_zz" : "b_yy";
  const auto& S = in.summary;
  f.have_best = S.has_best_trial();
  auto add = [&](const TrialRecord& t, const std::string& label) {
    f.points.push_back(point_of(in, f.have_best, t, label));
  };
  for (const auto& t : S.trials) add(t, std::to_string(t.id));
  if (in.baseline)
    for (size_t k = 0; k < in.baseline->trials.size(); ++k) {
      // Appended rather than "b" + to_string(k): GCC 12 warns wrongly on
      // that concatenation once inlined here (-Wrestrict, its bug 105329).
      std::string label = "b";
      add(in.baseline->trials[k], label.append(std::to_string(k)));
    }
  if (in.reference) {
    add(in.reference->coarse, "r8");
    add(in.reference->fine, "r16");
  }
  for (size_t k = 0; k < f.points.size(); ++k) {
    const Point& p = f.points[k];
    if (p.best) f.best_peak_error = p.peak_error;
    if (p.trial->phase == TrialPhase::baseline && p.trial->score.passed)
      f.baseline_index = static_cast<int>(k);
  }
  gather_runs(in, f);
  // 3D: the prototype block of params.json as it is (no size law assumed).
  f.upscale =
      in.dimension != 3 && f.have_best && in.prototype_particles > in.particles && in.particles > 0;
  if (f.have_best && in.particles > 0) f.proto_steps = prototype_steps(in);
}

}  // namespace demcal::report
