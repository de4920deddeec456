// Central-difference integration with global (mass-proportional) damping
// (README.md "Physics in one paragraph"):
//   v(n+½) = [(1 − D·Δt/2m)·v(n−½) + F·Δt/m] / (1 + D·Δt/2m)
// with D = ζ_t·2·sqrt(kn·m) per particle (and ζ_r·2·sqrt(kt·r²·I) for ω),
// so every particle has the same damping ratio.
//
// Threads (KernelOptions::threads > 1): a team of workers shares the two
// SIMD passes of each step — integrate and the pair forces — by ranges of
// particle blocks; the rest (walls, neighbour-list rebuilds, divergence
// checks) runs on the calling thread. Each particle's force is summed by one
// thread in its own fixed order, and the maxima the passes return are
// exact, so results are bit-identical for any thread count.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "world_impl.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DEMCAL_PAUSE() _mm_pause()
#else
#define DEMCAL_PAUSE() ((void)0)
#endif

namespace demcal {

namespace detail {

// Fork-join team: run(fn, ctx) calls fn(ctx, t) for t = 0 .. size − 1, t = 0
// on the calling thread, and returns when all are done. Workers spin briefly
// and then sleep on the epoch counter (the machine may be shared).
class KernelTeam {
 public:
  explicit KernelTeam(int size) : size_(size) {
    for (int t = 1; t < size; ++t) workers_.emplace_back([this, t] { work(t); });
  }
  ~KernelTeam() {
    stop_.store(true, std::memory_order_relaxed);
    epoch_.fetch_add(1, std::memory_order_release);
    epoch_.notify_all();
    for (auto& w : workers_) w.join();
  }
  KernelTeam(const KernelTeam&) = delete;
  KernelTeam& operator=(const KernelTeam&) = delete;
  int size() const { return size_; }

  void run(void (*fn)(void*, int), void* ctx) {
    fn_ = fn;
    ctx_ = ctx;
    pending_.store(size_ - 1, std::memory_order_relaxed);
    epoch_.fetch_add(1, std::memory_order_release);
    epoch_.notify_all();
    fn(ctx, 0);
    for (int spin = 0;; ++spin) {
      const int left = pending_.load(std::memory_order_acquire);
      if (left == 0) break;
      if (spin < kSpin)
        DEMCAL_PAUSE();
      else
        pending_.wait(left, std::memory_order_acquire);
    }
  }

 private:
  static constexpr int kSpin = 4000;
  void work(int t) {
    uint64_t seen = 0;
    for (;;) {
      uint64_t now;
      for (int spin = 0;; ++spin) {
        now = epoch_.load(std::memory_order_acquire);
        if (now != seen) break;
        if (spin < kSpin)
          DEMCAL_PAUSE();
        else
          epoch_.wait(seen, std::memory_order_acquire);
      }
      seen = now;
      if (stop_.load(std::memory_order_relaxed)) return;
      fn_(ctx_, t);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
    }
  }

  int size_;
  std::vector<std::thread> workers_;
  std::atomic<uint64_t> epoch_{0};
  std::atomic<int> pending_{0};
  std::atomic<bool> stop_{false};
  void (*fn_)(void*, int) = nullptr;
  void* ctx_ = nullptr;
};

TeamHandle::TeamHandle() noexcept = default;
TeamHandle::TeamHandle(const TeamHandle&) noexcept {}
TeamHandle::TeamHandle(TeamHandle&&) noexcept = default;
TeamHandle& TeamHandle::operator=(const TeamHandle&) noexcept {
  team.reset();
  return *this;
}
TeamHandle& TeamHandle::operator=(TeamHandle&&) noexcept = default;
TeamHandle::~TeamHandle() = default;

void team_run(TeamHandle& handle, int size, void (*fn)(void*, int), void* ctx) {
  if (handle.team && handle.team->size() != size) handle.team.reset();
  if (!handle.team) handle.team = std::make_unique<KernelTeam>(size);
  handle.team->run(fn, ctx);
}

}  // namespace detail

namespace {
constexpr int kBlock = 8;
constexpr double kFar = 1e100;  // padding lanes at (+kFar, +kFar), the ghost at (−kFar, −kFar)
}  // namespace

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
    case Divergence::kEnergyCreated:
      return "energy created by the integrator (step beyond the stable one)";
  }
  return "unknown";
}

