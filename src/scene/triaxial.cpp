// The triaxial test (triaxial.hpp): the biaxial protocol (biaxial.cpp) with
// six walls. The servo law, the consolidation damping and its fallback, the
// static criteria and the divergence handling are the 2D ones; the reasons
// given there hold here and are not repeated.
#include "demcal/scene/triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "demcal/io/format.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/consolidation_cache.hpp"
#include "derived_scales.hpp"
#include "protocol_steps.hpp"

namespace demcal {

namespace {

// +1 when the wall's inward direction is +axis (min walls).
double inward(SphereWallSide side) { return side % 2 == 0 ? 1.0 : -1.0; }

double wall_area(const SphereWorld& world, SphereWallSide side) {
  const int axis = side / 2;
  return world.extent((axis + 1) % 3) * world.extent((axis + 2) % 3);
}

constexpr SphereWallSide kLateral[4] = {kXMin, kXMax, kYMin, kYMax};

}  // namespace

// Overlap at σ3: a sphere of radius r carries about σ3·(2r)² per contact
// (the wall area of its cube), so δ/r = 4·σ3·r/kn. As in 2D
// (check_lateral_stress in config.cpp, check_resolvable in packing.cpp):
// δ/r at most kMaxOverlapAtSigma3 for the largest sphere (the peak is
// several times σ3 and the kernel stops at 0.5), and δ of the smallest
// resolved by the positions' round-off to a tenth of the consolidation
// tolerance.
void check_sphere_overlap(const SceneConfig& config, const SphereAssembly& a,
                          const std::string& which, const std::string& file) {
  if (a.size() == 0) return;
  const Material& m = config.material;
  const double sigma3 = config.test.lateral_stress;
  const double r_min = *std::min_element(a.r.begin(), a.r.end());
  const double r_max = *std::max_element(a.r.begin(), a.r.end());
  // The error names sigma3 or the stiffness (the round-off bound: or the
  // tolerance, when one below 1 resolves it), the one a --set changed
  // (detail::overlap_culprit), and the --set or file that gave it; `bound`
  // is the tolerance's (detail::resolving_tolerance; nullopt: none).
  const auto fail = [&](const std::string& kn_field, double kn, const std::string& what,
                        const std::optional<double>& bound) {
    const std::string field = detail::overlap_culprit(config, kn_field, bound);
    const double tolerance = config.test.consolidation_tolerance;
    if (field == "test.consolidation_tolerance")
      throw InputError(source_of(config, field), field,
                       what + ", or test.consolidation_tolerance at least " + num(*bound, 6) +
                           "; got " + num(tolerance));
    throw InputError(source_of(config, field), field,
                     what + "; got " + num(field == kn_field ? kn : sigma3));
  };
  const auto [kn_soft, soft_field] = detail::softer_normal_stiffness(m);
  const double limit = kMaxOverlapAtSigma3 * kn_soft / (4.0 * r_max);
  std::ostringstream msg;
  if (sigma3 > limit) {
    msg << "the overlap at sigma3, 4*sigma3*r/kn = " << 4.0 * sigma3 * r_max / kn_soft
        << " of the largest radius " << r_max << " m (sigma3 = " << sigma3 << " Pa, " << soft_field
        << " = " << kn_soft << " N/m), must stay below " << kMaxOverlapAtSigma3
        << ": test.lateral_stress must be at most " << limit << " Pa, or " << soft_field
        << " at least " << 4.0 * sigma3 * r_max / kMaxOverlapAtSigma3 << " N/m";
    fail(soft_field, kn_soft, msg.str(), std::nullopt);
  }
  double coordinate = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    coordinate = std::max({coordinate, std::abs(a.lo[axis]), std::abs(a.hi[axis])});
  const bool stiff_wall = m.wall.kn > m.particle.kn;
  const double kn = stiff_wall ? m.wall.kn : m.particle.kn;
  const std::string kn_field = stiff_wall ? "material.wall.kn" : "material.kn";
  const double delta = 4.0 * sigma3 * r_min * r_min / kn;
  const double roundoff = 0.5 * std::numeric_limits<double>::epsilon() * coordinate;
  const double wanted = 0.1 * config.test.consolidation_tolerance;
  if (roundoff <= wanted * delta) return;
  msg << "the overlap at sigma3, 4*sigma3*r_min^2/kn = " << delta << " m (sigma3 = " << sigma3
      << " Pa, " << kn_field << " = " << kn << " N/m), is not resolved by positions up to "
      << coordinate << " m (round-off " << roundoff
      << " m must stay below a tenth of consolidation_tolerance of it): test.lateral_stress must "
         "be at least "
      << roundoff / wanted * kn / (4.0 * r_min * r_min) << " Pa for " << which << "'s assembly ("
      << a.size() << " spheres" << (file.empty() ? "" : ", from " + file) << "), or " << kn_field
      << " at most " << 4.0 * sigma3 * r_min * r_min * wanted / roundoff << " N/m";
  if (!file.empty())
    msg << ", or " << file << "'s positions within " << wanted * delta / (roundoff / coordinate)
        << " m of the origin";
  fail(kn_field, kn, msg.str(), detail::resolving_tolerance(roundoff, delta));
}

SphereMaterial sphere_material(const Material& material) {
  SphereMaterial m;
  m.density = material.density;
  m.particle = material.particle;
  m.wall = material.wall;
  m.contact_damping_ratio = material.contact_damping_ratio;
  return m;
}

SphereAssembly make_sphere_assembly(const SceneConfig& config, const std::string& which) {
  if (config.dimension != 3)
    throw InputError(config.source, "dimension", "a sphere assembly needs \"dimension\": 3");
  const AssemblySpec& s = config.assembly;
  SphereAssembly a;
  if (s.type == "fcc")
    a = fcc_packing(s.cells_x, s.cells_y, s.cells_z, s.radius);
  else if (s.type == "random")
    a = random_sphere_gas(s);
  else if (s.type == "file") {
    require_config_file(config, "assembly.file", s.file);
    a = read_sphere_file(s.file);
  } else
    throw InputError(config.source, "assembly.type",
                     "\"" + s.type + "\" is not a 3D assembly (fcc, random or file)");
  check_sphere_assembly(config, a, which);
  return a;
}

void check_sphere_assembly(const SceneConfig& config, const SphereAssembly& a,
                           const std::string& which, const std::string& file) {
  detail::check_derived_scales(config, a.r, file);
  check_sphere_overlap(config, a, which, file);
}

double wall_pressure(const SphereWorld& world, SphereWallSide side) {
  // The spheres push the wall outward: −inward·F is the compressive force.
  return -inward(side) * world.wall(side).force[side / 2] / wall_area(world, side);
}

double servo_velocity(const SphereWorld& world, SphereWallSide side, double target_stress,
                      double gain) {
  const double dt = world.integration().dt;
  const double error = target_stress - wall_pressure(world, side);
  // R = kn_wall + c/Δt with the wall contacts' dashpots (servo_resistance,
  // the 2D servo's formula and reason, biaxial.cpp; c of the heaviest
  // sphere at this run's mass scaling, as integration_for's masses).
  const SphereMaterial& mat = world.material();
  const double m_max =
      sphere_mass(mat.density * world.integration().mass_scaling, world.max_radius());
  const double resistance = servo_resistance(mat.wall.kn, mat.contact_damping_ratio, m_max, dt);
  const ServoWall wall{error, wall_area(world, side), world.wall(side).contacts, inward(side),
                       world.wall(side).velocity};
  return servo_step_velocity(wall, gain, resistance, mat.wall.kn, dt, world.min_radius());
}

Integration integration_for(const SphereWorld& world, const AlgorithmSpec& algorithm) {
  Integration in;
  in.mass_scaling = algorithm.mass_scaling;
  in.damping_ratio_translation = algorithm.damping_ratio_translation;
  in.damping_ratio_rotation = algorithm.damping_ratio_rotation;
  in.lock_rotation = algorithm.lock_rotation;
  // Δt_crit = 2·sqrt(m_min/kn) at this run's mass scaling (the smallest
  // sphere is the lightest: one density).
  const double m_min =
      sphere_mass(world.material().density * algorithm.mass_scaling, world.min_radius());
  const double dt_crit = critical_time_step(m_min, world.material().particle.kn);
  in.dt = algorithm.dt_ratio * dt_crit;
  return in;
}

namespace {

TriaxialState consolidate_fresh(const SceneConfig& config, const SphereAssembly& assembly,
                                const ConsolidationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const TestSpec& test = config.test;
  TriaxialState state{SphereWorld(sphere_material(config.material), assembly.x, assembly.y,
                                  assembly.z, assembly.r, assembly.lo, assembly.hi)};
  SphereWorld& world = state.world;
  const double mu = config.material.particle.friction;
  // Light damping for the fastest relaxation of the slow collective modes
  // (biaxial.cpp, consolidate(): measured there).
  // Contact dashpots lower the stable step: α shrunk as in 2D (consolidation_alpha).
  const AlgorithmSpec settle = detail::consolidation_settings(
      config, kConsolidationDampingRatio, world.min_radius(), world.max_radius());
  const detail::ConsolidationOutcome o = detail::run_consolidation<SphereWallSide, 6>(
      world, test, mu, settle, integration_for, options);
  for (int i = 0; i < world.size(); ++i)
    world.set_velocity(i, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  world.update_forces();
  // Every trial starts from this state: number the particles so that the
  // kernel's SIMD blocks are full (the same physical state).
  world.reorder(world.block_friendly_order());
  for (int axis = 0; axis < 3; ++axis) state.extent0[axis] = world.extent(axis);
  detail::finish_consolidation(state, o, test, t0);
  return state;
}

}  // namespace

TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const std::string& cache_dir,
                                   const ConsolidationOptions& options) {
  return consolidate_cached<TriaxialState>(
      cache_dir, config, assembly, [&] { return consolidate_fresh(config, assembly, options); });
}

TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const ConsolidationOptions& options) {
  return consolidate_triaxial(config, assembly, consolidation_cache_dir(), options);
}

