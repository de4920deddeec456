#include "demcal/scene/biaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
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

double consolidation_dashpot_factor(double zeta_c, double m_max, double kn, double kn_wall,
                                    double dt0) {
  if (zeta_c <= 0.0) return 1.0;
  const double gamma_max = 2.0 * zeta_c * std::sqrt(m_max / std::min(kn, kn_wall));
  return dashpot_step_factor(gamma_max / dt0);
}

double servo_velocity(const World& world, WallSide side, double target_stress, double gain) {
  const bool vertical = side == kLeft || side == kRight;
  const double length = vertical ? world.height() : world.width();
  const double dt = world.integration().dt;
  const int contacts = std::max(1, world.wall(side).contacts);
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
  const double resistance = servo_resistance(mat, m_max, dt);
  double move = gain * error * length * mat.thickness / (resistance * contacts);
  // Never more than servo_move_cap (kServoMoveCapRatio of the smallest
  // radius) per step.
  const double cap = servo_move_cap(world.min_radius());
  move = std::clamp(move, -cap, cap);
  return kInward[side] * move / dt;
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
  AlgorithmSpec settle = detail::consolidation_settings(config, kConsolidationDampingRatio);
  // Contact dashpots lower the stable step: 2/ω·f(ζ), f = sqrt(1 + ζ²) − ζ,
  // ζ = ½·γ·ω, γ = 2·ζ_c·sqrt(m_eff/k) (stability.cpp). 2/ω·f(½·γ·ω)
  // decreases with ω, so if α = 0.2 is stable without them (ω_max·Δt₀ ≤ 2),
  // Δt₀·f(γ_max/Δt₀) is stable with them (γ_max: the heaviest particle on
  // the softer of particle and wall springs).
  if (const double zeta_c = config.material.contact_damping_ratio; zeta_c > 0.0) {
    const Material& mat = config.material;
    const double m_max =
        disk_mass(disk_areal_density(mat, settle.mass_scaling), world.max_radius());
    settle.dt_ratio *= consolidation_dashpot_factor(zeta_c, m_max, mat.particle.kn, mat.wall.kn,
                                                    integration_for(world, settle).dt);
  }
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
