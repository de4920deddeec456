// The calibration report (report.html, report.md): well-formed HTML that
// references nothing outside itself, the same facts in the Markdown, plots
// inline when gnuplot is there and a clear note when it is not.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/io/format.hpp"
#include "demcal/report/report.hpp"
#include "demcal/report/sphere_svg.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/search/evidence.hpp"
#include "demcal/search/trial_runner.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"

namespace fs = std::filesystem;
using namespace demcal;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// A small HTML5 checker: every element closed in order (void elements and
/// XML-style self-closing tags excepted), attributes quoted or bare without
/// '<', no stray '<', every '&' an entity, raw text of <style>/<script>
/// skipped, one <html> root. Returns "" when well-formed, else the problem
/// and where.
std::string html_problem(const std::string& h) {
  static const std::vector<std::string> kVoid{"area",   "base",  "br",    "col",  "embed",
                                              "hr",     "img",   "input", "link", "meta",
                                              "source", "track", "wbr"};
  std::vector<std::string> stack;
  int roots = 0;
  auto where = [&](size_t i) {
    const size_t a = i > 60 ? i - 60 : 0;
    return " at offset " + std::to_string(i) + ": ..." + h.substr(a, 120) + "...";
  };
  size_t i = 0;
  while (i < h.size()) {
    const char c = h[i];
    if (c == '&') {
      size_t j = i + 1;
      if (j < h.size() && h[j] == '#') ++j;
      const size_t start = j;
      while (j < h.size() && std::isalnum(static_cast<unsigned char>(h[j]))) ++j;
      if (j == start || j >= h.size() || h[j] != ';') return "bare '&'" + where(i);
      i = j + 1;
      continue;
    }
    if (c != '<') {
      ++i;
      continue;
    }
    if (h.compare(i, 4, "<!--") == 0) {
      const size_t e = h.find("-->", i + 4);
      if (e == std::string::npos) return "unterminated comment" + where(i);
      i = e + 3;
      continue;
    }
    if (h.compare(i, 2, "<!") == 0) {
      const size_t e = h.find('>', i);
      if (e == std::string::npos) return "unterminated declaration" + where(i);
      i = e + 1;
      continue;
    }
    const bool closing = i + 1 < h.size() && h[i + 1] == '/';
    size_t j = i + (closing ? 2 : 1);
    const size_t name_start = j;
    while (j < h.size() && (std::isalnum(static_cast<unsigned char>(h[j])) || h[j] == '-' ||
                            h[j] == ':' || h[j] == '_'))
      ++j;
    if (j == name_start) return "stray '<'" + where(i);
    const std::string name = lower(h.substr(name_start, j - name_start));
    // Attributes up to '>', quotes respected.
    bool self_closing = false;
    while (j < h.size() && h[j] != '>') {
      if (h[j] == '"' || h[j] == '\'') {
        const size_t e = h.find(h[j], j + 1);
        if (e == std::string::npos) return "unterminated attribute value" + where(j);
        if (h.substr(j, e - j).find('<') != std::string::npos)
          return "'<' inside an attribute value" + where(j);
        j = e + 1;
        continue;
      }
      if (h[j] == '<') return "'<' inside a tag" + where(j);
      if (h[j] == '/' && j + 1 < h.size() && h[j + 1] == '>') self_closing = true;
      ++j;
    }
    if (j >= h.size()) return "unterminated tag <" + name + where(i);
    i = j + 1;
    if (closing) {
      if (stack.empty()) return "</" + name + "> without an open element" + where(i);
      if (stack.back() != name) return "</" + name + "> closes <" + stack.back() + ">" + where(i);
      stack.pop_back();
      continue;
    }
    if (self_closing || std::find(kVoid.begin(), kVoid.end(), name) != kVoid.end()) continue;
    if (stack.empty()) {
      if (name != "html") return "content outside <html>: <" + name + ">" + where(i);
      ++roots;
    }
    if (name == "style" || name == "script") {
      const size_t e = lower(h).find("</" + name, i);
      if (e == std::string::npos) return "unterminated <" + name + ">" + where(i);
      i = e;
    }
    stack.push_back(name);
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + "> at the end";
  if (roots != 1) return "expected one <html> root, found " + std::to_string(roots);
  return "";
}

/// Everything that would make the page fetch something: URLs, src=,
/// <link>, @import, url() other than a local #fragment, href other than
/// a #fragment.
std::vector<std::string> external_references(const std::string& html) {
  const std::string h = lower(html);
  std::vector<std::string> out;
  for (const char* bad : {"http:", "https:", "ftp:", "file:", "src=", "<link", "@import", "<iframe",
                          "<object", "<embed"})
    if (h.find(bad) != std::string::npos) out.push_back(bad);
  for (size_t k = 0; (k = h.find("url(", k)) != std::string::npos; k += 4) {
    size_t j = k + 4;
    while (j < h.size() && (h[j] == ' ' || h[j] == '\'' || h[j] == '"')) ++j;
    if (j >= h.size() || h[j] != '#') out.push_back("url(" + h.substr(k + 4, 30));
  }
  for (size_t k = 0; (k = h.find("href=", k)) != std::string::npos; k += 5) {
    size_t j = k + 5;
    if (j < h.size() && (h[j] == '"' || h[j] == '\'')) ++j;
    if (j >= h.size() || h[j] != '#') out.push_back("href=" + h.substr(k + 5, 30));
  }
  return out;
}

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t k = 0; (k = s.find(what, k)) != std::string::npos; k += what.size()) ++n;
  return n;
}

/// A loading run with the shape of the hexagonal scene's: linear rise to a
/// peak, softening; σ trails b by `gap`; the servo lags by `servo`.
LoadingResult synthetic_run(int64_t steps, double gap, double servo) {
  LoadingResult r;
  r.particles = 100;
  r.steps_planned = r.steps_run = steps;
  r.scales.dt_crit = 9e-6;
  r.integration.dt = 0.25 * 9e-6;
  const int m = 60;
  for (int k = 0; k <= m; ++k) {
    MonitorPoint p;
    p.step = steps * k / m;
    const double e = 0.01 * k / m;  // compressive strain
    p.strain_yy = -e;
    const double q = e < 0.005 ? 1e5 + 1.1e8 * e : 6.5e5 - 2e6 * (e - 0.005);
    p.b << -1e5 * (1 + servo * k / m), -3e3 * e / 0.01, -3e3 * e / 0.01, -q;
    p.sigma = p.b;
    p.sigma(0, 0) *= 1.0 + gap * k / m;
    p.sigma(1, 1) *= 1.0 + 0.2 * gap * k / m;
    p.lateral_stress_error = servo * k / m;
    r.series.push_back(p);
  }
  const Peak peak = find_peak(r.series);
  r.peak_stress_yy = peak.stress_yy;
  r.peak_strain_yy = peak.strain_yy;
  return r;
}

