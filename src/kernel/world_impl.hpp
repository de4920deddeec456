// The 2D kernel's private state (structure of arrays, the sliced-ELLPACK
// neighbour list, scratch, the energy ledger, the thread team) and its
// passes. Only src/kernel sees this header: the layers above talk to a
// sample through World (include/demcal/kernel/world.hpp), which owns one
// WorldImpl and forwards each call, so a change here recompiles the kernel
// alone (Box2D v3 keeps b2World in src/ the same way).
#pragma once

#include "demcal/kernel/world.hpp"
#include "divergence.hpp"
#include "kernel_detail.hpp"

namespace demcal {

/// The 2D kernel's state and passes behind World (world.hpp documents the
/// public calls; World forwards each to this class).
class WorldImpl {
 public:
  WorldImpl(const Material& material, std::span<const double> x, std::span<const double> y,
            std::span<const double> radius, double left, double right, double bottom, double top,
            KernelOptions options = {});

  // --- setup -----------------------------------------------------------
  void set_integration(const Integration& integration);
  const Integration& integration() const { return integration_; }
  const Material& material() const { return material_; }
  const KernelOptions& options() const { return options_; }
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
  /// 8 particles at once and pads their neighbour lists to the longest, so
  /// inside each window of 64 consecutive particles (locality kept) the
  /// particles are sorted by neighbour count. On the random 400-disk REV it
  /// raises the share of real neighbours among the evaluated slots from 82 %
  /// to about 95 % (reports/performance.md).
  std::vector<int> block_friendly_order() const;
  int threads() const { return threads_; }
  /// Set the friction coefficient of particle–particle contacts (used by
  /// consolidation: frictionless compression, then friction on).
  void set_particle_friction(double mu) {
    material_.particle.friction = mu;
    ledger_ = {};
  }

  // --- stepping --------------------------------------------------------
  /// Advance `n` steps. Returns false as soon as the run diverged (see
  /// divergence()); then the state is left as it was at detection.
  bool step(int64_t n = 1);
  Divergence divergence() const { return divergence_; }
  /// The energy ledger's last reading: energy created by the integrator (a
  /// lower bound: friction is not counted) as a fraction of (start energy +
  /// |wall work| + dissipated); ≤ 0 for a stable run up to sampling error
  /// (KernelOptions::max_energy_created). It
  /// restarts whenever the state or the integration is set from outside.
  double energy_created() const { return ledger_.created; }
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
  int size() const { return n_; }
  std::span<const double> x() const { return view(x_); }
  std::span<const double> y() const { return view(y_); }
  std::span<const double> vx() const { return view(vx_); }
  std::span<const double> vy() const { return view(vy_); }
  std::span<const double> rotation() const { return view(theta_); }
  std::span<const double> omega() const { return view(omega_); }
  std::span<const double> radius() const { return view(r_); }
  double min_radius() const { return r_min_; }
  double max_radius() const { return r_max_; }
  std::span<const double> mass() const { return view(m_); }  ///< scaled masses
  std::span<const double> fx() const { return view(fx_); }   ///< net contact force
  std::span<const double> fy() const { return view(fy_); }
  std::span<const double> torque() const { return view(tq_); }

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

  std::vector<World::ContactView> contacts() const;
  /// Number of neighbour-list rebuilds so far (for tests and benchmarks).
  int64_t rebuilds() const { return rebuilds_; }
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
  static WorldImpl load_state(std::string_view bytes);

 private:
  WorldImpl() = default;  // load_state()
  template <class Self, class Visitor>
  static void visit_state(Self& self, Visitor& visit);  // every member (world_state.cpp)
  using Array = detail::AlignedVector<double>;
  std::span<const double> view(const Array& a) const { return {a.data(), static_cast<size_t>(n_)}; }

  // broad_phase.cpp
  void rebuild_neighbours();
  bool needs_rebuild() const;  // full displacement scan (after edits)
  // Block offsets of the sliced ELLPACK list for per-particle lists
  // [start[i], start[i + 1]): each block as many rows as its longest list.
  void layout_blocks(const std::vector<int>& start, std::vector<int>& block_slot) const;
  // The mirror list (mirror_block_, mirror_slot_) from the half list.
  void rebuild_mirror_list();
  // The places of the pair terms (term_block_, mirror_term_) for the list
  // and the threads' block ranges (pair_bounds_).
  void layout_terms();
  // contact.cpp: the SIMD passes over blocks [b0, b1), and the walls
  double pair_pass(int b0, int b1);               // returns the largest overlap/min(r_i, r_j)
  double sum_pass(int b0, int b1);                // mirrored pair terms (threads only)
  double pair_kernel(int b0, int b1, bool sums);  // the two above
  double integrate_pass(int b0, int b1);          // returns the largest displacement²
  void wall_pass();
  void compute_forces();
  /// Geometry and normal force of the pair (i, j) in the current state,
  /// exactly as the contact law evaluates it (for measures and views).
  struct PairState {
    double nx, ny, overlap;
    double vn;          // normal relative velocity, > 0 when opening
    double fn;          // normal force, with the dashpot (0 when apart)
    double fn_elastic;  // the spring's part kn·δ (0 when apart)
    bool touching;
  };
  PairState pair_state(int i, int j) const;
  // energy_balance.cpp: one reading of the energy ledger's rates
  struct EnergySample {
    double energy = 0.0;      // kinetic + elastic (pairs and walls) [J]
    double elastic = 0.0;     // elastic alone [J]
    double power_in = 0.0;    // work rate of the moving walls on the particles [W]
    double power_lost = 0.0;  // global damping [W]
  };
  EnergySample energy_sample() const;
  bool ledger_record(const EnergySample& sample);  // true when diverged
  // Power of the contact dashpots at the last force evaluation [W] (0
  // without contact damping). The ledger integrates it step by step: it
  // lives in the contact vibrations, which one sample in
  // energy_check_interval steps would alias.
  double dashpot_power() const;
  // Work rate of the moving walls on the particles at the last force
  // evaluation [W].
  double wall_power() const;
  // solver.cpp
  void integrate();
  void update_damping_coefficients();
  bool check_divergence();
  template <class Impl>
  friend bool detail::divergence_checks(Impl& w, bool finite, double ke, double extra_scale);
  // The SIMD passes over all blocks, shared among the threads (solver.cpp).
  double run_pair_pass();
  double run_integrate_pass();
  // One pass over the blocks, split among the threads by `bounds`; returns
  // the largest value the pass returned.
  double run_pass(double (WorldImpl::*pass)(int, int), const std::vector<int>& bounds);
  int active_threads() const;   // threads worth using for this size
  void update_thread_bounds();  // particle_bounds_ and pair_bounds_

