// The report's second part: the paper's panels, the diagnosis, the search
// history, speed against accuracy, upscaling, the assembly, every trial.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "assembly_svg.hpp"
#include "demcal/io/format.hpp"
#include "demcal/report/sphere_svg.hpp"
#include "sections.hpp"

namespace demcal::report {

namespace {

/// A row of the panel numbers: a run's largest |column a − column b| (b = 0:
/// its largest |column a|) over the series after the first point.
struct GapRow {
  std::string name;
  int a = 0, b = 0;
  bool percent = false;  ///< a servo error [%] (else a stress [kPa])
};

std::vector<GapRow> gap_rows(int dimension) {
  if (dimension == 3)
    return {{"max |b_zz − σ_zz|", col3::b_axial, col3::s_axial},
            {"max |b_xx − σ_xx|", col3::b_xx, col3::s_xx},
            {"max |b_yy − σ_yy|", col3::b_yy, col3::s_yy},
            {"max |σ_xy − σ_yx|", col3::s_xy, col3::s_yx},
            {"max |σ_xz − σ_zx|", col3::s_xz, col3::s_zx},
            {"max |σ_yz − σ_zy|", col3::s_yz, col3::s_zy},
            {"max |servo error|, wall x min", col3::servo_xmin, 0, true},
            {"max |servo error|, wall x max", col3::servo_xmax, 0, true},
            {"max |servo error|, wall y min", col3::servo_ymin, 0, true},
            {"max |servo error|, wall y max", col3::servo_ymax, 0, true}};
  return {{"max |b_yy − σ_yy|", col2::b_axial, col2::s_axial},
          {"max |b_xx − σ_xx|", col2::b_xx, col2::s_xx},
          {"max |σ_xy − σ_yx|", col2::s_xy, col2::s_yx},
          {"max |servo error|", col2::servo, 0, true}};
}

double max_gap(const PanelRun& r, const GapRow& g) {
  double m = 0.0;
  for (size_t k = 1; k < r.rows.size(); ++k)
    m = std::max(m, std::abs(r.at(k, g.a) - (g.b > 0 ? r.at(k, g.b) : 0.0)));
  return m;
}

/// The monitored peak of the axial boundary stress (column 2, compression
/// positive) and its strain (column 1), the first largest.
std::pair<double, double> monitored_peak(const PanelRun& r) {
  double peak = r.rows.empty() ? 0.0 : r.at(0, 2), strain = r.rows.empty() ? 0.0 : r.at(0, 1);
  for (size_t k = 1; k < r.rows.size(); ++k)
    if (r.at(k, 2) > peak) {
      peak = r.at(k, 2);
      strain = r.at(k, 1);
    }
  return {peak, strain};
}

/// A run's peak as its score has it: the largest at any loading step.
std::string scored_peak_text(const ReportFacts& f, const PanelRun& r) {
  const auto& c = r.score->criteria;
  return peak_text(f.axial, c.peak_stress_yy, c.peak_strain_yy, f.dimension);
}

/// A run's peak at its monitoring points (the panel table is in kPa and %,
/// compression positive).
std::string monitored_peak_text(const ReportFacts& f, const PanelRun& r) {
  const auto [peak, strain] = monitored_peak(r);
  return peak_text(f.axial, -1e3 * peak, -strain / 100.0, f.dimension);
}

/// Why the panel table gives two peaks, with the calibrated run's two when
/// they lie at different strains.
void write_two_peaks(Doc& d, const ReportFacts& f) {
  const PanelRun* r = f.result ? f.result : f.start;
  std::string text = "Two peaks of " + f.axial + " per run: the largest at any loading step ";
  text += "(tracked every step; the criteria, the certificate and the trials give this one) ";
  text += "and the largest at the " + std::to_string(r->rows.size()) + " monitoring points ";
  text += "(what the plots show; the assembly picture is taken there). A maximum between two ";
  text += "monitoring points is seen by the first alone, so on a flat peak the two are close ";
  text += "in stress but can lie far apart in strain.";
  const auto [mon_peak, mon_strain] = monitored_peak(*r);
  const auto& c = r->score->criteria;
  const std::string every = scored_peak_text(f, *r), monitored = monitored_peak_text(f, *r);
  if (c.peak_stress_yy < 0.0 && mon_peak > 0.0 &&
      strain_pct(c.peak_strain_yy, f.dimension) != strain_pct(-mon_strain / 100.0, f.dimension))
    text +=
        " The " + r->label + " run: " + every + " against " + monitored + ", " +
        num(100.0 * std::abs(c.peak_stress_yy + 1e3 * mon_peak) / std::abs(c.peak_stress_yy), 2) +
        " % apart in stress.";
  d.para(text, "small");
}

/// The panels' facts as a table: a column per run (and the reference).
void write_panel_numbers(Doc& d, const ReportFacts& f) {
  std::vector<std::string> head{"measure"};
  std::vector<const PanelRun*> runs;
  for (const auto& r : f.runs) runs.push_back(&r);
  if (f.have_ref_series) runs.push_back(&f.reference);
  for (const auto* r : runs) head.push_back(r->label);
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const std::string& name, const std::function<std::string(const PanelRun&)>& cell) {
    std::vector<std::string> r{name};
    for (const auto* x : runs) r.push_back(cell(*x));
    rows.push_back(r);
  };
  using R = const PanelRun&;
  row(peak_label(f, PeakKind::every_step), [&](R x) { return scored_peak_text(f, x); });
  row(peak_label(f, PeakKind::monitored), [&](R x) { return monitored_peak_text(f, x); });
  for (const auto& g : gap_rows(f.dimension))
    row(g.name, [&](R x) {
      const double v = max_gap(x, g);
      return g.percent ? pct(v / 100.0, 3) : kpa(1e3 * v);
    });
  row("force balance (criterion)", [](R x) { return num(x.score->criteria.force_balance, 3); });
  row("moment balance (criterion)", [](R x) { return num(x.score->criteria.moment_balance, 3); });
  row("servo (criterion)", [](R x) { return num(x.score->criteria.servo, 3); });
  row("oscillation (criterion)", [](R x) { return num(x.score->criteria.oscillation, 3); });
  // "no" would colour red: say it plainly.
  row("diverged?", [](R x) { return std::string(x.diverged ? "diverged" : "did not diverge"); });
  d.table(head, rows);
  write_two_peaks(d, f);
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
                      std::to_string(f.runs[0].rows.size()) + " monitoring points).";
  if (f.start)
    intro += " Start point: " + params_text(*f.start->params) +
             " (the paper's recommended multipliers with a size-based Nstep of " +
             grouped(in.particles > 0 ? f.start->params->steps / in.particles : 0) +
             " per particle, where the search starts).";
  if (f.result) intro += " Calibrated: " + params_text(*f.result->params) + ".";
  if (f.dimension == 3)
    intro +=
        " Triaxial test: z is the axial axis (top wall pushed down), the four lateral walls "
        "are servo-controlled at σ3.";
  d.para(intro);
  if (f.dimension == 3)
    for (const char* name : {"fig_a", "fig_lat_x", "fig_lat_y", "fig_shear_xy", "fig_shear_xz",
                             "fig_shear_yz", "fig_servo"})
      figures.put(d, name);
  else
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
  if (f.start) {
    const auto& s = *f.start->score;
    const Excesses r = excesses(s.criteria, in.tolerances);
    std::string text = "Start point (" + params_text(*f.start->params) + "): " +
                       (s.passed ? "passes every criterion. "
                                 : "does not pass (worst: " + r.worst_name() + " at " +
                                       fixed(r.worst(), 2) + "× its tolerance). ") +
                       sentence(s.diagnosis.message);
    if (!s.diagnosis.signature.empty() && s.diagnosis.parameter != "none")
      text += " Signature: " + sentence(s.diagnosis.signature);
    d.para(text);
  }
  if (f.result) {
    const auto& s = *f.result->score;
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

namespace {

/// 3D: what params.json's prototype block says (written by the upscaling
/// layer), or that the prototype is the REV when there is none.
void write_upscaling_3d(Doc& d, const ReportFacts& f) {
  const nlohmann::json& P = f.in->params;
  if (!P.is_object() || !P.contains("prototype") || !P["prototype"].is_object()) {
    d.para(
        "params.json has no prototype block: the prototype is the REV, and the REV parameters "
        "above are the answer.");
    return;
  }
  const nlohmann::json& B = P["prototype"];
  auto number = [&](const char* key) {
    if (!B.contains(key) || !B[key].is_number()) return std::string("n/a");
    const double v = B[key].get<double>();
    return key == std::string("particles") || key == std::string("steps")
               ? grouped(static_cast<int64_t>(std::llround(v)))
               : num(v, 6);
  };
  std::string source;
  if (B.contains("source") && B["source"].is_object()) {
    const auto& src = B["source"];
    if (src.contains("description") && src["description"].is_string())
      source = src["description"].get<std::string>();
    if (src.contains("kind") && src["kind"].is_string())
      source += (source.empty() ? "kind " : "; kind ") + src["kind"].get<std::string>();
  }
  const bool is_rev = B.contains("particles") && B["particles"].is_number() &&
                      B["particles"].get<double>() == static_cast<double>(f.in->particles);
  d.para(std::string(is_rev ? "The prototype is the REV" : "The prototype is not the REV") +
         " (params.json's prototype block" + (source.empty() ? "" : ": " + source) +
         "). In 3D the law Nstep(N) is measured (demcal scaling on a 3D family), not assumed "
         "linear: the sample's linear size grows as N^(1/3).");
  std::vector<std::vector<std::string>> rows;
  for (const char* key : {"particles", "steps", "dt_ratio", "dt", "damping_ratio_translation",
                          "damping_ratio_rotation", "mass_scaling"})
    rows.push_back({key, number(key)});
  d.table({"params.json prototype", "value"}, rows);
}

}  // namespace

void write_upscaling(Doc& d, const ReportFacts& f, const Figures& figures) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  d.heading(2, "Upscaling to the prototype", "upscaling");
  if (f.dimension == 3 && f.have_best) {
    write_upscaling_3d(d, f);
  } else if (!f.have_best) {
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

namespace {

void write_sphere_assembly(Doc& d, const ReportFacts& f) {
  if (!f.in->sphere_picture) {
    d.para("No picture: there is no calibrated run.");
    return;
  }
  const auto& p = *f.in->sphere_picture;
  const SphereColourScale cs = colour_scale(p);
  const std::string caption =
      "Calibrated run at its peak among the monitoring points (step " + grouped(p.step) + " of " +
      grouped(p.steps) + ", ε_zz = " + strain_pct(p.strain_zz, 3) + ", b_zz = " + kpa(p.stress_zz) +
      "): " + std::to_string(p.x.size()) +
      " spheres seen from the front right and above (z up; the box of walls dashed behind, "
      "faint in front), "
      "each coloured by the sum of the normal contact forces on it from the other spheres and "
      "the walls, " +
      num(cs.lo, 3) + " N to " + num(cs.hi, 3) +
      " N: the bright spheres carry the force chains. Only the spheres on the surface are "
      "visible; " +
      (f.in->vtk_file.empty()
           ? std::string("the whole assembly as VTK is written by demcal run (final.vtk).")
           : "the whole assembly with its contact network is in " + f.in->vtk_file +
                 " beside this report (ParaView: Glyph, type Sphere, scale array diameter, "
                 "factor 1).");
  d.html << "<figure>\n"
         << sphere_svg(p) << "\n<figcaption>" << esc(caption) << "</figcaption>\n</figure>\n";
  d.md << caption << " (picture in report.html)\n\n";
}

}  // namespace

void write_assembly(Doc& d, const ReportFacts& f) {
  d.heading(2, "The assembly at the peak", "assembly");
  if (f.dimension == 3) {
    write_sphere_assembly(d, f);
    return;
  }
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
      "Calibrated run at its peak among the monitoring points (step " + grouped(p.step) + " of " +
      grouped(p.steps) + ", ε_yy = " + pct(p.strain_yy, 3) + ", b_yy = " + kpa(p.stress_yy) +
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
  d.table({"trial", "phase", "α", "Nstep", "ζ_t", "ζ_r", "verdict", "FB/tol", "MB/tol", "servo/tol",
           "osc/tol", "peak " + f.axial + " [kPa]", "peak error", "particle-steps", "s",
           "objective", "diagnosis"},
          rows, "trials");
  d.details_end();
}

}  // namespace demcal::report