TrialRecord trial(int id, TrialPhase phase, double alpha, int64_t steps, double fb, bool passed,
                  bool complete = true, bool diverged = false) {
  TrialRecord t;
  t.id = id;
  t.phase = phase;
  t.params.dt_ratio = alpha;
  t.params.steps = steps;
  t.params.damping_ratio_translation = 0.5;
  t.params.damping_ratio_rotation = 0.0;
  t.steps_run = complete ? steps : steps / 3;
  t.wall_time_s = 1e-8 * static_cast<double>(t.steps_run) * 100.0;
  Score& s = t.score;
  s.criteria.force_balance = diverged ? std::numeric_limits<double>::infinity() : fb;
  s.criteria.moment_balance = 1e-7;
  s.criteria.servo = 0.002;
  s.criteria.oscillation = 1e-6;
  s.criteria.peak_stress_yy = -6.2e5 * (1.0 + 2e4 / static_cast<double>(steps));
  s.passed = passed;
  s.complete = complete;
  s.diverged = diverged;
  s.completed_fraction = static_cast<double>(t.steps_run) / static_cast<double>(steps);
  s.particle_steps = 100.0 * static_cast<double>(steps);
  s.diagnosis.message =
      passed ? "quasi-static: every criterion is within tolerance"
             : "b and sigma disagree <smoothly> & the loading is too fast | increase steps";
  return t;
}

ReportInput synthetic_input(bool evidence) {
  ReportInput in;
  in.scene = "synthetic_<scene>";
  in.command = "demcal calibrate configs/x.json -o 'out dir' --max-trials 80";
  in.accuracy = 0.02;
  in.lateral_stress = 1e5;
  in.dt_ratio_max = 0.277;
  in.particles = 100;
  in.prototype_particles = 40000;
  in.analytical_peak = -7.48e5;
  auto& S = in.summary;
  S.success = true;
  S.message = "calibrated: every criterion passed";
  S.strategy = Strategy::model;
  S.dt_ratio_stable = 0.292;
  S.trials = {trial(0, TrialPhase::search, 0.2, 50000, 0.03, false),
              trial(1, TrialPhase::search, 0.27, 25060, 0.05, false, false),
              trial(2, TrialPhase::search, 0.9, 25060, 0.05, false, false, true),
              trial(3, TrialPhase::verify, 0.277, 89370, 0.0075, true),
              trial(4, TrialPhase::verify, 0.277, 85000, 0.0085, false),
              trial(5, TrialPhase::certificate, 0.277, 178740, 0.004, true)};
  S.best_trial = S.trials[3];
  S.best = S.best_trial.params;
  S.certificate = {.steps = 89370,
                   .peak = -6.255e5,
                   .peak_doubled = -6.232e5,
                   .steps_doubled_peak_change = 0.0037,
                   .richardson_error = 0.0074,
                   .peak_halved = std::nullopt,  // 2D: no halved level
                   .steps_halved_peak_change = std::nullopt,
                   .passed = true};
  S.trials_run = 6;
  S.wall_time_s = 7.5;
  in.params = {{"rev",
                {{"particles", 100},
                 {"dt_ratio", 0.277},
                 {"dt", 2.5e-6},
                 {"dt_crit", 9.1e-6},
                 {"steps", 89370},
                 {"damping_ratio_translation", 0.5},
                 {"damping_translation", 456.0},
                 {"damping_ratio_rotation", 0.0},
                 {"damping_rotation", 0.0},
                 {"mass_scaling", 1.0}}},
               {"prototype",
                {{"particles", 40000},
                 {"dt_ratio", 0.277},
                 {"dt", 2.5e-6},
                 {"dt_crit", 9.1e-6},
                 {"steps", 35748000},
                 {"damping_ratio_translation", 0.5},
                 {"damping_translation", 456.0},
                 {"damping_ratio_rotation", 0.0},
                 {"damping_rotation", 0.0},
                 {"mass_scaling", 1.0}}},
               {"config_sha256", "abc123"},
               {"seed", 1},
               {"version", "test"}};
  Tolerances tol;
  in.tolerances = tol;
  for (int k = 0; k < 2; ++k) {
    ReportRun r;
    r.label = k == 0 ? "start point" : "calibrated";
    r.params = k == 0 ? S.trials[0].params : S.best;
    r.run = synthetic_run(r.params.steps, k == 0 ? 0.03 : 0.002, k == 0 ? 0.004 : 0.002);
    r.score = score_run(r.run, in.lateral_stress, tol);
    (k == 0 ? in.start : in.best) = r;
  }
  AssemblyPicture pic;
  pic.x = {1e-3, 2e-3, 1.5e-3};
  pic.y = {1e-3, 1e-3, 1.866e-3};
  pic.r = {5e-4, 5e-4, 5e-4};
  pic.rotation = {0.01, -0.02, 0.0};
  pic.left = 5e-4;
  pic.right = 2.5e-3;
  pic.bottom = 5e-4;
  pic.top = 2.4e-3;
  pic.forces = {{1e-3, 1e-3, 2e-3, 1e-3, 300.0, false}, {1e-3, 1e-3, 1e-3, 5e-4, 500.0, true}};
  pic.step = 44000;
  pic.steps = 89370;
  pic.strain_yy = -0.005;
  pic.stress_yy = -6.25e5;
  in.picture = pic;
  if (evidence) {
    BaselineResult b;
    b.trials = {trial(0, TrialPhase::baseline, 0.2, 50000, 0.03, false),
                trial(1, TrialPhase::baseline, 0.2, 100000, 0.015, false),
                trial(2, TrialPhase::baseline, 0.2, 200000, 0.006, true)};
    b.passed = true;
    b.params = b.trials.back().params;
    b.particle_steps_total = 3.5e7;
    in.baseline = b;
    ReferenceEvidence ref;
    ref.coarse = trial(0, TrialPhase::reference, 0.277, 8 * 89370, 0.001, true);
    ref.fine = trial(1, TrialPhase::reference, 0.277, 16 * 89370, 0.0005, true);
    ref.fine_series = synthetic_run(16 * 89370, 0.0, 0.0).series;
    ref.peak = richardson_limit(kReferenceCoarse, ref.coarse.score.criteria.peak_stress_yy,
                                kReferenceFine, ref.fine.score.criteria.peak_stress_yy);
    in.reference = ref;
  }
  return in;
}

