// The biaxial test (README.md "Physics in one paragraph"): consolidation to isotropic σ3 with four
// servo walls, then loading: bottom fixed, top wall strain-controlled to a
// total vertical strain ε over Nstep steps, left and right walls servoed at
// σ3. Monitored at M points.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "demcal/kernel/world.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_progress.hpp"
#include "demcal/scene/loading_run.hpp"
#include "demcal/scene/packing.hpp"

namespace demcal {

/// One monitoring point of a loading run (the shared measures:
/// loading_run.hpp).
struct MonitorPoint : MonitorMeasures<Eigen::Matrix2d> {
  double strain_yy = 0.0;                           ///< (H − H0)/H0, negative in compression
  double left = 0, right = 0, bottom = 0, top = 0;  ///< wall positions
};

/// The consolidated sample, saved once and copied by every trial.
struct ConsolidatedState {
  /// The static packing. Its particles are renumbered for the kernel
  /// (World::block_friendly_order()), so they need not be in the assembly's order.
  World world;
  double width0 = 0.0, height0 = 0.0;  ///< box after consolidation
  int64_t steps = 0;                   ///< consolidation steps taken
  double wall_time_s = 0.0;
  bool converged = false;
  double stress_error = 0.0;      ///< max |p − σ3|/σ3 over the walls at the end
  double unbalanced_ratio = 0.0;  ///< at the end
  /// Read from the consolidation cache (consolidation_cache.hpp): `steps`
  /// are those the consolidation took, wall_time_s the reading's.
  bool from_cache = false;
};

/// The servo's largest wall move per step, as a share of the smallest
/// radius: a gas far from the walls is approached at this speed, a packing
/// never gets near it. demcal's servo_velocity (2D and 3D) and the exported
/// decks' servo (stage 1 and loading, `cap`) use it.
inline constexpr double kServoMoveCapRatio = 0.02;
/// kServoMoveCapRatio·r_min [m per step].
inline double servo_move_cap(double r_min) { return kServoMoveCapRatio * r_min; }

/// Servo of the consolidation and the loading: each step move the wall by
/// gain·(σ3 − p)·L·t/(R·n_c) toward the sample (see TestSpec::servo_gain),
/// R = servo_resistance(), plus servo_carry of the wall's last move (its
/// current velocity, which only this servo sets; walls start each phase
/// at rest), at most servo_move_cap. Without contact damping the carry is
/// 0. Returns the wall velocity.
double servo_velocity(const World& world, WallSide side, double target_stress, double gain);
/// The wall contacts' dashpot c = 2ζ_c·sqrt(kn_wall·m_max) [N·s/m] of the
/// heaviest particle (mass m_max, with the run's mass scaling): the most
/// damping; 0 without contact damping (ζ_c ≤ 0). The one formula of the 2D
/// and the 3D servo (triaxial.cpp) and of the exported decks.
double servo_wall_dashpot(double kn_wall, double zeta_c, double m_max);
/// servo_wall_dashpot with the material's kn_wall and ζ_c.
double servo_wall_dashpot(const Material& material, double m_max);
/// What a wall contact resists the servo's move by within a step Δt, per
/// unit of the move: R = kn_wall + c/Δt [N/m], c = servo_wall_dashpot
/// (kn_wall alone without contact damping). The one formula of demcal's
/// servo_velocity (2D and 3D) and the exported decks' servo (stage 1 and
/// loading).
double servo_resistance(double kn_wall, double zeta_c, double m_max, double dt);
/// servo_resistance with the material's kn_wall and ζ_c.
double servo_resistance(const Material& material, double m_max, double dt);
/// The share of its last move that the servo carries into the next
/// (servo_velocity, 2D and 3D, consolidation and loading): (R −
/// kn_wall)/R = (c/Δt)/R, R = servo_resistance; 0 without contact damping.
/// A wall already moving at v has the dashpot force c·v of that motion in
/// its reading; a move u_k changes the wall force within the step by
/// kn_wall·u_k + c·(u_k − u_{k−1})/Δt per contact (the dashpot sees the
/// change of velocity). The move that changes it by gain·error is then
/// gain·error/R + servo_carry·u_{k−1}: the step's response is the per-step
/// law's (R), and a steady error drives the wall at the undamped law's
/// velocity gain·error/(kn_wall·Δt), not the kn_wall/R of it that the
/// per-step law reaches (reports/robustness.md, "The 3D consolidation at
/// contact damping 0.7").
inline double servo_carry(double kn_wall, double resistance) {
  return resistance > kn_wall ? (resistance - kn_wall) / resistance : 0.0;
}
/// What one servo step reads of its wall (2D or 3D).
struct ServoWall {
  double error = 0.0;     ///< σ3 − p, the stress still missing [Pa]
  double area = 0.0;      ///< the wall's area (2D: length × thickness) [m²]
  int contacts = 0;       ///< its contacts now (0 counts as 1)
  double inward = 0.0;    ///< +1 or −1: the direction toward the sample
  double velocity = 0.0;  ///< its velocity along its axis (the last move / Δt)
};
/// The servo law of servo_velocity, 2D and 3D alike: the move
/// gain·error·A/(R·n_c) toward the sample, R = `resistance`
/// (servo_resistance), plus servo_carry(kn_wall, R) of the last move, at
/// most servo_move_cap(r_min); returns the wall velocity inward·move/Δt.
double servo_step_velocity(const ServoWall& wall, double gain, double resistance, double kn_wall,
                           double dt, double r_min);
/// Λ, the bound on the dashpot network's "reduced-mass Laplacian"
/// G = Σ m_eff·b·bᵀ over the contacts (walls included) against the mass
/// matrix, vᵀGv ≤ Λ·vᵀMv, for any packing of particles of one density with
/// radii in [r_min, r_max] (radius_ratio = r_max/r_min ≥ 1) in a box, in
/// `dimension` 2 (disks) or 3 (spheres); biaxial.cpp derives it. A mode
/// then carries at most the damping ratio ζ_c·sqrt(Λ) from the contact
/// dashpots, whatever its frequency.
double consolidation_dashpot_coordination(int dimension, double radius_ratio);
/// The factor demcal's consolidation shrinks its step ratio α by for the
/// contact dashpots (2D and 3D): f(ζ_c·sqrt(Λ)), f = dashpot_step_factor,
/// Λ = consolidation_dashpot_coordination(dimension, r_max/r_min); stable
/// wherever the undamped α is (biaxial.cpp says why); 1 without contact
/// damping (ζ_c ≤ 0).
double consolidation_dashpot_factor(double zeta_c, int dimension, double r_min, double r_max);
/// The consolidation's step ratio α, its one home (demcal's consolidation in
/// 2D and 3D, the config checks and the exported decks): the undamped
/// consolidation's AlgorithmSpec{}.dt_ratio (0.2, the paper's start step)
/// times consolidation_dashpot_factor(zeta_c, dimension, r_min, r_max).
double consolidation_alpha(double zeta_c, int dimension, double r_min, double r_max);
/// The consolidation's step shrink: its α (`dt_ratio`, the undamped
/// consolidation's AlgorithmSpec{}.dt_ratio shrunk by
/// consolidation_dashpot_factor where contact dashpots lower the stable
/// step) over the undamped consolidation's.
inline double consolidation_step_shrink(double dt_ratio) {
  return dt_ratio / AlgorithmSpec{}.dt_ratio;
}
/// The step from which the friction phase runs at critical damping (the
/// first check at or after it; twice it when the frictionless phase was cut:
/// frictionless_phase_cut, run_consolidation): a quarter of the budget
/// `max_steps` in the simulated time of the undamped step, i.e. as many more
/// steps as the step shrank (`step_shrink`: consolidation_step_shrink;
/// scene/protocol_steps.hpp run_consolidation says why). The one home of the
/// formula: demcal's consolidations (2D and 3D) and the exported decks'
/// stage 1 (src/upscaling, deck::lammps_consolidation_quarter) use it.
inline int64_t critical_damping_after(int64_t max_steps, double step_shrink) {
  return step_shrink < 1.0
             ? static_cast<int64_t>(std::ceil(static_cast<double>(max_steps / 4) / step_shrink))
             : max_steps / 4;
}
/// The step at which a frictionless phase not yet static ends (friction
/// goes on: the first check at or after it): critical_damping_after, but at
/// most half the budget, so that friction keeps about the other half (the
/// cut comes at a check) to lock the packing. The half binds where contact
/// dashpots shrank the step below half the undamped one (step_shrink < 1/2:
/// ζ_c above 0.19 in 3D and 0.27 in 2D at a radius ratio of 5/3); without
/// it, below step_shrink 1/4 (ζ_c above 0.47 and 0.68) the quarter lay
/// beyond the budget, and a frictionless phase that creeps
/// (run_consolidation) ran the whole budget and failed. The one home of the
/// rule: demcal's consolidations and the decks' stage 1
/// (deck::lammps_consolidation_quarter, cons_cut).
inline int64_t frictionless_phase_cut(int64_t max_steps, double step_shrink) {
  return std::min(critical_damping_after(max_steps, step_shrink), max_steps / 2);
}
/// Compressive pressure on a wall from the particles [Pa].
double wall_pressure(const World& world, WallSide side);

/// The global damping ratio (translation and rotation) consolidation
/// settles with: light, so the packing's slow collective modes relax at their
/// own speed (biaxial.cpp; the exported decks' consolidation stage uses it).
inline constexpr double kConsolidationDampingRatio = 0.02;

/// Consolidate: frictionless servo compression to σ3 until static, then
/// friction on and static again. Throws std::runtime_error if it cannot.
/// Through the consolidation cache in consolidation_cache_dir() (the
/// environment's; consolidation_cache.hpp): the same state, bit for bit.
ConsolidatedState consolidate(const SceneConfig& config, const Assembly& assembly,
                              const ConsolidationOptions& options = {});
/// The same through the cache in `cache_dir`; "" consolidates afresh.
ConsolidatedState consolidate(const SceneConfig& config, const Assembly& assembly,
                              const std::string& cache_dir,
                              const ConsolidationOptions& options = {});

struct LoadingResult : LoadingRun<MonitorPoint> {
  /// The peak tracked at every step (monitoring points alone can miss a
  /// sharp peak by a monitoring interval): most compressive vertical wall
  /// stress −(p_top + p_bottom)/2, equal to b_yy for frictionless walls.
  double peak_stress_yy = 0.0;
  double peak_strain_yy = 0.0;
};

/// Called at each monitoring point; return false to stop the run early.
using MonitorCallback = std::function<bool(const MonitorPoint&)>;

/// Absolute integration parameters for an algorithm spec on a state.
Integration integration_for(const World& world, const AlgorithmSpec& algorithm);

/// The stable α = Δt/Δt_crit estimated from the stiffnesses of the
/// consolidated contact network (World::stability_estimate()), for the
/// mass scaling and rotation lock of `algorithm`.
double estimated_stable_dt_ratio(const ConsolidatedState& state, const AlgorithmSpec& algorithm);

/// Load a copy of the consolidated state. `final_state`, if given, receives
/// the world at the end (for pictures and VTK).
LoadingResult run_loading(const ConsolidatedState& start, const TestSpec& test,
                          const AlgorithmSpec& algorithm, const MonitorCallback& monitor = {},
                          World* final_state = nullptr);

/// The most compressive b_yy of a series and where it happened.
struct Peak {
  double stress_yy = 0.0;  ///< negative (compression)
  double strain_yy = 0.0;
  int index = -1;
};
Peak find_peak(const std::vector<MonitorPoint>& series);

}  // namespace demcal
