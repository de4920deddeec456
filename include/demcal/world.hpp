// The 2D DEM kernel: disks between four rigid walls, linear contacts, global
// damping, central-difference integration (DESIGN.md §2).
//
// Data-oriented in the manner of Box2D v3: particle state lives in flat
// arrays, the broad phase (broad_phase.cpp), the contact law (contact.cpp),
// the integrator (solver.cpp), the stress measures (stress.cpp) and the
// stability estimates (stability.cpp) are one file each. The kernel knows
// nothing about biaxial tests or calibration.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace demcal {

/// Linear spring contact law: normal force kn·δ, incremental tangential
/// spring kt capped by Coulomb friction·|Fn|.
struct ContactLaw {
  double kn = 1e8;        ///< normal stiffness [N/m]
  double kt = 5e7;        ///< tangential stiffness [N/m]
  double friction = 0.3;  ///< Coulomb coefficient μ [-]
};

/// Material of the particles and the walls.
struct Material {
  double density = 2650.0;  ///< ρ [kg/m³]
  double thickness = 1.0;   ///< disk = cylinder of thickness t [m]
  ContactLaw particle{1e8, 5e7, 0.3};
  ContactLaw wall{1e8, 5e7, 0.0};  ///< walls are frictionless by default
  /// Local (contact) viscous damping on the normal force, as a ratio of the
  /// critical value 2·sqrt(kn·m_eff). Off by default: the paper's damping is
  /// global.
  double contact_damping_ratio = 0.0;
};

/// The algorithmic parameters the kernel integrates with.
struct Integration {
  double dt = 0.0;                         ///< time step Δt [s]
  double damping_ratio_translation = 1.0;  ///< ζ_t = D_t / D_t^crit
  double damping_ratio_rotation = 1.0;     ///< ζ_r = D_r / D_r^crit
  double mass_scaling = 1.0;               ///< f_ms, multiplies m and I
  bool lock_rotation = false;              ///< diagnostic: ω ≡ 0 (spins are zeroed)
};

/// Reference scales of DESIGN.md §2 for the current assembly. Damping
/// coefficients are per particle (every particle gets the same damping
/// ratio); the values below are for the lightest particle and for the mean.
struct ReferenceScales {
  double dt_crit = 0.0;                   ///< 2·sqrt(m_min/kn) [s]
  double damping_translation_crit = 0.0;  ///< 2·sqrt(kn·m) for m_min [N·s/m]
  double damping_rotation_crit = 0.0;     ///< 2·sqrt(kt·r²·I) for m_min [N·m·s]
  double damping_translation_crit_mean = 0.0;
  double damping_rotation_crit_mean = 0.0;
  double mass_min = 0.0;  ///< smallest (scaled) mass [kg]
};

/// Estimates of the largest stable step for the current contact network.
struct StabilityEstimate {
  /// Largest angular frequency² of the linearised, undamped system
  /// M⁻¹K (translation and rotation coupled), by power iteration: the
  /// explicit scheme is stable for ω_max·Δt < 2 whatever the damping.
  double omega2_max = 0.0;
  /// Gershgorin bound on ω²_max (always ≥ omega2_max; a safe upper bound).
  double omega2_gershgorin = 0.0;
  double dt_stable = 0.0;             ///< 2/ω_max [s]
  double dt_stable_gershgorin = 0.0;  ///< 2/sqrt(Gershgorin bound) [s]
  double dt_ratio_stable = 0.0;       ///< dt_stable / dt_crit
  double dt_ratio_stable_gershgorin = 0.0;
  /// The same, with rotation locked (translation only).
  double dt_ratio_stable_translation = 0.0;
};

enum WallSide : int { kLeft = 0, kRight = 1, kBottom = 2, kTop = 3 };