void expect_well_formed_and_self_contained(const Report& r) {
  EXPECT_EQ(html_problem(r.html), "");
  EXPECT_EQ(external_references(r.html), std::vector<std::string>{});
  EXPECT_EQ(r.html.rfind("<!DOCTYPE html>", 0), 0u);
  // User text is escaped, in the HTML and kept readable in the Markdown.
  EXPECT_NE(r.html.find("synthetic_&lt;scene&gt;"), std::string::npos);
  EXPECT_EQ(r.html.find("<scene>"), std::string::npos);
  EXPECT_NE(r.markdown.find("\\| increase steps"), std::string::npos);
}

/// The facts a user needs first, present in both files.
void expect_facts(const Report& r) {
  for (const char* fact :
       {"89,370", "35,748,000", "0.277", "2.5e-06", "456", "0.740 %",
        "The answer: calibrated parameters", "Convergence certificate",
        "demcal calibrate configs/x.json -o &#39;out dir&#39;", "Diagnosis in words",
        "Search history", "Speed against accuracy", "Pareto front", "Upscaling to the prototype",
        "The assembly at the peak"}) {
    const std::string f = fact;
    EXPECT_NE(r.html.find(f), std::string::npos) << "HTML lacks " << f;
    std::string md;  // the Markdown has the apostrophes the HTML escapes
    for (size_t k = 0; k < f.size(); ++k) {
      if (f.compare(k, 5, "&#39;") == 0) {
        md += '\'';
        k += 4;
      } else {
        md += f[k];
      }
    }
    EXPECT_NE(r.markdown.find(md), std::string::npos) << "Markdown lacks " << md;
  }
}

}  // namespace

TEST(Report, CheckerCatchesWhatItShould) {
  const std::string ok =
      "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><style>a<b</style>"
      "</head><body><p>x &amp; y</p><svg><path d='M0 0'/></svg></body></html>";
  EXPECT_EQ(html_problem(ok), "");
  EXPECT_NE(html_problem("<html><body><p>x</body></html>"), "");  // </body> closes <p>
  EXPECT_NE(html_problem("<html><body><p>x</p>"), "");            // unclosed
  EXPECT_NE(html_problem("<html><p>a < b</p></html>"), "");       // stray '<'
  EXPECT_NE(html_problem("<html><p>a & b</p></html>"), "");       // bare '&'
  EXPECT_NE(html_problem("<html></html><html></html>"), "");      // two roots
  EXPECT_FALSE(external_references("<img src=\"x.png\">").empty());
  EXPECT_FALSE(external_references("<a href=\"https://x\">").empty());
  EXPECT_FALSE(external_references("<link rel=stylesheet href=a.css>").empty());
  EXPECT_FALSE(external_references("<rect fill=\"url(pic.png)\"/>").empty());
  EXPECT_TRUE(external_references("<use xlink:href='#gpPt1'/><rect fill=\"url(#g)\"/>").empty());
}

TEST(Report, WithoutGnuplotEveryNumberAndHowToGetThePlots) {
  ReportOptions options;
  options.gnuplot = "demcal-test-no-such-gnuplot";
  for (bool evidence : {false, true}) {
    const Report r = make_report(synthetic_input(evidence), options);
    EXPECT_FALSE(r.plots);
    expect_well_formed_and_self_contained(r);
    expect_facts(r);
    EXPECT_NE(r.html.find("apt-get install gnuplot-nox"), std::string::npos);
    EXPECT_NE(r.plot_status.find("apt-get install gnuplot-nox"), std::string::npos);
    // The assembly picture needs no gnuplot.
    EXPECT_EQ(count(r.html, "<svg"), 1);
    EXPECT_NE(r.html.find("class=\"assembly\""), std::string::npos);
    // The start point's diagnosis and the rejected neighbour are in words.
    EXPECT_NE(r.markdown.find("Start point (α 0.2, Nstep 50,000"), std::string::npos);
    EXPECT_NE(r.markdown.find("Nstep 85,000 (-5 %)"), std::string::npos);
    if (evidence) {
      EXPECT_NE(r.markdown.find("converged reference 2·P(16N) − P(8N)"), std::string::npos);
      EXPECT_NE(r.markdown.find("paper's recipe done mechanically"), std::string::npos);
      EXPECT_NE(r.markdown.find("| b2 |"), std::string::npos);
    } else {
      EXPECT_NE(r.markdown.find("measured with --evidence"), std::string::npos);
    }
  }
}

TEST(Report, WithGnuplotThePlotsAreInlineAndDeterministic) {
  if (find_program("gnuplot").empty())
    DEMCAL_SKIP_MISSING("gnuplot", "gnuplot-nox", "plot checks skipped");
  const ReportInput in = synthetic_input(true);
  const Report r = make_report(in);
  EXPECT_TRUE(r.plots) << r.plot_status;
  expect_well_formed_and_self_contained(r);
  expect_facts(r);
  // Panels a, b, lateral, servo, history, speed, upscaling + the assembly.
  EXPECT_EQ(count(r.html, "<svg"), 8);
  EXPECT_EQ(count(r.html, "class=\"plot"), 7);
  EXPECT_EQ(r.html.find("<?xml"), std::string::npos);
  EXPECT_EQ(r.html.find("apt-get install gnuplot-nox"), std::string::npos);
  // Ids are unique across the inline figures.
  EXPECT_EQ(count(r.html, "id='g0-gpPt1'"), 1);
  EXPECT_EQ(count(r.html, "id='gpPt1'"), 0);
  // Same input, same bytes.
  EXPECT_EQ(make_report(in).html, r.html);
}

