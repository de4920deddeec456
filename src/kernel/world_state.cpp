// The whole state of a World as bytes, and back (WorldImpl::save_state,
// WorldImpl::load_state): what the consolidation cache stores.
//
// Every member is written, the neighbour list and its scratch included, so
// that a World read back is a copy of the one saved: it rebuilds its list,
// sums its forces and steps exactly as the original would (a state rebuilt
// from positions alone would differ in the tangential histories and in when
// the list is next rebuilt). Not the pair terms, which live within a
// step, nor their places, which follow from the list (layout_terms). The
// bytes: state_bytes.hpp (shared with the sphere kernel,
// sphere_world_state.cpp). The threads are not state: a World read back
// starts its own on first use, as a copy does.
#include <algorithm>

#include "state_bytes.hpp"
#include "world_impl.hpp"

namespace demcal {

namespace {

// The last character numbers the layout: '2' since the half neighbour list,
// '3' since the pair terms' places (term_block_, mirror_term_), '4' since
// block_power_ holds 8 lanes per block, '5' since the pair terms and their
// places are no longer saved; a state of an older layout does not read:
// rebuilt, not misread.
constexpr std::string_view kMark("demWorl5", 8);
constexpr const char* kWhat = "World::load_state";

// A new member of these structs must be visited below: the sizes catch one
// that is not (x86-64 layouts; the shared ones: state_bytes.hpp).
static_assert(sizeof(Material) == 9 * sizeof(double));
static_assert(sizeof(Wall) == 48);  // 4 doubles and an int, 16-byte aligned

}  // namespace

template <class Self, class Visitor>
void WorldImpl::visit_state(Self& w, Visitor& v) {
  detail::visit_law(w.material_.particle, v);
  detail::visit_law(w.material_.wall, v);
  v(w.material_.density);
  v(w.material_.thickness);
  v(w.material_.contact_damping_ratio);
  detail::visit_options(w.options_, v);
  detail::visit_integration(w.integration_, v);
  v(w.threads_);
  v(w.n_);
  v(w.nblocks_);
  v(w.ghost_);
  for (auto* a :
       {&w.x_,       &w.y_,           &w.vx_,          &w.vy_,         &w.theta_,   &w.omega_,
        &w.r_,       &w.inv_r_,       &w.m_,           &w.inertia_,    &w.fx_,      &w.fy_,
        &w.tq_,      &w.block_power_, &w.ca_t_,        &w.cb_t_,       &w.ca_r_,    &w.cb_r_,
        &w.slot_ft_, &w.slot_r_,      &w.new_slot_ft_, &w.new_slot_r_, &w.x_built_, &w.y_built_,
        &w.slot_ir_, &w.new_slot_ir_})
    v(*a);
  v(w.wall_dashpot_power_);
  for (int s = 0; s < 4; ++s) {
    v(w.wall_ft_[s]);
    v(w.wall_fn_[s]);
    v(w.wall_candidates_[s]);
    v(w.wall_built_[s]);
    auto& wall = w.walls_[s];
    v(wall.position);
    v(wall.velocity);
    v(wall.force.x());
    v(wall.force.y());
    v(wall.contacts);
  }
  for (auto* a : {&w.block_slot_, &w.pair_i_, &w.pair_j_, &w.pair_slot_, &w.pair_bounds_,
                  &w.particle_bounds_, &w.nbr_start_, &w.nbr_list_, &w.cell_start_, &w.cell_next_,
                  &w.new_block_slot_, &w.mirror_block_, &w.mirror_count_, &w.mirror_src_block_})
    v(*a);
  v(w.slot_j_);
  v(w.new_slot_j_);
  v(w.mirror_slot_);
  v(w.block_fused_);
  v(w.skin_);
  v(w.r_max_);
  v(w.r_min_);
  v(w.list_valid_);
  v(w.rebuilds_);
  v(w.max_overlap_ratio_seen_);
  v(w.initial_energy_);
  v(w.energy_scale_);
  auto& l = w.ledger_;
  v(l.started);
  v(l.step);
  v(l.energy0);
  v(l.work);
  v(l.lost);
  v(l.power_in);
  v(l.power_lost);
  v(l.dashpot);
  v(l.created);
  v(w.divergence_);
  v(w.divergence_step_);
  v(w.steps_);
  v(w.time_);
}

std::string WorldImpl::save_state() const {
  return detail::write_state(kMark, [&](detail::StateWriter& v) { visit_state(*this, v); });
}

WorldImpl WorldImpl::load_state(std::string_view bytes) {
  WorldImpl w;
  const detail::StateReader reader =
      detail::read_state(bytes, kMark, kWhat, [&](detail::StateReader& v) { visit_state(w, v); });
  // The arrays the passes index by particle, block and slot must fit the
  // sizes read (a checksum guards the cache's bytes; this guards the reader).
  const size_t cap = static_cast<size_t>(w.ghost_) + 8;
  const bool fits =
      w.n_ >= 0 && w.nblocks_ == (w.n_ + 7) / 8 && w.ghost_ == 8 * w.nblocks_ &&
      w.x_.size() == cap && w.y_.size() == cap && w.vx_.size() == cap && w.vy_.size() == cap &&
      w.theta_.size() == cap && w.omega_.size() == cap && w.r_.size() == cap &&
      w.inv_r_.size() == cap && w.m_.size() == cap && w.inertia_.size() == cap &&
      w.fx_.size() == cap && w.fy_.size() == cap && w.tq_.size() == cap && w.ca_t_.size() == cap &&
      w.cb_t_.size() == cap && w.ca_r_.size() == cap && w.cb_r_.size() == cap &&
      w.block_slot_.size() == static_cast<size_t>(w.nblocks_) + 1 &&
      w.slot_j_.size() == w.slot_ft_.size() && w.slot_r_.size() == w.slot_ft_.size() &&
      static_cast<size_t>(w.block_slot_.back()) <= w.slot_j_.size() &&
      w.slot_ir_.size() == w.slot_ft_.size() &&
      (w.mirror_block_.empty() ||
       (w.mirror_block_.size() == static_cast<size_t>(w.nblocks_) + 1 &&
        static_cast<size_t>(w.mirror_block_.back()) <= w.mirror_slot_.size() &&
        w.mirror_src_block_.size() == static_cast<size_t>(w.nblocks_) &&
        w.block_fused_.size() == static_cast<size_t>(w.nblocks_) && w.pair_bounds_.size() >= 2 &&
        w.pair_bounds_.front() == 0 && w.pair_bounds_.back() == w.nblocks_ &&
        std::is_sorted(w.pair_bounds_.begin(), w.pair_bounds_.end())));
  for (int s = 0; s < 4; ++s)
    if (w.wall_ft_[s].size() != static_cast<size_t>(w.n_) ||
        w.wall_fn_[s].size() != static_cast<size_t>(w.n_))
      reader.fail();
  if (!fits) reader.fail();
  for (int j : w.slot_j_)
    if (j < 0 || j > w.ghost_) reader.fail();
  for (int s : w.mirror_slot_)
    if (s < 0 || s > w.block_slot_.back()) reader.fail();
  for (int b : w.mirror_src_block_)
    if (b < 0 || b >= w.nblocks_) reader.fail();
  // The places of the pair terms, from the members checked above, and the
  // pair terms' arrays sized to them (as the sphere state does): laid out
  // once the list exists, as rebuild_neighbours does.
  if (!w.mirror_block_.empty()) w.layout_terms();
  return w;
}

}  // namespace demcal
