// Set-up, central-difference integration with global damping, stepping and
// the divergence checks of the sphere kernel (sphere_world.hpp). The same
// scheme as the 2D kernel (solver.cpp), for v and for the vector ω:
//   v(n+½) = [(1 − D·Δt/2m)·v(n−½) + F·Δt/m] / (1 + D·Δt/2m)
// with D = ζ_t·2·sqrt(kn·m) per particle (ζ_r·2·sqrt(kt·r²·I) for ω, with
// I in place of m), so every sphere has the same damping ratio.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "demcal/kernel/particle_scales.hpp"
#include "sphere_world_impl.hpp"

namespace demcal {

namespace {
constexpr int kBlock = 8;
constexpr double kFar = 1e100;  // padding lanes at +kFar, the ghost at −kFar
}  // namespace

SphereWorldImpl::SphereWorldImpl(const SphereMaterial& material, std::span<const double> x,
                                 std::span<const double> y, std::span<const double> z,
                                 std::span<const double> radius, const std::array<double, 3>& lo,
                                 const std::array<double, 3>& hi, KernelOptions options)
    : material_(material), options_(options) {
  const size_t n = x.size();
  if (y.size() != n || z.size() != n || radius.size() != n)
    throw std::invalid_argument("SphereWorld: x, y, z and radius differ in length");
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] > lo[a])) throw std::invalid_argument("SphereWorld: walls must enclose a volume");
  if (n > static_cast<size_t>(1) << 28)
    throw std::invalid_argument("SphereWorld: too many particles");
  for (double r : radius)
    if (!(r > 0.0) || !std::isfinite(r))
      throw std::invalid_argument("SphereWorld: radius must be > 0");
  // The SIMD path is chosen here, in the caller's thread: kernel_simd()
  // throws for a DEMCAL_SIMD it cannot honour (a pass may first run on a
  // worker thread).
  kernel_simd();
  n_ = static_cast<int>(n);
  nblocks_ = (n_ + kBlock - 1) / kBlock;
  ghost_ = kBlock * nblocks_;
  const size_t cap = static_cast<size_t>(ghost_) + kBlock;  // padding, ghost, one spare block
  // Padding lanes far away at +kFar, the ghost at −kFar, both of radius 0.
  for (auto* a : {&x_, &y_, &z_}) {
    a->assign(cap, kFar);
    (*a)[ghost_] = -kFar;
  }
  std::copy(x.begin(), x.end(), x_.begin());
  std::copy(y.begin(), y.end(), y_.begin());
  std::copy(z.begin(), z.end(), z_.begin());
  r_.assign(cap, 0.0);
  std::copy(radius.begin(), radius.end(), r_.begin());
  inv_r_.assign(cap, 0.0);
  for (int i = 0; i < n_; ++i) inv_r_[i] = 1.0 / r_[i];
  for (auto* a : {&vx_, &vy_, &vz_, &wx_, &wy_,   &wz_,   &m_,    &inertia_, &fx_,  &fy_,
                  &fz_, &tx_, &ty_, &tz_, &ca_t_, &cb_t_, &ca_r_, &cb_r_,    &d_t_, &d_r_})
    a->assign(cap, 0.0);
  x_built_ = x_;
  y_built_ = y_;
  z_built_ = z_;
  for (auto* a : {&block_lost_, &block_released_, &block_slid_, &block_power_}) a->assign(cap, 0.0);
  block_slot_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  mirror_block_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  mirror_src_block_.resize(static_cast<size_t>(nblocks_));
  for (int b = 0; b < nblocks_; ++b) mirror_src_block_[b] = b;  // no mirrored slots yet
  block_fused_.assign(static_cast<size_t>(nblocks_), 0);
  for (int s = 0; s < 6; ++s) {
    walls_[s].position = (s % 2 == 0) ? lo[s / 2] : hi[s / 2];
  }
  nbr_start_.assign(n + 1, 0);
  r_min_ = n ? *std::min_element(radius.begin(), radius.end()) : 1.0;
  r_max_ = n ? *std::max_element(radius.begin(), radius.end()) : 1.0;
  skin_ = options_.skin_ratio * r_min_;
  set_threads(options_.threads);
  set_integration(integration_);
  update_forces();
}