TriaxialState consolidate_triaxial(const SceneConfig& config, const SphereAssembly& assembly,
                                   const ConsolidationCallback& progress) {
  ConsolidationOptions options;
  options.progress = progress;
  return consolidate_triaxial(config, assembly, options);
}

double estimated_stable_dt_ratio(const TriaxialState& state, const AlgorithmSpec& algorithm) {
  return detail::stable_dt_ratio_of<SphereWorld>(state.world, algorithm, integration_for);
}

namespace {

/// The global damping's power at a monitoring point (D as the kernel sets
/// it: ζ times the critical value of each sphere's scaled mass and inertia)
/// and the top wall's power.
void damping_powers(const SphereWorld& world, TriaxialPoint& p) {
  const Integration& in = world.integration();
  const double kn = world.material().particle.kn, kt = world.material().particle.kt;
  const auto m = world.mass();
  const auto inertia = world.inertia();
  const auto r = world.radius();
  const auto vx = world.vx(), vy = world.vy(), vz = world.vz();
  const auto wx = world.omega_x(), wy = world.omega_y(), wz = world.omega_z();
  double pt = 0.0, pr = 0.0;
  for (int i = 0; i < world.size(); ++i) {
    pt += critical_damping_translation(kn, m[i]) * (vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i]);
    pr += critical_damping_rotation(kt, r[i], inertia[i]) *
          (wx[i] * wx[i] + wy[i] * wy[i] + wz[i] * wz[i]);
  }
  p.damping_power_translation = in.damping_ratio_translation * pt;
  p.damping_power_rotation = in.lock_rotation ? 0.0 : in.damping_ratio_rotation * pr;
  const SphereWall& top = world.wall(kZMax);
  p.axial_power = -top.force[2] * top.velocity;
}

}  // namespace

