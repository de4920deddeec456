// The report's second part: the paper's panels, the diagnosis, the search
// history, speed against accuracy, upscaling, the assembly, every trial.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "assembly_svg.hpp"
#include "demcal/io/format.hpp"
#include "sections.hpp"

namespace demcal::report {

namespace {

/// What the panels show of one series, in numbers.
struct SeriesNumbers {
  double peak = 0, peak_strain = 0, max_gap_yy = 0, max_gap_xx = 0, max_asym = 0, max_servo = 0;
  Criteria c;
  bool diverged = false;
};

SeriesNumbers series_numbers(const std::vector<MonitorPoint>& s, const Criteria& c, bool diverged) {
  SeriesNumbers f;
  f.c = c;
  f.diverged = diverged;
  const Peak pk = find_peak(s);
  f.peak = pk.stress_yy;
  f.peak_strain = pk.strain_yy;
  for (size_t k = 1; k < s.size(); ++k) {
    const auto& p = s[k];
    f.max_gap_yy = std::max(f.max_gap_yy, std::abs(p.b(1, 1) - p.sigma(1, 1)));
    f.max_gap_xx = std::max(f.max_gap_xx, std::abs(p.b(0, 0) - p.sigma(0, 0)));
    f.max_asym = std::max(f.max_asym, std::abs(p.sigma(0, 1) - p.sigma(1, 0)));
    f.max_servo = std::max(f.max_servo, std::abs(p.lateral_stress_error));
  }
  return f;
}

/// The panels' facts as a table: a column per run (and the reference).
void write_panel_numbers(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  std::vector<std::string> head{"measure"};
  for (const auto* r : f.runs) head.push_back(r->label);
  if (f.have_ref_series) head.push_back("Nstep ×16");
  std::vector<SeriesNumbers> fs;
  for (const auto* r : f.runs)
    fs.push_back(series_numbers(r->run.series, r->score.criteria, r->run.diverged));
  if (f.have_ref_series)
    fs.push_back(
        series_numbers(in.reference->fine_series, in.reference->fine.score.criteria, false));
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const std::string& name,
                 const std::function<std::string(const SeriesNumbers&)>& cell) {
    std::vector<std::string> r{name};
    for (const auto& x : fs) r.push_back(cell(x));
    rows.push_back(r);
  };
  using N = const SeriesNumbers&;
  row("peak b_yy (monitoring points)", [](N x) { return kpa(x.peak); });
  row("strain at the peak", [](N x) { return pct(x.peak_strain, 3); });
  row("max |b_yy − σ_yy|", [](N x) { return kpa(x.max_gap_yy); });
  row("max |b_xx − σ_xx|", [](N x) { return kpa(x.max_gap_xx); });
  row("max |σ_xy − σ_yx|", [](N x) { return kpa(x.max_asym); });
  row("max |servo error|", [](N x) { return pct(x.max_servo, 3); });
  row("force balance (criterion)", [](N x) { return num(x.c.force_balance, 3); });
  row("moment balance (criterion)", [](N x) { return num(x.c.moment_balance, 3); });
  row("servo (criterion)", [](N x) { return num(x.c.servo, 3); });
  row("oscillation (criterion)", [](N x) { return num(x.c.oscillation, 3); });
  // "no" would colour red: say it plainly.
  row("diverged?", [](N x) { return std::string(x.diverged ? "diverged" : "did not diverge"); });
  d.table(head, rows);
}

}  // namespace

void write_panels(Doc& d, const ReportFacts& f, const Figures& figures) {
  const ReportInput& in = *f.in;
  d.heading(2, "Start point and result: the paper's panels", "panels");
  if (f.runs.empty()) {
    d.para("No runs with series were recorded.");
    return;
  }
  std::string intro = "Each run below was rerun with its whole series (" +
                      std::to_string(f.runs[0]->run.series.size()) + " monitoring points).";
  if (in.start)
    intro += " Start point: " + params_text(in.start->params) +
             " (the paper's recommended multipliers with a size-based Nstep of " +
             grouped(in.particles > 0 ? in.start->params.steps / in.particles : 0) +
             " per particle, where the search starts).";
  if (in.best) intro += " Calibrated: " + params_text(in.best->params) + ".";
  d.para(intro);
  for (const char* name : {"fig_a", "fig_b", "fig_lat", "fig_servo"}) figures.put(d, name);
  write_panel_numbers(d, f);
}

