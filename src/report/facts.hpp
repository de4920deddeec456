// What the report's sections and plots share, computed once from the
// ReportInput: the trial points (search, baseline, reference), the chosen
// and paper-recipe points, the runs with series, the upscaling; and the
// report's small text helpers. Private to the report.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "demcal/report/report.hpp"

namespace demcal::report {

/// 1234567 → "1,234,567".
std::string grouped(int64_t v);
/// A stress in Pa as "12.5 kPa".
std::string kpa(double pa);
/// A strain (a fraction) in %: three decimals in 2D, three significant
/// digits in 3D (the triaxial scenes load to strains of 1e-5).
std::string strain_pct(double fraction, int dimension);
/// A diagnosis message as a sentence: capital first letter, final period.
std::string sentence(std::string s);
/// "α 0.277, Nstep 89,370, ζ_t 0.5, ζ_r 0".
std::string params_text(const AlgorithmSpec& p);
/// The same for gnuplot's enhanced text: plain digits and my own words only.
std::string params_gp(const AlgorithmSpec& p);
/// A peak of the axial boundary stress as "-206.8 kPa at ε_zz = -0.387 %":
/// `stress` [Pa] (compression negative, as b) and `strain` (a fraction) of
/// the loading axis; `axial` is ReportFacts::axial ("b_yy", "b_zz").
std::string peak_text(const std::string& axial, double stress, double strain, int dimension);
/// "diverged", "stopped early", "pass" or "FAIL".
std::string verdict(const TrialRecord& t);

/// One trial in the history and the speed-vs-accuracy chart.
struct Point {
  std::string label;                   ///< "12", "b3", "r8"
  const TrialRecord* trial = nullptr;  ///< its phase, parameters and score
  double cost = 0.0;                   ///< particle-steps planned
  double seconds = 0.0;  ///< wall time (extrapolated to the full run when stopped early)
  std::optional<double> peak_error;
  bool best = false;
};

/// The columns of a run's panel table (gnuplot's numbering, from 1): the
/// compressive strain of the loading axis [%], then stresses [kPa] (the
/// normal components compression positive, shear tension positive) and
/// servo errors [%]. One layout per dimension.
namespace col2 {
enum : int { strain = 1, b_axial, s_axial, s_xy, s_yx, b_xx, s_xx, servo };
}
namespace col3 {
enum : int {
  strain = 1,
  b_axial,  // zz
  s_axial,
  b_xx,
  s_xx,
  b_yy,
  s_yy,
  s_xy,
  s_yx,
  s_xz,
  s_zx,
  s_yz,
  s_zy,
  servo_xmin,
  servo_xmax,
  servo_ymin,
  servo_ymax
};
}

/// A run of the paper's panels, whatever the dimension: its series as the
/// panel table (rows of the columns above; rows[k][c − 1] is column c).
struct PanelRun {
  std::string label;
  const AlgorithmSpec* params = nullptr;
  const Score* score = nullptr;
  bool diverged = false;
  bool result = false;  ///< the calibrated run (the reference goes on its panel)
  std::vector<std::vector<double>> rows;
  /// The value of column c at row k.
  double at(size_t k, int c) const { return rows[k][static_cast<size_t>(c - 1)]; }
};
/// The panel table of a 2D series (col2) and of a 3D one (col3).
std::vector<std::vector<double>> panel_rows(const std::vector<MonitorPoint>& series);
std::vector<std::vector<double>> panel_rows(const std::vector<TriaxialPoint>& series);

struct ReportFacts {
  const ReportInput* in = nullptr;  ///< everything below points into it
  int dimension = 2;
  std::string axial;          ///< the loading axis' boundary stress: "b_yy" (2D), "b_zz" (3D)
  bool have_best = false;     ///< a trial ran (the summary has a result)
  std::vector<Point> points;  ///< search trials, then b0…, then r8, r16
  std::optional<double> best_peak_error;
  int baseline_index = -1;          ///< in points: the passing paper-recipe trial
  std::vector<PanelRun> runs;       ///< start point, result (those with series)
  const PanelRun* start = nullptr;  ///< in runs, when rerun
  const PanelRun* result = nullptr;
  bool have_ref_series = false;  ///< the 16×Nstep reference kept its series (2D)
  PanelRun reference;            ///< its panel table, when it did
  bool upscale = false;          ///< a prototype larger than the REV
  int64_t proto_steps = 0;       ///< Nstep of the prototype

  ReportFacts() = default;
  ReportFacts(const ReportFacts&) = delete;  // start and result point into runs
  ReportFacts& operator=(const ReportFacts&) = delete;

  const Point* baseline() const {
    return baseline_index < 0 ? nullptr : &points[static_cast<size_t>(baseline_index)];
  }
};
/// The report gives two peaks of a run's axial boundary stress: the largest
/// at any loading step (the run tracks it every step; the criteria, the
/// certificate and the trials' peaks are this one) and the largest at the
/// monitoring points (what the plots show and where the assembly picture is
/// taken). On a flat peak they differ little in stress but can lie far
/// apart in strain. Each table names which one it gives, in these words.
enum class PeakKind { every_step, monitored };
std::string peak_label(const ReportFacts& f, PeakKind kind);

/// Fills `f` (not copyable: it points into itself).
void gather_facts(const ReportInput& in, ReportFacts& f);

}  // namespace demcal::report