WorldImpl::WorldImpl(const Material& material, std::span<const double> x, std::span<const double> y,
                     std::span<const double> radius, double left, double right, double bottom,
                     double top, KernelOptions options)
    : material_(material), options_(options) {
  const size_t n = x.size();
  if (y.size() != n || radius.size() != n)
    throw std::invalid_argument("World: x, y and radius differ in length");
  if (!(right > left) || !(top > bottom))
    throw std::invalid_argument("World: walls must enclose a positive area");
  if (n > static_cast<size_t>(1) << 28) throw std::invalid_argument("World: too many particles");
  for (double r : radius)
    if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("World: radius must be > 0");
  // The SIMD path is chosen here, in the caller's thread: kernel_simd()
  // throws for a DEMCAL_SIMD it cannot honour (a pass may first run on a
  // worker thread).
  kernel_simd();
  n_ = static_cast<int>(n);
  nblocks_ = (n_ + kBlock - 1) / kBlock;
  ghost_ = kBlock * nblocks_;
  const size_t cap = static_cast<size_t>(ghost_) + kBlock;  // padding, ghost, one spare block
  auto init = [&](Array& a, double value) { a.assign(cap, value); };
  init(x_, kFar);
  init(y_, kFar);
  std::copy(x.begin(), x.end(), x_.begin());
  std::copy(y.begin(), y.end(), y_.begin());
  x_[ghost_] = y_[ghost_] = -kFar;
  init(r_, 0.0);
  std::copy(radius.begin(), radius.end(), r_.begin());
  init(inv_r_, 0.0);
  for (int i = 0; i < n_; ++i) inv_r_[i] = 1.0 / r_[i];
  for (Array* a : {&vx_, &vy_, &theta_, &omega_, &fx_, &fy_, &tq_, &m_, &inertia_, &ca_t_, &cb_t_,
                   &ca_r_, &cb_r_})
    init(*a, 0.0);
  x_built_ = x_;
  y_built_ = y_;
  for (auto& h : wall_ft_) h.assign(n, 0.0);
  for (auto& h : wall_fn_) h.assign(n, 0.0);
  block_slot_.assign(static_cast<size_t>(nblocks_) + 1, 0);
  block_power_.assign(static_cast<size_t>(kBlock) * (nblocks_ + 1), 0.0);  // 8 lanes per block
  r_min_ = n ? *std::min_element(radius.begin(), radius.end()) : 1.0;
  r_max_ = n ? *std::max_element(radius.begin(), radius.end()) : 1.0;
  skin_ = options_.skin_ratio * r_min_;
  walls_[kLeft].position = left;
  walls_[kRight].position = right;
  walls_[kBottom].position = bottom;
  walls_[kTop].position = top;
  set_threads(options_.threads);
  set_integration(integration_);
  update_forces();
}

void WorldImpl::set_threads(int threads) {
  options_.threads = detail::thread_count(threads, "World");
  threads_ = options_.threads;
  if (team_.team && team_.team->size() != active_threads()) team_.team.reset();
  update_thread_bounds();
}

void WorldImpl::set_options(const KernelOptions& options) {
  options_ = options;
  ledger_ = {};
  skin_ = options_.skin_ratio * r_min_;
  list_valid_ = false;  // the next step rebuilds the list with this skin
  set_threads(options.threads);
}

int WorldImpl::active_threads() const { return detail::active_threads(threads_, nblocks_); }

void WorldImpl::update_thread_bounds() {
  detail::thread_bounds(active_threads(), nblocks_, block_slot_, particle_bounds_, pair_bounds_);
  layout_terms();
}

double WorldImpl::run_pass(double (WorldImpl::*pass)(int, int), const std::vector<int>& bounds) {
  return detail::run_pass(team_, active_threads(), nblocks_, this, pass, bounds);
}

double WorldImpl::run_pair_pass() {
  // One thread sums the mirrored pair terms block by block inside the pair
  // pass; threads in a second pass after the barrier (the same sums).
  const double mo = run_pass(&WorldImpl::pair_pass, pair_bounds_);
  if (active_threads() > 1) run_pass(&WorldImpl::sum_pass, particle_bounds_);
  return mo;
}

double WorldImpl::run_integrate_pass() {
  return run_pass(&WorldImpl::integrate_pass, particle_bounds_);
}