TriaxialResult run_triaxial_loading(const TriaxialState& start, const TestSpec& test,
                                    const AlgorithmSpec& algorithm, const TriaxialMonitor& monitor,
                                    SphereWorld* final_state,
                                    const TriaxialWorldObserver& observe) {
  const auto t0 = std::chrono::steady_clock::now();
  SphereWorld world = start.world;
  TriaxialResult out;
  const double h0 = start.extent0[2];
  detail::start_loading(world, out, algorithm, test, h0, integration_for, kZMin, kZMax);
  const double sigma3 = test.lateral_stress;
  detail::run_monitored<TriaxialPoint>(
      world, out, test.monitor_points, start.world.steps_taken(),
      [&](TriaxialPoint& p) {
        p.strain_zz = (world.extent(2) - h0) / h0;
        double lateral = 0.0;
        for (int k = 0; k < 4; ++k) {
          const double pk = wall_pressure(world, kLateral[k]);
          p.servo_error[k] = (pk - sigma3) / sigma3;
          lateral += 0.25 * pk;
        }
        p.lateral_stress_error = (lateral - sigma3) / sigma3;
        for (int s = 0; s < 6; ++s)
          p.walls[s] = world.wall(static_cast<SphereWallSide>(s)).position;
        damping_powers(world, p);
        if (observe) observe(p, world);
      },
      monitor,
      [&] {
        for (SphereWallSide side : kLateral)
          world.wall(side).velocity = servo_velocity(world, side, sigma3, test.servo_gain);
      },
      [&] {
        const double axial = 0.5 * (wall_pressure(world, kZMin) + wall_pressure(world, kZMax));
        double lateral = 0.0;
        for (SphereWallSide side : kLateral) lateral += 0.25 * wall_pressure(world, side);
        const double strain = (world.extent(2) - h0) / h0;
        if (-axial < out.peak_stress_zz) {
          out.peak_stress_zz = -axial;
          out.peak_strain_zz = strain;
        }
        if (lateral > 0.0 && axial / lateral > out.peak_ratio) {
          out.peak_ratio = axial / lateral;
          out.peak_ratio_strain = strain;
        }
      });
  out.wall_time_s = seconds_since(t0);
  if (final_state) *final_state = std::move(world);
  return out;
}

std::optional<double> analytical_peak_ratio_3d(const SceneConfig& config) {
  if (config.dimension != 3 || config.assembly.type != "fcc") return std::nullopt;
  const double ratio =
      fcc_peak_ratio_walled(config.material.particle.friction, config.assembly.cells_x,
                            config.assembly.cells_y, config.assembly.cells_z);
  if (!std::isfinite(ratio)) return std::nullopt;
  return ratio;
}

std::optional<double> reference_peak_3d(const SceneConfig& config) {
  if (!config.algorithm.lock_rotation) return std::nullopt;
  const auto ratio = analytical_peak_ratio_3d(config);
  if (!ratio) return std::nullopt;
  return -*ratio * config.test.lateral_stress;
}

}  // namespace demcal