/// A rigid axis-aligned wall. `position` is x for left/right, y for
/// bottom/top; `velocity` along the same axis. The kernel moves it by
/// velocity·Δt each step and reports the force the particles exert on it.
struct Wall {
  double position = 0.0;
  double velocity = 0.0;
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  ///< force of particles on the wall [N]
  int contacts = 0;
};

/// Full (non-symmetric) 2×2 tensors and scalar equilibrium measures.
struct Measures {
  Eigen::Matrix2d boundary_stress = Eigen::Matrix2d::Zero();     ///< b [Pa]
  Eigen::Matrix2d homogenized_stress = Eigen::Matrix2d::Zero();  ///< σ [Pa]
  double kinetic_energy_translation = 0.0;                       ///< [J]
  double kinetic_energy_rotation = 0.0;                          ///< [J]
  double elastic_energy = 0.0;                                   ///< stored in the springs [J]
  double unbalanced_force_ratio = 0.0;                           ///< mean|F_net| / mean|f_contact|
  double inertial_number = 0.0;                                  ///< ε̇·d·sqrt(ρ/p)
  double mean_pressure = 0.0;                                    ///< −tr(σ)/2 [Pa]
  double coordination_number = 0.0;                              ///< 2·contacts / particles
  int particle_contacts = 0;
  int wall_contacts = 0;
  double volume = 0.0;  ///< W·H·t [m³]
};

/// Why a run stopped before its end.
enum class Divergence { kNone = 0, kNotFinite, kOverlap, kEnergy };
const char* to_string(Divergence d);

/// Kernel tuning that does not change the physics.
struct KernelOptions {
  double skin_ratio = 0.3;         ///< Verlet skin as a fraction of r_min
  double max_overlap_ratio = 0.5;  ///< overlap/r_min beyond which a run has diverged
  int check_interval = 32;         ///< steps between divergence checks
  /// Kinetic energy beyond this multiple of max(elastic energy, work scale)
  /// means energy is growing without bound.
  double max_energy_ratio = 1e3;
};

/// A 2D assembly of disks in a rectangular box of four walls.
class World {
 public:
  World(const Material& material, std::span<const double> x, std::span<const double> y,
        std::span<const double> radius, double left, double right, double bottom, double top,
        KernelOptions options = {});

  // --- setup -----------------------------------------------------------
  void set_integration(const Integration& integration);
  const Integration& integration() const { return integration_; }
  const Material& material() const { return material_; }
  const KernelOptions& options() const { return options_; }
  /// Set the friction coefficient of particle–particle contacts (used by
  /// consolidation: frictionless compression, then friction on).
  void set_particle_friction(double mu) { material_.particle.friction = mu; }

  // --- stepping --------------------------------------------------------
  /// Advance `n` steps. Returns false as soon as the run diverged (see
  /// divergence()); then the state is left as it was at detection.
  bool step(int64_t n = 1);
  Divergence divergence() const { return divergence_; }
  int64_t divergence_step() const { return divergence_step_; }
  int64_t steps_taken() const { return steps_; }
  double time() const { return time_; }

  // --- measures --------------------------------------------------------
  /// b, σ, energies and ratios of the current state. `strain_rate` feeds the
  /// inertial number.
  Measures measure(double strain_rate = 0.0) const;
  ReferenceScales reference_scales() const;
  /// Stable-step estimates for the current contact network (call after at
  /// least one step or with contacts present).
  StabilityEstimate stability_estimate(int iterations = 300) const;
  /// V·(b − σ) predicted by the first moment of the net particle forces,
  /// Σ_p x^p ⊗ F_p (origin at the box centre), divided by V: equals b − σ.
  Eigen::Matrix2d net_force_moment() const;

