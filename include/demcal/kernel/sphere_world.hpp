// The 3D DEM kernel: spheres in a box of six rigid walls, linear contacts,
// global damping, central-difference integration. The same shape and
// conventions as the 2D kernel (world.hpp), as Box3D mirrors Box2D:
// particle state in flat arrays, one file per concern —
//   sphere_world.cpp           set-up, integration, stepping, divergence
//   sphere_broad_phase.cpp     cell grid + Verlet skin, contact histories
//   sphere_contact.cpp         the contact law (pairs and walls)
//   sphere_stress.cpp          b, σ, energies, ratios
//   sphere_stability.cpp       reference scales, stable-step estimates
//   sphere_energy_balance.cpp  the energy ledger of the divergence check
// The contact, integration, damping and option types are the 2D kernel's
// (one definition each): ContactLaw, Integration (thickness unused),
// ReferenceScales, StabilityEstimate, Divergence, KernelOptions.
//
// Layout for speed (reports/performance.md, "3D"): the 2D kernel's. State
// in 64-byte aligned flat arrays padded to blocks of 8 particles; a half
// neighbour list in sliced ELLPACK (each pair evaluated once, from its lower
// index; a particle's force the sum over its own slots, then, in a second
// pass and a fixed order, over its mirrored ones: no scatter); the pair
// and particle passes SIMD over 8, 4 or 2 lanes chosen at run time
// (kernel_simd(), DEMCAL_SIMD); threads share the blocks, results
// bit-identical for any thread count; no allocation in a step without a
// list rebuild.
//
// Physics (SI, tension positive):
//  - m = ρ·(4/3)·π·r³·f_ms, I = (2/5)·m·r²;
//  - normal force kn·δ along the centre line (δ = overlap), optional
//    contact damping on it (off by default);
//  - tangential force: an incremental spring kt with a 3-vector history,
//    kept in the current contact plane and turned with the contact every
//    step (see sphere_contact.cpp), capped by Coulomb μ·Fn; no rolling or
//    twisting resistance;
//  - v(n+½) = [(1 − D Δt/2m)·v(n−½) + F·Δt/m]/(1 + D Δt/2m), the same for the
//    vector ω with D_r and I; D_t = ζ_t·2·sqrt(kn·m), D_r = ζ_r·2·sqrt(kt·r²·I)
//    per particle; x(n+1) = x(n) + v(n+½)·Δt. Orientations are not tracked
//    (a sphere's orientation enters no force).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "demcal/kernel/world.hpp"

namespace demcal {

class SphereWorldImpl;

/// Material of the spheres and the walls.
struct SphereMaterial {
  double density = 2650.0;  ///< ρ [kg/m³]
  ContactLaw particle{1e8, 5e7, 0.3};
  ContactLaw wall{1e8, 5e7, 0.0};  ///< walls are frictionless by default
  /// Local viscous damping on the normal force, as a ratio of the critical
  /// value 2·sqrt(kn·m_eff). Off by default: the damping is global.
  double contact_damping_ratio = 0.0;
};

/// The six walls: the lower and upper plane normal to each axis.
enum SphereWallSide : int { kXMin = 0, kXMax = 1, kYMin = 2, kYMax = 3, kZMin = 4, kZMax = 5 };

/// A rigid axis-aligned plane. `position` is its coordinate along its axis
/// (side / 2: 0 = x, 1 = y, 2 = z), `velocity` along the same axis. The
/// kernel moves it by velocity·Δt each step. A protocol servoes a wall
/// through its velocity, as the 2D biaxial protocol does: the energy ledger
/// counts the work of a moving wall from the moves the kernel makes, so a
/// `position` set directly between steps (allowed, e.g. for set-up) is work
/// it cannot see.
struct SphereWall {
  double position = 0.0;
  double velocity = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< force of the particles on the wall [N]
  int contacts = 0;
};

/// Full (non-symmetric) 3×3 tensors and scalar equilibrium measures.
struct SphereMeasures {
  Eigen::Matrix3d boundary_stress = Eigen::Matrix3d::Zero();     ///< b [Pa]
  Eigen::Matrix3d homogenized_stress = Eigen::Matrix3d::Zero();  ///< σ [Pa]
  double kinetic_energy_translation = 0.0;                       ///< [J]
  double kinetic_energy_rotation = 0.0;                          ///< [J]
  double elastic_energy = 0.0;                                   ///< stored in the springs [J]
  double unbalanced_force_ratio = 0.0;                           ///< mean|F_net| / mean|f_contact|
  double inertial_number = 0.0;                                  ///< ε̇·d·sqrt(ρ/p)
  double mean_pressure = 0.0;                                    ///< −tr(σ)/3 [Pa]
  double coordination_number = 0.0;                              ///< 2·contacts / particles
  int particle_contacts = 0;
  int wall_contacts = 0;
  double volume = 0.0;  ///< box volume [m³]
};

/// An assembly of spheres in a box of six walls.
class SphereWorld {
 public:
  /// Walls at lo[a] and hi[a] along each axis a.
  SphereWorld(const SphereMaterial& material, std::span<const double> x, std::span<const double> y,
              std::span<const double> z, std::span<const double> radius,
              const std::array<double, 3>& lo, const std::array<double, 3>& hi,
              KernelOptions options = {});
  SphereWorld(const SphereWorld& other);
  SphereWorld(SphereWorld&& other) noexcept;
  SphereWorld& operator=(const SphereWorld& other);
  SphereWorld& operator=(SphereWorld&& other) noexcept;
  ~SphereWorld();

