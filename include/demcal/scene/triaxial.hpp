// The triaxial test (README "3D: spheres and the triaxial test"), the 3D counterpart of
// biaxial.hpp: spheres in a box of six rigid frictionless walls. Consolidation to isotropic σ3 with
// all six walls servo-controlled, once per sample (frictionless, then friction on), then loading:
// bottom wall (z min) fixed, top wall (z max) down at constant velocity to the axial strain ε over
// Nstep steps, the four lateral walls servo-controlled at σ3 (σ2 = σ3).
// Monitored at M points. Stresses tension positive; z is the axial axis.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "demcal/kernel/sphere_world.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_progress.hpp"
#include "demcal/scene/loading_run.hpp"
#include "demcal/scene/sphere_packing.hpp"

namespace demcal {

/// One monitoring point of a triaxial loading run (the shared measures:
/// loading_run.hpp; lateral_stress_error over the four lateral walls).
struct TriaxialPoint : MonitorMeasures<Eigen::Matrix3d> {
  double strain_zz = 0.0;  ///< (H − H0)/H0, negative in compression
  /// (p − σ3)/σ3, signed, of the lateral walls x min, x max, y min, y max.
  std::array<double, 4> servo_error{};
  std::array<double, 6> walls{};  ///< positions, SphereWallSide order
  /// Power the global damping takes from the particles at this step [W]:
  /// Σ D_t·|v|² and Σ D_r·|ω|² (the rotational drag of the scoring).
  double damping_power_translation = 0.0;
  double damping_power_rotation = 0.0;
  /// Power the moving (top) wall puts into the sample, −F_z·v_z [W].
  double axial_power = 0.0;
};

/// The consolidated sample, made once and copied by every run.
struct TriaxialState {
  /// The static packing. Its particles are renumbered for the kernel
  /// (SphereWorld::block_friendly_order()), so they need not be in the
  /// assembly's order.
  SphereWorld world;
  std::array<double, 3> extent0{};  ///< box edges after consolidation
  int64_t steps = 0;                ///< consolidation steps taken
  double wall_time_s = 0.0;
  bool converged = false;
  double stress_error = 0.0;      ///< max |p − σ3|/σ3 over the six walls at the end
  double unbalanced_ratio = 0.0;  ///< at the end
  /// Read from the consolidation cache (consolidation_cache.hpp): `steps`
  /// are those the consolidation took, wall_time_s the reading's.
  bool from_cache = false;
};

/// The sphere material of a config's material block (thickness unused).
SphereMaterial sphere_material(const Material& material);
/// Build the sphere assembly a 3D config asks for (fcc, random gas, file)
/// and check that the overlap at σ3 is resolvable (check_sphere_overlap):
/// otherwise an InputError naming the field a --set changed, with that
/// --set (detail::overlap_culprit: test.lateral_stress when none did).
SphereAssembly make_sphere_assembly(const SceneConfig& config,
                                    const std::string& which = "the scene");
/// Refuse (InputError) a sigma3 whose overlap the spheres of `a` cannot
/// carry or resolve: 4*sigma3*r_max/kn at most kMaxOverlapAtSigma3, and
/// the positions' round-off below a tenth of consolidation_tolerance of
/// the overlap 4*sigma3*r_min^2/kn (check_resolvable's rule in 2D).
/// make_sphere_assembly checks its own; a prototype read from a particle
/// `file` (named in the message) is checked by the commands that
/// consolidate it. `which` names the assembly.
void check_sphere_overlap(const SceneConfig& config, const SphereAssembly& a,
                          const std::string& which, const std::string& file = "");
/// The checks make_sphere_assembly gives the assembly it builds, before it
/// is consolidated: the scales its radii derive (masses, inertias, steps,
/// damping: finite, normal doubles) and check_sphere_overlap; as
/// check_assembly in 2D. For spheres read or cut from a particle `file`
/// the errors name the file (a radius as its column r): a file of 1e-150 m
/// spheres is refused for its radii, not for a sigma3 of 1e146 Pa.
void check_sphere_assembly(const SceneConfig& config, const SphereAssembly& a,
                           const std::string& which, const std::string& file = "");

/// Compressive pressure on a wall from the spheres [Pa].
double wall_pressure(const SphereWorld& world, SphereWallSide side);
/// Servo of the consolidation and the loading: move the wall by
/// gain·(σ3 − p)·A/(R·n_c) toward the sample this step (A the wall's area,
/// n_c its contacts), as the 2D servo_velocity: R = servo_resistance
/// (biaxial.hpp), kn_wall plus the wall dashpots' c/Δt with contact damping
/// (c of the heaviest sphere at the run's mass scaling), plus servo_carry
/// (biaxial.hpp) of the wall's last move (its current velocity, which only
/// this servo sets; walls start each phase at rest), at most servo_move_cap
/// per step. Without contact damping the carry is 0. Returns the wall
/// velocity along its axis.
double servo_velocity(const SphereWorld& world, SphereWallSide side, double target_stress,
                      double gain);

/// Absolute integration parameters for an algorithm spec: Δt = α·Δt_crit
/// with Δt_crit from the kernel's masses at the spec's mass scaling
/// (SphereWorld::reference_scales(), the one home of m = ρ(4/3)πr³).
Integration integration_for(const SphereWorld& world, const AlgorithmSpec& algorithm);

/// Consolidate: all six walls servo to σ3, frictionless until static, then
/// friction on and static again; light global damping (ζ = 0.02) with the
/// 2D fallback to critical damping after a quarter of the budget (of
/// simulated time at the undamped step: later when contact dashpots shrink
/// the step, protocol_steps.hpp). Static:
/// every wall stress within test.consolidation_tolerance of σ3 and the
/// unbalanced-force ratio below test.consolidation_unbalanced. Throws
/// std::runtime_error saying what was reached if it cannot. options.threads
/// steps the sphere kernel on that many threads (0: every core; the state
/// is bit-identical for any count and steps on one thread afterwards);
/// options.progress is called at every check (every 200 steps). Through the
/// consolidation cache in consolidation_cache_dir() (the environment's;
/// consolidation_cache.hpp), as the 2D consolidate(): the same state, bit
/// for bit.
TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const ConsolidationOptions& options = {});
/// The same through the cache in `cache_dir`; "" consolidates afresh.
TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const std::string& cache_dir,
                                   const ConsolidationOptions& options = {});
