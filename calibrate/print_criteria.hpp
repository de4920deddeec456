// The criteria of a run as the commands print them: one home for the lines
// `demcal run` and `demcal score` share.
#pragma once

#include <ostream>

#include "demcal/scoring/triaxial_scoring.hpp"

namespace demcal::cli {

/// The 3D criteria, combined and per plane, two indented lines: the
/// combined ones are `judged` (the Score's: scored_criteria(), whose moment
/// balance has the rotational drag folded in), the planes' from `c`.
void print_triaxial_criteria(std::ostream& out, const TriaxialCriteria& c, const Criteria& judged);

}  // namespace demcal::cli
