// The criteria of a run as the commands print them: one home for the lines
// `demcal run` and `demcal score` share.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

#include "demcal/scoring/triaxial_scoring.hpp"

namespace demcal::cli {

/// The 3D criteria, combined and per plane, two indented lines: the
/// combined ones are `judged` (the Score's: scored_criteria(), whose moment
/// balance has the rotational drag folded in), the planes' from `c`.
void print_triaxial_criteria(std::ostream& out, const TriaxialCriteria& c, const Criteria& judged);

/// "  peak b_yy -6.927e+05 Pa at strain -0.0015 (sigma1/sigma3 6.927": the
/// peak of the axial boundary stress b (b_zz in 3D), which the criteria,
/// the report and params.json call the peak; not the homogenized sigma,
/// which differs from it by the force-balance gap. Without `strain`, no
/// "at strain"; the parenthesis is left open for the caller to add to or
/// close.
void print_peak(std::ostream& out, bool three_d, double peak, std::optional<double> strain,
                double sigma3);

/// How far a diverged run got, in the words every line about it uses
/// (`demcal run`'s headline, the unscored criteria of `run` and `score`):
/// "diverged at step 16 of 25000", the step whose divergence checks failed
/// (the steps before it completed) of those planned; "diverged" when the
/// step is not known (-1: a series that does not say it).
std::string divergence_words(int64_t divergence_step, int64_t steps_planned);

/// A diverged run's criteria are not scored (its verdict is FAIL whatever
/// they read): the trend ones (force balance, servo) need a window of
/// monitoring points it did not reach and read 0, which printed as numbers
/// would read as a perfect run's. One line instead (`demcal run`, `demcal
/// score`); `rms` (2D) adds the RMS lateral force balance and servo error
/// over the points it did reach, as a clue.
void print_unscored_criteria(std::ostream& out, int64_t divergence_step, int64_t steps_planned,
                             const Criteria& c, bool rms);

}  // namespace demcal::cli
