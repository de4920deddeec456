// Consolidation progress on stderr, for every command that consolidates
// (2D and 3D): a consolidation never runs for minutes silently.
#pragma once

#include "demcal/scene/consolidation_progress.hpp"

namespace demcal::cli {

/// Seconds between progress lines by default: a consolidation that ends
/// sooner prints none.
inline constexpr double kProgressEverySeconds = 2.0;

/// A callback that prints one line on stderr (phase, step, criteria, time
/// so far and the estimate) when at least `every_s` seconds have passed
/// since the start or the last line; 0 prints at every check.
ConsolidationCallback consolidation_progress(double every_s = kProgressEverySeconds);

}  // namespace demcal::cli
