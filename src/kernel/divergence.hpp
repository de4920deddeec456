// The divergence checks both kernels run every KernelOptions::check_interval
// steps (solver.cpp, sphere_world.cpp) and the energy ledger's reading they
// end with (energy_balance.cpp, sphere_energy_balance.cpp explain what each
// kernel books), written once. Private to src/kernel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "demcal/kernel/world.hpp"  // Divergence, KernelOptions

namespace demcal::detail {

/// Starts ledger `l` (either kernel's Ledger) at its first sample, taken at
/// step `step` with energy `energy`: cleared, then started there. Returns
/// false when it had started already (then the sample is a reading).
template <class Ledger>
bool ledger_start(Ledger& l, int64_t step, double energy) {
  if (l.started) return false;
  l = {};
  l.started = true;
  l.step = step;
  l.energy0 = energy;
  return true;
}

/// The ledger's reading: the energy created since it started, E − E0 − W +
/// lost (`work` W the walls' on the particles, `lost` what the kernel books
/// as dissipated), as a fraction of E0 + |W| + lost; 0 when that is 0.
inline double ledger_reading(double energy, double energy0, double work, double lost) {
  const double created = energy - energy0 - work + lost;
  const double scale = energy0 + std::abs(work) + lost;
  return scale > 0.0 ? created / scale : 0.0;
}

/// Takes ledger `l`'s reading (into l.created) at a sample taken at step
/// `step` (the ledger's last sample from now on) with energy `energy`; a
/// reading beyond KernelOptions::max_energy_created, or not finite, means
/// the integrator made energy: sets `divergence` and returns true.
template <class Ledger>
bool ledger_read(Ledger& l, int64_t step, double energy, double work, double lost,
                 const KernelOptions& options, Divergence& divergence) {
  l.step = step;
  l.created = ledger_reading(energy, l.energy0, work, lost);
  if (std::isfinite(l.created) && l.created <= options.max_energy_created) return false;
  divergence = Divergence::kEnergyCreated;
  return true;
}

/// The checks of a kernel `w` (WorldImpl, SphereWorldImpl) after it summed
/// its kinetic energy `ke` and found its state `finite` or not, in order:
/// not finite; an overlap beyond max_overlap_ratio; kinetic energy beyond
/// max_energy_ratio times the largest energy the system has held (its
/// springs, at the start, or `extra_scale`: the 3D kernel's wall work, a wall
/// can throw a sphere within one sampling interval; 0 in 2D); then the
/// energy ledger, when a sample is due (its pair loop also refreshes the
/// energy scale: every energy_check_interval steps; the scale is a running
/// maximum, so a slightly older value only makes the check a little
/// stricter). Sets w.divergence_ and returns true when one fires.
template <class Impl>
bool divergence_checks(Impl& w, bool finite, double ke, double extra_scale) {
  if (!finite || !std::isfinite(ke)) {
    w.divergence_ = Divergence::kNotFinite;
    return true;
  }
  if (w.max_overlap_ratio_seen_ > w.options_.max_overlap_ratio) {
    w.divergence_ = Divergence::kOverlap;
    return true;
  }
  std::optional<typename Impl::EnergySample> sample;
  // A sample is due when none was taken since the ledger (re)started, or
  // energy_check_interval steps (at least 1) after the last.
  if (!w.ledger_.started ||
      w.steps_ - w.ledger_.step >= std::max(1, w.options_.energy_check_interval)) {
    sample = w.energy_sample();
    w.energy_scale_ = std::max({w.energy_scale_, sample->elastic, w.initial_energy_});
  }
  // Kinetic energy far beyond anything the springs have ever stored (or the
  // walls have done as work) cannot come from the loading: an unstable mode
  // is growing.
  const double scale = std::max({w.energy_scale_, w.initial_energy_, extra_scale});
  if (scale > 0.0 && ke > w.options_.max_energy_ratio * scale) {
    w.divergence_ = Divergence::kEnergy;
    return true;
  }
  return sample && w.ledger_record(*sample);
}

}  // namespace demcal::detail
