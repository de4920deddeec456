// The 3D kernel's private state (structure of arrays, the sliced-ELLPACK
// neighbour list, scratch, the energy ledger, the thread team) and its
// passes, as world_impl.hpp is for the 2D kernel. Only src/kernel sees this
// header: SphereWorld (include/demcal/kernel/sphere_world.hpp) owns one
// SphereWorldImpl and forwards each call.
#pragma once

#include "demcal/kernel/sphere_world.hpp"
#include "divergence.hpp"
#include "kernel_detail.hpp"

namespace demcal {

/// An assembly of spheres in a box of six walls.
class SphereWorldImpl {
 public:
  /// Walls at lo[a] and hi[a] along each axis a.
  SphereWorldImpl(const SphereMaterial& material, std::span<const double> x,
                  std::span<const double> y, std::span<const double> z,
                  std::span<const double> radius, const std::array<double, 3>& lo,
                  const std::array<double, 3>& hi, KernelOptions options = {});

  // --- setup -----------------------------------------------------------
  void set_integration(const Integration& integration);
  const Integration& integration() const { return integration_; }
  const SphereMaterial& material() const { return material_; }
  const KernelOptions& options() const { return options_; }
  /// Replace the kernel options; the energy ledger restarts.
  void set_options(const KernelOptions& options);
  /// Friction of particle–particle contacts (frictionless consolidation,
  /// then friction on).
  void set_particle_friction(double mu) {
    material_.particle.friction = mu;
    ledger_ = {};
  }

  // --- stepping --------------------------------------------------------
  /// Advance `n` steps; false as soon as the run diverged (see divergence()).
  bool step(int64_t n = 1);
  Divergence divergence() const { return divergence_; }
  /// The energy ledger's last reading (World::energy_created has the meaning).
  double energy_created() const { return ledger_.created; }
  int64_t divergence_step() const { return divergence_step_; }
  int64_t steps_taken() const { return steps_; }
  double time() const { return time_; }

  // --- measures --------------------------------------------------------
  SphereMeasures measure(double strain_rate = 0.0) const;
  ReferenceScales reference_scales() const;
  /// Stable-step estimates for the current contact network, 6 DOF per sphere.
  StabilityEstimate stability_estimate(int iterations = 300) const;
  /// (1/V)·Σ_p x^p ⊗ F_p (origin at the box centre): equals b − σ.
  Eigen::Matrix3d net_force_moment() const;

  // --- state access (flat arrays) ----------------------------------------
  int size() const { return n_; }
  std::span<const double> x() const { return view(x_); }
  std::span<const double> y() const { return view(y_); }
  std::span<const double> z() const { return view(z_); }
  std::span<const double> vx() const { return view(vx_); }
  std::span<const double> vy() const { return view(vy_); }
  std::span<const double> vz() const { return view(vz_); }
  std::span<const double> omega_x() const { return view(wx_); }
  std::span<const double> omega_y() const { return view(wy_); }
  std::span<const double> omega_z() const { return view(wz_); }
  std::span<const double> radius() const { return view(r_); }
  double min_radius() const { return r_min_; }
  double max_radius() const { return r_max_; }
  std::span<const double> mass() const { return view(m_); }           ///< scaled masses
  std::span<const double> inertia() const { return view(inertia_); }  ///< scaled moments
  std::span<const double> fx() const { return view(fx_); }            ///< net contact force
  std::span<const double> fy() const { return view(fy_); }
  std::span<const double> fz() const { return view(fz_); }
  std::span<const double> torque_x() const { return view(tx_); }
  std::span<const double> torque_y() const { return view(ty_); }
  std::span<const double> torque_z() const { return view(tz_); }

  /// Direct state edits for tests and scene set-up. With rotation locked the
  /// spin is ignored (kept 0).
  void set_velocity(int i, const Eigen::Vector3d& v, const Eigen::Vector3d& omega);
  void set_position(int i, const Eigen::Vector3d& p);

