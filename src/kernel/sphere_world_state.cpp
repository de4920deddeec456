// The whole state of a SphereWorld as bytes, and back
// (SphereWorldImpl::save_state, SphereWorldImpl::load_state): what the
// consolidation cache stores for a triaxial sample, as world_state.cpp is
// for the 2D kernel and for the same reasons. Every member is written, the
// neighbour list (slots, histories, mirror list, CSR form), the wall
// candidates and their histories, the walls, the energy ledger and its
// running totals and the rebuild scratch included, so that a SphereWorld
// read back is a copy of the one saved: it rebuilds its list, sums its
// forces and steps exactly as the original would. The bytes:
// state_bytes.hpp. The threads are not state: a SphereWorld read back
// starts its own on first use, as a copy does. Nor are the pair terms
// (pfx_ .. ptz_: written by each pair pass before its sums read them) and
// their places (term_block_, mirror_term_, term_ring.hpp): those follow
// from the list and the threads' block ranges, so the SphereWorld read
// back lays them out again.
#include <algorithm>
#include <array>
#include <string>

#include "sphere_world_impl.hpp"
#include "state_bytes.hpp"

namespace demcal {

namespace {

// The last character numbers the layout ('2' since the pair terms are no
// longer saved); another kernel's (the 2D World's "demWorl…") or another
// layout's bytes do not read: rebuilt, not misread.
constexpr std::string_view kMark("demSphr2", 8);
constexpr const char* kWhat = "SphereWorld::load_state";

// A new member of these structs, or of SphereWorldImpl, must be visited
// below: the sizes catch one that is not (x86-64 layouts, libstdc++).
static_assert(sizeof(SphereMaterial) == 8 * sizeof(double));
static_assert(sizeof(SphereWall) == 48);  // 5 doubles and an int
static_assert(sizeof(SphereWorldImpl) == 3304,
              "a member was added to SphereWorldImpl: visit it in visit_state "
              "(sphere_world_state.cpp), renumber kMark, then update this size");

bool ascending_from_zero(const std::vector<int>& a) {
  return !a.empty() && a.front() == 0 && std::is_sorted(a.begin(), a.end());
}

template <class V>
bool within(const V& a, int lo, int hi) {
  return std::all_of(a.begin(), a.end(), [&](int v) { return v >= lo && v <= hi; });
}

}  // namespace

template <class Self>
auto SphereWorldImpl::particle_arrays(Self& w) {
  return std::array{&w.x_,          &w.y_,           &w.z_,
                    &w.vx_,         &w.vy_,          &w.vz_,
                    &w.wx_,         &w.wy_,          &w.wz_,
                    &w.r_,          &w.inv_r_,       &w.m_,
                    &w.inertia_,    &w.fx_,          &w.fy_,
                    &w.fz_,         &w.tx_,          &w.ty_,
                    &w.tz_,         &w.ca_t_,        &w.cb_t_,
                    &w.ca_r_,       &w.cb_r_,        &w.d_t_,
                    &w.d_r_,        &w.block_lost_,  &w.block_released_,
                    &w.block_slid_, &w.block_power_, &w.x_built_,
                    &w.y_built_,    &w.z_built_};
}

template <class Self, class Visitor>
void SphereWorldImpl::visit_state(Self& w, Visitor& v) {
  v(w.material_.density);
  detail::visit_law(w.material_.particle, v);
  detail::visit_law(w.material_.wall, v);
  v(w.material_.contact_damping_ratio);
  detail::visit_options(w.options_, v);
  detail::visit_integration(w.integration_, v);
  v(w.threads_);
  v(w.n_);
  v(w.nblocks_);
  v(w.ghost_);
  for (auto* a : particle_arrays(w)) v(*a);
  v(w.damping_dissipated_);
  v(w.friction_dissipated_);
  v(w.dashpot_power_);
  v(w.dashpot_dissipated_);
  v(w.wall_work_);
  v(w.wall_work_abs_);
  for (auto& d : w.wall_push_) v(d);
  for (auto& d : w.wall_move_) v(d);
  v(w.block_slot_);
  v(w.slot_j_);
  for (auto* a : {&w.hx_, &w.hy_, &w.hz_, &w.slot_r_, &w.slot_ir_}) v(*a);
  for (auto* a : {&w.mirror_block_, &w.mirror_count_, &w.mirror_src_block_}) v(*a);
  v(w.block_fused_);
  v(w.mirror_slot_);
  for (auto* a : {&w.nbr_start_, &w.nbr_j_, &w.pair_slot_, &w.pair_bounds_, &w.particle_bounds_})
    v(*a);
  for (int s = 0; s < 6; ++s) {
    v(w.wall_candidates_[s]);
    v(w.wall_gather_[s]);
    for (auto* a : {&w.wall_hx_[s], &w.wall_hy_[s], &w.wall_hz_[s], &w.wall_fn_[s]}) v(*a);
  }
  for (auto* a : {&w.new_wall_hx_, &w.new_wall_hy_, &w.new_wall_hz_}) v(*a);
  for (auto* a : {&w.cell_start_, &w.cell_next_, &w.new_block_slot_}) v(*a);
  v(w.new_slot_j_);
  for (auto* a : {&w.new_hx_, &w.new_hy_, &w.new_hz_, &w.new_slot_r_, &w.new_slot_ir_}) v(*a);
  for (auto& d : w.wall_built_) v(d);
  v(w.skin_);
  v(w.r_min_);
  v(w.r_max_);
  v(w.list_valid_);
  v(w.rebuilds_);
  for (auto& wall : w.walls_) {
    v(wall.position);
    v(wall.velocity);
    for (int a = 0; a < 3; ++a) v(wall.force[a]);
    v(wall.contacts);
  }
  v(w.max_overlap_ratio_seen_);
  v(w.initial_energy_);
  v(w.energy_scale_);
  auto& l = w.ledger_;
  v(l.started);
  v(l.step);
  v(l.energy0);
  v(l.created);
  v(w.divergence_);
  v(w.divergence_step_);
  v(w.steps_);
  v(w.time_);
}

std::string SphereWorldImpl::save_state() const {
  return detail::write_state(kMark, [&](detail::StateWriter& v) { visit_state(*this, v); });
}

SphereWorldImpl SphereWorldImpl::load_state(std::string_view bytes) {
  SphereWorldImpl w;
  const detail::StateReader reader =
      detail::read_state(bytes, kMark, kWhat, [&](detail::StateReader& v) { visit_state(w, v); });
  // The arrays the passes index by particle, block, slot and wall candidate
  // must fit the sizes read (a checksum guards the cache's bytes; this
  // guards the reader).
  reader.require(w.n_ >= 0 && w.nblocks_ == (w.n_ + 7) / 8 && w.ghost_ == 8 * w.nblocks_ &&
                 w.threads_ >= 1);
  const size_t n = static_cast<size_t>(w.n_), nb = static_cast<size_t>(w.nblocks_);
  const size_t cap = static_cast<size_t>(w.ghost_) + 8;
  for (const Array* a : particle_arrays(w)) reader.require(a->size() == cap);
  // The half list: block_slot_ ascending, its slots' arrays of that size.
  reader.require(w.block_slot_.size() == nb + 1 && ascending_from_zero(w.block_slot_));
  const size_t ns = static_cast<size_t>(w.block_slot_.back());
  reader.require(w.slot_j_.size() == ns && within(w.slot_j_, 0, w.ghost_));
  for (const Array* a : {&w.hx_, &w.hy_, &w.hz_, &w.slot_r_, &w.slot_ir_})
    reader.require(a->size() == ns);
  // The mirror list: entries of the pair terms.
  reader.require(w.mirror_block_.size() == nb + 1 && ascending_from_zero(w.mirror_block_) &&
                 static_cast<size_t>(w.mirror_block_.back()) <= w.mirror_slot_.size() &&
                 within(w.mirror_slot_, 0, static_cast<int>(ns)) &&
                 w.mirror_src_block_.size() == nb &&
                 within(w.mirror_src_block_, 0, w.nblocks_ - 1) && w.block_fused_.size() == nb);
  // The CSR form: pairs i < j and their slots.
  reader.require(w.nbr_start_.size() == n + 1 && ascending_from_zero(w.nbr_start_) &&
                 static_cast<size_t>(w.nbr_start_.back()) == w.nbr_j_.size() &&
                 w.pair_slot_.size() == w.nbr_j_.size() && within(w.nbr_j_, 0, w.n_ - 1) &&
                 within(w.pair_slot_, 0, static_cast<int>(ns) - 1));
  // The threads' block ranges.
  const size_t t = static_cast<size_t>(w.active_threads());
  for (const std::vector<int>* b : {&w.pair_bounds_, &w.particle_bounds_})
    reader.require(b->size() == t + 1 && ascending_from_zero(*b) && b->back() == w.nblocks_);
  // The walls' candidates, padded to blocks, and their histories.
  for (int s = 0; s < 6; ++s) {
    const size_t padded = w.wall_gather_[s].size();
    reader.require(padded % 8 == 0 && w.wall_candidates_[s].size() <= padded &&
                   within(w.wall_candidates_[s], 0, w.n_ - 1) &&
                   within(w.wall_gather_[s], 0, w.ghost_));
    for (const Array* a : {&w.wall_hx_[s], &w.wall_hy_[s], &w.wall_hz_[s], &w.wall_fn_[s]})
      reader.require(a->size() == padded);
  }
  // The places of the pair terms, from the members checked above, and the
  // pair terms' arrays sized to them.
  w.layout_terms();
  return w;
}

}  // namespace demcal