namespace {

/// Distance of `p` from the result `b` in the search space, each axis
/// normalised by its range (α by its span, Nstep by 400× in log, ζ by 4).
double search_distance(const AlgorithmSpec& p, const AlgorithmSpec& b, double a_span) {
  const double da = (p.dt_ratio - b.dt_ratio) / a_span;
  const double dn =
      std::log10(static_cast<double>(p.steps) / static_cast<double>(b.steps)) / std::log10(400.0);
  const double dt = (p.damping_ratio_translation - b.damping_ratio_translation) / 4.0;
  const double dr = (p.damping_ratio_rotation - b.damping_ratio_rotation) / 4.0;
  return std::sqrt(da * da + dn * dn + dt * dt + dr * dr);
}

/// What differs between a trial's parameters `p` and the result `b`.
std::string differs_from(const AlgorithmSpec& p, const AlgorithmSpec& b) {
  std::vector<std::string> parts;
  auto rel = [](double v, double ref) { return ref != 0 ? (v - ref) / std::abs(ref) : 0.0; };
  const double steps_change = rel(static_cast<double>(p.steps), static_cast<double>(b.steps));
  if (std::abs(steps_change) > 0.005)
    parts.push_back("Nstep " + grouped(p.steps) + " (" + signed_pct(steps_change, 0) + ")");
  if (std::abs(p.dt_ratio - b.dt_ratio) > 0.0005)
    parts.push_back("α " + num(p.dt_ratio, 3) + " (result " + num(b.dt_ratio, 3) + ")");
  if (std::abs(p.damping_ratio_translation - b.damping_ratio_translation) > 0.005)
    parts.push_back("ζ_t " + num(p.damping_ratio_translation, 3) + " (result " +
                    num(b.damping_ratio_translation, 3) + ")");
  if (std::abs(p.damping_ratio_rotation - b.damping_ratio_rotation) > 0.005)
    parts.push_back("ζ_r " + num(p.damping_ratio_rotation, 3) + " (result " +
                    num(b.damping_ratio_rotation, 3) + ")");
  std::string out;
  for (size_t k = 0; k < parts.size(); ++k) out += (k ? ", " : "") + parts[k];
  return out.empty() ? std::string("same parameters") : out;
}

/// Rejected neighbourhoods: the failed trials nearest to the result.
void write_rejected_neighbours(Doc& d, const ReportFacts& f, int near_failures) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  const double a_span = std::max(0.05, in.dt_ratio_max > 0 ? in.dt_ratio_max : 0.3);
  std::vector<std::pair<double, const TrialRecord*>> failed;
  for (const auto& t : S.trials)
    if (!t.score.passed) failed.push_back({search_distance(t.params, S.best, a_span), &t});
  std::stable_sort(failed.begin(), failed.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (failed.size() > static_cast<size_t>(near_failures)) failed.resize(near_failures);
  if (failed.empty()) {
    d.para("No trial failed: there is no rejected neighbourhood to describe.");
    return;
  }
  d.para(
      "Rejected neighbourhoods: the failed trials nearest to the result (distance in the "
      "search space normalised by its ranges), what differs from the result, and why they "
      "failed.");
  std::vector<std::vector<std::string>> rows;
  for (const auto& [dd, t] : failed) {
    const Excesses r = excesses(t->score.criteria, in.tolerances);
    rows.push_back(
        {std::to_string(t->id), differs_from(t->params, S.best), verdict(*t),
         t->score.diverged ? "diverged" : r.worst_name() + " " + fixed(r.worst(), 2) + "×",
         t->score.diagnosis.message.empty() ? "(no diagnosis recorded)"
                                            : sentence(t->score.diagnosis.message)});
  }
  d.table({"trial", "differs from the result in", "verdict", "worst criterion / tolerance",
           "diagnosis"},
          rows);
}

}  // namespace

