#include "demcal/scene/biaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "demcal/io/format.hpp"
#include "demcal/scene/consolidation_cache.hpp"
#include "protocol_steps.hpp"

namespace demcal {

namespace {

// +1 when the wall's inward direction is +axis.
constexpr double kInward[4] = {+1.0, -1.0, +1.0, -1.0};

}  // namespace

double wall_pressure(const World& world, WallSide side) {
  const Wall& w = world.wall(side);
  const bool vertical = side == kLeft || side == kRight;
  const double length = vertical ? world.height() : world.width();
  const double normal_force = vertical ? w.force.x() : w.force.y();
  // The particles push the wall outward: −inward·F is the compressive force.
  return -kInward[side] * normal_force / (length * world.material().thickness);
}

double servo_wall_dashpot(double kn_wall, double zeta_c, double m_max) {
  if (zeta_c <= 0.0) return 0.0;
  return 2.0 * zeta_c * std::sqrt(kn_wall * m_max);
}

double servo_wall_dashpot(const Material& material, double m_max) {
  return servo_wall_dashpot(material.wall.kn, material.contact_damping_ratio, m_max);
}

double servo_resistance(double kn_wall, double zeta_c, double m_max, double dt) {
  const double c = servo_wall_dashpot(kn_wall, zeta_c, m_max);
  return c > 0.0 ? kn_wall + c / dt : kn_wall;
}

double servo_resistance(const Material& material, double m_max, double dt) {
  return servo_resistance(material.wall.kn, material.contact_damping_ratio, m_max, dt);
}

// The consolidation's step with contact dashpots (consolidation_dashpot_factor).
//
// 1. Stability. The kernel's step is leapfrog, the dashpots explicit (their
// force at x(n) uses v(n−½)), the global damping centred: linearised on a
// contact network, M(v⁺ − v⁻) = −Δt·K·x − Δt·C·v⁻ − Δt·D·(v⁺ + v⁻)/2 with
// M the masses and inertias, K the springs (normal and tangential, walls'
// kn_wall too), C = Σ c_k·b_k·b_kᵀ the normal dashpots (b_k: the contact's
// normal relative velocity, c_k = 2ζ_c·sqrt(kn_k·m_eff,k), m_eff the
// reduced mass, m_i at a wall), D ≥ 0 diagonal. With v⁻ = v̄ − (v⁺ − v⁻)/2
// this is the centred scheme with the mass M' = M − Δt·C/2, whose energy
//   E = ½·vᵀ(M' − Δt²·K/4)·v + ½·x̄ᵀ·K·x̄   (v = v(n−½), x̄ the mid-step x)
// falls by Δt·v̄ᵀ(C + D)·v̄ ≥ 0 each step (v̄ = (v⁺ + v⁻)/2), so the scheme
// is stable (E bounds v and x̄) if
//   Δt/2·vᵀCv + Δt²/4·vᵀKv < vᵀMv   for every v.                       (S)
// For one mass on one spring this is ω²Δt² + 4ζωΔt < 4, the root of
// dashpot_step_factor (particle_scales.hpp), exactly. The walls move at the
// servo's velocity: a forcing of this system, not one of its modes (the
// servo's own loop divides by R = kn_wall + c/Δt, servo_resistance, which
// keeps its gain per step whatever Δt).
//
// 2. The dashpots against the springs and the masses. For any τ > 0,
// c_k·(b_kᵀv)² = 2ζ_c·sqrt(kn_k(b_kᵀv)²·m_eff,k(b_kᵀv)²)
//             ≤ ζ_c·(τ·kn_k(b_kᵀv)² + m_eff,k(b_kᵀv)²/τ),
// so vᵀCv ≤ ζ_c·(τ·vᵀKv + vᵀGv/τ), G = Σ m_eff,k·b_k·b_kᵀ (K holds the
// normal springs and more). If vᵀGv ≤ Λ·vᵀMv (3.), the best τ gives
// vᵀCv ≤ 2ζ_c·sqrt(Λ·κ)·vᵀMv, κ = vᵀKv/vᵀMv ≤ ω²_max, and (S) holds if
// Δt·ζ_c·sqrt(Λ)·ω + Δt²ω²/4 < 1 at ω = ω_max (the left side grows with κ):
//   ω_max·Δt < 2·f(ζ_c·sqrt(Λ)),   f = dashpot_step_factor.
// Every mode carries at most the damping ratio ζ_c·sqrt(Λ), whatever its
// frequency. The undamped consolidation step Δt0 (α = 0.2) is taken to be
// stable, ω_max·Δt0 ≤ 2, in every state it passes through (the protocol's
// premise: a gas has no springs, a packing's ω_max is its contacts'); then
// Δt0·f(ζ_c·sqrt(Λ)) is stable with the dashpots. The bound before
// 2026-12-03 paired the heaviest particle's dashpot γ_max with the fastest
// mode Δt0 could carry (ζ = γ_max/Δt0), which no mode has at once: on
// random_500_3d (r_max/r_min = 5/3) 10.7·ζ_c against ζ_c·sqrt(Λ) = 4.0·ζ_c.
//
// 3. Λ, geometric. (p − q)² ≤ 2p² + 2q² and m_eff ≤ m_i, m_j give
//   vᵀGv ≤ Σ_i m_i·Σ_{k∋i} w_k·(n_k·v_i)² ≤ Σ_i m_i|v_i|²·λ_max(Σ_{k∋i} w_k·n_k·n_kᵀ)
// with w_k = 2m_j/(m_i + m_j) for a neighbour j, 1 for a wall. At most one
// wall per axis touches i (the box is wider than a particle), their
// normals are orthogonal: Σ_walls (n·e)² ≤ 1 for a unit e. The neighbours:
// j and k, touching i and not each other, radii u_j·r_i and u_k·r_i, lie at
// an angle φ seen from i's centre with sin²(φ/2) ≥ t_j·t_k, t = u/(1 + u)
// (law of cosines, equality when they touch). Give each neighbour the cap
// of directions within β_j = asin(sqrt(t_j·t*)) of its own, t* = t of the
// smallest radius r_min: β_j + β_k ≤ 2·asin(sqrt(t_j·t_k)) ≤ φ (t* ≤ t_j,
// t_k), so the caps are disjoint. For a unit e and ψ the angle to the axis
// ±e, ψ_j ≥ ψ − β_max over j's cap, so w_j·cos²ψ_j ≤ (w_j/A_j)·∫_cap
// cos²(max(0, ψ − β_max)) and, the caps disjoint,
//   Σ_j w_j·(n_j·e)² ≤ max_j (w_j/A_j)·J(β_max),
//   J = ∫_sphere cos²(max(0, ψ − β)) = 4π·(1 − ⅔cos β + ⅓sin 2β)  (3D),
//                                     = π + 2β + sin 2β            (2D),
// A_j the cap's area 2π(1 − cos β_j) (3D) or length 2β_j (2D), β_max the
// largest neighbour's. Λ = 1 + that, the worst over r_i in [r_min, r_max]:
// w grows with r_j and falls with r_i, β (so A) the same, so on a cell of
// radii [s_a, s_b]·r_min × [q_a, q_b]·r_min w/A ≤ w(s_a, q_b)/A(s_b, q_a):
// the grid's maximum bounds it (kGrid cells a side, ~1 % above the limit).
// Λ = 7.6 (2D), 16.0 (3D) at r_max/r_min = 5/3; 5.8 and 11.6 for one size.
// Linearised on the current contacts, as the kernel's estimates; exact for
// touching particles (overlaps of δ/r narrow the angles by about as much).
namespace {

double radius_cap_area(int dimension, double beta) {
  return dimension == 3 ? 2.0 * std::numbers::pi * (1.0 - std::cos(beta)) : 2.0 * beta;
}

double axis_weight_integral(int dimension, double beta) {
  return dimension == 3 ? 4.0 * std::numbers::pi *
                              (1.0 - 2.0 / 3.0 * std::cos(beta) + std::sin(2.0 * beta) / 3.0)
                        : std::numbers::pi + 2.0 * beta + std::sin(2.0 * beta);
}

}  // namespace

double consolidation_dashpot_coordination(int dimension, double radius_ratio) {
  if (dimension != 2 && dimension != 3)
    throw std::invalid_argument("consolidation_dashpot_coordination: dimension 2 or 3");
  if (!(radius_ratio >= 1.0) || !std::isfinite(radius_ratio))
    throw std::invalid_argument("consolidation_dashpot_coordination: radius ratio >= 1");
  constexpr int kGrid = 64;
  const int cells = radius_ratio > 1.0 ? kGrid : 1;
  const auto radius = [&](int k) { return 1.0 + (radius_ratio - 1.0) * k / cells; };
  // Neighbour q against particle s (radii in units of r_min).
  const auto weight = [&](double s, double q) {
    return 2.0 * std::pow(q, dimension) / (std::pow(s, dimension) + std::pow(q, dimension));
  };
  const auto cap_angle = [](double s, double q) {
    return std::asin(std::sqrt(q / (s + q) / (1.0 + s)));
  };
  double lambda = 0.0;
  for (int a = 0; a < cells; ++a) {
    const double sa = radius(a), sb = radius(a + 1);
    double density = 0.0;
    for (int c = 0; c < cells; ++c)
      density = std::max(density, weight(sa, radius(c + 1)) /
                                      radius_cap_area(dimension, cap_angle(sb, radius(c))));
    lambda = std::max(lambda,
                      1.0 + density * axis_weight_integral(dimension, cap_angle(sa, radius_ratio)));
  }
  return lambda;
}

double consolidation_dashpot_factor(double zeta_c, int dimension, double r_min, double r_max) {
  if (zeta_c <= 0.0) return 1.0;
  return dashpot_step_factor(
      zeta_c * std::sqrt(consolidation_dashpot_coordination(dimension, r_max / r_min)));
}

double consolidation_alpha(double zeta_c, int dimension, double r_min, double r_max) {
  return AlgorithmSpec{}.dt_ratio * consolidation_dashpot_factor(zeta_c, dimension, r_min, r_max);
}

double servo_velocity(const World& world, WallSide side, double target_stress, double gain) {
  const bool vertical = side == kLeft || side == kRight;
  const double length = vertical ? world.height() : world.width();
  const double dt = world.integration().dt;
  const double error = target_stress - wall_pressure(world, side);
  // The wall's contacts resist a move by kw per unit length, and their
  // dashpots by c/Δt more within the step (c = 2ζ_c·sqrt(kw·m), the heaviest
  // particle's: the most damping). Leaving the dashpots out makes the servo
  // overshoot by gain·c/(Δt·kw) = gain·ζ_c/α each step, and beyond 1 the
  // wall velocity flips and grows: the loop, not the integrator, creates
  // energy (issue 14: contact damping 0.2 "diverged" in consolidation).
  // R = kw + c/Δt: servo_resistance, which the exported decks share.
  const Material& mat = world.material();
  const double m_max =
      disk_mass(disk_areal_density(mat, world.integration().mass_scaling), world.max_radius());
  // (The area L·t is rounded first: where thickness is not 1 the move
  // differs from the one before servo_step_velocity in its last bits.)
  const ServoWall wall{error, length * mat.thickness, world.wall(side).contacts, kInward[side],
                       world.wall(side).velocity};
  return servo_step_velocity(wall, gain, servo_resistance(mat, m_max, dt), mat.wall.kn, dt,
                             world.min_radius());
}

double servo_step_velocity(const ServoWall& wall, const double gain, const double resistance,
                           const double kn_wall, const double dt, const double r_min) {
  double move = gain * wall.error * wall.area / (resistance * std::max(1, wall.contacts));
  // A moving wall's dashpot force is in its reading: carry servo_carry of
  // the last move (velocity·Δt, toward the sample) into this one.
  const double carry = servo_carry(kn_wall, resistance);
  if (carry > 0.0) move += carry * wall.inward * wall.velocity * dt;
  // Never more than servo_move_cap (kServoMoveCapRatio of the smallest
  // radius) per step.
  const double cap = servo_move_cap(r_min);
  move = std::clamp(move, -cap, cap);
  return wall.inward * move / dt;
}

Integration integration_for(const World& world, const AlgorithmSpec& algorithm) {
  // Δt_crit = 2·sqrt(m_min/kn) with the mass scaling of this run.
  const Material& mat = world.material();
  const double m_min =
      disk_mass(disk_areal_density(mat, algorithm.mass_scaling), world.min_radius());
  Integration in;
  in.mass_scaling = algorithm.mass_scaling;
  in.dt = algorithm.dt_ratio * critical_time_step(m_min, mat.particle.kn);
  in.damping_ratio_translation = algorithm.damping_ratio_translation;
  in.damping_ratio_rotation = algorithm.damping_ratio_rotation;
  in.lock_rotation = algorithm.lock_rotation;
  return in;
}

namespace {

ConsolidatedState consolidate_fresh(const SceneConfig& config, const Assembly& assembly,
                                    const ConsolidationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const TestSpec& test = config.test;
  ConsolidatedState state{World(config.material, assembly.x, assembly.y, assembly.r, assembly.left,
                                assembly.right, assembly.bottom, assembly.top)};
  World& world = state.world;
  const double mu = config.material.particle.friction;
  // Damping for the fastest relaxation, not the loading's. ζ = 1 is critical
  // for one particle on one contact, so it heavily over-damps the packing's
  // slow collective modes, whose frequencies are a small fraction of the
  // contact frequency: those modes then creep. A light global damping lets
  // them relax at their own speed. Measured (steps to the same tolerances,
  // reports/calibration-cost.md): ζ = 1 → 0.02 cuts random_400 from 398 600
  // to 12 600 steps and a 500-disk lognormal REV from 1 536 200 to 61 200;
  // a 400-disk REV with radius ratio 3 did not converge in 2·10⁶ steps at
  // ζ = 1 and needs 60 600 at 0.02; hexagonal REVs need 1 400 at most.
  // Contact dashpots lower the stable step: α·f(ζ_c·sqrt(Λ)) is stable
  // wherever α is without them (consolidation_alpha).
  const AlgorithmSpec settle = detail::consolidation_settings(
      config, kConsolidationDampingRatio, world.min_radius(), world.max_radius());
  const detail::ConsolidationOutcome o =
      detail::run_consolidation<WallSide, 4>(world, test, mu, settle, integration_for, options);
  for (int i = 0; i < world.size(); ++i) world.set_velocity(i, 0.0, 0.0, 0.0);
  world.update_forces();
  // Every trial starts from this state: number the particles so that the
  // kernel's SIMD blocks are full (the same physical state).
  world.reorder(world.block_friendly_order());
  state.width0 = world.width();
  state.height0 = world.height();
  detail::finish_consolidation(state, o, test, t0);
  return state;
}

}  // namespace

ConsolidatedState consolidate(const SceneConfig& config, const Assembly& assembly,
                              const std::string& cache_dir, const ConsolidationOptions& options) {
  return consolidate_cached<ConsolidatedState>(
      cache_dir, config, assembly, [&] { return consolidate_fresh(config, assembly, options); });
}

ConsolidatedState consolidate(const SceneConfig& config, const Assembly& assembly,
                              const ConsolidationOptions& options) {
  return consolidate(config, assembly, consolidation_cache_dir(), options);
}

double estimated_stable_dt_ratio(const ConsolidatedState& state, const AlgorithmSpec& algorithm) {
  return detail::stable_dt_ratio_of<World>(state.world, algorithm, integration_for);
}

LoadingResult run_loading(const ConsolidatedState& start, const TestSpec& test,
                          const AlgorithmSpec& algorithm, const MonitorCallback& monitor,
                          World* final_state) {
  const auto t0 = std::chrono::steady_clock::now();
  World world = start.world;
  LoadingResult out;
  const double h0 = start.height0;
  detail::start_loading(world, out, algorithm, test, h0, integration_for, kBottom, kTop);
  const double sigma3 = test.lateral_stress;
  detail::run_monitored<MonitorPoint>(
      world, out, test.monitor_points, start.world.steps_taken(),
      [&](MonitorPoint& p) {
        p.strain_yy = (world.height() - h0) / h0;
        const double lateral = 0.5 * (wall_pressure(world, kLeft) + wall_pressure(world, kRight));
        p.lateral_stress_error = (lateral - sigma3) / sigma3;
        p.left = world.wall(kLeft).position;
        p.right = world.wall(kRight).position;
        p.bottom = world.wall(kBottom).position;
        p.top = world.wall(kTop).position;
      },
      monitor,
      [&] {
        world.wall(kLeft).velocity = servo_velocity(world, kLeft, sigma3, test.servo_gain);
        world.wall(kRight).velocity = servo_velocity(world, kRight, sigma3, test.servo_gain);
      },
      [&] {
        const double vertical = -0.5 * (wall_pressure(world, kTop) + wall_pressure(world, kBottom));
        if (vertical < out.peak_stress_yy) {
          out.peak_stress_yy = vertical;
          out.peak_strain_yy = (world.height() - h0) / h0;
        }
      });
  out.wall_time_s = seconds_since(t0);
  if (final_state) *final_state = std::move(world);
  return out;
}

Peak find_peak(const std::vector<MonitorPoint>& series) {
  Peak p;
  for (int i = 0; i < static_cast<int>(series.size()); ++i) {
    if (p.index < 0 || series[i].b(1, 1) < p.stress_yy) {
      p.index = i;
      p.stress_yy = series[i].b(1, 1);
      p.strain_yy = series[i].strain_yy;
    }
  }
  return p;
}

}  // namespace demcal
