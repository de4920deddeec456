// The report's plots: gnuplot scripts and data files planned from the
// report's facts, rendered in one gnuplot run (set terminal svg), each
// figure inlined where a section asks for it. Private to the report.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "doc.hpp"
#include "facts.hpp"

namespace demcal::report {

struct Figure {
  std::string name;  ///< output file "name.svg"
  std::string script;
  std::string caption;
};

/// Every figure of a report and the data files their scripts read.
struct PlotPlan {
  std::map<std::string, std::string> files;
  std::vector<Figure> figures;  ///< in order: panels, history, speed, upscaling
};
PlotPlan plan_plots(const ReportFacts& facts);

/// The plan after gnuplot ran.
struct Figures {
  PlotPlan plan;
  std::map<std::string, std::string> svgs;  ///< figure name → inline <svg>
  bool complete = false;                    ///< every figure rendered
  std::string status;                       ///< what happened to the plots, in words
  std::string missing;                      ///< shown in place of a figure not rendered

  /// The named figure with its caption (nothing when it was not planned).
  void put(Doc& d, const std::string& name) const;
};
/// Render with options.gnuplot ("" renders nothing).
Figures render_figures(const ReportFacts& facts, const ReportOptions& options);

}  // namespace demcal::report