TEST(Report, AFailedCalibrationStillReportsWhatItTried) {
  ReportInput in = synthetic_input(false);
  in.summary.success = false;
  in.summary.message = "no trial passed every criterion within 6 trials";
  in.summary.best_trial = TrialRecord{};
  in.summary.best = AlgorithmSpec{};
  in.summary.certificate = Certificate{};
  in.summary.trials.erase(in.summary.trials.begin() + 3);
  in.best.reset();
  in.picture.reset();
  in.params = nlohmann::json::object();
  for (const std::string gnuplot : {"demcal-test-no-such-gnuplot", "gnuplot"}) {
    ReportOptions options;
    options.gnuplot = gnuplot;
    const Report r = make_report(in, options);
    EXPECT_EQ(html_problem(r.html), "") << gnuplot;
    EXPECT_EQ(external_references(r.html), std::vector<std::string>{});
    EXPECT_NE(r.markdown.find("**FAILURE**: no trial passed"), std::string::npos);
    EXPECT_NE(r.markdown.find("No trial passed every criterion"), std::string::npos);
    EXPECT_NE(r.markdown.find("Start point (α 0.2"), std::string::npos);
    EXPECT_NE(r.markdown.find("The answer: no parameter set passed"), std::string::npos);
  }
}

// The analytical peak is a row of the criteria table where the scene has
// one (hexagonal) and no row at all where it has none (a random packing):
// not an "n/a" that reads like a missing number.
TEST(Report, AnalyticalPeakRowOnlyWhereThereIsOne) {
  ReportInput in = synthetic_input(false);
  ReportOptions options;
  options.gnuplot = "";
  const Report hex = make_report(in, options);
  EXPECT_NE(hex.markdown.find("| analytical peak (rotation locked, walled box) | -748 kPa |"),
            std::string::npos);
  in.analytical_peak.reset();
  const Report random = make_report(in, options);
  EXPECT_EQ(html_problem(random.html), "");
  EXPECT_EQ(random.markdown.find("analytical peak"), std::string::npos);
  EXPECT_EQ(random.html.find("analytical peak"), std::string::npos);
}

// A run tracks its peak at every loading step (the criteria's and the
// certificate's) and records monitoring points (the plots', the picture's).
// On a flat peak the step-level maximum can fall between two points: the
// two peaks then differ a little in stress and more in strain. Every figure
// of a peak's strain says which peak it is, and the panel table gives both
// with the reason.
TEST(Report, EveryPeakStrainSaysWhichPeakItIs) {
  ReportInput in = synthetic_input(false);
  // The synthetic monitored peak: 650 kPa at ε_yy = −0.5 %; the step-level
  // one a little higher, between two monitoring points.
  in.best->run.peak_stress_yy = -6.51e5;
  in.best->run.peak_strain_yy = -0.0049;
  in.best->score = score_run(in.best->run, in.lateral_stress, in.tolerances);
  ASSERT_EQ(in.best->score.criteria.peak_strain_yy, -0.0049);
  ReportOptions options;
  options.gnuplot = "";
  const Report r = make_report(in, options);
  EXPECT_EQ(html_problem(r.html), "");
  const std::string every = "peak b_yy, largest at any loading step (criteria, certificate)",
                    monitored = "peak b_yy, largest at the monitoring points (plots, picture)";
  // The criteria table: the step-level peak, named.
  EXPECT_NE(r.markdown.find("| " + every + " | -651 kPa at ε_yy = -0.490 % |"), std::string::npos);
  // The panel table: both, per run (start point, calibrated).
  EXPECT_NE(r.markdown.find("| " + every +
                            " | -650 kPa at ε_yy = -0.500 % | -651 kPa at ε_yy = "
                            "-0.490 % |"),
            std::string::npos);
  EXPECT_NE(r.markdown.find("| " + monitored +
                            " | -650 kPa at ε_yy = -0.500 % | -650 kPa at ε_yy = -0.500 % |"),
            std::string::npos);
  EXPECT_NE(r.markdown.find("The calibrated run: -651 kPa at ε_yy = -0.490 % against -650 kPa at "
                            "ε_yy = -0.500 %, 0.15 % apart in stress."),
            std::string::npos);
  // No line gives a peak's strain without saying which peak it is.
  std::istringstream lines(r.markdown);
  int with_strain = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("ε_yy = ") == std::string::npos || line.find("peak") == std::string::npos)
      continue;
    ++with_strain;
    EXPECT_TRUE(line.find("any loading step") != std::string::npos ||
                line.find("monitoring points") != std::string::npos)
        << line;
  }
  EXPECT_EQ(with_strain, 5);  // criteria row, two panel rows, the note, the picture
}

TEST(Report, GnuplotRunnerNeedsNoShell) {
  std::string error;
  auto none = run_gnuplot("demcal-test-no-such-gnuplot", "", {}, {"a.svg"}, &error);
  EXPECT_TRUE(none.empty());
  EXPECT_NE(error.find("not found"), std::string::npos);
  if (find_program("gnuplot").empty())
    DEMCAL_SKIP_MISSING("gnuplot", "gnuplot-nox",
                        "a file name with shell metacharacters is not plotted");
  // A data file name with shell metacharacters is only ever a file name.
  auto out = run_gnuplot("gnuplot",
                         "set terminal svg\nset output 'a.svg'\nplot 'd;$(x).dat' u 1:2 w l\n"
                         "unset output\n",
                         {{"d;$(x).dat", "0 0\n1 1\n"}}, {"a.svg"}, &error);
  ASSERT_EQ(out.count("a.svg"), 1u) << error;
  EXPECT_NE(out["a.svg"].find("</svg>"), std::string::npos);
  // A failing script reports gnuplot's complaint.
  out = run_gnuplot("gnuplot", "set nonsense_option\n", {}, {"a.svg"}, &error);
  EXPECT_TRUE(out.empty());
  EXPECT_NE(error.find("gnuplot failed"), std::string::npos);
}

