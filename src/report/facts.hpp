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
/// A diagnosis message as a sentence: capital first letter, final period.
std::string sentence(std::string s);
/// "α 0.277, Nstep 89,370, ζ_t 0.5, ζ_r 0".
std::string params_text(const AlgorithmSpec& p);
/// The same for gnuplot's enhanced text: plain digits and my own words only.
std::string params_gp(const AlgorithmSpec& p);
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

struct ReportFacts {
  const ReportInput* in = nullptr;  ///< everything below points into it
  bool have_best = false;           ///< a trial ran (the summary has a result)
  std::vector<Point> points;        ///< search trials, then b0…, then r8, r16
  std::optional<double> best_peak_error;
  int baseline_index = -1;             ///< in points: the passing paper-recipe trial
  std::vector<const ReportRun*> runs;  ///< start point, result (those with series)
  bool have_ref_series = false;        ///< the 16×Nstep reference kept its series
  bool upscale = false;                ///< a prototype larger than the REV
  int64_t proto_steps = 0;             ///< Nstep of the prototype

  const Point* baseline() const {
    return baseline_index < 0 ? nullptr : &points[static_cast<size_t>(baseline_index)];
  }
};
ReportFacts gather_facts(const ReportInput& in);

}  // namespace demcal::report
