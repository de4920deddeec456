// Upscaling (README.md "Upscaling, verification and export"; evidence in
// reports/scaling.md): from the parameters calibrated on a small REV to the
// user's prototype.
//
// The dimensionless multipliers α = Δt/Δt_crit, ζ_t = D_t/D_t^crit,
// ζ_r = D_r/D_r^crit and the mass scaling carry over unchanged; Nstep grows
// with the particle count (Tu & Andrade: linearly; ScalingLaw lets a
// measured exponent replace it, see reports/scaling.md); the absolute Δt,
// D_t and D_r are recomputed from the prototype's own particles: Δt_crit
// from its smallest particle, the damping coefficients from its masses
// (quoted for the lightest particle and for the mean, as the kernel applies
// them per particle).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/kernel/sphere_world.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/trial_runner.hpp"

namespace demcal {

// ParticleScales and particle_scales(radii, material, mass_scaling) live in
// the kernel layer (demcal/kernel/particle_scales.hpp), included here so that
// callers of this header keep compiling.

/// How the loading length Nstep grows with the particle count:
/// Nstep(N) = Nstep_REV·(N/N_REV)^exponent. Tu & Andrade's law is linear
/// (exponent 1); `demcal scaling` measures the exponent for our kernel.
struct ScalingLaw {
  double exponent = 1.0;
  std::string source = "Tu & Andrade (2008): Nstep proportional to N";
  std::string name() const;  ///< "linear" or "power"
};
/// The law as JSON ({law, exponent, source}) and back. A missing
/// "exponent" reads as linear; errors name `source`.
nlohmann::json to_json(const ScalingLaw& law);
ScalingLaw scaling_law_from_json(const nlohmann::json& j, const std::string& source);

/// The law upscaling uses when no study is named (--law, --exponent, a
/// params.json's "upscaling" block): Nstep ∝ L², L the sample's linear
/// size, i.e. Tu & Andrade's linear law for disks and N^(2/3) for spheres
/// (reports/scaling-3d.md: the force balance's drag term grows as L², the
/// servo error as L; measured at fixed multipliers up to 23 328 spheres).
ScalingLaw default_law(int dimension);

/// Nstep for `n_proto` particles from a calibration on `n_rev` particles.
int64_t upscale_steps(int64_t steps_rev, int64_t n_rev, int64_t n_proto,
                      const ScalingLaw& law = {});
/// What a user must know when the prototype is smaller than the REV
/// (empty when n_proto >= n_rev): the law was measured upward from the REV,
/// and below it the steps shrink faster than the servo error allows (that
/// error grows as L/Nstep, the law keeps only the force balance's L²/Nstep),
/// so `demcal verify` may fail there. One text for every command.
std::string below_rev_note(int64_t n_rev, int64_t n_proto, const ScalingLaw& law);
/// Nstep of a prototype of the REV's own size, which nothing upscales (the
/// law's factor is 1), in words, where a command says how Nstep was
/// upscaled: "88140 steps, the REV's: not upscaled (the prototype has the
/// REV's 100 particles, factor 1)"; `what` names them (particles, spheres).
/// One text for export and verify (upscale names the law it applied).
std::string rev_size_steps_words(int64_t steps, int64_t n_rev, const char* what);
/// The REV's parameters for the prototype: Nstep upscaled, every
/// multiplier unchanged.
AlgorithmSpec upscale(const AlgorithmSpec& rev, int64_t n_rev, int64_t n_proto,
                      const ScalingLaw& law = {});

/// A parameter block of params.json (the keys of `rev` and `prototype`):
/// particles, dt, dt_ratio, dt_crit, steps, damping_translation,
/// damping_ratio_translation, damping_rotation, damping_ratio_rotation,
/// mass_scaling, plus the reference values they come from (radius_min,
/// mass_min, the critical damping of the lightest and of the mean
/// particle, and the mean damping coefficients).
nlohmann::json param_block(const AlgorithmSpec& params, const ParticleScales& scales);

/// Where a prototype's particles come from.
struct PrototypeSource {
  std::string kind;    ///< "file", "generated" or "rev" (the REV itself)
  std::string file;    ///< for "file"
  std::string tiling;  ///< "NXxNY" when the file's packing was mirror-tiled (verify --tile)
  int64_t particles = 0;
  std::string description;  ///< one line for reports
};

/// The config's assembly resized to about `particles` particles: the same
/// generator with the same distribution and seed (hexagonal/square: the
/// column:row ratio kept; fcc: the cells_x:cells_y:cells_z ratio kept, 4
/// spheres a cell, each edge rounded to the nearest whole cell; random, 2D
/// or 3D: count). A family of scenes that differ only in size. Throws
/// InputError for a file assembly (cut a REV instead, rev.hpp).
SceneConfig scene_of_size(const SceneConfig& config, int64_t particles);
/// The particle count scene_of_size(config, particles)'s generator makes,
/// without generating it: columns·rows (hexagonal, square), 4 a cell (fcc),
/// the count (random). Lattices round: two requests can make one count
/// (`scaling` refuses such sizes before consolidating any).
int64_t particles_of_size(const SceneConfig& config, int64_t particles);
/// Why the config's generator may make another count than the one asked,
/// for an error: "a hexagonal lattice of whole columns and rows", "an FCC
/// lattice of whole cells"; "" for random (it makes the count asked).
std::string size_rounding(const SceneConfig& config);

/// Where a prototype's particle count came from, for its errors: a
/// command's --particles (file "--particles", no field), a params.json's
/// prototype block (its path, "prototype.particles") or the config's
/// prototype.particles.
struct CountOrigin {
  std::string file, field;
};

/// The prototype the config names (prototype.file, else prototype.particles
/// with the config's generator, else the REV itself); `particles` and
/// `file` override the config when set, `particles` given by
/// `count_origin` (named in its errors). The assembly is as generated or
/// read (not consolidated). A file's radii are checked as it is read
/// (check_particle_file_scales): every command derives the prototype's Δt
/// and damping from them.
Assembly prototype_assembly(const SceneConfig& config, int64_t particles = 0,
                            const std::string& file = "", PrototypeSource* source = nullptr,
                            const CountOrigin& count_origin = {"--particles", ""});

/// The 3D prototype the config names, as prototype_assembly() for disks:
/// prototype.file (CSV x,y,z,r), else prototype.particles spheres from the
/// config's generator (scene_of_size: an FCC block with the REV's cell
/// aspect, or a random gas with the REV's radius distribution and seed),
/// else the REV itself. A 3D file REV has no generator to resize: a
/// particle count then draws that many radii from the REV's file into a
/// gas (generate_rev). As read or generated, not consolidated; `rev`,
/// `upscale`, `verify` and `params.json` all take their prototype here.
SphereAssembly prototype_spheres(const SceneConfig& config, int64_t particles = 0,
                                 const std::string& file = "", PrototypeSource* source = nullptr,
                                 const CountOrigin& count_origin = {"--particles", ""});

/// Refuse, before any work, a prototype that make_assembly's checks
/// (check_assembly; 3D: make_sphere_assembly's, check_sphere_assembly)
/// refuse, which a generated prototype went through and a particle file
/// did not: radii whose masses, inertias or steps are no normal doubles
/// (a file of 1e-150 m disks consolidated into "diverged: non-finite
/// state"), or a contact overlap at sigma3 its positions cannot resolve to
/// the consolidation's tolerance (a packing at x ~ 1e6 m). For the
/// commands that consolidate or run the prototype (verify, export); upscale
/// and calibrate only derive its scales (the radii's part, which
/// prototype_assembly and prototype_spheres check for a file as they read
/// it: here it repeats, at the cost of a pass over the radii). A prototype
/// `source` read from a file is named, with the distance from the origin
/// its positions must keep; the REV as its own prototype is "the scene".
void check_prototype_assembly(const SceneConfig& config, const Assembly& prototype,
                              const PrototypeSource& source);
void check_prototype_assembly(const SceneConfig& config, const SphereAssembly& prototype,
                              const PrototypeSource& source);

/// The reference scales of spheres (the kernel's own masses m = ρ(4/3)πr³
/// at `params`' mass scaling, via SphereWorld::reference_scales()) with the
/// radius and mean-mass entries filled in: the 3D REV block and the 3D
/// prototype block of params.json both come from here.
ParticleScales sphere_scales(const SphereWorld& world, const Material& material,
                             const AlgorithmSpec& params);

/// The `prototype` block of params.json for a calibration: the REV's
/// parameters `rev` (calibrated on `n_rev` particles) upscaled to the
/// prototype the config names, with Δt and damping recomputed from the
/// prototype's particles (disks, or spheres for a 3D config). Meant to be called by `demcal
/// calibrate`:
///   params["prototype"] = prototype_block(config, summary.best, n_rev);
///   params["upscaling"] = upscaling_block(config, n_rev);
nlohmann::json prototype_block(const SceneConfig& config, const AlgorithmSpec& rev, int64_t n_rev,
                               const ScalingLaw& law = {}, int64_t particles = 0,
                               const std::string& file = "");
/// {law, exponent, factor = Nstep_proto/Nstep_REV, n_rev, n_proto, source}.
nlohmann::json upscaling_block(int64_t n_rev, int64_t n_proto, const ScalingLaw& law = {});

/// A JSON file (params.json, scaling.json); errors name the file.
nlohmann::json read_json_file(const std::string& path);

/// The REV's algorithmic parameters back from a params.json (its `rev`
/// block). Errors name the file and the key.
struct RevParams {
  AlgorithmSpec params;
  int64_t particles = 0;
  ParticleScales scales;  ///< as recorded (dt_crit, damping crit values)
};
RevParams rev_params_from_json(const nlohmann::json& params, const std::string& source);
/// The scene config a params.json was calibrated with: its "config" object
/// when present (nothing otherwise).
std::optional<SceneConfig> config_from_params(const nlohmann::json& params,
                                              const std::string& source);

/// The smallest Nstep that passes every criterion with the multipliers of
/// `params` held fixed (params.steps is the first guess). Force balance,
/// servo and moment balance fall like 1/Nstep at fixed multipliers
/// (reports/optimizers.md), so each run predicts the next guess; the
/// search brackets and stops when a passing run is within 7 % of the
/// tolerances or after `max_runs` runs. With `stop` set (a SIGINT handler's
/// flag) the running run ends at its next monitoring point, no further run
/// starts, and the search returns `interrupted`: not a result (the run the
/// stop cut is left out of trials).
struct StepSearch {
  bool found = false;
  bool interrupted = false;
  TrialRecord best;                 ///< the smallest passing run
  std::vector<TrialRecord> trials;  ///< every run, in order
  double particle_steps = 0.0;      ///< total cost
  int reused = 0;                   ///< of trials, taken from StepSearchRecord::earlier
};
/// What a step search reports as it goes and what it may reuse (both
/// optional): a scaling study keeps a size's finished runs, so that a
/// search stopped after hours of runs at a large size resumes, not restarts.
struct StepSearchRecord {
  /// Called after each run, reused or not, with the search's runs so far.
  std::function<void(const std::vector<TrialRecord>& trials, bool reused)> on_trial;
  /// The runs of an earlier search from the same start on the same runner,
  /// in order. The search is deterministic, so its k-th run asks for the
  /// parameters the k-th earlier one ran, and takes that run instead of
  /// running it again; from the first one that differs on, it runs.
  std::vector<TrialRecord> earlier;
};
StepSearch smallest_passing_steps(const TrialRunner& runner, const AlgorithmSpec& params,
                                  const Tolerances& tolerances = {},
                                  const std::atomic<bool>* stop = nullptr, int max_runs = 8,
                                  const StepSearchRecord& record = {});
/// The same on a consolidated disk REV (BiaxialRunner).
StepSearch smallest_passing_steps(const SceneConfig& config, const ConsolidatedState& state,
                                  const AlgorithmSpec& params, const Tolerances& tolerances = {},
                                  int max_runs = 8);

/// Least-squares fits of Nstep against N (scaling.md).
struct LinearFit {
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
};
/// y = slope·x + intercept, R² of the fit.
LinearFit fit_linear(std::span<const double> x, std::span<const double> y);
/// y = c·x^p by a linear fit of log y on log x: slope = p,
/// intercept = log c, r2 in log space.
LinearFit fit_power(std::span<const double> x, std::span<const double> y);

}  // namespace demcal
