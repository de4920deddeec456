// The sections of the report, in the order they appear, each written to
// both documents from the report's facts. Private to the report.
#pragma once

#include "doc.hpp"
#include "facts.hpp"
#include "plots.hpp"

namespace demcal::report {

/// Title, success banner, one line on the scene and the run.
void write_title(Doc& d, const ReportFacts& f);
/// The answer and why to trust it, in a few bullets; the navigation bar.
void write_at_a_glance(Doc& d, const ReportFacts& f);
/// Parameter table, criteria, certificate, evidence, how to reproduce.
void write_answer(Doc& d, const ReportFacts& f);
/// The paper's panels for the start point and the result, and their numbers.
void write_panels(Doc& d, const ReportFacts& f, const Figures& figures);
/// The start point and the result in words; rejected neighbours of the result.
void write_diagnosis(Doc& d, const ReportFacts& f, int near_failures);
void write_history(Doc& d, const ReportFacts& f, const Figures& figures);
/// Speed against accuracy: the figure, the Pareto front, the marked points.
void write_speed(Doc& d, const ReportFacts& f, const Figures& figures);
void write_upscaling(Doc& d, const ReportFacts& f, const Figures& figures);
/// The assembly at the peak, drawn as SVG.
void write_assembly(Doc& d, const ReportFacts& f);
/// Every trial (search, baseline, reference) in a folded table.
void write_all_trials(Doc& d, const ReportFacts& f);

}  // namespace demcal::report
