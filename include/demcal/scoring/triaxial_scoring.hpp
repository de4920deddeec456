// Scoring a triaxial (3D) run: the criteria of the three coordinate planes,
// the Score the calibration works on, its early stop, and summary.json.
// The 3D default tolerances (triaxial_tolerances) and the rotational drag
// criterion come from reports/atlas-3d.md, which measures that they hold.
#pragma once

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"

namespace demcal {

/// The 3D criteria, from the 2D ones of scoring.hpp: force balance, servo,
/// oscillation and moment balance in the xz and yz planes (each exactly the
/// biaxial measure: axial component against its own scale, lateral against
/// σ3), and for the horizontal pair the symmetric xy shear gap (up to the
/// axial peak, as every gap), its noise, and the xy moment balance.
/// The servo error is measured on each of the four lateral walls on its own
/// (servo_walls, x min, x max, y min, y max: the 2D measure, max |trend| of
/// (p − σ3)/σ3, per wall); the planes' own servo is that of the mean of
/// their two walls. `combined` holds the largest of each (servo: of the four
/// walls), for the tolerances.
///
/// Rotational drag (3D only): the share of the axial wall's power that the
/// global rotational damping takes, P_r/P_z with P_r = Σ D_r·|ω|² and
/// P_z = −F_z·v_z of the top wall, its largest trend up to the peak. At
/// fixed lateral stress, power the damping dissipates must be supplied by
/// the axial wall, ΔP = Δb_zz·ε̇_zz·V, so the share is the relative
/// over-prediction of b_zz that the drag causes: a direct estimate of its
/// peak error. Moment balance (Σ of the torques) does not see it in an FCC
/// crystal, whose torques cancel between symmetric spheres
/// (reports/atlas-3d.md). The translational share (Σ D_t·|v|², the affine
/// flow damped included) is reported beside it; force balance already
/// measures that drag.
struct TriaxialCriteria {
  Criteria xz, yz, xy;
  std::array<double, 4> servo_walls{};
  double rotational_drag = 0.0;
  double translational_drag = 0.0;
  Criteria combined;
  /// The most compressive b_zz among the monitoring points and its strain
  /// (combined.peak_stress_yy holds the step-level peak when the run
  /// tracked one: compute_triaxial_criteria(TriaxialResult)).
  double monitored_peak_stress_zz = 0.0, monitored_peak_strain_zz = 0.0;
  /// Measures of these criteria the series could not give (`demcal score`
  /// on a series without the column): "servo_xmin" .. "servo_ymax" (the
  /// walls' servo_walls), "rotational_drag", "translational_drag", with
  /// what is missing; the planes' own in their Criteria::not_available
  /// (combined: "rotational_drag" too, so the verdict says it was not
  /// checked). Empty for demcal's own runs.
  std::map<std::string, std::string> not_available;
};

/// Tolerance on the rotational drag: a quarter of the 2 % peak accuracy
/// target (the share is the peak error it causes, see TriaxialCriteria).
inline constexpr double kRotationalDragTolerance = 0.003;

/// The default tolerances of a triaxial (3D) run: the 2D ones with force
/// balance and servo tightened (reports/atlas-3d.md: at the 2D values a
/// random 3D REV passing at their edge is 3 % off the converged peak, the
/// rate-driven error being larger in 3D). Moment balance and oscillation
/// are the 2D values.
Tolerances triaxial_tolerances();
/// The tolerances for a config: triaxial_tolerances() in 3D, the 2D
/// defaults otherwise.
Tolerances default_tolerances(const SceneConfig& config);

/// The combined criteria a 3D Score is judged on: `c.combined` with the
/// rotational drag folded into moment balance (both measure rotational
/// disequilibrium: the net torques' sum, and each sphere's torque against
/// its damping): moment_balance = max(its own value,
/// t.moment_balance·rotational_drag/kRotationalDragTolerance) (the drag's
/// share, when the drag's is the larger, in moment_from_drag; not folded
/// in when the drag is not available), so its
/// excess is the larger of the two excesses and every user of the four
/// criteria (search constraints, rate excess, diagnosis: moment imbalance
/// with high ζ_r is "damping_rotation decrease") sees the drag.
Criteria scored_criteria(const TriaxialCriteria& c, const Tolerances& t);

/// The criteria of a monitored series; the peak is the monitored one.
TriaxialCriteria compute_triaxial_criteria(const std::vector<TriaxialPoint>& series, double s3);
/// The same with the peak tracked at every step (run.peak_stress_zz, as the
/// 2D compute_criteria(LoadingResult) takes run.peak_stress_yy), when the
/// run has one; `reference_peak` (b_zz, negative: e.g. −analytical_peak_ratio_3d·σ3)
/// adds the combined criteria's peak_error.
TriaxialCriteria compute_triaxial_criteria(const TriaxialResult& run, double s3,
                                           std::optional<double> reference_peak = std::nullopt);

/// The planes' criteria as summary.json holds them ("criteria_planes": xz,
/// yz, the xy shear and moment terms, the four walls' servo errors, the
/// drags, and "combined_without_drag": `c.combined`, the planes' largest
/// values before the rotational drag is folded in). The criteria a verdict
/// judges are the Score's (scored_criteria()), "criteria" beside it.
nlohmann::json to_json(const TriaxialCriteria& c);

/// A triaxial run scored as score_run() scores a biaxial one: the combined
/// criteria (peak_stress_yy holds the axial peak b_zz), the verdict against
/// `tolerances`, completeness, cost and the diagnosis.
Score score_triaxial_run(const TriaxialResult& run, double s3, const Tolerances& tolerances);
/// The same from the run's criteria already computed (`demcal run` and
/// `demcal score` write them beside the Score): score_of() on
/// scored_criteria(c, tolerances), so every 3D verdict judges the same
/// numbers.
Score score_triaxial_run(const TriaxialResult& run, const TriaxialCriteria& c,
                         const Tolerances& tolerances);
/// The algorithmic parameters a triaxial run was made with.
AlgorithmSpec run_parameters(const TriaxialResult& run);

/// The rotational drag's share at one monitoring point, P_r/P_z (0 while
/// the axial wall does no work): the series whose trend up to the peak is
/// TriaxialCriteria::rotational_drag.
double rotational_drag_share(const TriaxialPoint& point);

/// The early stop of a triaxial trial: EarlyFailure (scoring.hpp) on each
/// of the three planes, fed the same points compute_triaxial_criteria()
/// scores; failed once any plane has certainly failed (the combined
/// criteria are the planes' maxima), or once the rotational drag has:
/// its trend at point k is final once kTrendHalfWidth more points are in,
/// and it counts in the final maximum when k is at or before the running
/// peak (the first most compressive b_zz so far: the final peak is that one
/// or a later one, never an earlier one), so the largest such trend is a
/// lower bound of the final drag. Trends after the running peak are not:
/// the peak may already be passed, and they would not count.
class TriaxialEarlyFailure {
 public:
  TriaxialEarlyFailure(const Tolerances& tolerances, double factor, int monitor_points, double s3);
  bool add(const TriaxialPoint& point);
  /// The lower bound of the final rotational drag so far.
  double rotational_drag_bound() const { return drag_bound_; }

