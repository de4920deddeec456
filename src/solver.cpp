// Central-difference integration with global (mass-proportional) damping,
// DESIGN.md §2:
//   v(n+½) = [(1 − D·Δt/2m)·v(n−½) + F·Δt/m] / (1 + D·Δt/2m)
// with D = ζ_t·2·sqrt(kn·m) per particle (and ζ_r·2·sqrt(kt·r²·I) for ω),
// so every particle has the same damping ratio.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "demcal/world.hpp"

namespace demcal {

const char* to_string(Divergence d) {
  switch (d) {
    case Divergence::kNone:
      return "none";
    case Divergence::kNotFinite:
      return "non-finite state";
    case Divergence::kOverlap:
      return "overlap beyond limit";
    case Divergence::kEnergy:
      return "kinetic energy growing without bound";
  }
  return "unknown";
}

World::World(const Material& material, std::span<const double> x, std::span<const double> y,
             std::span<const double> radius, double left, double right, double bottom, double top,
             KernelOptions options)
    : material_(material), options_(options) {
  const size_t n = x.size();
  if (y.size() != n || radius.size() != n)
    throw std::invalid_argument("World: x, y and radius differ in length");
  if (!(right > left) || !(top > bottom))
    throw std::invalid_argument("World: walls must enclose a positive area");
  x_.assign(x.begin(), x.end());
  y_.assign(y.begin(), y.end());
  r_.assign(radius.begin(), radius.end());
  for (double r : r_)
    if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("World: radius must be > 0");
  vx_.assign(n, 0.0);
  vy_.assign(n, 0.0);
  theta_.assign(n, 0.0);
  omega_.assign(n, 0.0);
  fx_.assign(n, 0.0);
  fy_.assign(n, 0.0);
  tq_.assign(n, 0.0);
  m_.resize(n);
  inertia_.resize(n);
  ca_t_.resize(n);
  cb_t_.resize(n);
  ca_r_.resize(n);
  cb_r_.resize(n);
  for (auto& h : wall_ft_) h.assign(n, 0.0);
  for (auto& h : wall_fn_) h.assign(n, 0.0);
  r_min_ = n ? *std::min_element(r_.begin(), r_.end()) : 1.0;
  r_max_ = n ? *std::max_element(r_.begin(), r_.end()) : 1.0;
  skin_ = options_.skin_ratio * r_min_;
  walls_[kLeft].position = left;
  walls_[kRight].position = right;
  walls_[kBottom].position = bottom;
  walls_[kTop].position = top;
  set_integration(integration_);
  update_forces();
}

void World::set_integration(const Integration& integration) {
  if (!(integration.dt >= 0.0) || !std::isfinite(integration.dt))
    throw std::invalid_argument("World: dt must be finite and >= 0");
  if (!(integration.mass_scaling > 0.0))
    throw std::invalid_argument("World: mass_scaling must be > 0");
  integration_ = integration;
  // Locked rotation means ω ≡ 0: a spin left from before the lock would
  // otherwise keep loading the tangential springs through the contact-point
  // velocity while θ stays frozen.
  if (integration_.lock_rotation) std::fill(omega_.begin(), omega_.end(), 0.0);
  const double rho_t = material_.density * material_.thickness * integration_.mass_scaling;
  for (int i = 0; i < size(); ++i) {
    m_[i] = rho_t * std::numbers::pi * r_[i] * r_[i];
    inertia_[i] = 0.5 * m_[i] * r_[i] * r_[i];
  }
  update_damping_coefficients();
}

void World::update_damping_coefficients() {
  const double dt = integration_.dt;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  for (int i = 0; i < size(); ++i) {
    const double dtc = integration_.damping_ratio_translation * 2.0 * std::sqrt(kn * m_[i]);
    const double c = dtc * dt / (2.0 * m_[i]);
    ca_t_[i] = (1.0 - c) / (1.0 + c);
    cb_t_[i] = dt / m_[i] / (1.0 + c);
    const double drc =
        integration_.damping_ratio_rotation * 2.0 * std::sqrt(kt * r_[i] * r_[i] * inertia_[i]);
    const double cr = drc * dt / (2.0 * inertia_[i]);
    ca_r_[i] = (1.0 - cr) / (1.0 + cr);
    cb_r_[i] = dt / inertia_[i] / (1.0 + cr);
  }
}

void World::set_velocity(int i, double vx, double vy, double omega) {
  vx_[i] = vx;
  vy_[i] = vy;
  omega_[i] = integration_.lock_rotation ? 0.0 : omega;
}

void World::set_position(int i, double x, double y) {
  x_[i] = x;
  y_[i] = y;
  list_valid_ = false;
}

void World::update_forces() {
  if (needs_rebuild()) rebuild_neighbours();
  const double dt = integration_.dt;
  // Re-evaluating forces in place must not add a tangential increment twice.
  integration_.dt = 0.0;
  compute_forces();
  integration_.dt = dt;
}

void World::integrate() {
  const int n = size();
  const double dt = integration_.dt;
  for (int i = 0; i < n; ++i) {
    vx_[i] = ca_t_[i] * vx_[i] + cb_t_[i] * fx_[i];
    vy_[i] = ca_t_[i] * vy_[i] + cb_t_[i] * fy_[i];
    x_[i] += vx_[i] * dt;
    y_[i] += vy_[i] * dt;
  }
  if (!integration_.lock_rotation) {
    for (int i = 0; i < n; ++i) {
      omega_[i] = ca_r_[i] * omega_[i] + cb_r_[i] * tq_[i];
      theta_[i] += omega_[i] * dt;
    }
  }
  for (auto& w : walls_) w.position += w.velocity * dt;
}

bool World::check_divergence() {
  const int n = size();
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x_[i]) || !std::isfinite(y_[i]) || !std::isfinite(omega_[i])) {
      divergence_ = Divergence::kNotFinite;
      return true;
    }
  }
  if (max_overlap_ratio_seen_ > options_.max_overlap_ratio) {
    divergence_ = Divergence::kOverlap;
    return true;
  }
  // Kinetic energy far beyond anything the springs have ever stored cannot
  // come from the loading: an unstable mode is growing.
  double ke = 0.0;
  for (int i = 0; i < n; ++i)
    ke += m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i]) + inertia_[i] * omega_[i] * omega_[i];
  ke *= 0.5;
  double el = 0.0;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  for (size_t k = 0; k < pair_fn_.size(); ++k)
    el += 0.5 * (pair_fn_[k] * pair_fn_[k] / kn + (kt > 0 ? pair_ft_[k] * pair_ft_[k] / kt : 0.0));
  energy_scale_ = std::max({energy_scale_, el, initial_energy_});
  if (!std::isfinite(ke) ||
      (energy_scale_ > 0.0 && ke > options_.max_energy_ratio * energy_scale_)) {
    divergence_ = Divergence::kEnergy;
    return true;
  }
  return false;
}

bool World::step(int64_t count) {
  if (divergence_ != Divergence::kNone) return false;
  if (initial_energy_ < 0.0) {
    const Measures m = measure();
    initial_energy_ = m.kinetic_energy_translation + m.kinetic_energy_rotation + m.elastic_energy;
  }
  const int interval = std::max(1, options_.check_interval);
  for (int64_t s = 0; s < count; ++s) {
    integrate();
    if (needs_rebuild()) rebuild_neighbours();
    compute_forces();
    ++steps_;
    time_ += integration_.dt;
    if (steps_ % interval == 0) {
      if (check_divergence()) {
        divergence_step_ = steps_;
        return false;
      }
    }
  }
  return true;
}

}  // namespace demcal
