#include "facts.hpp"

#include <algorithm>
#include <cmath>

#include "demcal/io/format.hpp"

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
    steps = in.params["prototype"]["steps"].get<int64_t>();
  return steps;
}

}  // namespace

ReportFacts gather_facts(const ReportInput& in) {
  ReportFacts f;
  f.in = &in;
  const auto& S = in.summary;
  f.have_best = S.best_trial.score.particle_steps > 0.0;  // default-constructed: none
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
  if (in.start) f.runs.push_back(&*in.start);
  if (in.best) f.runs.push_back(&*in.best);
  f.have_ref_series = in.reference && !in.reference->fine_series.empty();
  f.upscale = f.have_best && in.prototype_particles > in.particles && in.particles > 0;
  if (f.have_best && in.particles > 0) f.proto_steps = prototype_steps(in);
  return f;
}

}  // namespace demcal::report