  Material material_;
  KernelOptions options_;
  Integration integration_;
  int threads_ = 1;

  // Particle state (structure of arrays). Index n_ .. 8·nblocks_ − 1 are
  // inert padding lanes; index ghost_ = 8·nblocks_ is the ghost particle
  // that empty slots point to (far away, radius 0: never in contact).
  int n_ = 0, nblocks_ = 0, ghost_ = 0;
  Array x_, y_, vx_, vy_, theta_, omega_, r_, inv_r_;
  Array m_, inertia_;   // scaled mass and inertia
  Array fx_, fy_, tq_;  // net contact force and torque
  Array block_power_;   // dashpot power of each block's lanes, 8 per block (damped pass only)
  double wall_dashpot_power_ = 0.0;
  // per-particle integration coefficients: v ← a·v + b·F (0 for padding)
  Array ca_t_, cb_t_, ca_r_, cb_r_;
  // wall contacts: tangential force history per particle and wall
  std::array<std::vector<double>, 4> wall_ft_;
  std::array<std::vector<double>, 4> wall_fn_;  // last normal force (0 when apart)

  // Verlet neighbour list (half: pairs i < j; sliced ELLPACK, see
  // broad_phase.cpp): block b's slots are [block_slot_[b], block_slot_[b +
  // 1]), rows of 8; each particle's neighbours j > i in increasing index,
  // then ghosts. slot_ft_ is the tangential force of each slot (pair), kept
  // across rebuilds.
  std::vector<int> block_slot_;
  detail::AlignedVector<int> slot_j_;
  Array slot_ft_;
  Array slot_r_;   // radius of the slot's neighbour (contiguous: one gather less)
  Array slot_ir_;  // its inverse
  // Per slot, written by the pair pass: the pair's force on i (pfx_, pfy_)
  // and its torques on i and j (pti_, ptj_). Block b's slot s has its terms
  // at term_block_[b] + s − block_slot_[b]: blocks share places in a ring
  // once no sum needs their terms any more (layout_terms; term_ring.hpp);
  // index term_block_.back() is a zero slot.
  Array pfx_, pfy_, pti_, ptj_;
  std::vector<int> term_block_;
  // Mirror list (sliced ELLPACK like the list): block b's rows are
  // [mirror_block_[b], mirror_block_[b + 1]); particle j's entries are the
  // slots of its pairs (i, j), i < j, in increasing i, then the zero slot
  // block_slot_.back(); mirror_term_ the same entries as places of the pair
  // terms.
  std::vector<int> mirror_block_, mirror_count_;
  detail::AlignedVector<int> mirror_slot_, mirror_term_;
  // Per block: the lowest block holding one of its mirrored slots, and
  // whether the threaded pair pass has summed it (contact.cpp).
  std::vector<int> mirror_src_block_;
  std::vector<unsigned char> block_fused_;
  // The pairs i < j of the list, sorted by (i, j), and the slot of i's copy.
  std::vector<int> pair_i_, pair_j_, pair_slot_;
  // Block ranges of the threads for the pair pass (balanced by slots) and
  // for the particle pass.
  std::vector<int> pair_bounds_, particle_bounds_;
  // scratch for rebuilds (kept to avoid allocation)
  std::vector<int> nbr_start_, nbr_list_, cell_start_, cell_next_;
  std::vector<int> new_block_slot_;
  detail::AlignedVector<int> new_slot_j_;
  Array new_slot_ft_, new_slot_r_, new_slot_ir_;
  std::array<std::vector<int>, 4> wall_candidates_;
  Array x_built_, y_built_;
  std::array<double, 4> wall_built_{};
  double skin_ = 0.0;
  double r_max_ = 0.0, r_min_ = 0.0;
  bool list_valid_ = false;
  int64_t rebuilds_ = 0;

  std::array<Wall, 4> walls_;
  double max_overlap_ratio_seen_ = 0.0;
  double initial_energy_ = -1.0;  // KE + elastic energy when stepping began
  double energy_scale_ = 0.0;     // largest energy the system has held
  struct Ledger {
    bool started = false;
    int64_t step = 0;  // of the last sample
    double energy0 = 0.0, work = 0.0, lost = 0.0, power_in = 0.0, power_lost = 0.0;
    double dashpot = 0.0;  // dissipated by the contact dashpots, summed every step
    double created = 0.0;  // last reading, relative
  } ledger_;

  Divergence divergence_ = Divergence::kNone;
  int64_t divergence_step_ = -1;
  int64_t steps_ = 0;
  double time_ = 0.0;
  detail::TeamHandle team_;
};

}  // namespace demcal