  SphereWall& wall(SphereWallSide side) { return walls_[side]; }
  const SphereWall& wall(SphereWallSide side) const { return walls_[side]; }
  /// Box edge along axis a (0 = x, 1 = y, 2 = z).
  double extent(int axis) const {
    return walls_[2 * axis + 1].position - walls_[2 * axis].position;
  }
  double volume() const { return extent(0) * extent(1) * extent(2); }
  Eigen::Vector3d centre() const;

  std::vector<SphereWorld::ContactView> contacts() const;
  int64_t rebuilds() const { return rebuilds_; }
  /// Share of the neighbour slots the pair pass evaluates that hold a real
  /// neighbour (the rest pad each block's rows to its longest list).
  double neighbour_slot_fill() const;
  /// The same share for the mirror list (each pair once more, padded to the
  /// longest row of its higher index's block).
  double mirror_slot_fill() const;
  /// Renumber the spheres (SphereWorld::reorder; sphere_world_reorder.cpp).
  void reorder(std::span<const int> order);
  /// An order for reorder() that fills the SIMD blocks (block_order.hpp).
  std::vector<int> block_friendly_order() const;

  /// Threads for stepping this world (KernelOptions::threads: 0 = all
  /// cores). Results are bit-identical for any thread count.
  void set_threads(int threads);
  int threads() const { return threads_; }

  /// Recompute forces for the current state without moving anything and
  /// without a tangential increment.
  void update_forces();

  // --- the whole state as bytes (sphere_world_state.cpp) -----------------
  /// Every member of the state, bit for bit (this build's layout and byte
  /// order; the threads are not state): the SphereWorld load_state() reads
  /// back steps exactly as this one, as a copy does. For the consolidation
  /// cache.
  std::string save_state() const;
  /// The SphereWorld of save_state()'s bytes. Bytes that do not read as one
  /// (another kernel's or layout's, cut, sizes that do not fit together)
  /// throw std::runtime_error.
  static SphereWorldImpl load_state(std::string_view bytes);

 private:
  SphereWorldImpl() = default;  // load_state()
  template <class Self, class Visitor>
  static void visit_state(Self& self, Visitor& visit);  // every member (sphere_world_state.cpp)
  // The arrays of one value per particle lane (padding and ghost included),
  // as pointers (sphere_world_state.cpp: saved, and sized when read back).
  template <class Self>
  static auto particle_arrays(Self& self);
  using Array = detail::AlignedVector<double>;
  std::span<const double> view(const Array& a) const { return {a.data(), static_cast<size_t>(n_)}; }

  // sphere_broad_phase.cpp
  void rebuild_neighbours();
  void rebuild_mirror_list();      // part of rebuild_neighbours
  void rebuild_wall_candidates();  // part of rebuild_neighbours
  // The places of the pair terms (term_block_, mirror_term_) for the list
  // and the threads' block ranges (pair_bounds_): detail::layout_terms.
  void layout_terms();
  bool needs_rebuild() const;
  // sphere_contact.cpp
  struct PairGeometry {
    Eigen::Vector3d n;  // unit, i to j
    double overlap, fn;
    bool touching;
  };
  PairGeometry pair_geometry(int i, int j) const;
  /// Tangential force on i of the k-th pair of the half list (i < j).
  Eigen::Vector3d pair_history(int k) const {
    const int s = pair_slot_[k];
    return {hx_[s], hy_[s], hz_[s]};
  }
  // sphere_stress.cpp: pair k of the half list (i < j = nbr_j_[k]) as
  // measure() and contacts() read it: its geometry, its history h (the
  // tangential force on i) and its normal force fn (0 apart).
  struct PairForce {
    int j;
    PairGeometry g;
    Eigen::Vector3d h;
    double fn;
    bool carries_force() const { return !(fn <= 0.0 && h.squaredNorm() == 0.0); }
  };
  PairForce pair_force(int i, int k) const;
  // The SIMD passes over particle blocks [b0, b1) (sphere_contact.cpp):
  // pair forces (returns the largest overlap/r), the mirrored sums, and integration (returns
  // the largest squared displacement since the last build).
  double pair_pass(int b0, int b1);
  // Adds what each particle receives from its mirrored slots (returns 0).
  double sum_pass(int b0, int b1);
  double integrate_pass(int b0, int b1);
  // Run a pass over all blocks, shared among the threads by `bounds`;
  // returns the largest value it returned (sphere_world.cpp).
  double run_pass(double (SphereWorldImpl::*pass)(int, int), const std::vector<int>& bounds);
  int active_threads() const;
  void update_thread_bounds();
  // The wall contacts (SIMD, one pass over every wall's candidates after
  // the particles' sums; the same sums for any thread count).
  void wall_pass();
  void compute_forces();
  /// Signed distance from wall s to the centre of i, along the inward normal.
  double wall_distance(int s, int i) const;
  // sphere_energy_balance.cpp
  struct EnergySample {
    double energy = 0.0, elastic = 0.0;
  };
  EnergySample energy_sample() const;
  bool ledger_record(const EnergySample& sample);
  // sphere_world.cpp
  void integrate();
  void book_wall_work();
  void update_damping_coefficients();
  bool check_divergence();
  template <class Impl>
  friend bool detail::divergence_checks(Impl& w, bool finite, double ke, double extra_scale);

