// The runs a calibration report shows besides the search's own trials, as
// facts the report renders: the start point and the result rerun with their
// whole monitored series, the assembly at the result's peak, and (with
// --evidence) a reference from the result's multipliers at 8× and 16× Nstep.
// The paper-recipe baseline is paper_recipe_baseline() in calibration.hpp.
//
// The search's trials keep only their criteria (trials.jsonl), not their
// series, so the report's runs are reruns: deterministic, they reproduce the
// trials' numbers exactly.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/calibration.hpp"

namespace demcal {

/// A run shown in the report with its whole monitored series.
struct ReportRun {
  std::string label;  ///< "start point", "calibrated"
  AlgorithmSpec params;
  LoadingResult run;
  Score score;
};

/// The assembly at one instant: enough to draw it.
struct AssemblyPicture {
  std::vector<double> x, y, r, rotation;  ///< rotation [rad], counter-clockwise positive
  struct Force {
    double x1 = 0, y1 = 0, x2 = 0, y2 = 0;  ///< particle centre to centre (or to the wall)
    double fn = 0;                          ///< normal force [N]
    bool wall = false;
  };
  std::vector<Force> forces;
  double left = 0, right = 0, bottom = 0, top = 0;
  int64_t step = 0, steps = 0;  ///< loading step of the picture, of the run
  double strain_yy = 0, stress_yy = 0;
};
/// The picture of a world state (particle–particle contacts from
/// World::contacts(), wall contacts from the overlap and the wall's kn).
AssemblyPicture picture_of(const World& world);

/// The start point and the result rerun with their series, and the picture
/// of the result at its peak.
struct ResultRuns {
  std::optional<ReportRun> start, best;
  std::optional<AssemblyPicture> picture;  ///< the result at its peak
};
/// Rerun the start point and summary.best (when a trial ran) with their
/// series, in parallel when jobs > 1, then the result once more, stopped at
/// its peak, for the picture. About two and a half trials.
ResultRuns rerun_start_and_result(const SceneConfig& config, const ConsolidatedState& state,
                                  const AlgorithmSpec& start, const CalibrationSummary& summary,
                                  const Tolerances& tolerances, int jobs);

// --- 3D (spheres, triaxial test) ----------------------------------------

/// A triaxial run shown in the report with its whole monitored series.
struct ReportRun3D {
  std::string label;  ///< "start point", "calibrated"
  AlgorithmSpec params;
  TriaxialResult run;
  Score score;  ///< score_triaxial_run()
};

/// The sphere assembly at one instant: enough to draw it.
struct SpherePicture {
  std::vector<double> x, y, z, r;
  /// Sum of the normal contact forces on each sphere, from the other
  /// spheres and the walls [N]: what the picture is coloured by.
  std::vector<double> force;
  std::array<double, 3> lo{}, hi{};  ///< wall positions (x, y, z)
  int64_t step = 0, steps = 0;       ///< loading step of the picture, of the run
  double strain_zz = 0, stress_zz = 0;
};
/// The picture of a sphere world (particle contacts from
/// SphereWorld::contacts(), wall contacts kn·overlap as for 2D picture_of()).
SpherePicture picture_of(const SphereWorld& world);

/// The 3D ResultRuns, with the world at the result's peak (for final.vtk).
struct ResultRuns3D {
  std::optional<ReportRun3D> start, best;
  std::optional<SpherePicture> picture;
  std::optional<SphereWorld> world;
};
/// rerun_start_and_result() for a triaxial scene: the peak is the
/// monitoring point of the most compressive b_zz.
ResultRuns3D rerun_start_and_result(const SceneConfig& config, const TriaxialState& state,
                                    const AlgorithmSpec& start, const CalibrationSummary& summary,
                                    const Tolerances& tolerances, int jobs);

/// The --evidence reference: the result's multipliers at 8× and 16× Nstep,
/// and the peak extrapolated to infinite Nstep by richardson_limit(),
/// P_ref = 2·P(16N) − P(8N) (peak error ∝ 1/Nstep).
inline constexpr int kReferenceCoarse = 8, kReferenceFine = 16;  ///< × the result's Nstep
struct ReferenceEvidence {
  TrialRecord coarse, fine;  ///< 8×Nstep and 16×Nstep
  std::vector<MonitorPoint> fine_series;
  double peak = 0.0;  ///< Richardson-extrapolated peak b_yy (negative)
};
ReferenceEvidence run_refined_reference(const SceneConfig& config, const ConsolidatedState& state,
                                        const AlgorithmSpec& best, const Tolerances& tolerances,
                                        int jobs);

}  // namespace demcal
