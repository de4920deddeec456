#include "plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <tuple>

#include "demcal/io/format.hpp"
#include "html.hpp"

namespace demcal::report {

namespace {

// Data files for gnuplot: numbers only, '?' for a missing value.
std::string dat(double v) {
  if (!std::isfinite(v)) return "?";
  char b[48];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

std::string terminal(int w, int h) {
  return "set terminal svg size " + std::to_string(w) + "," + std::to_string(h) +
         " dynamic enhanced font 'sans,11' background '#ffffff'\n";
}

std::string common() {
  return "set encoding utf8\nset grid lc rgb '#e0e0e0' lw 1\nset border lc rgb '#555555'\n"
         "set key box lt rgb '#cccccc' opaque samplen 2.5 spacing 1.1 font ',10'\n"
         "set datafile missing '?'\n";
}

/// A run's panel table as a gnuplot data file.
std::string series_dat(const PanelRun& r) {
  std::ostringstream o;
  for (const auto& row : r.rows) {
    for (size_t c = 0; c < row.size(); ++c) o << (c ? " " : "") << dat(row[c]);
    o << '\n';
  }
  return o.str();
}

std::string gp_range(double lo, double hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi))) return "[*:*]";
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    lo -= 1.0;
    hi += 1.0;
  }
  const double pad = 0.06 * (hi - lo);
  return "[" + dat(lo - pad) + ":" + dat(hi + pad) + "]";
}

// ---------------------------------------------------------------------------
// The paper's panels: one figure per quantity, a panel per run, shared axes.

struct SeriesFigure {
  std::string name, ylabel;
  std::vector<std::tuple<int, std::string, std::string>> curves;  ///< column, title, style
  std::string extra;            ///< gnuplot commands before the panels
  bool with_reference = false;  ///< the 16×Nstep reference on the result's panel
  std::string caption;
  std::vector<double> include;  ///< values the y range must show
};

