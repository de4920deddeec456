// Scene and calibration configs (JSON). Every default lives here, in the
// member initialisers, and nowhere else; README.md documents the keys.
//
// Parsing validates everything: a wrong type, an unknown key, a value out of
// range gives one InputError naming the file and the key.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "demcal/io/input_error.hpp"
#include "demcal/kernel/material.hpp"

namespace demcal {

/// The most particles an assembly may have. The kernel keeps about 1 kB of
/// state per particle (positions, velocities, forces, the neighbour list
/// and its contact history) and every parallel trial holds its own copy:
/// 10^7 particles is about 10 GB per trial, and the REV a calibration needs
/// has 10^2 to 10^5. Larger requests are refused up front (exit 2) instead
/// of dying in an allocation.
inline constexpr int64_t kMaxParticles = 10'000'000;
inline constexpr const char* kMaxParticlesWhy =
    "10000000 (about 1 kB of kernel state per particle and trial: 10 GB; a calibration REV "
    "has 1e2 to 1e5)";
/// The longest loading (Nstep) a config's algorithm.steps or a params.json's
/// rev.steps may ask for.
inline constexpr int64_t kMaxSteps = 10'000'000'000;
/// The largest test.consolidation_max_steps a config may give: a budget
/// bound beyond it is no value to ask for (check_servo_gain, the contact
/// damping's budget in derived_scales.cpp).
inline constexpr int64_t kMaxConsolidationSteps = 1'000'000'000;
/// A particle count a file holds (a config's prototype.particles, a
/// params.json's rev.particles and prototype.particles): a whole number
/// from `min` to kMaxParticles, read without a cast that can overflow
/// (json_integer); 2.5, "12", 1e11 are an InputError naming `file` and
/// `field`, json_integer's message and the limit with its reason (exit
/// status 2).
int64_t particle_count(const nlohmann::json& value, int64_t min, const std::string& file,
                       const std::string& field);
/// The largest overlap at sigma3, relative to the radius, a config may ask
/// for (test.lateral_stress): see check_lateral_stress in config.cpp.
inline constexpr double kMaxOverlapAtSigma3 = 0.05;
/// test.consolidation_tolerance (a fraction of lateral_stress) must be
/// below this, and positive.
inline constexpr double kConsolidationToleranceBelow = 1.0;

/// The range of a real quantity that a config, a command-line option and a
/// series' metadata (`demcal score`) all give: finite, above `lo` (or at it
/// when `lo_included`), at most `hi`. One range per quantity, below, read
/// by each of them.
struct RealRange {
  double lo = 0.0;
  bool lo_included = false;
  double hi = std::numeric_limits<double>::infinity();
  bool contains(double v) const {
    return std::isfinite(v) && (lo_included ? v >= lo : v > lo) && v <= hi;
  }
  /// "> 0", ">= 0", "> 0 and <= 1e+12": the message's "must be ...".
  std::string text() const;
};
/// A positive quantity: a step (dt, dt_crit [s]), algorithm.mass_scaling.
inline constexpr RealRange kPositive{0.0, false};
/// algorithm.damping_ratio_translation and _rotation.
inline constexpr RealRange kDampingRatio{0.0, true};
/// algorithm.mass_scaling.
inline constexpr RealRange kMassScaling = kPositive;
/// σ3 [Pa] given on the command line (--lateral-stress); a config's
/// test.lateral_stress, and a series' "# lateral_stress" with it, is
/// positive and bounded by its contact stiffness instead (check_lateral_stress
/// in config.cpp), which a series does not carry.
inline constexpr RealRange kLateralStress{0.0, false, 1e12};
/// A reference peak |σ| [Pa] given on the command line (--reference-peak).
inline constexpr RealRange kReferencePeak{0.0, false, 1e15};

/// The defaults of `assembly.type` and `test.type` in a 3D config
/// (`"dimension": 3`): the 2D defaults (hexagonal, biaxial) have no 3D
/// meaning.
inline constexpr const char* kDefaultAssembly3D = "fcc";
inline constexpr const char* kDefaultTest3D = "triaxial";

struct AssemblySpec {
  /// 2D: hexagonal | square | random | file; 3D: fcc | random | file.
  std::string type = "hexagonal";
  int columns = 10;      ///< hexagonal/square
  int rows = 10;         ///< hexagonal/square
  double radius = 5e-4;  ///< hexagonal/square/fcc [m]
  /// fcc: unit cells along x, y, z (4 spheres each, cube axes along the box).
  int cells_x = 4, cells_y = 4, cells_z = 4;
  int count = 400;                       ///< random
  std::string distribution = "uniform";  ///< random: uniform | lognormal
  double radius_min = 3.75e-4;           ///< random uniform [m]
  double radius_max = 6.25e-4;           ///< random uniform [m]
  double radius_mean = 5e-4;             ///< random lognormal: mean radius [m]
  double radius_std = 1e-4;              ///< random lognormal: standard deviation [m]
  double aspect = 1.0;                   ///< random: width/height of the initial box
  uint64_t seed = 1;                     ///< random
  /// file: CSV x,y,r (2D) or x,y,z,r (3D); written relative to the config's
  /// folder, held (and written to params.json) as an absolute path
  std::string file;
};

struct TestSpec {
  std::string type = "biaxial";  ///< 2D: biaxial; 3D: triaxial (kDefaultTest3D)
  double lateral_stress = 1e5;   ///< σ3, compressive magnitude [Pa] (3D: σ2 = σ3)
  /// Total compressive strain ε of the top wall (the axial strain along z in 3D).
  double vertical_strain = 0.01;
  int monitor_points = 200;  ///< M
  /// Servo: each step a lateral wall moves by gain·(σ3 − p)·L·t/(kn_wall·n_c),
  /// the fraction `gain` of the move that would cancel the stress error if
  /// only its n_c wall contacts deformed (the true stiffness is lower, so
  /// gain ≤ 1 never overshoots statically). The servo lags the dilating
  /// sample by an error ∝ 1/(gain·Nstep): measured on hex_10x10 at Nstep
  /// 1e5, RMS error 2.0 % at gain 0.05, 0.21 % at 0.5, 0.10 % at 1, with the
  /// same b − σ noise at every gain (no zig-zag), and likewise on
  /// random_400. 0.5 keeps a margin below 1.
  double servo_gain = 0.5;
  /// Consolidation ends when every wall stress is within this fraction of σ3
  /// and the unbalanced-force ratio is below `consolidation_unbalanced`.
  double consolidation_tolerance = 1e-3;
  double consolidation_unbalanced = 1e-4;
  int64_t consolidation_max_steps = 2000000;
};

/// The algorithmic parameters of one run (the config's `algorithm` block;
/// its keys are also read by the report and by other tools).
struct AlgorithmSpec {
  double dt_ratio = 0.2;                   ///< α = Δt/Δt_crit
  int64_t steps = 100000;                  ///< Nstep (loading)
  double damping_ratio_translation = 1.0;  ///< ζ_t
  double damping_ratio_rotation = 1.0;     ///< ζ_r
  double mass_scaling = 1.0;               ///< f_ms
  bool lock_rotation = false;              ///< diagnostic
};

/// The one JSON form of an AlgorithmSpec (the config's `algorithm` block,
/// trials.jsonl's `params`, the sweep's and the scaling study's records):
/// every member by its name.
nlohmann::json to_json(const AlgorithmSpec& algorithm);
/// Its inverse, checked as the config is: missing keys keep `base`, a wrong
/// type, a value out of range or an unknown key throws InputError naming
/// `source` and `field`.key.
AlgorithmSpec algorithm_from_json(const nlohmann::json& json, const std::string& source,
                                  const std::string& field = "algorithm",
                                  const AlgorithmSpec& base = {});

/// The calibration block of a config; CalibrationOptions (search layer)
/// takes its defaults from here.
struct CalibrationSpec {
  double accuracy = 0.02;  ///< target relative error of the peak
  /// The first search's trials at most (--max-trials); verification of the
  /// model's prediction, the convergence certificate and the tightened
  /// searches after a failed certificate come on top.
  int max_trials = 80;
  uint64_t seed = 1;
};

/// The fewest search trials a calibration accepts (max_trials, --max-trials):
/// the model strategy's two starts need 4 + 2 probes each (calibration.cpp
/// asserts it), and every strategy's two starts at least 5 (COBYLA's simplex
/// in 4 parameters). Less is refused, not raised.
inline constexpr int kMinSearchTrials = 12;
inline constexpr const char* kMinSearchTrialsWhy =
    "the search's two starts need 6 trials each; verification and the certificate come on top";

struct PrototypeSpec {
  int64_t particles = 0;  ///< 0: the REV itself
  std::string file;
};

struct OutputSpec {
  bool vtk = true;
};

struct SceneConfig {
  std::string name = "scene";
  /// 2: disks, biaxial test (plane strain); 3: spheres, triaxial test.
  int dimension = 2;
  Material material;
  AssemblySpec assembly;
  TestSpec test;
  AlgorithmSpec algorithm;
  CalibrationSpec calibration;
  PrototypeSpec prototype;
  OutputSpec output;
  std::string source;  ///< file name, or "<embedded default>"
  std::string text;    ///< the JSON as read (for the config hash)
  /// The --set overrides applied to the file (load_config), for errors
  /// found after reading: source_of() names the one that gave a key.
  std::vector<std::string> sets;
};

/// What an error about `field` (e.g. "algorithm.dt_ratio") names: the last
/// --set that gave it or a section holding it ("--set algorithm.dt_ratio=0.5":
/// its value is the one read), else nothing. One rule for the errors found
/// when the config is parsed and those found later (the stable step).
std::optional<std::string> set_source(const std::vector<std::string>& sets,
                                      const std::string& field);
/// The field a check across keys names (kt against kn, an overlap at
/// sigma3 against sigma3, kn and t): the first of `fields` a --set gave
/// (set_source()), else the first. The user's latest change is named with
/// the --set that made it, not the file's value it broke against; with
/// none, or both, the first (the check's own field). One rule for every
/// such check (detail::overlap_culprit too). `fields` is not empty.
std::string changed_field(const std::vector<std::string>& sets,
                          const std::vector<std::string>& fields);
/// set_source(), else the config's file.
std::string source_of(const SceneConfig& config, const std::string& field);
/// A file the config names at `field` (assembly.file) can be read: else an
/// InputError naming the config (or the --set that gave it) and the field,
/// then the path and what is wrong with it ("no such file"). Errors inside
/// the file name the file itself and its line.
void require_config_file(const SceneConfig& config, const std::string& field,
                         const std::string& path);

/// The stable-step rule (`demcal run`, params.json): a dt_ratio beyond the
/// stable dt_ratio estimated from the consolidated contact network is bad
/// input, an InputError naming `file` and `field`, with `remedy` (what to
/// do instead) in parentheses.
void require_stable_dt_ratio(double dt_ratio, double stable, const std::string& file,
                             const std::string& field, const std::string& remedy);

/// What a calibration (calibrate, scaling) needs of config.calibration
/// before it runs: max_trials at least kMinSearchTrials. Checked there, not
/// when the config is read, so that run, check, upscale and a params.json
/// of an older config still read a config with fewer.
void require_calibration_budget(const SceneConfig& config);

/// Parse and validate. `source` names the file in errors; relative paths in
/// the config (assembly.file, prototype.file) are resolved against its
/// folder and made absolute, so that to_json() writes paths that read the
/// same from any folder. `sets`: the --set overrides already applied to
/// `json` (config.sets), for the checks across keys that name the one a
/// --set changed (the overlap at sigma3).
SceneConfig parse_config(const nlohmann::json& json, const std::string& source,
                         const std::vector<std::string>& sets = {});
SceneConfig parse_config_text(std::string_view text, const std::string& source);
SceneConfig load_config(const std::string& path);
/// What every command loads: `path` (empty: the embedded default) with the
/// --set overrides applied. Any problem with the file (missing, a folder, a
/// device, a symlink loop), its JSON (syntax, a duplicate key, a number out
/// of range) or a value is one InputError naming the file and the key.
/// config.text is the file's text, or the JSON with the overrides applied.
SceneConfig load_config(const std::string& path, const std::vector<std::string>& sets);
/// JSON text to a tree, with the checks of load_config: a duplicate key is
/// an InputError naming it.
nlohmann::json parse_config_json(std::string_view text, const std::string& source);
SceneConfig default_config();
std::string_view default_config_text();

/// Apply `section.key=value` overrides (value parsed as JSON, else string);
/// a malformed one is an InputError naming the --set, and so is a key
/// given twice (require_distinct_set_keys).
void apply_overrides(nlohmann::json& json, const std::vector<std::string>& sets);
/// A key two --set give ("--set a.b=1 --set a.b=2") is an InputError naming
/// the second, the key and both values: the last would be read silently,
/// and the first would look applied (as a key given twice in one JSON object,
/// parse_config_json). A section and then a key in it are two keys (the
/// section replaced, then the key changed in it); a key and then a section
/// holding it ("--set a.b=1 --set a={...}") is an InputError naming both
/// --sets: the section would replace the key, silently. A malformed --set
/// (no '=', or a key with an empty part: "material..kn") is an InputError
/// first, apply_overrides' (before any two keys are compared: "material."
/// is no key inside "material"). Checked by apply_overrides, and by the params.json commands before
/// they drop the --set they do not apply (check_params_options).
void require_distinct_set_keys(const std::vector<std::string>& sets);

/// `json` with the overrides applied (in place), parsed: an error in a key
/// a --set gave names that --set (the last one for the key or a section
/// holding it: its value is the one read), any other error `source`.
SceneConfig parse_config_with_overrides(nlohmann::json& json, const std::vector<std::string>& sets,
                                        const std::string& source);

/// The config back as JSON (every key, defaults filled in).
nlohmann::json to_json(const SceneConfig& config);

/// Hex SHA-256 of a string (config hashes in outputs).
std::string sha256_hex(std::string_view data);

}  // namespace demcal