void SphereWorldImpl::set_threads(int threads) {
  options_.threads = detail::thread_count(threads, "SphereWorld");
  threads_ = options_.threads;
  update_thread_bounds();
}

int SphereWorldImpl::active_threads() const { return detail::active_threads(threads_, nblocks_); }

void SphereWorldImpl::update_thread_bounds() {
  detail::thread_bounds(active_threads(), nblocks_, block_slot_, particle_bounds_, pair_bounds_);
  layout_terms();
}

double SphereWorldImpl::run_pass(double (SphereWorldImpl::*pass)(int, int),
                                 const std::vector<int>& bounds) {
  return detail::run_pass(team_, active_threads(), nblocks_, this, pass, bounds);
}

void SphereWorldImpl::set_options(const KernelOptions& options) {
  options_ = options;
  ledger_ = {};
  skin_ = options_.skin_ratio * r_min_;
  list_valid_ = false;
  set_threads(options.threads);
}

void SphereWorldImpl::set_integration(const Integration& integration) {
  if (!(integration.dt >= 0.0) || !std::isfinite(integration.dt))
    throw std::invalid_argument("SphereWorld: dt must be finite and >= 0");
  if (!(integration.mass_scaling > 0.0))
    throw std::invalid_argument("SphereWorld: mass_scaling must be > 0");
  integration_ = integration;
  ledger_ = {};
  // Locked rotation means ω ≡ 0 (a spin left from before would keep loading
  // the tangential springs).
  if (integration_.lock_rotation)
    for (auto* w : {&wx_, &wy_, &wz_}) std::fill(w->begin(), w->end(), 0.0);
  const double rho = material_.density * integration_.mass_scaling;
  for (int i = 0; i < n_; ++i) {
    m_[i] = sphere_mass(rho, r_[i]);
    inertia_[i] = sphere_inertia(m_[i], r_[i]);
  }
  update_damping_coefficients();
}

void SphereWorldImpl::update_damping_coefficients() {
  const double dt = integration_.dt;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  for (int i = 0; i < n_; ++i) {
    // ζ·(2·sqrt(kn·m)) equals (ζ·2)·sqrt(kn·m) to the bit: ×2 is exact.
    const double dtc =
        integration_.damping_ratio_translation * critical_damping_translation(kn, m_[i]);
    d_t_[i] = dtc;
    const double c = dtc * dt / (2.0 * m_[i]);
    ca_t_[i] = (1.0 - c) / (1.0 + c);
    cb_t_[i] = dt / m_[i] / (1.0 + c);
    const double drc =
        integration_.damping_ratio_rotation * critical_damping_rotation(kt, r_[i], inertia_[i]);
    d_r_[i] = drc;
    const double cr = drc * dt / (2.0 * inertia_[i]);
    ca_r_[i] = (1.0 - cr) / (1.0 + cr);
    cb_r_[i] = dt / inertia_[i] / (1.0 + cr);
  }
}

void SphereWorldImpl::set_velocity(int i, const Eigen::Vector3d& v, const Eigen::Vector3d& omega) {
  ledger_ = {};
  vx_[i] = v.x();
  vy_[i] = v.y();
  vz_[i] = v.z();
  const bool lock = integration_.lock_rotation;
  wx_[i] = lock ? 0.0 : omega.x();
  wy_[i] = lock ? 0.0 : omega.y();
  wz_[i] = lock ? 0.0 : omega.z();
}

void SphereWorldImpl::set_position(int i, const Eigen::Vector3d& p) {
  ledger_ = {};
  x_[i] = p.x();
  y_[i] = p.y();
  z_[i] = p.z();
  list_valid_ = false;
}

