// Scoring: from a loading run's monitored series, how far it was from
// quasi-static, and which algorithmic parameter is to blame. Knows nothing
// of the search that uses it (DESIGN.md §2.1, §3).
//
// Every measure is a relative number (0 = perfect). Series points are
// compared at the monitoring points after the first (the consolidated state
// is static by construction).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "demcal/biaxial.hpp"

namespace demcal {

/// Tolerances a quasi-static run must meet. Defaults are chosen so that a
/// run passing all of them reproduces the converged peak within the 2 %
/// accuracy target on the shipped scenes (reports/signature-atlas.md).
struct Tolerances {
  double force_balance = 0.02;   ///< max over components of the normalised b − σ gap
  double moment_balance = 0.02;  ///< RMS(σxy − σyx)/σ3
  double servo = 0.02;           ///< RMS lateral-wall stress error / σ3
  double oscillation = 0.01;     ///< robust noise of b − σ, per component scale
};

struct Criteria {
  /// Paper's form: RMS(b_yy − σ_yy)/RMS(b_yy).
  double force_balance_paper = 0.0;
  /// b − σ per component: xx, xy, yx against σ3; yy against RMS(b_yy).
  double force_balance_xx = 0.0, force_balance_yy = 0.0;
  double force_balance_xy = 0.0, force_balance_yx = 0.0;
  double force_balance = 0.0;   ///< the largest of the four above
  double moment_balance = 0.0;  ///< RMS(σxy − σyx)/σ3
  double servo = 0.0;           ///< RMS of the lateral stress error
  /// Step-to-step noise (robust, from second differences) of b − σ: the
  /// transient oscillation where b and σ disagree, largest component.
  double oscillation = 0.0;
  /// Noise that b_yy and σ_yy share (zigzag / stick-slip), over RMS(b_yy).
  double zigzag = 0.0;
  /// Post-peak softening (b_yy_end − peak)/|peak| ≥ 0 and the post-peak
  /// spread: ~0 both for a perfectly plastic plateau.
  double post_peak_softening = 0.0;
  double plateau_spread = 0.0;
  /// Other codes' measures, for comparison.
  double kinetic_energy_ratio_max = 0.0;  ///< max KE / elastic energy
  double unbalanced_force_ratio_mean = 0.0;
  double unbalanced_force_ratio_max = 0.0;
  double inertial_number_max = 0.0;
  /// Peak (b_yy, negative) and, when a reference is given, its relative error.
  double peak_stress_yy = 0.0;
  double peak_strain_yy = 0.0;
  std::optional<double> peak_error;
};

struct Diagnosis {
  std::string parameter;    ///< "steps", "dt", "damping_translation", ... or "none"
  std::string direction;    ///< "increase", "decrease" or ""
  double confidence = 0.0;  ///< 0..1
  std::string message;      ///< one sentence for a user
};

struct Score {
  Criteria criteria;
  bool diverged = false;
  bool complete = true;  ///< false when the run stopped early
  bool passed = false;   ///< every criterion within tolerance, not diverged
  /// Per criterion: value/tolerance (≤ 1 passes).
  double force_balance_excess = 0.0, moment_balance_excess = 0.0, servo_excess = 0.0,
         oscillation_excess = 0.0;
  double worst_excess = 0.0;  ///< the largest of the four
  Diagnosis diagnosis;
};

/// Criteria of a series. `reference_peak` (b_yy, negative) adds peak_error.
Criteria compute_criteria(const LoadingResult& run, double lateral_stress,
                          std::optional<double> reference_peak = std::nullopt);
Score score_run(const LoadingResult& run, double lateral_stress, const Tolerances& tolerances,
                std::optional<double> reference_peak = std::nullopt);
Diagnosis diagnose(const Criteria& criteria, const Tolerances& tolerances, bool diverged);

/// Robust noise level of a series: median |x_k − (x_{k−1}+x_{k+1})/2|
/// scaled so that white noise of standard deviation s gives s.
double robust_noise(const std::vector<double>& series);

nlohmann::json to_json(const Criteria& criteria);
nlohmann::json to_json(const Tolerances& tolerances);
nlohmann::json to_json(const Diagnosis& diagnosis);

}  // namespace demcal