/// The y range of a series figure: every curve of every run, except that a
/// diverged run does not set it (its values explode; it is clipped, and its
/// panel says it diverged).
std::pair<double, double> series_range(const std::vector<PanelRun>& runs,
                                       const SeriesFigure& spec) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : spec.include) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool any_finished = false;
  for (const auto& r : runs) any_finished = any_finished || !r.diverged;
  for (const auto& r : runs) {
    if (r.diverged && any_finished) continue;
    for (size_t k = 0; k < r.rows.size(); ++k)
      for (const auto& [c, t, s] : spec.curves) {
        const double v = r.at(k, c);
        if (std::isfinite(v)) {
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
  }
  return {lo, hi};
}

void add_series_figure(PlotPlan& plot, const ReportFacts& f, const SeriesFigure& spec) {
  const auto& runs = f.runs;
  if (runs.empty()) return;
  double strain = 0.0;
  for (const auto& r : runs)
    for (size_t k = 0; k < r.rows.size(); ++k) strain = std::max(strain, r.at(k, 1));
  const auto [lo, hi] = series_range(runs, spec);
  std::ostringstream g;
  g << terminal(1060, 370) << "set output '" << spec.name << ".svg'\n"
    << common() << "set multiplot layout 1," << runs.size() << "\n"
    << "set xlabel '"
    << (f.dimension == 3 ? "axial strain −ε_{zz} [%]" : "vertical strain −ε_{yy} [%]")
    << "'\nset ylabel '" << spec.ylabel << "'\n"
    << "set xrange [0:" << dat(strain > 0 ? strain : 1.0) << "]\nset yrange " << gp_range(lo, hi)
    << "\nset key top right\n"
    << spec.extra;
  for (size_t k = 0; k < runs.size(); ++k) {
    g << "set title '"
      << (runs[k].label == "start point" ? std::string("start point: ") : runs[k].label + ": ")
      << params_gp(*runs[k].params) << (runs[k].diverged ? "  (DIVERGED)" : "") << "'\n";
    g << "plot ";
    bool first = true;
    for (const auto& [c, t, s] : spec.curves) {
      g << (first ? "" : ", ") << "'run" << k << ".dat' u 1:" << c << " w l " << s << " t '" << t
        << "'";
      first = false;
    }
    if (spec.with_reference && f.have_ref_series && runs[k].result)
      g << ", 'ref.dat' u 1:2 w l lw 1 dt 3 lc rgb '#333333' t 'N_{step} ×16 (near-converged)'";
    g << "\n";
  }
  g << "unset multiplot\nunset output\nreset\n";
  plot.figures.push_back({spec.name, g.str(), spec.caption});
}

/// σ3 as a dashed line, for the lateral panels.
std::string sigma3_line(double s3) {
  return "set arrow 1 from graph 0, first " + dat(s3 / 1e3) + " to graph 1, first " +
         dat(s3 / 1e3) + " nohead dt 2 lc rgb '#666666'\nset label 1 'σ_3' at graph 0.98, first " +
         dat(s3 / 1e3) + " right offset 0,-0.8 tc rgb '#666666'\n";
}

/// ± the servo tolerance [%] as dashed lines.
std::string servo_lines(double tolerance) {
  const std::string t = dat(100.0 * tolerance);
  return "set arrow 1 from graph 0, first " + t + " to graph 1, first " + t +
         " nohead dt 2 lc rgb '#b3261e'\nset arrow 2 from graph 0, first -" + t +
         " to graph 1, first -" + t + " nohead dt 2 lc rgb '#b3261e'\n";
}

/// The axial panel: boundary stress b_ii and homogenized σ_ii along the
/// loading axis `ii` ("yy" in 2D, "zz" in 3D), with the 16×Nstep reference
/// where there is one. `Axis`: the strain's name, `bodies` what is loaded.
void add_axial_figure(PlotPlan& plot, const ReportFacts& f, int b_col, int s_col,
                      const std::string& ii, const std::string& Axis, const std::string& axis,
                      const std::string& bodies) {
  add_series_figure(plot, f,
                    {"fig_a",
                     "compressive stress [kPa]",
                     {{b_col, "−b_{" + ii + "} boundary", "lw 5 lc rgb '#9ecae1'"},
                      {s_col, "−σ_{" + ii + "} homogenized", "lw 1.5 lc rgb '#08306b'"}},
                     "set key bottom right\n",
                     true,
                     "(a) " + Axis + " boundary stress b_" + ii + " and homogenized stress σ_" +
                         ii + " against the " + axis +
                         " strain, compression positive, start point (left) and calibrated run "
                         "(right), same axes. A static run has the two curves on top of each "
                         "other; a gap means the " +
                         bodies +
                         " are not in force balance (loading too fast, too much or too little "
                         "damping).",
                     {}});
}

/// A lateral panel: boundary stress b_ii and homogenized σ_ii against σ3
/// (dashed), in light and dark shades of one colour.
void add_lateral_figure(PlotPlan& plot, const ReportFacts& f, const std::string& name,
                        const std::string& ii, int b_col, int s_col, const std::string& light,
                        const std::string& dark, const std::string& caption) {
  const double s3 = f.in->lateral_stress;
  add_series_figure(plot, f,
                    {name,
                     "lateral compressive stress [kPa]",
                     {{b_col, "−b_{" + ii + "} boundary", "lw 5 lc rgb '" + light + "'"},
                      {s_col, "−σ_{" + ii + "} homogenized", "lw 1.5 lc rgb '" + dark + "'"}},
                     sigma3_line(s3),
                     false,
                     caption,
                     {s3 / 1e3}});
}

/// A shear panel: the pair σ_ij, σ_ji of the homogenized stress; `head`
/// names them at the start of the caption.
void add_shear_figure(PlotPlan& plot, const ReportFacts& f, const std::string& name,
                      const std::string& ij, const std::string& ji, int ij_col, int ji_col,
                      const std::string& light, const std::string& dark, const std::string& head) {
  add_series_figure(
      plot, f,
      {name,
       "shear stress [kPa] (tension positive)",
       {{ij_col, "σ_{" + ij + "}", "lw 3 lc rgb '" + light + "'"},
        {ji_col, "σ_{" + ji + "}", "lw 1.2 lc rgb '" + dark + "'"}},
       "",
       false,
       head + " Moment balance means they coincide; large and opposite values mean rotational "
              "disequilibrium (time step too large, or rotational damping too high).",
       {}});
}

/// The servo panel: the lateral walls' stress errors [%] against ± the
/// servo tolerance (dashed).
void add_servo_figure(PlotPlan& plot, const ReportFacts& f, const std::string& ylabel,
                      std::vector<std::tuple<int, std::string, std::string>> curves,
                      const std::string& caption) {
  const double servo = f.in->tolerances.servo;
  add_series_figure(plot, f,
                    {"fig_servo",
                     ylabel,
                     std::move(curves),
                     servo_lines(servo),
                     false,
                     caption,
                     {-100.0 * servo, 100.0 * servo}});
}

/// The 2D panels: axial, the shear pair, lateral, the servo error.
void add_series_figures_2d(PlotPlan& plot, const ReportFacts& f) {
  add_axial_figure(plot, f, col2::b_axial, col2::s_axial, "yy", "Vertical", "vertical",
                   "particles");
  add_shear_figure(plot, f, "fig_b", "xy", "yx", col2::s_xy, col2::s_yx, "#fdae6b", "#7f2704",
                   "(b) Off-diagonal homogenized stresses σ_xy and σ_yx.");
  add_lateral_figure(
      plot, f, "fig_lat", "xx", col2::b_xx, col2::s_xx, "#a1d99b", "#00441b",
      "Lateral components: boundary stress b_xx and homogenized σ_xx against σ3 (dashed). Global "
      "damping that drags against the lateral expansion shows up as σ_xx above b_xx: extra "
      "confinement and an over-predicted peak.");
  add_servo_figure(plot, f, "servo error (p_{lateral} − σ_3)/σ_3 [%]",
                   {{col2::servo, "servo error", "lw 1.5 lc rgb '#54278f'"}},
                   "Boundary-control (servo) error of the lateral walls: mean lateral wall stress "
                   "against σ3, in %. Dashed: ± the servo tolerance (applied to the trend of this "
                   "curve).");
}

/// The 3D panels: axial, each lateral component, the three shear pairs,
/// the four lateral walls' servo errors.
void add_series_figures_3d(PlotPlan& plot, const ReportFacts& f) {
  add_axial_figure(plot, f, col3::b_axial, col3::s_axial, "zz", "Axial", "axial", "spheres");
  const struct {
    const char *name, *ii, *light, *dark;
    int b_col, s_col;
  } lateral[2] = {{"fig_lat_x", "xx", "#a1d99b", "#00441b", col3::b_xx, col3::s_xx},
                  {"fig_lat_y", "yy", "#fdd0a2", "#7f2704", col3::b_yy, col3::s_yy}};
  for (const auto& p : lateral)
    add_lateral_figure(plot, f, p.name, p.ii, p.b_col, p.s_col, p.light, p.dark,
                       std::string("Lateral component ") + p.ii + ": boundary stress b_" + p.ii +
                           " and homogenized σ_" + p.ii +
                           " against σ3 (dashed). Global damping that drags against the lateral "
                           "expansion shows up as σ above b: extra confinement and an "
                           "over-predicted peak.");
  const struct {
    const char *name, *ij, *ji, *light, *dark;
    int c1, c2;
  } shear[3] = {{"fig_shear_xy", "xy", "yx", "#fdae6b", "#7f2704", col3::s_xy, col3::s_yx},
                {"fig_shear_xz", "xz", "zx", "#bcbddc", "#3f007d", col3::s_xz, col3::s_zx},
                {"fig_shear_yz", "yz", "zy", "#a6dba0", "#00441b", col3::s_yz, col3::s_zy}};
  for (const auto& p : shear)
    add_shear_figure(
        plot, f, p.name, p.ij, p.ji, p.c1, p.c2, p.light, p.dark,
        std::string("(b) Shear pair σ_") + p.ij + " and σ_" + p.ji + " of the homogenized stress.");
  add_servo_figure(plot, f, "servo error (p_{wall} − σ_3)/σ_3 [%]",
                   {{col3::servo_xmin, "x min", "lw 1.5 lc rgb '#1b9e77'"},
                    {col3::servo_xmax, "x max", "lw 1.5 dt 2 lc rgb '#1b9e77'"},
                    {col3::servo_ymin, "y min", "lw 1.5 lc rgb '#7570b3'"},
                    {col3::servo_ymax, "y max", "lw 1.5 dt 2 lc rgb '#7570b3'"}},
                   "Boundary-control (servo) error of each of the four lateral walls: its stress "
                   "against σ3, in %. Dashed red: ± the servo tolerance (applied to the trend of "
                   "each curve).");
}

void add_series_figures(PlotPlan& plot, const ReportFacts& f) {
  for (size_t k = 0; k < f.runs.size(); ++k)
    plot.files["run" + std::to_string(k) + ".dat"] = series_dat(f.runs[k]);
  if (f.have_ref_series) plot.files["ref.dat"] = series_dat(f.reference);
  if (f.dimension == 3)
    add_series_figures_3d(plot, f);
  else
    add_series_figures_2d(plot, f);
}

// ---------------------------------------------------------------------------
// Search history: Nstep, criteria over tolerances and objective per trial.

/// Writes hist.dat (id, Nstep, the four ratios, objective) and one file per
/// verdict; returns the clauses of the Nstep panel and, in `any_ratio`,
/// which ratios have a value to plot.
std::vector<std::string> add_history_files(PlotPlan& plot, const ReportFacts& f,
                                           bool any_ratio[4]) {
  const Tolerances& tol = f.in->tolerances;
  std::ostringstream h, hp, hf, he, hd, hb;
  int64_t best_so_far = 0;
  for (const auto& t : f.in->summary.trials) {
    const Score& s = t.score;
    const Excesses r = excesses(s.criteria, tol);
    const double rv[4] = {r.force_balance, r.moment_balance, r.servo, r.oscillation};
    h << t.id << ' ' << t.params.steps;
    for (int k = 0; k < 4; ++k) {
      const bool ok = !s.diverged && std::isfinite(rv[k]) && rv[k] > 0;
      any_ratio[k] = any_ratio[k] || ok;
      h << ' ' << (ok ? dat(rv[k]) : "?");
    }
    h << ' ' << dat(objective(s, tol)) << '\n';
    std::ostringstream& o = s.diverged ? hd : !s.complete ? he : s.passed ? hp : hf;
    o << t.id << ' ' << t.params.steps << '\n';
    if (s.passed && s.complete && (best_so_far == 0 || t.params.steps < best_so_far))
      best_so_far = t.params.steps;
    if (best_so_far > 0) hb << t.id << ' ' << best_so_far << '\n';
  }
  plot.files["hist.dat"] = h.str();
  std::vector<std::string> clauses;
  auto add = [&](const std::string& file, const std::string& content, const std::string& clause) {
    if (content.empty()) return;
    plot.files[file] = content;
    clauses.push_back("'" + file + "' " + clause);
  };
  add("hist_best.dat", hb.str(), "u 1:2 w steps lw 2 lc rgb '#176b2c' t 'cheapest passing so far'");
  add("hist_pass.dat", hp.str(), "u 1:2 w p pt 7 ps 0.9 lc rgb '#2ca02c' t 'pass'");
  add("hist_fail.dat", hf.str(), "u 1:2 w p pt 6 ps 0.9 lc rgb '#d62728' t 'fail'");
  add("hist_early.dat", he.str(),
      "u 1:2 w p pt 4 ps 0.8 lc rgb '#ff7f0e' t 'stopped early (fail)'");
  add("hist_div.dat", hd.str(), "u 1:2 w p pt 2 ps 1.0 lc rgb '#000000' t 'diverged'");
  return clauses;
}

void add_history_figure(PlotPlan& plot, const ReportFacts& f) {
  const auto& trials = f.in->summary.trials;
  if (trials.empty()) return;
  bool any_ratio[4] = {false, false, false, false};
  const std::vector<std::string> clauses = add_history_files(plot, f, any_ratio);
  std::ostringstream g;
  g << terminal(1060, 760) << "set output 'fig_history.svg'\n"
    << common() << "set multiplot layout 3,1\nset xrange [-0.5:" << trials.back().id + 0.5 << "]\n"
    << "set key outside right top\nset lmargin 12\nset rmargin 30\n";
  // Panel 1: Nstep per trial.
  g << "set logscale y\nset format y '%.0f'\nset ylabel 'N_{step} (cost)'\nset xlabel ''\n"
       "set title 'Trials in order: the loading steps tried and the cheapest passing so "
       "far'\nplot ";
  for (size_t k = 0; k < clauses.size(); ++k) g << (k ? ", " : "") << clauses[k];
  g << "\n";
  // Panel 2: criteria / tolerance.
  const char* names[4] = {"force balance", "moment balance", "servo", "oscillation"};
  const char* colours[4] = {"#1f77b4", "#9467bd", "#8c564b", "#e377c2"};
  const int pts[4] = {7, 5, 9, 13};
  g << "set format y '10^{%L}'\nset ylabel 'criterion / tolerance'\nset title 'Each criterion "
       "per trial, divided by its "
       "tolerance (≤ 1 passes)'\n"
       "set arrow 1 from graph 0, first 1 to graph 1, first 1 nohead lw 1.5 dt 2 lc rgb "
       "'#b3261e'\n";
  bool any = false;
  std::ostringstream p2;
  for (int k = 0; k < 4; ++k) {
    if (!any_ratio[k]) continue;
    p2 << (any ? ", " : "plot ") << "'hist.dat' u 1:" << 3 + k << " w lp lw 1 pt " << pts[k]
       << " ps 0.6 lc rgb '" << colours[k] << "' t '" << names[k] << "'";
    any = true;
  }
  g << (any ? p2.str() : std::string("plot 1 notitle")) << "\n";
  // Panel 3: the objective.
  g << "unset arrow 1\nunset logscale y\nset format y '%g'\nset yrange [0:3]\nset xlabel "
       "'trial'\nset ylabel 'objective'\n"
       "set title 'Search objective: passed = log_{10}(particle-steps)/20 (< 1), failed 1 to 2, "
       "diverged 2 to 3'\n"
       "set arrow 2 from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc rgb '#888888'\n"
       "set arrow 3 from graph 0, first 2 to graph 1, first 2 nohead dt 2 lc rgb '#888888'\n"
       "plot 'hist.dat' u 1:7 w lp pt 7 ps 0.6 lw 1 lc rgb '#333333' t 'objective'\n";
  g << "unset multiplot\nunset output\nreset\n";
  plot.figures.push_back(
      {"fig_history", g.str(),
       "Search history. Top: Nstep of every trial (log), coloured by verdict, and the cheapest "
       "passing Nstep found so far. Middle: each criterion over its tolerance. Bottom: the "
       "objective the search minimises (every passing run beats every failing one)."});
}

// ---------------------------------------------------------------------------
// Speed against accuracy: cost (particle-steps, seconds) against error
// (force balance; with --evidence also the peak error), Pareto front marked.

bool finished(const Point& p) { return p.trial->score.complete && !p.trial->score.diverged; }
bool passed(const Point& p) { return p.trial->score.passed; }
bool in_phase(const Point& p, TrialPhase phase) { return p.trial->phase == phase; }

/// A class of points drawn with one style, in its own data file.
struct SpeedCategory {
  std::string file, clause;
  std::function<bool(const Point&)> in;
};

std::vector<SpeedCategory> speed_categories() {
  auto search = [](const Point& p) {
    return !in_phase(p, TrialPhase::baseline) && !in_phase(p, TrialPhase::reference);
  };
  return {{"sp_fail.dat", "w p pt 6 ps 0.9 lc rgb '#d62728' t 'search trial, fail'",
           [=](const Point& p) { return finished(p) && !passed(p) && search(p); }},
          {"sp_early.dat", "w p pt 4 ps 0.7 lc rgb '#ff7f0e' t 'stopped early (error so far)'",
           [](const Point& p) { return !p.trial->score.complete && !p.trial->score.diverged; }},
          {"sp_pass.dat", "w p pt 7 ps 0.9 lc rgb '#2ca02c' t 'search trial, pass'",
           [=](const Point& p) { return finished(p) && passed(p) && search(p); }},
          {"sp_base.dat",
           "w lp pt 9 ps 1.3 lw 1 dt 2 lc rgb '#e6550d' t 'paper recipe (Nstep doubled)'",
           [](const Point& p) { return finished(p) && in_phase(p, TrialPhase::baseline); }},
          {"sp_ref.dat", "w p pt 11 ps 1.3 lc rgb '#555555' t 'reference runs (8N, 16N)'",
           [](const Point& p) { return finished(p) && in_phase(p, TrialPhase::reference); }},
          {"sp_best.dat", "w p pt 3 ps 3 lw 2.5 lc rgb '#08519c' t 'chosen (calibrated)'",
           [](const Point& p) { return p.best; }}};
}

/// y: 0 force-balance error, 1 |peak error|; NaN when there is none.
double speed_y(const Point& p, int which) {
  if (which == 0) return p.trial->score.diverged ? NAN : p.trial->score.criteria.force_balance;
  return p.peak_error ? std::abs(*p.peak_error) : NAN;
}
/// x: 0 particle-steps, 1 seconds.
double speed_x(const Point& p, int which) { return which == 0 ? p.cost : p.seconds; }

bool plottable(double x, double y) {
  return std::isfinite(x) && x > 0 && std::isfinite(y) && y > 0;
}

/// The Pareto front of the finished points (no other finished trial is both
/// cheaper and more accurate), as a data file; "" when there is none.
std::string pareto_front_dat(const std::vector<Point>& points, int yr, int xc) {
  std::vector<std::pair<double, double>> xy;
  for (const auto& p : points) {
    if (!finished(p)) continue;
    const double x = speed_x(p, xc), y = speed_y(p, yr);
    if (plottable(x, y)) xy.push_back({x, y});
  }
  std::sort(xy.begin(), xy.end());
  std::ostringstream front;
  double ymin = std::numeric_limits<double>::infinity();
  for (const auto& [x, y] : xy)
    if (y < ymin) {
      ymin = y;
      front << dat(x) << ' ' << dat(y) << '\n';
    }
  return front.str();
}

/// One panel (row yr, column xc) of the speed figure; true when it drew data.
bool speed_panel(PlotPlan& plot, std::ostringstream& g, const ReportFacts& f, int yr, int xc) {
  const std::string cell = std::to_string(yr) + std::to_string(xc);
  std::vector<std::string> clauses;
  double ylo = std::numeric_limits<double>::infinity(), yhi = 0.0;
  for (const auto& c : speed_categories()) {
    std::ostringstream o;
    for (const auto& p : f.points) {
      if (!c.in(p)) continue;
      const double x = speed_x(p, xc), y = speed_y(p, yr);
      if (plottable(x, y)) {
        o << dat(x) << ' ' << dat(y) << '\n';
        ylo = std::min(ylo, y);
        yhi = std::max(yhi, y);
      }
    }
    if (o.str().empty()) continue;
    plot.files[cell + c.file] = o.str();
    clauses.push_back("'" + cell + c.file + "' u 1:2 " + c.clause);
  }
  const std::string front = pareto_front_dat(f.points, yr, xc);
  if (!front.empty()) {
    plot.files[cell + "sp_front.dat"] = front;
    clauses.insert(
        clauses.begin(),
        "'" + cell + "sp_front.dat' u 1:2 w steps lw 6 lc rgb '#fdd0a2' t 'Pareto front'");
  }
  const double limit = yr == 0 ? f.in->tolerances.force_balance : f.in->accuracy;
  if (yhi > 0) {
    // Whole decades, with headroom above the data for the key.
    ylo = std::pow(10.0, std::floor(std::log10(std::min(ylo, limit))));
    yhi = std::pow(10.0, std::ceil(std::log10(std::max(yhi, limit)) + 1.2));
    g << "set yrange [" << dat(ylo) << ":" << dat(yhi) << "]\n";
  } else {
    g << "set autoscale y\n";
  }
  g << "set xlabel '" << (xc == 0 ? "cost [particle-steps]" : "cost [s wall time]") << "'\n"
    << "set ylabel '"
    << (yr == 0 ? "force-balance error (criterion)" : "|peak error| vs converged reference")
    << "'\nset title '" << (yr == 0 ? "force-balance error" : "peak error") << " against cost in "
    << (xc == 0 ? "particle-steps" : "seconds") << "'\n"
    << "set arrow 1 from graph 0, first " << dat(limit) << " to graph 1, first " << dat(limit)
    << " nohead dt 2 lw 1.5 lc rgb '#b3261e'\n"
    << "set label 1 '" << (yr == 0 ? "tolerance" : "accuracy target") << "' at graph 0.98, first "
    << dat(limit) << " right offset 0,-0.7 tc rgb '#b3261e' font ',9'\n";
  if (clauses.empty()) {
    g << "unset logscale xy\nset xrange [0:1]\nset yrange [0:1]\nunset arrow 1\nunset label "
         "1\n"
         "set label 2 'no finished trial' at 0.5,0.5 center\nplot -1 notitle\n"
         "set logscale xy\nset autoscale\nunset label 2\n";
    return false;
  }
  g << "plot ";
  for (size_t k = 0; k < clauses.size(); ++k) g << (k ? ", " : "") << clauses[k];
  g << "\n";
  return true;
}

void add_speed_figure(PlotPlan& plot, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const int rows = in.reference ? 2 : 1;
  std::ostringstream g;
  g << terminal(1060, rows == 2 ? 780 : 420) << "set output 'fig_speed.svg'\n"
    << common() << "set multiplot layout " << rows << ",2\nset logscale xy\n"
    << "set format x '10^{%L}'\nset format y '10^{%L}'\nset key top right opaque "
       "font ',9'\n";
  bool drawn = false;
  for (int yr = 0; yr < rows; ++yr)
    for (int xc = 0; xc < 2; ++xc) drawn = speed_panel(plot, g, f, yr, xc) || drawn;
  g << "unset multiplot\nunset output\nreset\n";
  if (!drawn && f.points.empty()) return;
  plot.figures.push_back(
      {"fig_speed", g.str(),
       std::string("Speed against accuracy: every trial's cost (particle-steps planned, and "
                   "wall seconds, extrapolated to the full run for trials stopped early) "
                   "against its force-balance error") +
           (in.reference ? " (top) and its peak error against the converged reference "
                           "(bottom, finished trials)"
                         : "") +
           ". The shaded staircase is the Pareto front (no finished trial is both cheaper "
           "and more accurate; a failing trial can sit on it when it failed another "
           "criterion); "
           "the star is the chosen parameter set" +
           (in.baseline ? "; orange triangles joined by a dashed line, the paper's recipe with "
                          "Nstep doubled"
                        : "") +
           ". Wall seconds are noisy: trials ran in parallel on shared cores."});
}

// ---------------------------------------------------------------------------
// Upscaling: Nstep linear in the particle count, REV and prototype marked.

void add_upscale_figure(PlotPlan& plot, const ReportFacts& f) {
  if (!f.upscale) return;
  const ReportInput& in = *f.in;
  const double n0 = static_cast<double>(in.particles),
               n1 = static_cast<double>(in.prototype_particles);
  const double steps = static_cast<double>(in.summary.best.steps);
  const double proto_steps = static_cast<double>(f.proto_steps);
  const double per = steps / n0;
  const double a = n0 / 3.0, b = n1 * 3.0;
  plot.files["up_line.dat"] =
      dat(a) + ' ' + dat(per * a) + '\n' + dat(b) + ' ' + dat(per * b) + '\n';
  plot.files["up_pts.dat"] =
      dat(n0) + ' ' + dat(steps) + '\n' + dat(n1) + ' ' + dat(proto_steps) + '\n';
  std::ostringstream g;
  g << terminal(760, 400) << "set output 'fig_upscale.svg'\n"
    << common() << "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
    << "set xlabel 'particles N'\nset ylabel 'N_{step}'\nset key top left\n"
    << "set xrange [" << dat(a) << ":" << dat(b) << "]\n"
    << "set label 1 'REV' at first " << dat(n0) << ", first " << dat(steps) << " offset 1,-1\n"
    << "set label 2 'prototype' at first " << dat(n1) << ", first " << dat(proto_steps)
    << " right offset -1,1\n"
    << "set title 'N_{step} = " << num(per, 4) << " · N (linear in the particle count)'\n"
    << "plot 'up_line.dat' u 1:2 w l lw 2 lc rgb '#3182bd' t 'upscaling line', "
       "'up_pts.dat' u 1:2 w p pt 7 ps 1.8 lc rgb '#08306b' t 'REV and prototype'\n"
    << "unset output\nreset\n";
  plot.figures.push_back({"fig_upscale", g.str(),
                          "Upscaling: the multipliers do not depend on size; Nstep grows "
                          "linearly with the particle count (Tu & Andrade)."});
}

const char* kNoGnuplot =
    "Plot not rendered: gnuplot is not installed. Every number is in "
    "the tables of this report. To get the plots: apt-get install "
    "gnuplot-nox, then rerun the same command with --resume (every "
    "trial is reused).";

/// Every figure in one gnuplot run; a failed figure stops gnuplot's script,
/// so the missing ones are rendered alone. `error` receives the last failure.
std::map<std::string, std::string> run_figures(const std::string& gnuplot, const PlotPlan& plan,
                                               std::string& error) {
  std::string script;
  std::vector<std::string> outputs;
  for (const auto& f : plan.figures) {
    script += f.script;
    outputs.push_back(f.name + ".svg");
  }
  auto got = run_gnuplot(gnuplot, script, plan.files, outputs, &error);
  for (const auto& f : plan.figures) {
    if (got.count(f.name + ".svg")) continue;
    auto one = run_gnuplot(gnuplot, f.script, plan.files, {f.name + ".svg"}, &error);
    got.insert(one.begin(), one.end());
  }
  return got;
}

}  // namespace