 private:
  std::array<EarlyFailure, 3> planes_;
  double drag_limit_;  ///< factor × kRotationalDragTolerance
  int points_ = 0;     ///< added so far, the start included
  double peak_ = 0.0;
  int peak_index_ = -1;       ///< of the first most compressive b_zz so far
  std::vector<double> drag_;  ///< drag_[j] is point j + 1 (the start is not scored)
  size_t next_trend_ = 0;     ///< next drag_ index whose trend is taken
  double drag_bound_ = 0.0;
  bool failed_ = false;
};

/// What `demcal run` says of a 3D verdict: the 3D tolerances and what they hold.
extern const char* const kTriaxialVerdictNote;

/// How a 3D record's "criteria" read (key "axial_component" of summary.json,
/// params.json and verify.json): the 2D names, xx the lateral axes, yy the
/// axial z, shear the off-diagonals, each combined over the planes.
extern const char* const kTriaxialCriteriaNames;

/// summary.json of a triaxial run (`demcal run` on a 3D config): "criteria"
/// and the verdict are the Score's (score_triaxial_run(run, c, t): the
/// criteria judged, as `demcal score` writes them for the run's series),
/// "criteria_planes" to_json(c); "consolidation" consolidation_json(state)
/// (trial.hpp) with the state's stress_error, unbalanced_force_ratio and box.
nlohmann::json triaxial_run_summary(const SceneConfig& config, const TriaxialState& state,
                                    const TriaxialResult& run, const TriaxialCriteria& c,
                                    const Score& score, const Tolerances& t);

}  // namespace demcal
