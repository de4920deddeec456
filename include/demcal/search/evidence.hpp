// The runs a calibration report shows besides the search's own trials, as
// facts the report renders: the start point and the result rerun with their
// whole monitored series, the assembly at the result's peak, and (with
// --evidence) a reference from the result's multipliers at 8× and 16× Nstep.
// The paper-recipe baseline is paper_recipe_baseline() in calibration.hpp.
//
// The search's trials keep only their criteria (trials.jsonl), not their
// series, so the report's runs are reruns: deterministic, they reproduce the
// trials' numbers exactly. In 3D the calibrate command reruns nothing of the
// result: the search's runner keeps its series and its world at the peak
// (TriaxialRunner::keep_passing_runs), and the start point runs beside the
// search (KnownRuns3D); the report is the same.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/trial_runner.hpp"

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

/// One triaxial run with its series for the report, scored against
/// `tolerances`. With `stop` set during the run it ends at its next
/// monitoring point (run.stopped_early: not a run to show).
ReportRun3D report_run(const SceneConfig& config, const TriaxialState& state,
                       const std::string& label, const AlgorithmSpec& params,
                       const Tolerances& tolerances, const std::atomic<bool>* stop = nullptr);

/// What already ran, so that rerun_start_and_result() need not: the start
/// point (report_run(), e.g. beside the search on an idle core) and the
/// result as the search ran it (TriaxialRunner::kept_run()). Each is used
/// only when it ran exactly the parameters asked for and to its end.
struct KnownRuns3D {
  std::optional<ReportRun3D> start;
  std::optional<KeptTriaxialRun> best;
};

/// rerun_start_and_result() for a triaxial scene: the peak is the
/// monitoring point of the most compressive b_zz. Runs only what `known`
/// lacks; the result is the same either way (the runs are deterministic).
ResultRuns3D rerun_start_and_result(const SceneConfig& config, const TriaxialState& state,
                                    const AlgorithmSpec& start, const CalibrationSummary& summary,
                                    const Tolerances& tolerances, int jobs, KnownRuns3D known = {});

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
/// The same on any scene through its trial runner (3D: the axial peak
/// b_zz), without the fine run's series (fine_series stays empty).
ReferenceEvidence run_refined_reference(const TrialRunner& runner, const AlgorithmSpec& best,
                                        const Tolerances& tolerances, int jobs);

}  // namespace demcal
