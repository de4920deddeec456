// The scaling study behind `demcal scaling`: the proof of the upscaling law
// (issue #6 §3). A family of scenes that differ only in size is calibrated
// at every size up to calibrate_max; Nstep is fitted against N (linear:
// slope, intercept, R²; power: exponent), the multipliers' spread across
// sizes is measured, the smallest passing Nstep at FIXED multipliers (the
// largest calibrated REV's) is found at every size, and the law is checked
// forward: the largest size is run with the REV's multipliers and Nstep
// upscaled from it by the dimension's default law (default_law(): linear
// for disks, N^(2/3) for spheres), and scored against a run with twice the
// steps. The law chosen (scaling.json's `law`, read by --law) is that
// default while the forward check confirms it, the measured exponent when
// the default falls short.
//
// Per-size work (trials, results) goes to a work folder and is reused with
// `resume`; to_json() and scaling_markdown() give scaling.json and
// scaling.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_progress.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/upscaling/upscaling.hpp"

namespace demcal {

/// Particle counts "25,100,400": sorted, each >= 4 and given once (a
/// repeat is an error), at least two; errors name `option`.
std::vector<int64_t> parse_sizes(const std::string& text, const std::string& option = "--sizes");

struct ScalingStudyOptions {
  std::vector<int64_t> sizes;   ///< parse_sizes(); the largest is the forward size
  std::string sizes_text;       ///< as the user wrote them (for the report)
  int64_t calibrate_max = 400;  ///< larger sizes are only checked forward
  std::string work_dir;         ///< per-size work (created)
  int jobs = 0;
  bool resume = false;  ///< reuse the sizes (and a size's trials) already done in work_dir
  /// Set by the caller (a SIGINT handler) to stop cleanly: a calibration
  /// winds down keeping its finished trials; a consolidation ends at its
  /// next check, a run of a size's step search or the forward reference at
  /// its next monitoring point, and what they cut writes nothing (no
  /// fixed.json, reference.json); no further step starts, and the study
  /// returns with `interrupted` set. May be null.
  const std::atomic<bool>* stop = nullptr;
  /// Progress lines; may be empty.
  std::function<void(const std::string&)> log;
  /// Called at every check (200 steps) of each size's fresh consolidation,
  /// one size after another; may be empty.
  ConsolidationCallback consolidation_progress;
};

/// The smallest passing Nstep at the REV's multipliers, at one size.
struct FixedMultipliers {
  bool found = false;
  int64_t steps = 0;
  TrialRecord best;                 ///< the smallest passing run
  std::vector<TrialRecord> trials;  ///< every run, in order
  double wall_time_s = 0.0;
};

/// One size of the family.
struct ScalingSize {
  int64_t requested = 0, particles = 0;
  bool calibrated = false, success = false;
  AlgorithmSpec best;
  double richardson = 0.0, peak = 0.0;
  int trials = 0;
  double wall_time_s = 0.0;
  /// The size's consolidation (steps, wall time: a cache read's when
  /// from_cache): a calibrated size's calibration's, another's step
  /// search's (fixed multipliers).
  ConsolidationRecord consolidation;
  FixedMultipliers fixed;
};
/// A size as scaling.json records it (and as result.json stores a
/// calibrated size for resume), and back; errors name `source`. Its
/// consolidation is consolidation_json's record, flat (add_consolidation_flat):
/// consolidation_steps, consolidation_wall_time_s, consolidation_from_cache.
nlohmann::json to_json(const ScalingSize& size);
ScalingSize scaling_size_from_json(const nlohmann::json& json, const std::string& source);

/// A measured exponent within 0.1 of the law's: the law holds on the
/// family (a smaller one means the law spends steps for nothing, a larger
/// one that it falls short).
bool law_holds(double measured_exponent, const ScalingLaw& law);
/// The law in a few words for logs and scaling.md: "linear", "N^0.667".
std::string law_words(const ScalingLaw& law);

/// (max − min)/mean of a multiplier across sizes.
struct Spread {
  double mean = 0, min = 0, max = 0, relative = 0;
};
Spread spread_of(const std::vector<double>& values);

struct ScalingStudy {
  std::string scene, family;  ///< family: one line, e.g. "hexagonal generator"
  /// 2 (disks, biaxial) or 3 (spheres, triaxial): the sample's linear size
  /// grows as N^(1/dimension), so Nstep ∝ N^p is Nstep ∝ L^(dimension·p).
  int dimension = 2;
  bool from_file = false;
  std::vector<int64_t> sizes, calibrated_sizes;
  std::string sizes_text;
  int64_t calibrate_max = 0, ref_size = 0, forward_size = 0;
  std::map<int64_t, ScalingSize> results;  ///< by requested size
  /// Fits of the calibrated Nstep, of Nstep at fixed multipliers over all
  /// sizes and from the REV up; the number of sizes in each.
  LinearFit lin_cal, pow_cal, lin_fix, pow_fix, lin_rep, pow_rep;
  size_t n_cal = 0, n_fix = 0, n_rep = 0;
  Spread alpha, zeta_t, zeta_r;
  /// The law checked forward and chosen unless it falls short: the
  /// dimension's default_law() (linear for disks, N^(2/3) for spheres).
  ScalingLaw candidate;
  ScalingLaw measured, chosen;
  /// The measured exponent within 0.1 of 1 (law_holds() of the linear law).
  bool linear_holds = false;
  /// The forward check: the candidate law's run and its 2× reference.
  bool have_forward = false, forward_ok = false;
  TrialRecord law_run, reference;
  double law_peak_error = 0.0;
  double accuracy = 0.0;
  /// What every run of the study was scored with: the calibrations'
  /// (CalibrationOptions::from(config), the dimension's defaults), also the
  /// step searches' and the forward reference's.
  Tolerances tolerances;
  bool resumed = false;
  /// options.stop was set: the study stopped before its end, nothing else
  /// in it is complete (resume continues from the work folder).
  bool interrupted = false;
  double wall_time_s = 0.0;
};

/// The sizes' plan is usable: at least two sizes up to calibrate_max (the
/// largest of them is the REV the law is carried from) and the largest size
/// above it (the forward check, without which the study proves nothing).
/// Throws InputError naming --sizes; run_scaling_study() checks it first.
void check_scaling_sizes(const ScalingStudyOptions& options);
/// The same, and the particle counts the sizes make on `config`'s family
/// (a lattice generator rounds to whole cells, rows and columns; a REV cut
/// from a file takes whole particles; counted without consolidating) rise
/// with the sizes: two sizes that make one count, or a forward size that
/// makes no more than the REV, throw InputError naming --sizes and the
/// counts. A random family's sizes are gases that must consolidate
/// (gas_layers_fault, the rule of assembly.count and assembly.aspect): a
/// size that gives too few particles or one layer is refused, naming
/// --sizes and the size. A 3D file family is refused (assembly.type), as
/// the study does. Every size's assembly is then made and checked as a
/// scene's is before it is consolidated (the derived scales, the overlap
/// at sigma3; an REV cut from a file: check_assembly, naming the file),
/// none consolidated, nothing written: the result holds them for
/// run_scaling_study(), which runs them without making or checking any
/// again.
class ScalingFamily;
class CheckedScalingStudy {
 public:
  CheckedScalingStudy(CheckedScalingStudy&&) noexcept;
  CheckedScalingStudy& operator=(CheckedScalingStudy&&) noexcept;
  ~CheckedScalingStudy();