  SphereMaterial material_;
  KernelOptions options_;
  Integration integration_;
  int threads_ = 1;

  // Particle state (structure of arrays, 64-byte aligned), padded to whole
  // blocks of 8: index n_ .. 8·nblocks_ − 1 are inert padding lanes, index
  // ghost_ = 8·nblocks_ the ghost particle empty slots point to (far away,
  // radius 0: never in contact).
  int n_ = 0, nblocks_ = 0, ghost_ = 0;
  Array x_, y_, z_, vx_, vy_, vz_, wx_, wy_, wz_, r_, inv_r_;
  Array m_, inertia_;
  Array fx_, fy_, fz_, tx_, ty_, tz_;
  Array ca_t_, cb_t_, ca_r_, cb_r_;  // v ← a·v + b·F per particle (0 for padding)
  Array d_t_, d_r_;                  // damping coefficients D_t, D_r
  // Per block and lane (8 per block), written by the passes and summed
  // block by block in block order, each block by detail::lane_sum (the same
  // sums for any thread count and on every path): global damping loss of
  // the step (Σ D·|v̄|²/4) and, over the lane's slots, Σ|h|² of contacts
  // that opened and Σ μFn·(|h_trial| − μFn) of sliding ones (every pair
  // counted once); and (damped pass only) the contact dashpots' power
  // Σ (fe − fn)·v_n over the lane's slots.
  Array block_lost_, block_released_, block_slid_, block_power_;
  // Energy taken by global damping since the energy ledger started [J] (a
  // running total from the start, not a difference of two totals: that
  // would cancel catastrophically once most of the energy is gone).
  double damping_dissipated_ = 0.0;
  // Energy taken by Coulomb friction since the ledger started [J]: the
  // tangential spring energy a contact gives up when its force is capped
  // (sliding) or when it opens (sphere_contact.cpp explains why that is
  // dissipated, not created).
  double friction_dissipated_ = 0.0;
  // The contact dashpots' power at the last force evaluation, pairs and
  // walls [W], and the energy they took since the ledger started [J],
  // booked every step over the step that applies those forces (as the 2D
  // ledger does: sampled every energy_check_interval steps, a collision
  // shorter than the interval aliased, and one starting just before a
  // sample read as energy created).
  double dashpot_power_ = 0.0;
  double dashpot_dissipated_ = 0.0;
  // Work of the moving walls on the spheres since the ledger started [J],
  // summed every step by the trapezoidal rule over each wall's move: the
  // wall's push along its axis before and after the move (wall_push_) times
  // the move (wall_move_). (Sampled every energy_check_interval steps it
  // missed a collision shorter than the interval.)
  double wall_work_ = 0.0;
  // Σ|work| of the walls since construction (never reset): energy the
  // walls may have put into motion directly, a scale of the kEnergy check.
  double wall_work_abs_ = 0.0;
  std::array<double, 6> wall_push_{}, wall_move_{};

