// The signature atlas (reports/signature-atlas.md): around a benchmark parameter set, one
// algorithmic parameter out of bounds at a time, every trial scored and
// diagnosed, against the converged quasi-static peak of the same scene.
// One code path for both dimensions: the biaxial test on disks (2D) or the
// triaxial test on spheres (3D, scored by triaxial_scoring.hpp, whose
// combined criteria fill the 2D columns and whose planes add the 3D ones).
//
// The consolidated state is computed once by the caller; every trial copies
// it. Trials run on a std::thread pool, longest first.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"

namespace demcal {

/// One trial of the sweep.
struct SweepCase {
  std::string name;      ///< file-safe id: "steps_x1_6", "alpha_0.30", ...
  std::string group;     ///< benchmark | atlas | alpha_scan | convergence | grid
  std::string change;    ///< what differs from the benchmark, for people
  std::string expected;  ///< the paper's signature (reports/signature-atlas.md §5), "" if none
  AlgorithmSpec algorithm;
};

/// The paper's one-at-a-time cases around `benchmark` (Nstep ×1/6 and ×33,
/// Δt ×0.1 and ×1.5, ζ_t ×0.7 and ×4.3, ζ_r ×0 and ×2, mass scaling 10⁴ and
/// 10⁸ without damping at the benchmark's absolute Δt), the convergence
/// ladder (Nstep ×2, ×4, ×8, ×16; with ×33 it gives the reference), an α
/// scan at the benchmark's loading time (Nstep·Δt fixed) from 0.25 to 1.5
/// times `alpha_stable`, and, when `grid`, the tolerance-evidence grid
/// (Nstep × {¼, ½, 1, 2} against ζ_t and ζ_r, and α at fixed Nstep).
std::vector<SweepCase> atlas_cases(const AlgorithmSpec& benchmark, double alpha_stable,
                                   bool grid = true);

/// The converged quasi-static peak from the convergence ladder (Nstep
/// doubled from the benchmark): converged when a doubling changes the peak
/// by less than `tolerance`; the value is the Richardson extrapolation of
/// the two longest runs, p∞ = (N₂p₂ − N₁p₁)/(N₂ − N₁) (error ∝ 1/N).
struct ConvergedReference {
  double peak_stress_yy = 0.0;  ///< Richardson estimate (negative)
  bool converged = false;
  double last_change = 0.0;  ///< |p(2N) − p(N)|/|p(2N)| of the last pair
  double tolerance = 0.005;
  struct Rung {
    int64_t steps = 0;
    double peak_stress_yy = 0.0;
    double richardson = 0.0;  ///< with the previous rung (0 for the first)
  };
  std::vector<Rung> ladder;
};

/// How one trial ran, whatever the dimension.
struct SweepRun {
  bool diverged = false;
  Divergence divergence = Divergence::kNone;
  int64_t divergence_step = -1;
  int64_t steps_run = 0, steps_planned = 0;
  double dt = 0.0;  ///< absolute Δt run [s]
  double wall_time_s = 0.0;
  std::string series_csv;  ///< the monitored series (scene/run_output.hpp's series_csv)
};

struct SweepCaseResult {
  SweepCase spec;
  SweepRun run;
  Score score;  ///< peak_error against the converged reference (3D: the combined criteria)
  /// 3D only: the criteria of the three coordinate planes and of each lateral wall.
  std::optional<TriaxialCriteria> planes;
  std::optional<double> peak_error_analytical;
  double identity_residual = 0.0;  ///< gap_identity_residual() of the final state (2D and 3D)
  bool accurate = false;           ///< |peak_error| within the accuracy target
};

struct SweepSettings {
  int jobs = 0;  ///< 0: one per core
  bool grid = true;
  Tolerances tolerances;
  double accuracy = 0.02;  ///< peak accuracy target
  /// Called when a trial finishes (k of n, case name, seconds); may be empty.
  std::function<void(int, int, const std::string&, double)> progress;
};

/// For one criterion, the evidence behind its tolerance: over the finished
/// trials of a sweep, the largest threshold below which every trial was
/// accurate on its own (`safe_alone`), and with the other three criteria at
/// their tolerances (`safe_joint`); how many inaccurate trials it alone
/// rejects (`binding`).
struct CriterionEvidence {
  std::string name;
  double tolerance = 0.0;
  double safe_alone = 0.0;
  double safe_joint = 0.0;
  int binding = 0;
};

struct SweepResult {
  std::string scene;
  int dimension = 2;  ///< 2: disks, biaxial test; 3: spheres, triaxial test (z axial)
  int particles = 0;
  AlgorithmSpec benchmark;
  double alpha_stable = 0.0;
  double lateral_stress = 0.0;
  ConvergedReference reference;
  /// Hexagonal (2D) and FCC (3D) scenes, rotation locked; axial stress (negative).
  std::optional<double> analytical_peak;
  std::vector<SweepCaseResult> cases;  ///< in atlas_cases() order
  std::vector<CriterionEvidence> evidence;
  int false_passes = 0;             ///< passed every criterion, peak off by more than accuracy
  double worst_passed_error = 0.0;  ///< largest |peak error| among passed trials
  /// Largest |peak error| among trials whose paper-form force balance
  /// (RMS(b_yy − σ_yy)/RMS(b_yy)) is within 2 %: what the paper's criterion
  /// alone would certify.
  double worst_paper_form_error = 0.0;
  int false_rejects = 0;  ///< accurate but failed a criterion
  double accuracy = 0.02;
  Tolerances tolerances;
  /// The one consolidation (steps, wall time: a cache read's when from_cache).
  ConsolidationRecord consolidation;
  double wall_time_s = 0.0;
  int jobs = 1;
};

/// Run `cases` on copies of `state` (in parallel), compute the converged
/// reference from the "convergence" group (and the benchmark, and
/// "steps_x33"), score every case against it. The biaxial test on a disk
/// sample, or the triaxial test on a sphere sample (peak: the axial b_zz).
SweepResult run_sweep(const SceneConfig& config, const ConsolidatedState& state,
                      const std::vector<SweepCase>& cases, const SweepSettings& settings);
SweepResult run_sweep(const SceneConfig& config, const TriaxialState& state,
                      const std::vector<SweepCase>& cases, const SweepSettings& settings);

/// The reference from (Nstep, peak) pairs sorted by Nstep (see
/// ConvergedReference).
ConvergedReference converged_reference(std::vector<std::pair<int64_t, double>> peaks,
                                       double tolerance = 0.005);

/// atlas.json; its consolidation as consolidation_json records it (the
/// "consolidation" block), its wall time also as consolidation_time_s.
nlohmann::json to_json(const SweepResult& result);
/// atlas.md: the table (case, measures, peak vs reference, diagnosis), the
/// reference ladder and the tolerance evidence; in 3D with the per-plane
/// columns (force balance x, y, z; moment balance xz, yz, xy; servo per wall);
/// the consolidation's time, labelled when read from the cache.
std::string atlas_markdown(const SweepResult& result);
/// One row per finished case, every measure and the peak error (for plots);
/// in 3D the per-plane measures follow.
std::string evidence_csv(const SweepResult& result);

}  // namespace demcal