/// The same (the environment's cache), single-threaded, with a progress
/// callback.
TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const ConsolidationCallback& progress);

/// The stable α of the consolidated contact network (6 DOF per sphere).
double estimated_stable_dt_ratio(const TriaxialState& state, const AlgorithmSpec& algorithm);

struct TriaxialResult : LoadingRun<TriaxialPoint> {
  /// Tracked every step: the most compressive axial wall stress
  /// −(p_top + p_bottom)/2 (= b_zz for frictionless walls) and its strain.
  double peak_stress_zz = 0.0;
  double peak_strain_zz = 0.0;
  /// The largest σ1/σ3 with the lateral stress the walls actually carry,
  /// (p_top + p_bottom)/(p_xmin + p_xmax + p_ymin + p_ymax)·2, every step.
  double peak_ratio = 0.0;
  double peak_ratio_strain = 0.0;
};

/// Called at each monitoring point; return false to stop early.
using TriaxialMonitor = std::function<bool(const TriaxialPoint&)>;

/// Called at each monitoring point, before the monitor, with the world
/// there (read only; e.g. to copy the state at the peak).
using TriaxialWorldObserver = std::function<void(const TriaxialPoint&, const SphereWorld&)>;

/// Load a copy of the consolidated state; `final_state` receives the world
/// at the end.
TriaxialResult run_triaxial_loading(const TriaxialState& start, const TestSpec& test,
                                    const AlgorithmSpec& algorithm,
                                    const TriaxialMonitor& monitor = {},
                                    SphereWorld* final_state = nullptr,
                                    const TriaxialWorldObserver& observe = {});

/// σ1/σ3 at failure for the config's assembly when theory gives it: the
/// walled FCC lattice (fcc_peak_ratio_walled, Thornton 1979, rotation
/// absent). Nothing for other assemblies.
std::optional<double> analytical_peak_ratio_3d(const SceneConfig& config);

/// The peak b_zz a run of the config is scored against (its peak error):
/// −analytical_peak_ratio_3d·σ3 when the config locks rotation, the case
/// the theory is for; nothing otherwise (free spheres roll, and the walled
/// FCC peak falls below Thornton's: no reference, not a wrong one).
std::optional<double> reference_peak_3d(const SceneConfig& config);

}  // namespace demcal