void WorldImpl::set_integration(const Integration& integration) {
  if (!(integration.dt >= 0.0) || !std::isfinite(integration.dt))
    throw std::invalid_argument("World: dt must be finite and >= 0");
  if (!(integration.mass_scaling > 0.0))
    throw std::invalid_argument("World: mass_scaling must be > 0");
  integration_ = integration;
  ledger_ = {};
  // Locked rotation means ω ≡ 0: a spin left from before the lock would
  // otherwise keep loading the tangential springs through the contact-point
  // velocity while θ stays frozen.
  if (integration_.lock_rotation) std::fill(omega_.begin(), omega_.end(), 0.0);
  const double areal_density = disk_areal_density(material_, integration_.mass_scaling);
  for (int i = 0; i < size(); ++i) {
    m_[i] = disk_mass(areal_density, r_[i]);
    inertia_[i] = disk_inertia(m_[i], r_[i]);
  }
  update_damping_coefficients();
}

void WorldImpl::update_damping_coefficients() {
  const double dt = integration_.dt;
  const double kn = material_.particle.kn, kt = material_.particle.kt;
  for (int i = 0; i < size(); ++i) {
    const double dtc =
        integration_.damping_ratio_translation * critical_damping_translation(kn, m_[i]);
    const double c = dtc * dt / (2.0 * m_[i]);
    ca_t_[i] = (1.0 - c) / (1.0 + c);
    cb_t_[i] = dt / m_[i] / (1.0 + c);
    const double drc =
        integration_.damping_ratio_rotation * critical_damping_rotation(kt, r_[i], inertia_[i]);
    const double cr = drc * dt / (2.0 * inertia_[i]);
    ca_r_[i] = (1.0 - cr) / (1.0 + cr);
    cb_r_[i] = dt / inertia_[i] / (1.0 + cr);
  }
}

void WorldImpl::set_velocity(int i, double vx, double vy, double omega) {
  ledger_ = {};
  vx_[i] = vx;
  vy_[i] = vy;
  omega_[i] = integration_.lock_rotation ? 0.0 : omega;
}

void WorldImpl::set_position(int i, double x, double y) {
  ledger_ = {};
  x_[i] = x;
  y_[i] = y;
  list_valid_ = false;
}

void WorldImpl::update_forces() {
  if (needs_rebuild()) rebuild_neighbours();
  const double dt = integration_.dt;
  // Re-evaluating forces in place must not add a tangential increment twice.
  integration_.dt = 0.0;
  compute_forces();
  integration_.dt = dt;
}

void WorldImpl::integrate() {
  // Fused with the displacement scan of the neighbour-list check.
  const double max_d2 = run_integrate_pass();
  for (auto& w : walls_) w.position += w.velocity * integration_.dt;
  if (list_valid_ && detail::skin_exceeded(max_d2, walls_, wall_built_, skin_)) list_valid_ = false;
}

bool WorldImpl::check_divergence() {
  const int n = size();
  double ke = 0.0;
  bool finite = true;
  for (int i = 0; i < n; ++i) {
    finite = finite && std::isfinite(x_[i]) && std::isfinite(y_[i]) && std::isfinite(omega_[i]);
    ke += m_[i] * (vx_[i] * vx_[i] + vy_[i] * vy_[i]) + inertia_[i] * omega_[i] * omega_[i];
  }
  ke *= 0.5;
  // The energy scale without the walls' work (the 2D ledger samples it).
  return detail::divergence_checks(*this, finite, ke, 0.0);
}

bool WorldImpl::step(int64_t count) {
  if (divergence_ != Divergence::kNone) return false;
  if (initial_energy_ < 0.0) {
    const Measures m = measure();
    initial_energy_ = m.kinetic_energy_translation + m.kinetic_energy_rotation + m.elastic_energy;
  }
  const int interval = std::max(1, options_.check_interval);
  const bool dashpots = material_.contact_damping_ratio > 0.0;
  for (int64_t s = 0; s < count; ++s) {
    // The contact dashpots' dissipation over this step, with the forces
    // about to be applied (energy ledger).
    if (dashpots && ledger_.started) ledger_.dashpot += integration_.dt * dashpot_power();
    integrate();
    if (!list_valid_) rebuild_neighbours();
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
