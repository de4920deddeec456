// What a loading run records, the same in 2D (biaxial.hpp) and 3D
// (triaxial.hpp): each monitoring point's measures and the run's account.
// The two tests add their own axis (strain_yy or strain_zz), walls and peak.
#pragma once

#include <cstdint>
#include <vector>

#include "demcal/kernel/world.hpp"

namespace demcal {

/// The measures of one monitoring point; Matrix is Eigen::Matrix2d or
/// Matrix3d. Stresses tension positive.
template <class Matrix>
struct MonitorMeasures {
  int64_t step = 0;
  Matrix b = Matrix::Zero();      ///< boundary stress
  Matrix sigma = Matrix::Zero();  ///< homogenized stress
  double kinetic_energy = 0.0;    ///< translation + rotation
  double kinetic_energy_rotation = 0.0;
  double elastic_energy = 0.0;
  double unbalanced_force_ratio = 0.0;
  double inertial_number = 0.0;
  double coordination_number = 0.0;
  /// Lateral walls: (mean wall pressure − σ3)/σ3, signed.
  double lateral_stress_error = 0.0;
};

/// The account of a loading run of monitoring points `Point`.
template <class Point>
struct LoadingRun {
  std::vector<Point> series;
  int particles = 0;
  Integration integration;  ///< what was run (absolute Δt)
  ReferenceScales scales;
  int64_t steps_planned = 0;
  int64_t steps_run = 0;
  bool diverged = false;
  Divergence divergence = Divergence::kNone;
  int64_t divergence_step = -1;
  bool stopped_early = false;  ///< the monitor callback asked to stop
  double wall_time_s = 0.0;
  double strain_rate = 0.0;  ///< ε / (Nstep·Δt) [1/s]
};

}  // namespace demcal
