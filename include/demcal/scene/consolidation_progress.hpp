// What a consolidation (2D biaxial.hpp, 3D triaxial.hpp) reports while it
// runs: one record per check (every few hundred steps), for progress lines
// and a time estimate. Wall-clock fields only; the state never depends on them.
#pragma once

#include <cstdint>
#include <functional>

namespace demcal {

/// Progress of a consolidation, at every check (every 200 steps).
struct ConsolidationProgress {
  int phase = 0;  ///< 0 frictionless, 1 friction on
  int64_t steps = 0, max_steps = 0;
  double stress_error = 0.0;      ///< max |p − σ3|/σ3 over the walls
  double unbalanced_ratio = 0.0;  ///< unbalanced-force ratio
  double elapsed_s = 0.0;         ///< wall time since the consolidation started
  /// Wall time the rest of the step budget would take at the mean rate so
  /// far: an upper bound (the budget's end is a failure).
  double remaining_max_s = 0.0;
  /// Steps until this phase is static, extrapolated: the distance of the
  /// two criteria to their tolerances, max(ln(err/tol), ln(ufr/ufr_tol)),
  /// taken as linear in steps over the phase's last ten checks (both decay
  /// exponentially once the packing has formed); in the frictionless phase
  /// before its cut, at most the steps to the cut, where it ends static or
  /// not (frictionless_phase_cut). −1 when that distance is not shrinking (a
  /// gas still being compressed, noise); 0 when both criteria are met.
  int64_t steps_to_go = -1;
  /// Estimated wall time until this phase is static: steps_to_go at the
  /// mean rate so far, never above remaining_max_s; remaining_max_s when
  /// there is no trend (steps_to_go −1).
  double remaining_s = 0.0;
};
using ConsolidationCallback = std::function<void(const ConsolidationProgress&)>;

/// How a consolidation runs (2D consolidate(), 3D consolidate_triaxial());
/// none of it changes the state it reaches.
struct ConsolidationOptions {
  /// Kernel threads while consolidating (KernelOptions::threads; 0: every
  /// core). Results are bit-identical for any count; the state returned
  /// steps on one thread, as every World starts (its trials run in parallel).
  int threads = 1;
  /// Called at every check (every 200 steps) of a fresh consolidation; not
  /// called for a state read from the consolidation cache.
  ConsolidationCallback progress;
};

}  // namespace demcal