// The picture's wall contacts are the forces the walls feel: on each wall
// they sum to the wall's force as the scene measures it (wall_pressure ×
// wall length × thickness). Frictionless walls without contact damping carry
// kn·overlap per contact, and the kernel sums the same overlaps at the same
// positions, so the sums agree to rounding.
TEST(Report, PictureWallForcesSumToTheWallPressure) {
  const SceneConfig c = parse_config_text(R"({
    "material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3}, 
    "assembly": {"type": "hexagonal", "columns": 5, "rows": 5, "radius": 5e-4},
    "test": {"lateral_stress": 1e5}})",
                                          "test");
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  const World& w = state.world;
  const AssemblyPicture p = picture_of(w);
  double sum[4] = {0, 0, 0, 0};
  int particle_contacts = 0;
  for (const auto& f : p.forces) {
    if (!f.wall) {
      ++particle_contacts;
      continue;
    }
    // The wall end of the line sits on the wall.
    const int side = f.x2 == p.left     ? kLeft
                     : f.x2 == p.right  ? kRight
                     : f.y2 == p.bottom ? kBottom
                                        : kTop;
    sum[side] += f.fn;
  }
  EXPECT_GT(particle_contacts, 0);
  for (int side = 0; side < 4; ++side) {
    const bool vertical = side == kLeft || side == kRight;
    const double length = vertical ? w.height() : w.width();
    const double measured =
        wall_pressure(w, static_cast<WallSide>(side)) * length * w.material().thickness;
    ASSERT_GT(measured, 0.0) << "wall " << side;
    EXPECT_NEAR(sum[side], measured, 1e-9 * measured) << "wall " << side;
  }
}

// The evidence runs are reruns of what the search ran: deterministic, so a
// rerun reproduces the trial's numbers exactly, and the picture is the
// result at its peak. The reference is the result at 8× and 16× Nstep with
// the peak extrapolated for an error ∝ 1/Nstep: P(∞) = 2·P(16N) − P(8N).
TEST(Report, EvidenceRunsReproduceTheTrialsAndExtrapolateThePeak) {
  const SceneConfig c = parse_config_text(R"({
    "material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3}, 
    "assembly": {"type": "hexagonal", "columns": 5, "rows": 5, "radius": 5e-4},
    "test": {"lateral_stress": 1e5, "monitor_points": 40}})",
                                          "test");
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  const Tolerances tol;
  AlgorithmSpec best = c.algorithm, start = c.algorithm;
  best.steps = 3000;
  start.steps = 2000;
  CalibrationSummary summary;
  summary.success = true;
  summary.best = best;
  summary.best_trial = run_trial(c, state, best, tol);
  const TrialRecord start_trial = run_trial(c, state, start, tol);

  const ResultRuns runs = rerun_start_and_result(c, state, start, summary, tol, 2);
  ASSERT_TRUE(runs.start && runs.best && runs.picture);
  EXPECT_EQ(runs.best->label, "calibrated");
  EXPECT_EQ(runs.best->score.criteria.peak_stress_yy,
            summary.best_trial.score.criteria.peak_stress_yy);
  EXPECT_EQ(runs.best->score.criteria.force_balance,
            summary.best_trial.score.criteria.force_balance);
  EXPECT_EQ(runs.start->score.criteria.force_balance, start_trial.score.criteria.force_balance);
  const Peak peak = find_peak(runs.best->run.series);
  EXPECT_EQ(runs.picture->step, runs.best->run.series[peak.index].step);
  EXPECT_EQ(runs.picture->stress_yy, peak.stress_yy);
  EXPECT_EQ(runs.picture->steps, best.steps);
  EXPECT_EQ(runs.picture->x.size(), state.world.x().size());

  const ReferenceEvidence ref = run_refined_reference(c, state, best, tol, 2);
  EXPECT_EQ(ref.coarse.params.steps, 8 * best.steps);
  EXPECT_EQ(ref.fine.params.steps, 16 * best.steps);
  EXPECT_EQ(ref.coarse.phase, TrialPhase::reference);
  EXPECT_EQ(ref.fine.phase, TrialPhase::reference);
  // Richardson with Nstep ratios that are powers of two: exactly the
  // 2·P(16N) − P(8N) that params.json's evidence block has always held.
  EXPECT_EQ(ref.peak, 2.0 * ref.fine.score.criteria.peak_stress_yy -
                          ref.coarse.score.criteria.peak_stress_yy);
  ASSERT_FALSE(ref.fine_series.empty());
  EXPECT_EQ(ref.fine_series.back().step, ref.fine.params.steps);
}

TEST(Report, CalibrateWritesBothFiles) {
  const fs::path dir = test::fresh_path("report");
  const int status = test::wait_exit(test::spawn_demcal(
      {"calibrate", "-q", "--jobs", "2", "-o", dir.string(), test::shipped_config("hex_5x5")}));
  // 0: calibrated, 1: the calibration failed; the report is written either way.
  ASSERT_TRUE(status == 0 || status == 1) << status;
  const std::string html = test::read_text(dir / "report.html"),
                    md = test::read_text(dir / "report.md");
  EXPECT_EQ(html_problem(html), "");
  EXPECT_EQ(external_references(html), std::vector<std::string>{});
  for (const char* section :
       {"The answer:", "Convergence certificate", "Start point and result", "Diagnosis in words",
        "Speed against accuracy", "The assembly at the peak"}) {
    EXPECT_NE(html.find(section), std::string::npos) << section;
    EXPECT_NE(md.find(section), std::string::npos) << section;
  }
  EXPECT_NE(html.find("class=\"assembly\""), std::string::npos);
  if (!find_program("gnuplot").empty()) {
    EXPECT_GE(count(html, "class=\"plot"), 6);
  }
  // No temporary files left behind.
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------
// 3D: the sphere picture and the report of a triaxial calibration.

namespace {

/// The attribute `name` of every element `tag` of `svg`, in document order.
std::vector<std::string> attributes(const std::string& svg, const std::string& tag,
                                    const std::string& name) {
  std::vector<std::string> out;
  const std::string open = "<" + tag + " ";
  for (size_t k = 0; (k = svg.find(open, k)) != std::string::npos; k += open.size()) {
    const size_t end = svg.find('>', k);
    const size_t a = svg.find(" " + name + "=\"", k);
    if (a == std::string::npos || a > end) {
      out.push_back("");
      continue;
    }
    const size_t v = a + name.size() + 3;
    out.push_back(svg.substr(v, svg.find('"', v) - v));
  }
  return out;
}

/// The sphere assembly's <svg> element in a report page.
std::string sphere_svg_of(const std::string& html) {
  const size_t a = html.find("<svg class=\"assembly\"");
  if (a == std::string::npos) return "";
  return html.substr(a, html.find("</svg>", a) + 6 - a);
}

/// The config of a walled FCC sample of 2×2×2 cells (32 spheres).
const SceneConfig& fcc2_config() {
  static const SceneConfig c = parse_config_text(R"({"name": "fcc2", "dimension": 3,
      "material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3},
      "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
      "test": {"type": "triaxial", "lateral_stress": 1e5, "vertical_strain": 1e-5,
               "monitor_points": 40}})",
                                                 "fcc2.json");
  return c;
}