  // --- setup -----------------------------------------------------------
  void set_integration(const Integration& integration);
  const Integration& integration() const;
  const SphereMaterial& material() const;
  const KernelOptions& options() const;
  /// Replace the kernel options; the energy ledger restarts.
  void set_options(const KernelOptions& options);
  /// Friction of particle–particle contacts (frictionless consolidation,
  /// then friction on).
  void set_particle_friction(double mu);

  // --- stepping --------------------------------------------------------
  /// Advance `n` steps; false as soon as the run diverged (see divergence()).
  bool step(int64_t n = 1);
  Divergence divergence() const;
  /// The energy ledger's last reading (World::energy_created has the meaning).
  double energy_created() const;
  int64_t divergence_step() const;
  int64_t steps_taken() const;
  double time() const;

  // --- measures --------------------------------------------------------
  SphereMeasures measure(double strain_rate = 0.0) const;
  ReferenceScales reference_scales() const;
  /// Stable-step estimates for the current contact network, 6 DOF per sphere.
  StabilityEstimate stability_estimate(int iterations = 300) const;
  /// (1/V)·Σ_p x^p ⊗ F_p (origin at the box centre): equals b − σ.
  Eigen::Matrix3d net_force_moment() const;

  // --- state access (flat arrays) ----------------------------------------
  int size() const;
  std::span<const double> x() const;
  std::span<const double> y() const;
  std::span<const double> z() const;
  std::span<const double> vx() const;
  std::span<const double> vy() const;
  std::span<const double> vz() const;
  std::span<const double> omega_x() const;
  std::span<const double> omega_y() const;
  std::span<const double> omega_z() const;
  std::span<const double> radius() const;
  double min_radius() const;
  double max_radius() const;
  std::span<const double> mass() const;     ///< scaled masses
  std::span<const double> inertia() const;  ///< scaled moments
  std::span<const double> fx() const;       ///< net contact force
  std::span<const double> fy() const;
  std::span<const double> fz() const;
  std::span<const double> torque_x() const;
  std::span<const double> torque_y() const;
  std::span<const double> torque_z() const;

  /// Direct state edits for tests and scene set-up. With rotation locked the
  /// spin is ignored (kept 0).
  void set_velocity(int i, const Eigen::Vector3d& v, const Eigen::Vector3d& omega);
  void set_position(int i, const Eigen::Vector3d& p);

  SphereWall& wall(SphereWallSide side);
  const SphereWall& wall(SphereWallSide side) const;
  /// Box edge along axis a (0 = x, 1 = y, 2 = z).
  double extent(int axis) const;
  double volume() const;
  Eigen::Vector3d centre() const;

  /// Active particle–particle contacts (after the last force evaluation).
  struct ContactView {
    int i, j;
    Eigen::Vector3d normal;      ///< unit, from i to j
    double fn;                   ///< normal force, compressive > 0
    Eigen::Vector3d tangential;  ///< tangential force on i (in the contact plane)
    double overlap;
  };
  std::vector<ContactView> contacts() const;
  int64_t rebuilds() const;
  /// Share of the neighbour slots the pair pass evaluates that hold a real
  /// neighbour (the rest pad each block's rows to its longest list).
  double neighbour_slot_fill() const;
  /// The same share for the mirror list, which gives each particle its
  /// pairs with lower indices (padded to the longest such row of its block).
  double mirror_slot_fill() const;
  /// Renumber the particles: particle order[k] becomes particle k. Every
  /// per-particle quantity moves with its particle, contact histories
  /// included (pair and wall: a pair's history, the tangential force on its
  /// lower index, changes sign where the new numbering swaps the pair), and
  /// the forces are re-evaluated in the new order: the same physical state
  /// (sums run in another order, so later steps differ in the last bits);
  /// the identity changes no bit and rebuilds nothing. Throws
  /// std::invalid_argument unless `order` is a permutation of 0 … size() − 1.
  void reorder(std::span<const int> order);
  /// An order for reorder() that fills the SIMD blocks, the 2D kernel's
  /// (World::block_friendly_order): the kernel evaluates 8 particles at once
  /// and pads their half rows (neighbours of higher index) and mirror rows
  /// (lower index) to the longest of the block, so particles with as many
  /// neighbours on either side share a block: a greedy order of windows of
  /// 64 consecutive particles (locality kept) or the current numbering,
  /// whichever fills better, improved by a local search of swaps between
  /// nearby blocks; the identity where nothing fills the blocks better
  /// (reports/performance.md).
  std::vector<int> block_friendly_order() const;

  /// Threads for stepping this world (KernelOptions::threads: 0 = all
  /// cores). Results are bit-identical for any thread count.
  void set_threads(int threads);
  int threads() const;

  /// Recompute forces for the current state without moving anything and
  /// without a tangential increment.
  void update_forces();

  // --- the whole state as bytes (sphere_world_state.cpp) -----------------
  /// Every member of the state, bit for bit (this build's layout and byte
  /// order; the threads are not state): the SphereWorld load_state() reads
  /// back steps exactly as this one, as a copy does. For the consolidation
  /// cache (World::save_state is the 2D kernel's).
  std::string save_state() const;
  /// The SphereWorld of save_state()'s bytes. Bytes that do not read as one
  /// (another kernel's or layout's, cut, sizes that do not fit together)
  /// throw std::runtime_error.
  static SphereWorld load_state(std::string_view bytes);

 private:
  explicit SphereWorld(std::unique_ptr<SphereWorldImpl> impl);
  // The state and passes (src/kernel/sphere_world_impl.hpp, private to the
  // kernel).
  std::unique_ptr<SphereWorldImpl> impl_;
};

}  // namespace demcal
