// How dimension enters: two kernels of the same shape, not one template.
// This World is the 2D kernel (disks); a 3D kernel (spheres, SphereWorld)
// sits beside it as its own class with the same coarse interface: build
// from particles and walls, set_integration, step(n), measure() (boundary
// and homogenized stress, energies, unbalanced force), wall(side),
// reference_scales(), stability_estimate(). The layers above talk to a
// sample only through these calls, so scene, scoring and search take the
// kernel as a type parameter or through a thin adapter, and never see its
// arrays. Why not one World<Dim>: what is costly and tuned is not
// dimension-free — the contact law's tangential history is a scalar along
// one tangent in 2D and a vector that must be rotated with the contact in
// 3D, rotation is a scalar ω in 2D and a vector with a 3×3 inertia in 3D,
// the SIMD pass, the ELLPACK layout and the wall set differ, and the
// stability estimate's dofs per particle are 3 against 6. A template would
// be if-constexpr on every page. What is truly dimension-free is small and
// shared as free functions instead: the particle scales
// (particle_scales.hpp, where a sphere's mass and inertia can sit beside
// the disk's)
// and the normal contact law (src/kernel/contact_law.hpp, templated on the
// value type). This is the Box2D / Box3D split.
//
// The 2D DEM kernel: disks between four rigid walls, linear contacts, global
// damping, central-difference integration.
//
// Data-oriented in the manner of Box2D v3: particle state lives in flat
// arrays, the broad phase (broad_phase.cpp), the contact law (contact.cpp),
// the integrator (solver.cpp), the stress measures (stress.cpp) and the
// stability estimates (stability.cpp) are one file each. The kernel knows
// nothing about biaxial tests or calibration. This header holds the coarse
// calls and value types only: the arrays and passes are WorldImpl's
// (src/kernel/world_impl.hpp, private), which World owns and forwards to.
//
// Layout for speed (reports/performance.md): particles are processed in
// blocks of 8 (arrays padded to whole blocks, 64-byte aligned). The
// neighbour list is a half list — each pair (i, j), i < j, once, in i's row
// — in a sliced-ELLPACK layout: block b holds rows of 8 slots, slot (row,
// lane) being the row-th neighbour j > i of particle i = 8b + lane (a ghost
// index where a lane has fewer neighbours). Each pair is evaluated once;
// its force and torques are stored per slot, and each particle sums them in
// increasing index of the partner (its pairs with lower particles through a
// mirror list of their slots, then its own slots), then the walls: no
// scatter, SIMD lanes never conflict, and the summation order does not
// depend on how blocks are shared among threads.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "demcal/kernel/material.hpp"
#include "demcal/kernel/particle_scales.hpp"

namespace demcal {

/// The algorithmic parameters the kernel integrates with.
struct Integration {
  double dt = 0.0;                         ///< time step Δt [s]
  double damping_ratio_translation = 1.0;  ///< ζ_t = D_t / D_t^crit
  double damping_ratio_rotation = 1.0;     ///< ζ_r = D_r / D_r^crit
  double mass_scaling = 1.0;               ///< f_ms, multiplies m and I
  bool lock_rotation = false;              ///< diagnostic: ω ≡ 0 (spins are zeroed)
};

/// Estimates of the largest stable step for the current contact network.
struct StabilityEstimate {
  /// Largest angular frequency² of the linearised, undamped system
  /// M⁻¹K (translation and rotation coupled), by power iteration: the
  /// explicit scheme is stable for ω_max·Δt < 2 whatever the damping.
  double omega2_max = 0.0;
  /// Gershgorin bound on ω²_max (always ≥ omega2_max; a safe upper bound).
  double omega2_gershgorin = 0.0;
  /// 2/ω_max [s]; with contact dashpots 2/ω_max·(sqrt(1+ζ²) − ζ), ζ the
  /// bound on the top mode's dashpot damping (stability.cpp).
  double dt_stable = 0.0;
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
/// kEnergyCreated: the energy ledger (World::energy_created()) shows the
/// integrator creating energy — what a step beyond the stable one does when
/// sliding contacts or damping hold the unstable mode to a bounded rattle
/// instead of letting it blow up.
enum class Divergence { kNone = 0, kNotFinite, kOverlap, kEnergy, kEnergyCreated };
const char* to_string(Divergence d);

/// Kernel tuning that does not change the physics.
struct KernelOptions {
  double skin_ratio = 0.3;         ///< Verlet skin as a fraction of r_min
  double max_overlap_ratio = 0.5;  ///< overlap/r_min beyond which a run has diverged
  int check_interval = 32;         ///< steps between divergence checks
  /// Kinetic energy beyond this multiple of max(elastic energy, work scale)
  /// means energy is growing without bound.
  double max_energy_ratio = 1e3;
  /// Energy ledger, sampled every energy_check_interval steps: energy now −
  /// energy at the start − work of the walls + energy dissipated by damping
  /// (global and contact). Friction only dissipates, so for a stable scheme
  /// this is ≤ 0 up to sampling error; above max_energy_created × (start
  /// energy + |wall work| + dissipated) the run has diverged (kEnergyCreated).
  /// Measured (energy_balance.cpp): stable runs read below 0.012, runs past
  /// the stable step pass 0.1 within a few thousand steps.
  double max_energy_created = 0.1;
  int energy_check_interval = 128;
  /// Threads that share one World's step (1: the calling thread only). Worth
  /// it from about 10^4 particles; small REVs stay single-threaded (a
  /// calibration runs trials in parallel instead). Results are bit-identical
  /// for any thread count. 0 means std::thread::hardware_concurrency().
  int threads = 1;
};

/// The SIMD code path the kernel uses on this machine: "avx512" (x86-64-v4),
/// "avx2" (x86-64-v3) or "sse2" (any x86-64), chosen once at start-up from
/// the CPU (DEMCAL_SIMD=sse2|avx2|avx512 in the environment overrides it, for
/// benchmarks; unset or empty: the widest). Results are deterministic on a
/// given path; the paths with FMA may differ from the sse2 one in the last
/// bits. Throws std::invalid_argument, its message naming DEMCAL_SIMD, its
/// value and the paths this CPU runs, when DEMCAL_SIMD names no path or one
/// this CPU cannot run (so does every World and SphereWorld constructor).
const char* kernel_simd();

/// How the "avx512" path reads its neighbours' values: "hardware" (AVX-512
/// gather instructions, chosen on Intel CPUs since Sapphire Rapids, where
/// they are faster) or "emulated" (scalar loads put together; every other
/// path and CPU, and builds made with Clang). DEMCAL_GATHER=hardware|emulated
/// in the environment overrides it, for benchmarks. Both read the same
/// values, so results are the same bits either way. Throws
/// std::invalid_argument, naming DEMCAL_GATHER and its value, for a value
/// that is no way, or "hardware" on another path or in a build without it
/// (so does every World and SphereWorld constructor).
const char* kernel_gather();

class WorldImpl;

/// A 2D assembly of disks in a rectangular box of four walls.
class World {
 public:
  World(const Material& material, std::span<const double> x, std::span<const double> y,
        std::span<const double> radius, double left, double right, double bottom, double top,
        KernelOptions options = {});
  World(const World& other);
  World(World&& other) noexcept;
  World& operator=(const World& other);
  World& operator=(World&& other) noexcept;
  ~World();