/// That sample consolidated.
const TriaxialState& small_fcc() {
  static const TriaxialState state =
      consolidate_triaxial(fcc2_config(), make_sphere_assembly(fcc2_config()));
  return state;
}

}  // namespace

// Painter's order: whatever the order of the spheres in the picture, the one
// nearer the viewer is drawn after the one behind it, and a sphere moved
// along the line of sight lands on the same spot of the screen.
TEST(Report3D, TheSphereInFrontIsDrawnAfterTheOneBehind) {
  for (const SphereView view : {SphereView{}, SphereView{30.0, 20.0}, SphereView{-120.0, 60.0}}) {
    const double a = view.azimuth_deg * std::numbers::pi / 180.0,
                 e = view.elevation_deg * std::numbers::pi / 180.0;
    const double w[3] = {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
    SpherePicture p;
    // Sphere 0 in front of sphere 1 (3 mm nearer the viewer), listed first.
    p.x = {1e-3 + 3e-3 * w[0], 1e-3};
    p.y = {2e-3 + 3e-3 * w[1], 2e-3};
    p.z = {0.5e-3 + 3e-3 * w[2], 0.5e-3};
    p.r = {0.7e-3, 0.3e-3};
    p.force = {2.0, 1.0};
    p.lo = {-1e-3, -1e-3, -1e-3};
    p.hi = {6e-3, 6e-3, 6e-3};
    const auto drawn = project_spheres(p, view);
    ASSERT_EQ(drawn.size(), 2u);
    EXPECT_EQ(drawn[0].index, 1) << view.azimuth_deg;
    EXPECT_EQ(drawn[1].index, 0) << view.azimuth_deg;
    EXPECT_NEAR(drawn[1].depth - drawn[0].depth, 3e-3, 1e-12);
    EXPECT_NEAR(drawn[0].u, drawn[1].u, 1e-12);
    EXPECT_NEAR(drawn[0].v, drawn[1].v, 1e-12);
    // In the SVG: the small (back) circle first, the large one over it.
    const auto radii = attributes(sphere_svg(p, view), "circle", "r");
    ASSERT_EQ(radii.size(), 2u);
    EXPECT_LT(std::stod(radii[0]), std::stod(radii[1]));
  }
  // z is up on the screen, whatever the azimuth.
  SpherePicture p;
  p.x = {0, 0};
  p.y = {0, 0};
  p.z = {0, 1e-3};
  p.r = {1e-4, 1e-4};
  p.force = {0, 0};
  const auto d = project_spheres(p);
  const auto& low = d[0].index == 0 ? d[0] : d[1];
  const auto& high = d[0].index == 0 ? d[1] : d[0];
  EXPECT_GT(high.v, low.v);
}

// The picture of a consolidated sample: every sphere drawn once, coloured by
// the sum of the normal contact forces on it; the legend spans exactly the
// smallest to the largest of those sums. The sums are the kernel's: over
// all spheres they count each sphere contact twice and each wall contact
// once, and the wall contacts add up to the force the walls feel.
TEST(Report3D, EverySphereDrawnOnceColouredByItsContactForce) {
  const TriaxialState& state = small_fcc();
  const SphereWorld& w = state.world;
  const SpherePicture p = picture_of(w);
  ASSERT_EQ(p.force.size(), static_cast<size_t>(w.size()));
  double total = 0.0, contacts = 0.0, walls = 0.0;
  for (double f : p.force) total += f;
  for (const auto& c : w.contacts()) contacts += std::max(0.0, c.fn);
  for (int side = 0; side < 6; ++side)
    walls += std::abs(w.wall(static_cast<SphereWallSide>(side)).force[side / 2]);
  ASSERT_GT(walls, 0.0);
  EXPECT_NEAR(total, 2.0 * contacts + walls, 1e-9 * total);

  const std::string svg = sphere_svg(p);
  const auto fills = attributes(svg, "circle", "fill");
  ASSERT_EQ(fills.size(), p.x.size());
  const auto order = project_spheres(p);
  const SphereColourScale scale = colour_scale(p);
  for (size_t k = 0; k < order.size(); ++k)
    EXPECT_EQ(fills[k], "url(#sph-" + std::to_string(scale.bin(p.force[order[k].index])) + ")")
        << k;
  const auto [lo, hi] = std::minmax_element(p.force.begin(), p.force.end());
  ASSERT_LT(*lo, *hi);
  const auto legend_lo = attributes(svg, "g", "data-lo"),
             legend_hi = attributes(svg, "g", "data-hi");
  std::string lo_text, hi_text;
  for (size_t k = 0; k < legend_lo.size(); ++k)
    if (!legend_lo[k].empty()) {
      lo_text = legend_lo[k];
      hi_text = legend_hi[k];
    }
  ASSERT_FALSE(lo_text.empty());
  EXPECT_NEAR(std::stod(lo_text), *lo, 1e-8 * *hi);
  EXPECT_NEAR(std::stod(hi_text), *hi, 1e-8 * *hi);
  EXPECT_EQ(scale.bin(*lo), 0);
  EXPECT_EQ(scale.bin(*hi), kSphereColourBins - 1);
  EXPECT_EQ(html_problem("<html>" + svg + "</html>"), "");
}

// The 3D reruns reproduce the search's trials and the picture is the
// result at the monitoring point of its most compressive b_zz.
TEST(Report3D, RerunsReproduceTheTrialsAndPictureThePeak) {
  const TriaxialState& state = small_fcc();
  const SceneConfig& c = fcc2_config();
  const Tolerances tol;
  AlgorithmSpec best = c.algorithm, start = c.algorithm;
  best.steps = 3000;
  start.steps = 1500;
  CalibrationSummary summary;
  summary.success = true;
  summary.best = best;
  summary.best_trial.params = best;
  const TriaxialResult run = run_triaxial_loading(state, c.test, best);
  summary.best_trial.score = score_triaxial_run(run, 1e5, tol);
  const ResultRuns3D runs = rerun_start_and_result(c, state, start, summary, tol, 2);
  ASSERT_TRUE(runs.start && runs.best && runs.picture && runs.world);
  EXPECT_EQ(runs.best->score.criteria.force_balance,
            summary.best_trial.score.criteria.force_balance);
  EXPECT_EQ(runs.start->params.steps, start.steps);
  const auto& series = runs.best->run.series;
  size_t peak = 0;
  for (size_t k = 1; k < series.size(); ++k)
    if (series[k].b(2, 2) < series[peak].b(2, 2)) peak = k;
  EXPECT_EQ(runs.picture->step, series[peak].step);
  EXPECT_EQ(runs.picture->stress_zz, series[peak].b(2, 2));
  EXPECT_GT(runs.picture->step, 0);
  EXPECT_EQ(runs.picture->hi[2], runs.world->wall(kZMax).position);
  EXPECT_EQ(runs.picture->x.size(), static_cast<size_t>(state.world.size()));
}

// What the search kept (TriaxialRunner::keep_passing_runs: the result's
// series and its world at the peak) and a start point run beforehand
// (report_run) give the same report runs as the reruns, to the bit: the
// calibrate command shows them instead of rerunning. A failing trial is not
// kept; a known run of other parameters, or one cut short, is not used.
TEST(Report3D, KeptRunsAreTheReruns) {
  const TriaxialState& state = small_fcc();
  const SceneConfig& c = fcc2_config();
  // Tolerances loose enough that the run passes: what is kept is at issue
  // here (ζ_r = 0: the rotational drag's tolerance is not a setting).
  Tolerances loose;
  loose.force_balance = loose.moment_balance = loose.servo = loose.oscillation = 1e9;
  AlgorithmSpec best = c.algorithm, start = c.algorithm;
  best.steps = 3000;
  best.damping_ratio_rotation = 0.0;
  start.steps = 1500;
  TriaxialRunner runner(c, state);
  runner.keep_passing_runs(true);
  const TrialRun trial = runner.run(best, loose, true, 3.0, nullptr);
  ASSERT_TRUE(trial.score.passed && trial.score.complete);
  ASSERT_TRUE(runner.kept_run(best));
  EXPECT_FALSE(runner.kept_run(start));
  Tolerances tight = loose;
  tight.force_balance = 1e-12;
  AlgorithmSpec failing = best;
  failing.steps = 2000;
  EXPECT_FALSE(runner.run(failing, tight, false, 3.0, nullptr).score.passed);
  EXPECT_FALSE(runner.kept_run(failing));  // failed: not kept

  CalibrationSummary summary;
  summary.success = true;
  summary.best = best;
  summary.best_trial.params = best;
  summary.best_trial.score = trial.score;
  const ResultRuns3D rerun = rerun_start_and_result(c, state, start, summary, loose, 2);
  KnownRuns3D known;
  known.start = report_run(c, state, "start point", start, loose);
  known.best = runner.kept_run(best);
  const ResultRuns3D kept = rerun_start_and_result(c, state, start, summary, loose, 2, known);
  ASSERT_TRUE(rerun.best && rerun.start && rerun.picture && rerun.world);
  ASSERT_TRUE(kept.best && kept.start && kept.picture && kept.world);
  const auto same_series = [](const TriaxialResult& a, const TriaxialResult& b) {
    if (a.series.size() != b.series.size()) return false;
    for (size_t k = 0; k < a.series.size(); ++k)
      if (a.series[k].step != b.series[k].step || a.series[k].b != b.series[k].b ||
          a.series[k].sigma != b.series[k].sigma)
        return false;
    return a.peak_stress_zz == b.peak_stress_zz && a.steps_run == b.steps_run;
  };
  EXPECT_TRUE(same_series(kept.best->run, rerun.best->run));
  EXPECT_TRUE(same_series(kept.start->run, rerun.start->run));
  EXPECT_EQ(kept.best->label, "calibrated");
  EXPECT_EQ(kept.start->label, "start point");
  EXPECT_EQ(kept.best->score.criteria.force_balance, rerun.best->score.criteria.force_balance);
  EXPECT_EQ(kept.best->score.passed, rerun.best->score.passed);
  const SpherePicture &a = *kept.picture, &b = *rerun.picture;
  EXPECT_GT(b.step, 0);  // the peak is past the start: the kept world is used
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.stress_zz, b.stress_zz);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.force, b.force);  // contacts included: the whole state was kept
  EXPECT_EQ(a.hi, b.hi);
  EXPECT_EQ(world_vtk(*kept.world, "t"), world_vtk(*rerun.world, "t"));

  // Known runs of other parameters, or cut short, are rerun instead.
  KnownRuns3D other;
  other.start = report_run(c, state, "start point", best, loose);  // not the start
  const std::atomic<bool> stopped{true};
  other.best = runner.kept_run(best);
  other.best->params.steps = 2999;
  const ResultRuns3D fresh = rerun_start_and_result(c, state, start, summary, loose, 1, other);
  ASSERT_TRUE(fresh.start && fresh.best && fresh.picture);
  EXPECT_TRUE(same_series(fresh.start->run, rerun.start->run));
  EXPECT_TRUE(same_series(fresh.best->run, rerun.best->run));
  EXPECT_EQ(fresh.picture->force, b.force);
  KnownRuns3D cut;
  cut.start = report_run(c, state, "start point", start, loose, &stopped);
  EXPECT_TRUE(cut.start->run.stopped_early);
  const ResultRuns3D after_cut = rerun_start_and_result(c, state, start, summary, loose, 1, cut);
  EXPECT_TRUE(same_series(after_cut.start->run, rerun.start->run));
}