PlotPlan plan_plots(const ReportFacts& facts) {
  PlotPlan plan;
  add_series_figures(plan, facts);
  add_history_figure(plan, facts);
  add_speed_figure(plan, facts);
  add_upscale_figure(plan, facts);
  return plan;
}

Figures render_figures(const ReportFacts& facts, const ReportOptions& options) {
  Figures out;
  out.plan = plan_plots(facts);
  const std::string gnuplot = options.gnuplot.empty() ? "" : find_program(options.gnuplot);
  if (gnuplot.empty()) {
    out.missing = kNoGnuplot;
    out.status = options.gnuplot.empty()
                     ? "plots not rendered (disabled)"
                     : "plots not rendered: gnuplot was not found; every number is in "
                       "the tables. To get the plots: apt-get install gnuplot-nox, then "
                       "rerun the same command with --resume (it reuses every trial)";
    return out;
  }
  if (out.plan.figures.empty()) return out;
  std::string error;
  const auto got = run_figures(gnuplot, out.plan, error);
  int k = 0;
  for (const auto& f : out.plan.figures) {
    auto it = got.find(f.name + ".svg");
    if (it != got.end())
      out.svgs[f.name] = inline_svg(it->second, "g" + std::to_string(k) + "-", f.name,
                                    f.name == "fig_upscale" ? "plot narrow" : "plot");
    ++k;
  }
  out.complete = out.svgs.size() == out.plan.figures.size();
  out.status =
      out.complete ? std::string("plots rendered by gnuplot") : "some plots failed: " + error;
  out.missing = "Plot not rendered: " + error;
  return out;
}

void Figures::put(Doc& d, const std::string& name) const {
  for (const auto& f : plan.figures)
    if (f.name == name) {
      auto it = svgs.find(name);
      d.figure(it == svgs.end() ? "" : it->second, f.caption, missing);
      return;
    }
}

}  // namespace demcal::report
