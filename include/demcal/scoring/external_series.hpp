// A monitoring series written by another engine (the LAMMPS deck of
// `demcal export`, or any code that writes the documented CSV), scored with
// the criteria demcal applies to its own runs.
//
// The file (README "Scoring another engine's run"): comment lines start
// with '#'; a comment "# key = value" is metadata (a one-word key also
// without the spaces, "#key=value": metadata_line) (lateral_stress [Pa],
// steps, dt, dt_crit [s], particles, damping_ratio_translation,
// damping_ratio_rotation, mass_scaling, moment_lever_arm; the keys demcal's
// own runs add: peak_stress_yy [Pa] and peak_strain_yy, the 2D peak tracked
// at every step, taken over the monitored one; reference_peak [Pa], the
// reference of the peak error; divergence_step and divergence, a run its
// own checks stopped: SeriesMetadata, scene/run_output.hpp), each key once,
// its value in the range config.hpp gives the quantity (RealRange; steps a
// whole number from 1), after the column header only the results
// (kSeriesResultKeys); the first other line names the columns,
// comma-separated (a UTF-8 BOM before the first line is dropped); a row
// whose step is beyond "# steps" is refused; every further line is one
// monitoring point, tension positive, SI units. Columns are found by name,
// in any order: required step, strain_yy, b_xx, b_xy, b_yx, b_yy, s_xx,
// s_xy, s_yx, s_yy; optional kinetic_energy, kinetic_energy_rotation,
// elastic_energy, unbalanced_force_ratio, inertial_number,
// coordination_number, lateral_stress_error (else from p_left and p_right),
// wall_left, wall_right, wall_bottom, wall_top, torque_stress. What a
// missing optional column or metadata key would give is not known, never 0:
// the measure is left out of summary.json (its key omitted, listed under
// "not_available" with the column missing), the terminal prints "n/a (no
// column X)", a criterion it is is not checked (the verdict says so), and
// the diagnosis reads neither it nor a parameter the metadata do not give
// (a series without damping ratios is not an undamped run). demcal's own
// series.csv is such a file, with the metadata its run was scored with:
// scored here, it gives the run's criteria, verdict and diagnosis.
//
// A triaxial (3D) series is recognised by its axial strain column
// strain_zz: required step, strain_zz and the nine components of b
// (b_xx .. b_zz) and of σ (s_xx .. s_zz); optional the energies and ratios
// above, servo_error_xmin, _xmax, _ymin, _ymax (else from the pressures
// p_xmin .. p_ymax, else unknown), lateral_stress_error (else their mean),
// wall_xmin .. wall_zmax, damping_power_translation, damping_power_rotation
// and axial_power (the drag criteria; without them the drag is not known and
// moment balance is judged without it). demcal's 3D series.csv and
// the exported 3D LAMMPS deck's are such files; they are scored as `demcal run` scores a triaxial
// run (triaxial_scoring.hpp).
//
// Moment balance. In demcal V(σxy − σyx) = Σ_p T_p, the particles' net
// contact torques, exactly. An engine that applies a contact's tangential
// force at the lever arm r_i instead of r_i − δ/2 (LAMMPS) adds a static
// term −Σ_c δ_c f_t,c / V to σxy − σyx that vanishes with no choice of
// algorithmic parameter. When the file has torque_stress (Σ_p T_p / V), the
// moment-balance criterion is measured on it — rotational equilibrium in
// the engine's own model, the same quantity as demcal's — and the
// remainder ((σxy − σyx) − torque_stress)/σ3 is reported as the lever-arm
// floor. Without that column σxy − σyx is used as it is.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "demcal/scoring/scoring.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"

namespace demcal {

struct ExternalSeries {
  std::string source;                       ///< the file, for messages
  std::map<std::string, std::string> meta;  ///< "# key = value" lines
  /// 3 for a triaxial (sphere) series: it names the axial strain strain_zz.
  int dimension = 2;
  LoadingResult run;            ///< 2D: series and what is known of the run
  TriaxialResult triaxial;      ///< 3D: the same
  double lateral_stress = 0.0;  ///< σ3 [Pa]
  /// "# reference_peak" [Pa]: what the writer's peak error was taken
  /// against, compressive (negative) whichever sign the file gives it.
  std::optional<double> reference_peak;
  bool torque_column = false;  ///< torque_stress was given
  /// Per monitoring point: ((σxy − σyx) − torque_stress)/σ3 (empty without
  /// torque_stress).
  std::vector<double> lever_arm_floor;
  /// The measures the series cannot give (Criteria::not_available keys; 3D
  /// also "servo_xmin" .. "servo_ymax", "lateral_stress_error",
  /// "rotational_drag", "translational_drag"), with the column missing.
  std::map<std::string, std::string> not_available;
  /// The parameters its metadata give (the diagnosis reads only these).
  RunParameters parameters;
  /// A diverged series: why, in words (its non-finite row, or its
  /// metadata's "# divergence" as written: demcal's to_string(Divergence),
  /// the reason its run's summary gives).
  std::string divergence_reason;
};

/// Parse `text` (the content of `source`). `lateral_stress` overrides the
/// file's. Throws InputError naming the file and the line or column.
ExternalSeries parse_external_series(const std::string& text, const std::string& source,
                                     std::optional<double> lateral_stress = std::nullopt);

struct ExternalScore {
  Score score;
  double lever_arm_floor_rms = 0.0;  ///< RMS of ExternalSeries::lever_arm_floor
  double lever_arm_floor_max = 0.0;  ///< largest |value|
  /// 3D: the criteria of each plane (Score holds their combination).
  std::optional<TriaxialCriteria> planes;
};

/// The criteria, verdict and diagnosis of the series (score_run()).
ExternalScore score_external(const ExternalSeries& series, const Tolerances& tolerances,
                             std::optional<double> reference_peak = std::nullopt);

/// The verdict, one line: "PASS: ..." or "FAIL: ..." with the reason — the
/// diagnosis ("the run diverged: ..." for a diverged run, as `demcal run`
/// says it; the step and divergence_reason on a line of their own, as
/// there); for an incomplete one the steps it ran of those planned (the
/// diagnosis of the steps it has is then apart).
std::string score_verdict(const ExternalSeries& series, const ExternalScore& score);

/// summary.json of `demcal score`: a measure not available is omitted (as
/// to_json(Criteria) omits it); "not_checked" names the criteria not
/// checked; "verdict" is score_verdict().
nlohmann::json external_summary(const ExternalSeries& series, const ExternalScore& score,
                                const Tolerances& tolerances);

}  // namespace demcal
