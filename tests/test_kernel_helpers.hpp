// Shared scenes and helpers for the kernel physics tests (test_kernel_*.cpp).
//
// Units follow the product's default scene (reference_material,
// tests/support/scenes.hpp): r ≈ 5e-4 m, ρ = 2650 kg/m³, t = 1 m,
// kn = 1e8 N/m, kt = kn/2, so m ≈ 2.08e-3 kg, ω0 = sqrt(kn/m) ≈
// 2.2e5 rad/s and an overlap of 1e-6 m carries 100 N (≈ 100 kPa).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "demcal/kernel/world.hpp"
#include "demcal/scene/packing.hpp"
#include "support/scenes.hpp"

namespace demcal::kernel_test {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();
inline constexpr double kR = 5e-4;  // reference radius [m]

using test::reference_material;

struct Scene {
  std::vector<double> x, y, r;
  double left = 0, right = 0, bottom = 0, top = 0;
  World make(const Material& material, KernelOptions options = {}) const {
    return World(material, x, y, r, left, right, bottom, top, options);
  }
};

/// nx columns × ny horizontal rows of uniform disks, odd rows shifted by half
/// a spacing, pre-compressed: centre spacing 2r(1 − ε), so every lattice
/// contact overlaps by 2rε, and each wall overlaps the outermost disks by the
/// same amount (the shifted rows do not touch the side walls).
inline Scene hex_scene(int nx, int ny, double eps = 1e-3, double r = kR) {
  const Assembly a = hexagonal_packing(nx, ny, r, eps);
  return {a.x, a.y, a.r, a.left, a.right, a.bottom, a.top};
}

/// nx × ny polydisperse disks (radii uniform in [1 − spread, 1 + spread]·r)
/// on a loose square grid (spacing 2.2·r_max) with random jitter; no overlap.
inline Scene random_loose_scene(int nx, int ny, uint32_t seed, double spread = 0.3, double r = kR) {
  Scene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> rad((1.0 - spread) * r, (1.0 + spread) * r);
  const double rmax = (1.0 + spread) * r;
  const double sp = 2.2 * rmax;
  std::uniform_real_distribution<double> jitter(-0.09 * rmax, 0.09 * rmax);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      s.x.push_back((i + 0.5) * sp + jitter(rng));
      s.y.push_back((j + 0.5) * sp + jitter(rng));
      s.r.push_back(rad(rng));
    }
  s.left = 0.0;
  s.right = nx * sp;
  s.bottom = 0.0;
  s.top = ny * sp;
  return s;
}

/// One disk of radius kR pressed `delta` into the bottom wall of the box
/// [−20r, 20r] × [0, 10r], heavy (mass scaling 1e9), undamped, Δt = 1e-6 s,
/// its rotation locked unless `spin`: the velocities set before each step
/// are its motion (a 100 N force changes them by 5e-11 m/s a step).
inline World disk_on_bottom_wall(const Material& mat, double delta, bool spin = false) {
  const double r = kR;
  const std::vector<double> x{0.0}, y{r - delta}, rad{r};
  World w(mat, x, y, rad, -20 * r, 20 * r, 0.0, 10 * r);
  Integration in;
  in.dt = 1e-6;
  in.damping_ratio_translation = 0.0;
  in.damping_ratio_rotation = 0.0;
  in.mass_scaling = 1e9;
  in.lock_rotation = !spin;
  w.set_integration(in);
  return w;
}

/// Mean compressive stress on the four walls [Pa] (the force of the
/// particles on the left wall points left, etc.).
inline double mean_wall_stress(const World& w) {
  const double t = w.material().thickness;
  const double sx = (w.wall(kLeft).force.x() - w.wall(kRight).force.x()) / (2.0 * w.height() * t);
  const double sy = (w.wall(kBottom).force.y() - w.wall(kTop).force.y()) / (2.0 * w.width() * t);
  return -0.5 * (sx + sy);
}

/// Disk area over box area.
inline double packing_fraction(const World& w) {
  double a = 0.0;
  for (double r : w.radius()) a += 3.141592653589793 * r * r;
  return a / (w.width() * w.height());
}

/// Jam a loose scene: move all four walls inward (frictionless particles,
/// ζ = 1, α = 0.2, 3e-4·r_min per step) until the packing fraction reaches
/// `phi` (0.84 jams these polydisperse disks at ~1–2 MPa), stop the walls,
/// relax 5000 steps, switch friction to `mu` and relax `relax_steps` more.
inline void compact(World& w, double phi, double mu, int64_t relax_steps) {
  w.set_particle_friction(0.0);
  Integration in;
  in.dt = 0.2 * w.reference_scales().dt_crit;
  in.damping_ratio_translation = 1.0;
  in.damping_ratio_rotation = 1.0;
  w.set_integration(in);
  const double rmin = *std::min_element(w.radius().begin(), w.radius().end());
  const double v = 3e-4 * rmin / in.dt;
  w.wall(kLeft).velocity = v;
  w.wall(kRight).velocity = -v;
  w.wall(kBottom).velocity = v;
  w.wall(kTop).velocity = -v;
  for (int k = 0; k < 100000 && packing_fraction(w) < phi; ++k) w.step(10);
  for (int s = 0; s < 4; ++s) w.wall(static_cast<WallSide>(s)).velocity = 0.0;
  w.step(5000);
  w.set_particle_friction(mu);
  w.step(relax_steps);
}

/// Synchronised (full-step) velocities of the leapfrog state, undamped:
/// the kernel stores v(n−½) and F(n), and v(n) = v(n−½) + F(n)·Δt/(2m).
struct Energies {
  double kinetic = 0.0;   // ½ m v(n)² + ½ I ω(n)²
  double elastic = 0.0;   // springs at x(n)
  double modified = 0.0;  // kinetic + elastic − Δt²/8 Σ (F²/m + M²/I)
  double total() const { return kinetic + elastic; }
};

inline Energies synchronized_energies(const World& w) {
  Energies e;
  const double dt = w.integration().dt;
  const bool rot = !w.integration().lock_rotation;
  double f2 = 0.0;
  for (int i = 0; i < w.size(); ++i) {
    const double m = w.mass()[i];
    const double inertia = 0.5 * m * w.radius()[i] * w.radius()[i];
    const double vx = w.vx()[i] + 0.5 * dt * w.fx()[i] / m;
    const double vy = w.vy()[i] + 0.5 * dt * w.fy()[i] / m;
    e.kinetic += 0.5 * m * (vx * vx + vy * vy);
    f2 += (w.fx()[i] * w.fx()[i] + w.fy()[i] * w.fy()[i]) / m;
    if (rot) {
      const double om = w.omega()[i] + 0.5 * dt * w.torque()[i] / inertia;
      e.kinetic += 0.5 * inertia * om * om;
      f2 += w.torque()[i] * w.torque()[i] / inertia;
    }
  }
  e.elastic = w.measure().elastic_energy;
  e.modified = e.total() - dt * dt / 8.0 * f2;
  return e;
}

}  // namespace demcal::kernel_test