  // --- state access (flat arrays) ----------------------------------------
  int size() const { return static_cast<int>(x_.size()); }
  std::span<const double> x() const { return x_; }
  std::span<const double> y() const { return y_; }
  std::span<const double> vx() const { return vx_; }
  std::span<const double> vy() const { return vy_; }
  std::span<const double> rotation() const { return theta_; }
  std::span<const double> omega() const { return omega_; }
  std::span<const double> radius() const { return r_; }
  double min_radius() const { return r_min_; }
  double max_radius() const { return r_max_; }
  std::span<const double> mass() const { return m_; }  ///< scaled masses
  std::span<const double> fx() const { return fx_; }   ///< net contact force
  std::span<const double> fy() const { return fy_; }
  std::span<const double> torque() const { return tq_; }

  /// Direct state edits for tests and scene set-up; they invalidate the
  /// neighbour list. With rotation locked, the spin ω is ignored (kept 0).
  void set_velocity(int i, double vx, double vy, double omega);
  void set_position(int i, double x, double y);

  Wall& wall(WallSide side) { return walls_[side]; }
  const Wall& wall(WallSide side) const { return walls_[side]; }
  double width() const { return walls_[kRight].position - walls_[kLeft].position; }
  double height() const { return walls_[kTop].position - walls_[kBottom].position; }
  double volume() const { return width() * height() * material_.thickness; }
  Eigen::Vector2d centre() const;

  /// Active particle–particle contacts (after the last force evaluation).
  struct ContactView {
    int i, j;
    double nx, ny;  ///< unit normal from i to j
    double fn, ft;  ///< normal (compressive > 0) and tangential force on i
    double overlap;
  };
  std::vector<ContactView> contacts() const;
  /// Number of neighbour-list rebuilds so far (for tests and benchmarks).
  int64_t rebuilds() const { return rebuilds_; }

  /// Recompute forces for the current state without moving anything (after
  /// set-up or edits, so that measure() sees consistent forces).
  void update_forces();

 private:
  // broad_phase.cpp
  void rebuild_neighbours();
  bool needs_rebuild() const;
  // contact.cpp
  void compute_forces();
  // solver.cpp
  void integrate();
  void update_damping_coefficients();
  bool check_divergence();

  Material material_;
  KernelOptions options_;
  Integration integration_;

  // particle state (structure of arrays)
  std::vector<double> x_, y_, vx_, vy_, theta_, omega_, r_;
  std::vector<double> m_, inertia_;   // scaled mass and inertia
  std::vector<double> fx_, fy_, tq_;  // net contact force and torque
  // per-particle integration coefficients: v ← a·v + b·F
  std::vector<double> ca_t_, cb_t_, ca_r_, cb_r_;
  // wall contacts: tangential force history per particle and wall
  std::array<std::vector<double>, 4> wall_ft_;
  std::array<std::vector<double>, 4> wall_fn_;  // last normal force (0 when apart)

  // Verlet neighbour list: pairs (i < j) sorted by (i, j), with the
  // tangential force of each pair kept across rebuilds.
  std::vector<int> pair_i_, pair_j_;
  std::vector<double> pair_ft_;
  std::vector<double> pair_fn_;  // last normal force (0 when apart)
  std::vector<double> pair_nx_, pair_ny_;
  // scratch for rebuilds (kept to avoid allocation)
  std::vector<int> new_i_, new_j_;
  std::vector<double> new_ft_;
  std::vector<int> cell_start_, cell_next_;
  std::array<std::vector<int>, 4> wall_candidates_;
  std::vector<double> x_built_, y_built_;
  std::array<double, 4> wall_built_{};
  double skin_ = 0.0;
  double r_max_ = 0.0, r_min_ = 0.0;
  bool list_valid_ = false;
  int64_t rebuilds_ = 0;

  std::array<Wall, 4> walls_;
  double max_overlap_ratio_seen_ = 0.0;
  double initial_energy_ = -1.0;  // KE + elastic energy when stepping began
  double energy_scale_ = 0.0;     // largest energy the system has held

  Divergence divergence_ = Divergence::kNone;
  int64_t divergence_step_ = -1;
  int64_t steps_ = 0;
  double time_ = 0.0;
};

}  // namespace demcal
