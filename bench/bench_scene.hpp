// Scenes shared by the micro-benchmarks (bench_kernel.cpp) and the
// side-by-side driver against LAMMPS (bench_side_by_side.cpp).
//
// Hexagonal scene: nx columns × ny horizontal rows of uniform disks
// (r = 5e-4 m), odd rows shifted by half a spacing. The lattice is
// pre-compressed: centre spacing 2r(1 − ε), ε = 1e-3, i.e. an overlap of
// 1e-6 m (fn = 100 N, about 100 kPa) at every lattice contact from step 0,
// and each of the four frictionless walls overlaps the outermost disks by the
// same amount. Bottom, left and right walls are fixed; the top wall moves
// down at the speed that gives 1 % vertical strain over 1e5 steps.
// Material (reference_material in tests/support/scenes.hpp): ρ = 2650 kg/m³,
// t = 1 m, kn = 1e8 N/m, kt = 5e7 N/m, μ = 0.3; walls kn = 1e8, kt = 5e7,
// μ = 0. Integration: α = Δt/Δt_crit = 0.2 with Δt_crit from
// World::reference_scales(), ζ_t = ζ_r = 1.
//
// Random scene: n polydisperse disks, radii uniform in [0.8, 1.2]·5e-4 m,
// placed on a loose square grid (spacing 2.1·r_max) with random jitter
// (packing fraction ≈ 0.5), then compacted frictionless by moving all four
// walls inward until the mean wall stress reaches 100 kPa, then relaxed
// (compress–relax rounds until the stress stays above 80 kPa at rest).
// The benchmark then switches friction on (μ = 0.3), fixes the side and bottom
// walls and moves the top wall as in the hexagonal scene.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "demcal/kernel/world.hpp"
#include "demcal/scene/packing.hpp"
#include "support/scenes.hpp"

namespace demcal_bench {

struct Scene {
  std::string name;
  std::vector<double> x, y, r;
  double left = 0, right = 0, bottom = 0, top = 0;
  demcal::Material material;
};

inline constexpr double kRadius = 5e-4;
inline constexpr double kPreStrain = 1e-3;   // ε: overlap = 2r·ε
inline constexpr double kAlpha = 0.2;        // Δt / Δt_crit
inline constexpr double kStrain = 0.01;      // top-wall strain ...
inline constexpr double kStrainSteps = 1e5;  // ... over this many steps

/// The default scene's material (tests/support/scenes.hpp), as the tests use.
inline demcal::Material bench_material() { return demcal::test::reference_material(); }

/// nx columns × ny rows hexagonal packing, pre-compressed, walls touching.
inline Scene hex_scene(int nx, int ny) {
  Scene s;
  s.name = "hex_" + std::to_string(nx) + "x" + std::to_string(ny);
  s.material = bench_material();
  // Every contact and each wall overlaps by 2r·ε.
  const demcal::Assembly a = demcal::hexagonal_packing(nx, ny, kRadius, kPreStrain);
  s.x = a.x;
  s.y = a.y;
  s.r = a.r;
  s.left = a.left;
  s.right = a.right;
  s.bottom = a.bottom;
  s.top = a.top;
  return s;
}

/// Square-ish hexagonal packing with about n disks (nx = ny = round(√n)).
inline Scene hex_scene_n(int n) {
  const int side = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(n)))));
  return hex_scene(side, side);
}

/// Integration parameters of the benchmark: α = 0.2, ζ_t = ζ_r = 1.
inline void set_bench_integration(demcal::World& w) {
  demcal::Integration in;
  in.damping_ratio_translation = 1.0;
  in.damping_ratio_rotation = 1.0;
  in.dt = 0.0;
  w.set_integration(in);  // masses are set here; dt_crit needs them
  in.dt = kAlpha * w.reference_scales().dt_crit;
  w.set_integration(in);
}

/// Top-wall speed giving kStrain over kStrainSteps steps (negative: down).
inline double top_velocity(double height, double dt) {
  return -kStrain * height / (kStrainSteps * dt);
}