  // Verlet neighbour list, half (each pair once, from its lower index i < j)
  // in sliced ELLPACK blocks of 8 as the 2D kernel's (world.hpp): block b's
  // slots are [block_slot_[b], block_slot_[b + 1]), rows of 8, slot (row,
  // lane) the row-th neighbour j > i (increasing index) of particle i = 8b +
  // lane, then ghosts. hx_, hy_, hz_: each slot's tangential force on i,
  // kept across rebuilds; slot_r_, slot_ir_ the neighbour's radius and its
  // inverse. The pair pass writes, per slot, what j receives: the pair's
  // force on i (pfx_.., j takes its opposite) and the torque on j (ptx_..).
  // Block b's slot s has them at term_block_[b] + s − block_slot_[b]:
  // blocks share places in a ring once no sum needs their terms any more
  // (layout_terms; term_ring.hpp); one more place at the end (index
  // term_block_.back()) stays 0, the padding of the mirror list.
  std::vector<int> block_slot_;
  detail::AlignedVector<int> slot_j_;
  Array hx_, hy_, hz_, slot_r_, slot_ir_;
  Array pfx_, pfy_, pfz_, ptx_, pty_, ptz_;
  std::vector<int> term_block_;
  // Mirror list, sliced ELLPACK blocks of 8 like the half list: block b's
  // entries are [mirror_block_[b], mirror_block_[b + 1]), entry (row, lane)
  // the slot of the row-th pair (i, j) with i < j = 8b + lane, in increasing
  // i, padded with the zero slot block_slot_.back(); mirror_term_ the same
  // entries as places of the pair terms. The sum pass adds them, in this
  // fixed order, to the sums the pair pass wrote over j's own slots.
  std::vector<int> mirror_block_, mirror_count_;
  // Per block: the lowest block holding one of its mirrored slots (itself
  // if none), and whether the pair pass did its sums (sphere_contact.cpp).
  std::vector<int> mirror_src_block_;
  std::vector<unsigned char> block_fused_;
  detail::AlignedVector<int> mirror_slot_, mirror_term_;
  // The half list (pairs i < j) in CSR form, each row sorted by j, and the
  // slot of each pair (for measures, views and the ledger).
  std::vector<int> nbr_start_, nbr_j_, pair_slot_;
  // Block ranges of the threads: pair pass (balanced by slots), particle
  // passes (sum and integration).
  std::vector<int> pair_bounds_, particle_bounds_;
  // Wall contacts: per wall, the candidates (particles within skin of it,
  // in increasing index), and per candidate k (not per particle) the
  // tangential force history and the last normal force, contiguous for the
  // SIMD wall pass (sphere_contact.cpp, wall_pass) and carried over
  // rebuilds by a merge. A history's component along its wall's normal
  // stays 0. wall_gather_: the candidates padded with the ghost to whole
  // blocks of 8 (the arrays of k are padded alike, with zeros).
  std::array<std::vector<int>, 6> wall_candidates_;
  std::array<detail::AlignedVector<int>, 6> wall_gather_;
  std::array<Array, 6> wall_hx_, wall_hy_, wall_hz_, wall_fn_;
  Array new_wall_hx_, new_wall_hy_, new_wall_hz_;  // rebuild scratch
  // Scratch for rebuilds (kept to avoid allocation).
  std::vector<int> cell_start_, cell_next_, new_block_slot_;
  detail::AlignedVector<int> new_slot_j_;
  Array new_hx_, new_hy_, new_hz_, new_slot_r_, new_slot_ir_;
  Array x_built_, y_built_, z_built_;
  std::array<double, 6> wall_built_{};
  double skin_ = 0.0, r_min_ = 0.0, r_max_ = 0.0;
  bool list_valid_ = false;
  int64_t rebuilds_ = 0;

  std::array<SphereWall, 6> walls_;
  double max_overlap_ratio_seen_ = 0.0;
  double initial_energy_ = -1.0;
  double energy_scale_ = 0.0;
  struct Ledger {
    bool started = false;
    int64_t step = 0;
    double energy0 = 0.0;
    double created = 0.0;
  } ledger_;

  Divergence divergence_ = Divergence::kNone;
  int64_t divergence_step_ = -1;
  int64_t steps_ = 0;
  double time_ = 0.0;
  detail::TeamHandle team_;
};

}  // namespace demcal