// `demcal calibrate` on the shipped 3D scene cut to 2×2×2 cells (32 spheres,
// about a second), a few trials: report.html has
// every 3D panel, the sphere picture with a circle per sphere, the
// prototype said to be what params.json says, and final.vtk beside it.
TEST(Report3D, CalibrateWritesThe3DReportAndTheVtk) {
  const fs::path dir = test::fresh_path("report3d");
  const int status = test::wait_exit(test::spawn_demcal(
      {"calibrate", "-q", "--jobs", "2", "--max-trials", "12", "-o", dir.string(),
       test::shipped_config("fcc_4x4x4"), "--set", "assembly.cells_x=2", "--set",
       "assembly.cells_y=2", "--set", "assembly.cells_z=2"}));
  ASSERT_TRUE(status == 0 || status == 1) << status;
  const std::string html = test::read_text(dir / "report.html"),
                    md = test::read_text(dir / "report.md");
  EXPECT_EQ(html_problem(html), "");
  EXPECT_EQ(external_references(html), std::vector<std::string>{});
  for (const char* fact :
       {"spheres (REV, triaxial test)", "(a) Axial boundary stress b_zz", "Lateral component xx",
        "Lateral component yy", "Shear pair σ_xy and σ_yx", "Shear pair σ_xz and σ_zx",
        "Shear pair σ_yz and σ_zy", "each of the four lateral walls", "max |σ_yz − σ_zy|",
        "max |servo error|, wall y max", "peak b_zz at Nstep",
        "peak b_zz at Nstep/2 =", "the larger of 2 × |P(N) − P(2N)| and the halved change",
        "Diagnosis in words", "Search history", "Speed against accuracy",
        "Upscaling to the prototype", "The assembly at the peak", "final.vtk"}) {
    EXPECT_NE(html.find(fact), std::string::npos) << "HTML lacks " << fact;
    std::string in_md;  // the Markdown tables escape '|'
    for (char ch : std::string(fact)) in_md += ch == '|' ? std::string("\\|") : std::string(1, ch);
    EXPECT_NE(md.find(in_md), std::string::npos) << "Markdown lacks " << in_md;
  }
  const std::string svg = sphere_svg_of(html);
  EXPECT_EQ(count(svg, "<circle "), 32);  // 2×2×2 FCC cells
  if (!find_program("gnuplot").empty()) {
    // Axial, two lateral, three shear, servo; history; speed.
    EXPECT_EQ(count(html, "class=\"plot"), 9);
  }
  const std::string vtk = test::read_text(dir / "final.vtk");
  EXPECT_EQ(vtk.rfind("# vtk DataFile", 0), 0u);
  EXPECT_NE(vtk.find("POINTS 32 "), std::string::npos);
  fs::remove_all(dir);
}