 private:
  explicit CheckedScalingStudy(std::unique_ptr<ScalingFamily> family);
  std::unique_ptr<ScalingFamily> family_;
  friend CheckedScalingStudy check_scaling_sizes(const SceneConfig&, const ScalingStudyOptions&);
  friend ScalingStudy run_scaling_study(CheckedScalingStudy, const ScalingStudyOptions&);
};
CheckedScalingStudy check_scaling_sizes(const SceneConfig& config,
                                        const ScalingStudyOptions& options);

/// The particle file a scaling study cuts its family of REVs from (path)
/// and the config key naming it (key): the prototype's file, else the
/// assembly's, when assembly.type is "file" in 2D; both "" for a generated
/// family (and in 3D, where the study refuses a file: run_scaling_study
/// says why).
struct FamilyFile {
  std::string key, path;
};
FamilyFile scaling_family_file(const SceneConfig& config);

/// Run the study on the family of `config` (resized generators, or REVs cut
/// from the prototype file for a 2D file assembly); 2D and 3D configs run
/// the same code (the search, step search and runs through TrialRunner).
/// Checks first (check_scaling_sizes): bad input throws InputError before
/// anything is written.
ScalingStudy run_scaling_study(const SceneConfig& config, const ScalingStudyOptions& options);
/// The same on a study check_scaling_sizes() checked with these options'
/// sizes and calibrate_max (others: std::invalid_argument); the rest of
/// `options` (work_dir, resume, stop, logs) may be set after the check. The
/// check's config is the one run.
ScalingStudy run_scaling_study(CheckedScalingStudy checked, const ScalingStudyOptions& options);

/// scaling.json (schema demcal.scaling/1; "dimension" says which: a law is
/// only applied to params.json of its dimension).
nlohmann::json to_json(const ScalingStudy& study, const SceneConfig& config);
/// scaling.md.
std::string scaling_markdown(const ScalingStudy& study, const SceneConfig& config);

}  // namespace demcal