Eigen::Vector3d SphereWorldImpl::centre() const {
  return {0.5 * (walls_[kXMin].position + walls_[kXMax].position),
          0.5 * (walls_[kYMin].position + walls_[kYMax].position),
          0.5 * (walls_[kZMin].position + walls_[kZMax].position)};
}

void SphereWorldImpl::update_forces() {
  if (needs_rebuild()) rebuild_neighbours();
  const double dt = integration_.dt;
  // Re-evaluating forces in place must not add a tangential increment (nor
  // turn the histories by a spin) a second time.
  integration_.dt = 0.0;
  compute_forces();
  integration_.dt = dt;
  for (int s = 0; s < 6; ++s) wall_push_[s] = -walls_[s].force[s / 2];
}

void SphereWorldImpl::book_wall_work() {
  for (int s = 0; s < 6; ++s) {
    // wall.force is the spheres' force on the wall; the wall's on them is −force.
    const double push = -walls_[s].force[s / 2];
    const double work = 0.5 * (wall_push_[s] + push) * wall_move_[s];
    wall_work_ += work;
    wall_work_abs_ += std::abs(work);
    wall_push_[s] = push;
  }
}

void SphereWorldImpl::integrate() {
  // The scheme is m·(v⁺ − v⁻)/Δt = F − D·v̄, v̄ = (v⁺ + v⁻)/2, so the
  // damping removes exactly D·|v̄|²·Δt of (half-step) kinetic energy per
  // step: summed for the energy ledger (each block's lanes by the pass, the
  // blocks here in order: detail::block_lanes_sum), exact however fast the
  // decay. The pass also scans the displacements since the last list build.
  const double dt = integration_.dt;
  const double max_d2 = run_pass(&SphereWorldImpl::integrate_pass, particle_bounds_);
  const double lost = detail::block_lanes_sum(block_lost_.data(), nblocks_);
  damping_dissipated_ += lost * dt;
  for (int s = 0; s < 6; ++s) {
    wall_move_[s] = walls_[s].velocity * dt;
    walls_[s].position += wall_move_[s];
  }
  if (list_valid_ && detail::skin_exceeded(max_d2, walls_, wall_built_, skin_)) list_valid_ = false;
}

bool SphereWorldImpl::check_divergence() {
  double ke = 0.0;
  bool finite = true;
  for (int i = 0; i < n_; ++i) {
    finite = finite && std::isfinite(x_[i]) && std::isfinite(y_[i]) && std::isfinite(z_[i]) &&
             std::isfinite(wx_[i]) && std::isfinite(wy_[i]) && std::isfinite(wz_[i]);
    ke += m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i] + vz_[i] * vz_[i]) +
          inertia_[i] * (wx_[i] * wx_[i] + wy_[i] * wy_[i] + wz_[i] * wz_[i]);
  }
  ke *= 0.5;
  // The walls' work counts in the energy scale: a wall can throw a sphere
  // within one sampling interval.
  return detail::divergence_checks(*this, finite, ke, wall_work_abs_);
}

bool SphereWorldImpl::step(int64_t count) {
  if (divergence_ != Divergence::kNone) return false;
  if (initial_energy_ < 0.0) {
    const SphereMeasures m = measure();
    initial_energy_ = m.kinetic_energy_translation + m.kinetic_energy_rotation + m.elastic_energy;
  }
  const int interval = std::max(1, options_.check_interval);
  for (int64_t s = 0; s < count; ++s) {
    // The contact dashpots' loss over this step, at the forces it applies
    // (0 without dashpots).
    dashpot_dissipated_ += integration_.dt * dashpot_power_;
    integrate();
    if (!list_valid_) rebuild_neighbours();
    compute_forces();
    book_wall_work();
    ++steps_;
    time_ += integration_.dt;
    if (steps_ % interval == 0 && check_divergence()) {
      divergence_step_ = steps_;
      return false;
    }
  }
  return true;
}

}  // namespace demcal
