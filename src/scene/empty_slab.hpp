// The widest empty slab across an assembly: the tell of a stray particle,
// which no consolidation can press against the rest. Private to src/scene
// (protocol_steps.hpp).
#pragma once

#include <span>
#include <string>

namespace demcal::detail {

/// The widest gap along one axis between the particles' extents [c − r,
/// c + r]: a slab across the whole box that no particle reaches.
struct EmptySlab {
  int axis = -1;                ///< 0, 1, 2 for x, y, z; −1: no gap at all
  double from = 0.0, to = 0.0;  ///< its faces, from < to
  double covered = 0.0;         ///< the length of the axis the particles cover
  int beyond = 0;               ///< the particles on its side with fewer of them
  int nearest = -1;             ///< of those, the one whose extent comes nearest it

  double width() const { return to - from; }
};

/// The widest empty slab of the particles at `centres` (one span per axis,
/// each as long as `r`), over every axis.
EmptySlab widest_empty_slab(std::span<const std::span<const double>> centres,
                            std::span<const double> r);

/// What a consolidation's failure adds when the particles at `centres`
/// leave an empty slab wider than both the length they cover along its
/// axis and two of their largest diameters: the particles beyond it, which
/// a wall reaches alone and pushes across the gap against the global
/// damping's drag alone (its servo reads that drag as stress, so the wall
/// stalls short of σ3) or squeezes the rest into a layer over a face the
/// stray holds open. "" otherwise.
std::string stray_particle_note(std::span<const std::span<const double>> centres,
                                std::span<const double> r);

}  // namespace demcal::detail