/// A world for the biaxial-like compression: fixed bottom/left/right walls,
/// top wall moving down.
inline std::unique_ptr<demcal::World> make_compression_world(const Scene& s) {
  auto w =
      std::make_unique<demcal::World>(s.material, s.x, s.y, s.r, s.left, s.right, s.bottom, s.top);
  set_bench_integration(*w);
  w->wall(demcal::kTop).velocity = top_velocity(w->height(), w->integration().dt);
  w->update_forces();
  // As demcal's consolidation does: particles numbered for full SIMD blocks.
  w->reorder(w->block_friendly_order());
  return w;
}

/// Random polydisperse packing, compacted frictionless to ~100 kPa (see the
/// header comment). Deterministic for a given seed. Costs a few 10^4 steps.
inline Scene random_scene(int n, uint64_t seed = 12345, double target_pressure = 1e5) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> urad(0.8 * kRadius, 1.2 * kRadius);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double rmax = 1.2 * kRadius;
  const double sp = 2.1 * rmax;
  const int side = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n)))));
  Scene s;
  s.name = "random_" + std::to_string(n);
  s.material = bench_material();
  for (int k = 0; k < n; ++k) {
    const int i = k % side, j = k / side;
    const double rad = urad(rng);
    const double slack = 0.5 * sp - rad;  // jitter that keeps disks apart
    s.x.push_back((i + 0.5) * sp + (2.0 * u01(rng) - 1.0) * slack);
    s.y.push_back((j + 0.5) * sp + (2.0 * u01(rng) - 1.0) * slack);
    s.r.push_back(rad);
  }
  const int rows = (n + side - 1) / side;
  s.left = 0.0;
  s.right = side * sp;
  s.bottom = 0.0;
  s.top = rows * sp;

  // Frictionless compaction by all four walls.
  demcal::Material m = s.material;
  m.particle.friction = 0.0;
  demcal::World w(m, s.x, s.y, s.r, s.left, s.right, s.bottom, s.top);
  set_bench_integration(w);
  const double dt = w.integration().dt;
  const double t = m.thickness;
  // Wall speed: 1e-4·r_min per step; stops when the mean wall stress is reached.
  const double v = 1e-4 * 0.8 * kRadius / dt;
  auto set_speed = [&](double sp_) {
    w.wall(demcal::kLeft).velocity = sp_;
    w.wall(demcal::kRight).velocity = -sp_;
    w.wall(demcal::kBottom).velocity = sp_;
    w.wall(demcal::kTop).velocity = -sp_;
  };
  set_speed(v);
  auto wall_stress = [&] {
    const double sx =
        0.5 *
        (std::abs(w.wall(demcal::kLeft).force.x()) + std::abs(w.wall(demcal::kRight).force.x())) /
        (w.height() * t);
    const double sy =
        0.5 *
        (std::abs(w.wall(demcal::kBottom).force.y()) + std::abs(w.wall(demcal::kTop).force.y())) /
        (w.width() * t);
    return 0.5 * (sx + sy);
  };
  int64_t guard = 0;
  // Compress until the target is reached, stop, relax; the stress drops as
  // the frictionless packing rearranges, so repeat until it holds after the
  // relaxation (within 20 %).
  for (int round = 0; round < 50; ++round) {
    while (wall_stress() < target_pressure) {
      if (!w.step(100) || (guard += 100) > 2'000'000)
        throw std::runtime_error("random_scene: compaction failed");
      // Slow down near the target so the walls do not overshoot much.
      if (wall_stress() > 0.5 * target_pressure) set_speed(0.25 * v);
    }
    set_speed(0.0);
    if (!w.step(5000)) throw std::runtime_error("random_scene: relaxation diverged");
    if (wall_stress() > 0.8 * target_pressure) break;
    set_speed(0.25 * v);
  }
  set_speed(0.0);
  s.x.assign(w.x().begin(), w.x().end());
  s.y.assign(w.y().begin(), w.y().end());
  s.left = w.wall(demcal::kLeft).position;
  s.right = w.wall(demcal::kRight).position;
  s.bottom = w.wall(demcal::kBottom).position;
  s.top = w.wall(demcal::kTop).position;
  return s;
}

}  // namespace demcal_bench
