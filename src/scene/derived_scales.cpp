#include "derived_scales.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"
#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"

namespace demcal::detail {

namespace {

/// One input of a derived scale: its field, its value and the power it
/// enters with (log10 of its share: power·log10(value)).
struct Input {
  std::string field;
  double value;
  double power;
  std::string file =
      {};  ///< the file that gave it (a particle file's radii), else the config's field
  double share() const { return power * std::log10(value); }
};

/// The assembly's field that gives the smallest (or largest) radius.
std::string radius_field(const AssemblySpec& a, bool smallest) {
  if (a.type == "file") return "assembly.file";
  if (a.type != "random") return "assembly.radius";
  if (a.distribution == "lognormal") return "assembly.radius_mean";
  return smallest ? "assembly.radius_min" : "assembly.radius_max";
}

std::string shown(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// `value` of `what` (its formula) must be a finite normal number; else the
/// InputError names the input whose share is the largest (overflow) or the
/// smallest (underflow) and lists them all.
void require_normal(const SceneConfig& config, const std::string& what, double value,
                    const std::vector<Input>& given) {
  if (std::isnormal(value)) return;
  std::vector<Input> inputs;  // one per field, powers summed (r^2 of the mass and of I)
  for (const Input& in : given) {
    auto same = std::find_if(inputs.begin(), inputs.end(),
                             [&](const Input& i) { return i.field == in.field; });
    if (same == inputs.end())
      inputs.push_back(in);
    else
      same->power += in.power;
  }
  const bool overflow = !(std::abs(value) < std::numeric_limits<double>::max());  // inf, nan
  const Input* blamed = nullptr;
  for (const Input& in : inputs) {
    if (!(in.value > 0.0) || in.power == 0.0) continue;
    if (!blamed || (overflow ? in.share() > blamed->share() : in.share() < blamed->share()))
      blamed = &in;
  }
  std::ostringstream msg;
  msg << what << " is " << shown(value)
      << (overflow       ? " (it overflows)"
          : value == 0.0 ? " (it underflows to 0)"
                         : " (below the smallest normal double, 2.2e-308)")
      << " with";
  const char* sep = " ";
  for (const Input& in : inputs) {
    msg << sep << in.field << " = " << shown(in.value);
    sep = ", ";
  }
  msg << ": every particle's mass, inertia, critical step and damping must be a finite, "
         "normal number";
  const Input& named = blamed ? *blamed : inputs.front();
  if (blamed) msg << "; got " << shown(blamed->value);
  if (!named.file.empty()) throw InputError(named.file, named.field, msg.str());
  throw InputError(source_of(config, named.field), named.field, msg.str());
}

/// Refuses a wall too stiff for the consolidation's step ratio `alpha_c`.
// A particle held by a wall oscillates at least at sqrt(kn_wall/m), and
// the step is stable only while ω·Δt < 2: the global damping, semi-
// implicit, keeps the undamped bound (its amplification at ω·Δt = 2 is −1
// whatever the damping). So a wall stiffer than kn/α² makes every step of
// the consolidation, at α·2·sqrt(m/kn), grow the motion of the particles
// on the walls: "consolidation diverged: overlap beyond limit" within a
// few hundred steps (hex_5x5 and fcc_4x4x4 at wall.kn = 30·kn). A user's
// "rigid" wall is the usual cause. The loading's step is checked against
// the consolidated network, walls included, with --allow-unstable for
// whoever wants to watch it diverge (stable_dt_ratio_of).
void check_wall_stiffness(const SceneConfig& config, double alpha_c) {
  const Material& mat = config.material;
  const double wall_limit = mat.particle.kn / (alpha_c * alpha_c);
  if (!(mat.wall.kn < wall_limit)) {
    std::ostringstream msg;
    msg << shown(mat.wall.kn / mat.particle.kn)
        << " times kn: a particle on a wall is stable only at steps below 2*sqrt(m/kn_wall) = "
        << shown(std::sqrt(mat.particle.kn / mat.wall.kn))
        << " of the critical step 2*sqrt(m/kn), less still with its contacts with other "
           "particles, and the consolidation steps at "
        << shown(alpha_c)
        << " of it (alpha 0.2, shrunk for the contact dashpots): its walls would diverge. A wall "
           "as stiff as the particles keeps its overlaps as small as theirs; material.wall.kn must "
           "stay below kn/alpha^2 = "
        << shown(wall_limit) << ", and well below (hex_5x5 stalls at 20 kn); got "
        << shown(mat.wall.kn);
    throw InputError(source_of(config, "material.wall.kn"), "material.wall.kn", msg.str());
  }
}

/// Refuses a contact damping ratio whose quickest contact cannot settle
/// within test.consolidation_max_steps of the consolidation's step (m_min the
/// lightest particle's mass, dt_crit its critical step, radii in [r_min, r_max]).
/// The error names the ratio, or the budget when a --set changed it and none
/// the ratio (changed_field) and a budget it may be meets the ratio, each
/// with its own bound.
// An over-damped contact (ζ_c > 1) creeps: its relative motion, m_eff·ẍ
// + c·ẋ + kn·x = 0 with c = 2ζ_c·sqrt(kn·m_eff), relaxes at best at the
// slow root ω·(ζ_c − sqrt(ζ_c² − 1)), about ω/(2ζ_c), while the step
// shrinks as 1/(2ζ_c·sqrt(Λ)) (consolidation_dashpot_factor): the steps
// per time constant grow as ζ_c². The quickest contact is the stiffest
// and lightest (ω = sqrt(2kn/m_min) for two of the smallest particles,
// sqrt(kn_wall/m_min) for one on a wall); where even it needs more than
// test.consolidation_max_steps steps for one time constant, no contact
// can settle within the budget. The servo then reads the wall's dashpot
// force as stress and the unbalanced-force ratio sees no inertia while
// the particles still creep: hex_5x5 ran all 2·10⁶ steps and failed at
// ζ_c = 1e6 (1e10, 1e100 the same), "consolidated" in 600 steps at 500
// and 1e4 (one time constant is 4.3·10⁶ and 1.7·10⁹ steps there), at 1e4
// into a state whose loading diverged ("kinetic energy growing without
// bound") at dt_ratio 1e-6 and 1e-30, below its stable 4.6e-6; it
// consolidated in 71 600, 208 400 and 429 000 steps at 50, 100 and 200
// (42 600, 170 000 and 680 000 per time constant), and at 300 and 342,
// its bound. The bounds at 2·10⁶ steps: hex_5x5 342, random_400 321,
// fcc_4x4x4 288; all consolidate at 1, 2 and 5.
void check_contact_damping_budget(const SceneConfig& config, double m_min, double dt_crit,
                                  double r_min, double r_max) {
  const Material& mat = config.material;
  const double zeta_c = mat.contact_damping_ratio;
  if (zeta_c > 1.0) {
    const double omega =
        std::sqrt(std::max(2.0 * mat.particle.kn, mat.wall.kn) / m_min);  // the quickest contact
    const auto steps_per_time_constant = [&](double zeta) {
      const double slow_root = omega / (zeta + std::sqrt((zeta - 1.0) * (zeta + 1.0)));
      const double step = consolidation_alpha(zeta, config.dimension, r_min, r_max) * dt_crit;
      return 1.0 / (slow_root * step);
    };
    const double budget = static_cast<double>(config.test.consolidation_max_steps);
    const double needed = steps_per_time_constant(zeta_c);
    if (!(needed <= budget)) {
      double lo = 1.0, hi = zeta_c;  // the largest ratio the budget covers: bisected
      for (int k = 0; k < 200 && hi - lo > 1e-6 * lo; ++k) {
        const double mid = std::sqrt(lo * hi);  // geometric: zeta may be 1e100
        (steps_per_time_constant(mid) <= budget ? lo : hi) = mid;
      }
      std::ostringstream why;
      why << "over-damps every contact: the quickest (omega = " << shown(omega)
          << " rad/s) creeps back with the time constant 1/(omega*(zeta - sqrt(zeta^2 - 1))) = "
          << shown(1.0 / (omega / (zeta_c + std::sqrt((zeta_c - 1.0) * (zeta_c + 1.0))))) << " s, "
          << shown(needed)
          << " of the consolidation's steps (shrunk for the dashpots), more than "
             "test.consolidation_max_steps = "
          << config.test.consolidation_max_steps
          << ": no contact could settle within the budget, and its criteria would read the "
             "dashpots' forces as a static state";
      const std::string budget_field = "test.consolidation_max_steps";
      const std::string field =
          changed_field(config.sets, {"material.contact_damping_ratio", budget_field});
      std::ostringstream msg;
      if (field == budget_field && needed <= static_cast<double>(kMaxConsolidationSteps)) {
        // The smallest budget that covers the ratio, the integer to type.
        msg << "must be at least " << static_cast<int64_t>(std::ceil(needed))
            << " for material.contact_damping_ratio " << shown(zeta_c) << ", which " << why.str()
            << "; got " << config.test.consolidation_max_steps;
        throw InputError(source_of(config, budget_field), budget_field, msg.str());
      }
      msg << why.str() << ". material.contact_damping_ratio must stay below " << shown(lo)
          << " for this budget (or raise test.consolidation_max_steps); got " << shown(zeta_c);
      throw InputError(source_of(config, "material.contact_damping_ratio"),
                       "material.contact_damping_ratio", msg.str());
    }
  }
}

}  // namespace

NamedStiffness softer_normal_stiffness(const Material& material) {
  if (material.wall.kn < material.particle.kn) return {material.wall.kn, "material.wall.kn"};
  return {material.particle.kn, "material.kn"};
}

std::string overlap_culprit(const SceneConfig& config, const std::string& kn_field,
                            const std::optional<double>& tolerance) {
  std::vector<std::string> fields{"test.lateral_stress", kn_field};
  // 2D: the force on a disk per unit stress is sigma3*2r*t.
  if (config.dimension == 2) fields.push_back("material.thickness");
  // The round-off must stay below a tenth of the tolerance of the overlap:
  // the tolerance, when one it may be resolves it.
  if (tolerance) fields.push_back("test.consolidation_tolerance");
  return changed_field(config.sets, fields);
}

std::optional<double> resolving_tolerance(double roundoff, double delta) {
  const double tolerance = 10.0 * roundoff / delta;
  if (tolerance < kConsolidationToleranceBelow) return tolerance;
  return std::nullopt;
}

void check_derived_scales(const SceneConfig& config, std::span<const double> radii,
                          const std::string& radii_file) {
  if (radii.empty()) return;
  // A radius: the config's assembly field, or the particle file's column r.
  auto radius = [&](double r, bool smallest, double power) {
    return radii_file.empty() ? Input{radius_field(config.assembly, smallest), r, power}
                              : Input{"r", r, power, radii_file};
  };
  const bool three_d = config.dimension == 3;
  const Material& mat = config.material;
  const AlgorithmSpec& alg = config.algorithm;
  const double r_min = *std::min_element(radii.begin(), radii.end());
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const char* body = three_d ? "sphere" : "disk";

  // The inputs of a mass: ρ, f_ms (2D: t) and r^3 (2D: r^2).
  auto mass_inputs = [&](double r, bool smallest) {
    std::vector<Input> in{{"material.density", mat.density, 1.0},
                          {"algorithm.mass_scaling", alg.mass_scaling, 1.0}};
    if (!three_d) in.push_back({"material.thickness", mat.thickness, 1.0});
    in.push_back(radius(r, smallest, three_d ? 3.0 : 2.0));
    return in;
  };
  auto scaled = [](std::vector<Input> in, double factor) {
    for (Input& i : in) i.power *= factor;
    return in;
  };
  auto with = [](std::vector<Input> in, std::vector<Input> more) {
    in.insert(in.end(), more.begin(), more.end());
    return in;
  };
  // The masses as the kernels compute them (triaxial.cpp, biaxial.cpp).
  auto mass_of = [&](double r) {
    return three_d ? sphere_mass(mat.density * alg.mass_scaling, r)
                   : disk_mass(disk_areal_density(mat, alg.mass_scaling), r);
  };
  auto inertia_of = [&](double m, double r) {
    return three_d ? sphere_inertia(m, r) : disk_inertia(m, r);
  };
  const std::string mass_formula = three_d ? "f_ms*rho*(4/3)*pi*r^3" : "f_ms*rho*t*pi*r^2";
  const std::string inertia_formula = three_d ? "(2/5)*m*r^2" : "m*r^2/2";

  double m_min = 0.0;
  for (const bool smallest : {true, false}) {
    const double r = smallest ? r_min : r_max;
    const std::string which = std::string(smallest ? "the smallest " : "the largest ") + body +
                              "'s (r = " + shown(r) + " m) ";
    const std::vector<Input> m_in = mass_inputs(r, smallest);
    const double m = mass_of(r);
    require_normal(config, which + "mass " + mass_formula, m, m_in);
    const double inertia = inertia_of(m, r);
    const std::vector<Input> i_in = with(m_in, {radius(r, smallest, 2.0)});
    require_normal(config, which + "moment of inertia " + inertia_formula, inertia, i_in);
    require_normal(config, which + "critical damping 2*sqrt(kn*m)",
                   critical_damping_translation(mat.particle.kn, m),
                   with(scaled(m_in, 0.5), {{"material.kn", mat.particle.kn, 0.5}}));
    require_normal(config, which + "critical damping against a wall 2*sqrt(kn_wall*m)",
                   critical_damping_translation(mat.wall.kn, m),
                   with(scaled(m_in, 0.5), {{"material.wall.kn", mat.wall.kn, 0.5}}));
    if (mat.particle.kt > 0.0)
      require_normal(config, which + "rotational critical damping 2*sqrt(kt*r^2*I)",
                     critical_damping_rotation(mat.particle.kt, r, inertia),
                     with(scaled(i_in, 0.5),
                          {{"material.kt", mat.particle.kt, 0.5}, radius(r, smallest, 1.0)}));
    // The loading's global damping, as the kernels apply it (solver.cpp,
    // sphere_world.cpp): D = ratio·D_crit, semi-implicit, v⁺ = ((1 − c)·v⁻
    // + Δt/m·F)/(1 + c) with c = D·Δt/(2m) (= 2·ratio·alpha for
    // translation, 2·ratio·alpha·sqrt(kt·r²·m/(kn·I)) for rotation, whatever
    // the mass). D must be finite and 1/(1 + c) normal: a ratio of 1e306
    // made D inf, c inf, (1 − c)/(1 + c) NaN, and the loading "diverged:
    // non-finite state" with the advice to decrease dt_ratio. Short of that
    // a large ratio is the overdamped limit, integrated as such (the mean
    // velocity F/D), which the criteria judge.
    const double dt = alg.dt_ratio * critical_time_step(m, mat.particle.kn);
    const double d_t =
        alg.damping_ratio_translation * critical_damping_translation(mat.particle.kn, m);
    if (d_t > 0.0) {
      const std::vector<Input> d_in =
          with(scaled(m_in, 0.5),
               {{"material.kn", mat.particle.kn, 0.5},
                {"algorithm.damping_ratio_translation", alg.damping_ratio_translation, 1.0}});
      require_normal(config, which + "global damping damping_ratio_translation*2*sqrt(kn*m)", d_t,
                     d_in);
      require_normal(config, which + "damped step's factor 1/(1 + D*dt/(2m))",
                     1.0 / (1.0 + d_t * dt / (2.0 * m)),
                     {{"algorithm.damping_ratio_translation", alg.damping_ratio_translation, -1.0},
                      {"algorithm.dt_ratio", alg.dt_ratio, -1.0}});
    }
    const double d_r =
        alg.damping_ratio_rotation * critical_damping_rotation(mat.particle.kt, r, inertia);
    if (d_r > 0.0) {
      const std::vector<Input> d_in =
          with(scaled(i_in, 0.5),
               {{"material.kt", mat.particle.kt, 0.5},
                radius(r, smallest, 1.0),
                {"algorithm.damping_ratio_rotation", alg.damping_ratio_rotation, 1.0}});
      require_normal(config,
                     which + "rotational global damping damping_ratio_rotation*2*sqrt(kt*r^2*I)",
                     d_r, d_in);
      require_normal(config, which + "damped rotation's factor 1/(1 + D_r*dt/(2I))",
                     1.0 / (1.0 + d_r * dt / (2.0 * inertia)),
                     {{"algorithm.damping_ratio_rotation", alg.damping_ratio_rotation, -1.0},
                      {"algorithm.dt_ratio", alg.dt_ratio, -1.0},
                      {"material.kt", mat.particle.kt, -0.5},
                      {"material.kn", mat.particle.kn, 0.5}});
    }
    if (smallest) m_min = m;
  }
  // The steps, at the lightest particle (the smallest: one density).
  const std::vector<Input> m_in = scaled(mass_inputs(r_min, true), 0.5);
  const std::string lightest =
      std::string("the critical step 2*sqrt(m_min/kn) of the smallest ") + body;
  const double dt_crit = critical_time_step(m_min, mat.particle.kn);
  const std::vector<Input> crit_in = with(m_in, {{"material.kn", mat.particle.kn, -0.5}});
  require_normal(config, lightest, dt_crit, crit_in);
  require_normal(
      config,
      std::string("the critical step 2*sqrt(m_min/kn_wall) of the smallest ") + body + " on a wall",
      critical_time_step(m_min, mat.wall.kn),
      with(m_in, {{"material.wall.kn", mat.wall.kn, -0.5}}));
  require_normal(config, "the loading's step dt_ratio*dt_crit", alg.dt_ratio * dt_crit,
                 with(crit_in, {{"algorithm.dt_ratio", alg.dt_ratio, 1.0}}));
  // The consolidation's step: its own α, shrunk for contact dashpots
  // (consolidation_alpha, which the consolidation runs with).
  const double alpha_c =
      consolidation_alpha(mat.contact_damping_ratio, config.dimension, r_min, r_max);
  require_normal(
      config, "the consolidation's step", alpha_c * dt_crit,
      with(crit_in, {{"material.contact_damping_ratio", mat.contact_damping_ratio, -1.0}}));
  // The walls against the consolidation's step.
  check_wall_stiffness(config, alpha_c);
  // Contact dashpots beyond critical: their creep against the budget.
  check_contact_damping_budget(config, m_min, dt_crit, r_min, r_max);
}

}  // namespace demcal::detail