  // --- setup -----------------------------------------------------------
  void set_integration(const Integration& integration);
  const Integration& integration() const;
  const Material& material() const;
  const KernelOptions& options() const;
  /// Threads for stepping this World (see KernelOptions::threads).
  void set_threads(int threads);
  /// Replace the kernel options (threads included); the energy ledger restarts.
  void set_options(const KernelOptions& options);
  /// Renumber the particles: particle order[k] becomes particle k. Every
  /// per-particle quantity moves with its particle, contact histories
  /// included, and the forces are re-evaluated in the new order: the same
  /// physical state (sums run in another order, so later steps differ in the
  /// last bits); the identity changes no bit and rebuilds nothing. Throws
  /// std::invalid_argument unless `order` is a permutation of 0 … size() − 1.
  void reorder(std::span<const int> order);
  /// An order for reorder() that fills the SIMD blocks: the kernel evaluates
  /// 8 particles at once and pads their half rows (neighbours of higher
  /// index) and mirror rows (lower index) to the longest of the block, so
  /// particles with as many neighbours on either side share a block: a
  /// greedy order of windows of 64 consecutive particles (locality kept) or
  /// the current numbering, whichever fills better, improved by a local
  /// search of swaps between nearby blocks; the identity where nothing
  /// fills the blocks better (reports/performance.md).
  std::vector<int> block_friendly_order() const;
  int threads() const;
  /// Set the friction coefficient of particle–particle contacts (used by
  /// consolidation: frictionless compression, then friction on).
  void set_particle_friction(double mu);

  // --- stepping --------------------------------------------------------
  /// Advance `n` steps. Returns false as soon as the run diverged (see
  /// divergence()); then the state is left as it was at detection.
  bool step(int64_t n = 1);
  Divergence divergence() const;
  /// The energy ledger's last reading: energy created by the integrator (a
  /// lower bound: friction is not counted) as a fraction of (start energy +
  /// |wall work| + dissipated); ≤ 0 for a stable run up to sampling error
  /// (KernelOptions::max_energy_created). It
  /// restarts whenever the state or the integration is set from outside.
  double energy_created() const;
  int64_t divergence_step() const;
  int64_t steps_taken() const;
  double time() const;

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
  int size() const;
  std::span<const double> x() const;
  std::span<const double> y() const;
  std::span<const double> vx() const;
  std::span<const double> vy() const;
  std::span<const double> rotation() const;
  std::span<const double> omega() const;
  std::span<const double> radius() const;
  double min_radius() const;
  double max_radius() const;
  std::span<const double> mass() const;  ///< scaled masses
  std::span<const double> fx() const;    ///< net contact force
  std::span<const double> fy() const;
  std::span<const double> torque() const;

  /// Direct state edits for tests and scene set-up; they invalidate the
  /// neighbour list. With rotation locked, the spin ω is ignored (kept 0).
  void set_velocity(int i, double vx, double vy, double omega);
  void set_position(int i, double x, double y);

  Wall& wall(WallSide side);
  const Wall& wall(WallSide side) const;
  double width() const;
  double height() const;
  double volume() const;  ///< W·H·t [m³]
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
  int64_t rebuilds() const;
  /// Share of the neighbour slots the pair pass evaluates that hold a real
  /// neighbour (the rest pad each block's rows to its longest list).
  double neighbour_slot_fill() const;

  /// Recompute forces for the current state without moving anything (after
  /// set-up or edits, so that measure() sees consistent forces).
  void update_forces();

  // --- the whole state as bytes (world_state.cpp) ------------------------
  /// Every member of the state, bit for bit (this build's layout and byte
  /// order; the threads are not state): the World load_state() reads back
  /// steps exactly as this one, as a copy does. For the consolidation cache.
  std::string save_state() const;
  /// The World of save_state()'s bytes. Bytes that do not read as one (cut,
  /// sizes that do not fit together) throw std::runtime_error.
  static World load_state(std::string_view bytes);

 private:
  explicit World(std::unique_ptr<WorldImpl> impl);
  // The state and passes (src/kernel/world_impl.hpp, private to the kernel).
  std::unique_ptr<WorldImpl> impl_;
};

}  // namespace demcal