// A 3D calibration with no result still reports its start point; without a
// prototype block in params.json the report says the prototype is the REV,
// and with one it shows that block.
TEST(Report3D, NoResultAndThePrototypeBlock) {
  const TriaxialState& state = small_fcc();
  const SceneConfig& c = fcc2_config();
  ReportInput in;
  in.scene = "fcc2";
  in.command = "demcal calibrate fcc2.json";
  in.lateral_stress = 1e5;
  in.particles = in.prototype_particles = state.world.size();
  in.summary.success = false;
  in.summary.message = "no trial passed every criterion within 1 trials";
  AlgorithmSpec start = c.algorithm;
  start.steps = 1500;
  attach_runs(in, rerun_start_and_result(c, state, start, in.summary, in.tolerances, 1));
  ASSERT_EQ(in.dimension, 3);
  ASSERT_TRUE(in.start3);
  EXPECT_FALSE(in.best3 || in.sphere_picture);
  ReportOptions options;
  options.gnuplot = "";
  const Report failed = make_report(in, options);
  EXPECT_EQ(html_problem(failed.html), "");
  EXPECT_NE(failed.markdown.find("The answer: no parameter set passed"), std::string::npos);
  EXPECT_NE(failed.markdown.find("Start point (α 0.2, Nstep 1,500"), std::string::npos);
  EXPECT_NE(failed.markdown.find("No picture: there is no calibrated run."), std::string::npos);
  EXPECT_EQ(sphere_svg_of(failed.html), "");

  // A result and params.json's blocks.
  in.summary.success = true;
  in.summary.best = start;
  in.summary.best_trial.params = start;
  in.summary.best_trial.score = in.start3->score;
  in.summary.best_trial.score.particle_steps = 1.0;
  in.params = {{"rev", {{"particles", 32}, {"steps", 1500}}}};
  attach_runs(in, rerun_start_and_result(c, state, start, in.summary, in.tolerances, 1));
  const Report rev = make_report(in, options);
  EXPECT_NE(rev.markdown.find("params.json has no prototype block: the prototype is the REV"),
            std::string::npos);
  EXPECT_EQ(count(sphere_svg_of(rev.html), "<circle "), 32);
  in.params["prototype"] = {{"particles", 20000},
                            {"steps", 2000000},
                            {"source", {{"kind", "scaled"}, {"description", "a test block"}}}};
  const Report proto = make_report(in, options);
  EXPECT_NE(proto.markdown.find("The prototype is not the REV (params.json's prototype block: a "
                                "test block; kind scaled)"),
            std::string::npos);
  EXPECT_NE(proto.markdown.find("| steps | 2,000,000 |"), std::string::npos);
}

// 3D alike: the FCC lattice's analytical peak is a row; a random packing
// (no analytical value) has none.
TEST(Report3D, AnalyticalPeakRowOnlyWhereThereIsOne) {
  const TriaxialState& state = small_fcc();
  const SceneConfig& c = fcc2_config();
  ReportInput in;
  in.scene = "fcc2";
  in.command = "demcal calibrate fcc2.json";
  in.lateral_stress = 1e5;
  in.particles = in.prototype_particles = state.world.size();
  AlgorithmSpec start = c.algorithm;
  start.steps = 1500;
  in.summary.success = true;
  in.summary.best = start;
  in.summary.best_trial.params = start;
  in.summary.best_trial.score.particle_steps = 1.0;
  attach_runs(in, rerun_start_and_result(c, state, start, in.summary, in.tolerances, 1));
  ASSERT_TRUE(in.best3);
  in.summary.best_trial.score = in.best3->score;
  ReportOptions options;
  options.gnuplot = "";
  const Report random = make_report(in, options);
  EXPECT_NE(random.markdown.find("| for comparison (not criteria) | value |"), std::string::npos);
  EXPECT_EQ(random.markdown.find("analytical peak"), std::string::npos);
  in.analytical_peak = -*analytical_peak_ratio_3d(c) * in.lateral_stress;
  const Report fcc = make_report(in, options);
  EXPECT_NE(fcc.markdown.find("| analytical peak (walled FCC lattice, rotation locked; Thornton "
                              "1979) | " +
                              num(*in.analytical_peak / 1e3, 4) + " kPa |"),
            std::string::npos);
}