void write_diagnosis(Doc& d, const ReportFacts& f, int near_failures) {
  const ReportInput& in = *f.in;
  d.heading(2, "Diagnosis in words", "diagnosis");
  if (in.start) {
    const auto& s = in.start->score;
    const Excesses r = excesses(s.criteria, in.tolerances);
    std::string text = "Start point (" + params_text(in.start->params) + "): " +
                       (s.passed ? "passes every criterion. "
                                 : "does not pass (worst: " + r.worst_name() + " at " +
                                       fixed(r.worst(), 2) + "× its tolerance). ") +
                       sentence(s.diagnosis.message);
    if (!s.diagnosis.signature.empty() && s.diagnosis.parameter != "none")
      text += " Signature: " + sentence(s.diagnosis.signature);
    d.para(text);
  }
  if (in.best) {
    const auto& s = in.best->score;
    d.para((in.summary.success ? "Calibrated run: " : "Best run found (not certified): ") +
           std::string(s.passed ? "passes every criterion" : "does not pass") +
           (s.diagnosis.message.empty() ? "." : ". " + sentence(s.diagnosis.message)));
  }
  if (f.have_best) write_rejected_neighbours(d, f, near_failures);
}

void write_history(Doc& d, const ReportFacts& f, const Figures& figures) {
  const auto& trials = f.in->summary.trials;
  d.heading(2, "Search history", "history");
  if (trials.empty()) {
    d.para("No trials.");
    return;
  }
  int pass = 0, fail = 0, early = 0, div = 0;
  for (const auto& t : trials) {
    if (t.score.diverged)
      ++div;
    else if (!t.score.complete)
      ++early;
    else if (t.score.passed)
      ++pass;
    else
      ++fail;
  }
  d.para(std::to_string(trials.size()) + " trials: " + std::to_string(pass) + " passed, " +
         std::to_string(fail) + " failed, " + std::to_string(early) +
         " stopped early (certain failures), " + std::to_string(div) +
         " diverged. Every trial with its criteria is in the table at the end and in "
         "DIR/trials.jsonl.");
  figures.put(d, "fig_history");
}

namespace {

std::string peak_error_cell(const Point& p, const char* none) {
  return p.peak_error ? signed_pct(*p.peak_error, 2) : std::string(none);
}

/// The Pareto front in numbers: force-balance error against particle-steps.
void write_pareto_front(Doc& d, const ReportFacts& f) {
  std::vector<const Point*> fin;
  for (const auto& p : f.points)
    if (p.trial->score.complete && !p.trial->score.diverged &&
        p.trial->score.criteria.force_balance > 0)
      fin.push_back(&p);
  std::stable_sort(fin.begin(), fin.end(), [](const Point* a, const Point* b) {
    return a->cost < b->cost || (a->cost == b->cost && a->trial->score.criteria.force_balance <
                                                           b->trial->score.criteria.force_balance);
  });
  std::vector<std::vector<std::string>> rows;
  double ymin = std::numeric_limits<double>::infinity();
  for (const Point* p : fin) {
    if (p->trial->score.criteria.force_balance >= ymin) continue;
    ymin = p->trial->score.criteria.force_balance;
    rows.push_back({p->label + (p->best ? " (chosen)" : ""), to_string(p->trial->phase),
                    params_text(p->trial->params), sci(p->cost), num(p->seconds, 3),
                    num(p->trial->score.criteria.force_balance, 3), verdict(*p->trial),
                    peak_error_cell(*p, "n/a")});
  }
  d.heading(3, "Pareto front (force-balance error against particle-steps)");
  d.table({"trial", "phase", "parameters", "particle-steps", "seconds", "force balance", "verdict",
           "peak error vs reference"},
          rows);
}

}  // namespace

void write_speed(Doc& d, const ReportFacts& f, const Figures& figures) {
  d.heading(2, "Speed against accuracy", "speed");
  std::string intro =
      "What each trial costs against how far from static it was. The chosen point is the "
      "cheapest trial that passes every criterion and the convergence certificate.";
  if (!f.in->reference)
    intro +=
        " Peak errors against a converged reference are measured with --evidence (it "
        "runs the calibrated multipliers at 8× and 16× Nstep, and the paper's recipe).";
  d.para(intro);
  figures.put(d, "fig_speed");
  write_pareto_front(d, f);
  std::vector<std::vector<std::string>> marks;
  const Point* base = f.baseline();
  for (const auto& p : f.points)
    if (p.best || &p == base)
      marks.push_back({p.best ? "chosen (calibrated)" : "paper recipe", p.label,
                       params_text(p.trial->params), sci(p.cost), num(p.seconds, 3),
                       num(p.trial->score.criteria.force_balance, 3), peak_error_cell(p, "n/a")});
  if (!marks.empty()) {
    d.heading(3, "Highlighted points");
    d.table({"point", "trial", "parameters", "particle-steps", "seconds", "force balance",
             "peak error vs reference"},
            marks);
  }
}

