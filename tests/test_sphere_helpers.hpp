// Shared scenes and helpers for the sphere kernel tests (test_sphere_*.cpp).
//
// Units as the 2D kernel tests: r = 5e-4 m, ρ = 2650 kg/m³, kn = 1e8 N/m,
// kt = kn/2, so m ≈ 1.39e-6 kg and an overlap of 1e-6 m carries 100 N.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "demcal/kernel/sphere_world.hpp"

namespace demcal::sphere_test {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();
inline constexpr double kR = 5e-4;

inline SphereMaterial test_material(double mu = 0.3, double wall_mu = 0.0) {
  SphereMaterial m;
  m.density = 2650.0;
  m.particle = {1e8, 5e7, mu};
  m.wall = {1e8, 5e7, wall_mu};
  m.contact_damping_ratio = 0.0;
  return m;
}

struct Scene {
  std::vector<double> x, y, z, r;
  std::array<double, 3> lo{}, hi{};
  SphereWorld make(const SphereMaterial& material, KernelOptions options = {}) const {
    return SphereWorld(material, x, y, z, r, lo, hi, options);
  }
  void add(const Eigen::Vector3d& p, double radius) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
    r.push_back(radius);
  }
};

/// Set integration at α = Δt/Δt_crit with global damping ratio ζ on
/// translation and rotation on `w` and return it.
inline Integration set_damped(SphereWorld& w, double alpha, double zeta,
                              double mass_scaling = 1.0) {
  Integration in;
  in.damping_ratio_translation = zeta;
  in.damping_ratio_rotation = zeta;
  in.mass_scaling = mass_scaling;
  w.set_integration(in);  // masses first, then the step from them
  in.dt = alpha * w.reference_scales().dt_crit;
  w.set_integration(in);
  return in;
}

/// Set undamped integration at α = Δt/Δt_crit on `w` and return it.
inline Integration set_undamped(SphereWorld& w, double alpha, double mass_scaling = 1.0) {
  return set_damped(w, alpha, 0.0, mass_scaling);
}

inline Eigen::Vector3d position(const SphereWorld& w, int i) {
  return {w.x()[i], w.y()[i], w.z()[i]};
}
inline Eigen::Vector3d velocity(const SphereWorld& w, int i) {
  return {w.vx()[i], w.vy()[i], w.vz()[i]};
}
inline Eigen::Vector3d spin(const SphereWorld& w, int i) {
  return {w.omega_x()[i], w.omega_y()[i], w.omega_z()[i]};
}
inline Eigen::Vector3d force(const SphereWorld& w, int i) {
  return {w.fx()[i], w.fy()[i], w.fz()[i]};
}
inline Eigen::Vector3d torque(const SphereWorld& w, int i) {
  return {w.torque_x()[i], w.torque_y()[i], w.torque_z()[i]};
}

/// Energies with velocities synchronised to full steps (v(n) = v(n−½) +
/// F(n)·Δt/(2m), undamped) and the leapfrog's modified energy
/// E − (Δt²/8)·Σ(|F|²/m + |M|²/I), conserved exactly by the linear scheme.
struct Energies {
  double kinetic = 0.0, elastic = 0.0, modified = 0.0;
  double total() const { return kinetic + elastic; }
};

inline Energies synchronized_energies(const SphereWorld& w) {
  Energies e;
  const double dt = w.integration().dt;
  const bool rot = !w.integration().lock_rotation;
  double f2 = 0.0;
  for (int i = 0; i < w.size(); ++i) {
    const double m = w.mass()[i], inertia = w.inertia()[i];
    const Eigen::Vector3d v = velocity(w, i) + 0.5 * dt * force(w, i) / m;
    e.kinetic += 0.5 * m * v.squaredNorm();
    f2 += force(w, i).squaredNorm() / m;
    if (rot) {
      const Eigen::Vector3d om = spin(w, i) + 0.5 * dt * torque(w, i) / inertia;
      e.kinetic += 0.5 * inertia * om.squaredNorm();
      f2 += torque(w, i).squaredNorm() / inertia;
    }
  }
  e.elastic = w.measure().elastic_energy;
  e.modified = e.total() - dt * dt / 8.0 * f2;
  return e;
}

/// A heavy sphere (mass scaling 1e15, undamped, Δt = 1e-6 s) of radius kR
/// pressed by δ onto wall `side` of the box [−L, L]³ (g its inward normal).
inline SphereWorld sphere_on_wall(const SphereMaterial& mat, int side, double delta, double L) {
  const int a = side / 2;
  const double sign = (side % 2 == 0) ? 1.0 : -1.0;
  Scene s;
  s.add(-sign * L * Eigen::Vector3d::Unit(a) + (kR - delta) * sign * Eigen::Vector3d::Unit(a), kR);
  s.lo = {-L, -L, -L};
  s.hi = {L, L, L};
  SphereWorld w = s.make(mat);
  Integration in = set_undamped(w, 0.0, 1e15);
  in.dt = 1e-6;
  w.set_integration(in);
  return w;
}

}  // namespace demcal::sphere_test
