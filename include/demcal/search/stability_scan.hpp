// The stability scan (issue #9 §3; 3D: issue #18): load the consolidated REV
// (disks, biaxial test; or spheres, triaxial test) at a ladder of
// time steps α = Δt/Δt_crit around the estimate from the stiffnesses,
// find the smallest α at which the run diverges (bisection between the
// last stable and the first diverged rung), and compare it with the
// estimate. Every trial is reported with its divergence and step; none can
// hang (a fixed number of steps each).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"

namespace demcal {

struct StabilityScanOptions {
  double from = 0.5;   ///< first rung, × the estimated stable α
  double to = 2.0;     ///< last rung, × the estimated stable α
  int points = 16;     ///< rungs, evenly spaced in α
  int bisections = 6;  ///< refinements between the last stable and first diverged rung
  /// Loading steps per trial (1 % strain in that many steps, the config's
  /// damping and mass scaling). Divergence shows within a few thousand.
  int64_t steps = 20000;
  int jobs = 0;  ///< trials in parallel; 0: one per core
};

struct StabilityTrial {
  double dt_ratio = 0.0;
  bool diverged = false;
  Divergence divergence = Divergence::kNone;
  int64_t divergence_step = -1;  ///< loading step at detection
  int64_t steps_run = 0;
  bool bisection = false;  ///< a refinement, not a rung of the ladder
};

struct StabilityScanResult {
  int dimension = 2;               ///< 2: disks (3 DOF each); 3: spheres (6 DOF each)
  double dt_ratio_estimate = 0.0;  ///< estimated_stable_dt_ratio() of the consolidated REV
  /// The Gershgorin bound's α (a safe lower bound on the limit) and the
  /// translation-only α, of the same probe.
  double dt_ratio_gershgorin = 0.0, dt_ratio_translation = 0.0;
  /// The measured limit: largest α that ran to the end below the smallest α
  /// that diverged (0 when no rung diverged / every rung did).
  double dt_ratio_last_stable = 0.0, dt_ratio_first_diverged = 0.0;
  /// Stable rungs above the first diverged one (0 for a sharp limit).
  int stable_above_limit = 0;
  std::vector<StabilityTrial> trials;  ///< sorted by α
  double damping_ratio_translation = 0.0, damping_ratio_rotation = 0.0;
  int64_t steps = 0;
  double wall_time_s = 0.0;
  /// Measured limit (midpoint of the bracket) over the estimate.
  double ratio() const;
};

StabilityScanResult stability_scan(const SceneConfig& config, const ConsolidatedState& state,
                                   const StabilityScanOptions& options = {});
StabilityScanResult stability_scan(const SceneConfig& config, const TriaxialState& state,
                                   const StabilityScanOptions& options = {});

nlohmann::json to_json(const StabilityScanResult& result);
std::string stability_markdown(const StabilityScanResult& result, const std::string& scene);

/// "" when the measured limit is the estimate (within 3 %: the Lanczos
/// estimate's ~1 % and the bisection's width); otherwise the caveat that
/// the rungs between the two ran without a global blow-up but not
/// necessarily stable: a local rattle whose contacts slide keeps its energy
/// below the kernel's global checks (measured on polydisperse 2D samples,
/// reports/robustness.md §3). The markdown and the terminal print it.
std::string beyond_estimate_caveat(const StabilityScanResult& result);

}  // namespace demcal