void write_upscaling(Doc& d, const ReportFacts& f, const Figures& figures) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  d.heading(2, "Upscaling to the prototype", "upscaling");
  if (!f.have_best) {
    d.para("No calibrated Nstep to upscale.");
  } else if (!f.upscale) {
    d.para(
        "No prototype larger than the REV is configured (prototype.particles): the REV "
        "parameters are the answer. With a prototype, Nstep_prototype = Nstep_REV · "
        "N_prototype / N_REV and the multipliers stay.");
  } else {
    d.para("Nstep_prototype = Nstep_REV · N_prototype / N_REV = " + grouped(S.best.steps) + " · " +
           grouped(in.prototype_particles) + " / " + grouped(in.particles) + " = " +
           grouped(f.proto_steps) + " (" +
           num(static_cast<double>(S.best.steps) / static_cast<double>(in.particles), 4) +
           " steps per particle); α, ζ_t and ζ_r are kept (they do not depend on size).");
    figures.put(d, "fig_upscale");
  }
}

void write_assembly(Doc& d, const ReportFacts& f) {
  d.heading(2, "The assembly at the peak", "assembly");
  if (!f.in->picture) {
    d.para("No picture: there is no calibrated run.");
    return;
  }
  const auto& p = *f.in->picture;
  double fmax = 0, tmax = 0;
  int pp = 0, pw = 0;
  for (const auto& force : p.forces) {
    fmax = std::max(fmax, force.fn);
    (force.wall ? pw : pp)++;
  }
  for (double t : p.rotation) tmax = std::max(tmax, std::abs(t));
  const std::string caption =
      "Calibrated run at its peak (step " + grouped(p.step) + " of " + grouped(p.steps) +
      ", ε_yy = " + pct(p.strain_yy, 3) + ", b_yy = " + kpa(p.stress_yy) +
      "): " + std::to_string(p.x.size()) +
      " disks coloured by their rotation since the start of "
      "loading (red counter-clockwise, blue clockwise, largest " +
      num(tmax * 180.0 / std::numbers::pi, 3) + "°); " + std::to_string(pp) +
      " particle contacts (black) and " + std::to_string(pw) +
      " wall contacts (brown), line width proportional to the normal force (largest " +
      num(fmax, 3) + " N).";
  d.html << "<figure>\n"
         << assembly_svg(p) << "\n<figcaption>" << esc(caption) << "</figcaption>\n</figure>\n";
  d.md << caption << " (picture in report.html)\n\n";
}

void write_all_trials(Doc& d, const ReportFacts& f) {
  const Tolerances& tol = f.in->tolerances;
  d.heading(2, "All trials", "trials");
  std::vector<std::vector<std::string>> rows;
  for (const auto& p : f.points) {
    const auto& t = *p.trial;
    const Excesses r = excesses(t.score.criteria, tol);
    auto ratio = [&](double v) { return t.score.diverged ? std::string("-") : fixed(v, 2); };
    rows.push_back({p.label + (p.best ? "*" : ""), to_string(t.phase), num(t.params.dt_ratio, 4),
                    grouped(t.params.steps), num(t.params.damping_ratio_translation, 3),
                    num(t.params.damping_ratio_rotation, 3), verdict(t), ratio(r.force_balance),
                    ratio(r.moment_balance), ratio(r.servo), ratio(r.oscillation),
                    t.score.complete && !t.score.diverged
                        ? num(t.score.criteria.peak_stress_yy / 1e3, 4)
                        : "-",
                    peak_error_cell(p, "-"), sci(p.cost), num(t.wall_time_s, 3),
                    num(objective(t.score, tol), 4), sentence(t.score.diagnosis.message)});
  }
  d.para(
      "Criteria are divided by their tolerances (≤ 1 passes). * marks the chosen trial; b: "
      "paper-recipe trials, r8/r16: the reference runs (--evidence). Seconds are as run "
      "(trials stopped early ran only part of the loading).");
  d.details_begin("Show all " + std::to_string(f.points.size()) + " trials");
  d.table(
      {"trial", "phase", "α", "Nstep", "ζ_t", "ζ_r", "verdict", "FB/tol", "MB/tol", "servo/tol",
       "osc/tol", "peak b_yy [kPa]", "peak error", "particle-steps", "s", "objective", "diagnosis"},
      rows, "trials");
  d.details_end();
}

}  // namespace demcal::report
