#include "demcal/upscaling/upscaling.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>

#include "demcal/io/files.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/io/quoted_json.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/rev_3d.hpp"

namespace demcal {

std::string ScalingLaw::name() const {
  return std::abs(exponent - 1.0) < 1e-12 ? "linear" : "power";
}

nlohmann::json to_json(const ScalingLaw& law) {
  return {{"law", law.name()}, {"exponent", law.exponent}, {"source", law.source}};
}

ScalingLaw scaling_law_from_json(const nlohmann::json& j, const std::string& source) {
  ScalingLaw law;
  if (!j.is_object()) throw InputError(source, "", "scaling law: expected an object");
  if (j.contains("exponent")) {
    if (!j["exponent"].is_number())
      throw InputError(source, "exponent", "must be a number, got " + quoted_json(j["exponent"]));
    law.exponent = j["exponent"].get<double>();
    if (!(law.exponent > 0.0 && law.exponent <= 3.0))
      throw InputError(source, "exponent", "must be in (0, 3], got " + j["exponent"].dump());
  }
  if (j.contains("source") && j["source"].is_string())
    law.source = j["source"].get<std::string>();
  else
    law.source = source;
  return law;
}

ScalingLaw default_law(int dimension) {
  ScalingLaw law;
  if (dimension == 3) {
    // The drag of the background damping on spheres moving with the
    // imposed strain rate puts b and sigma apart by ~ zeta·L²/Nstep: the
    // force balance needs Nstep ∝ L², and L² ∝ N^(2/3) for spheres (∝ N for
    // disks: Tu & Andrade's linear law); the servo error needs only ∝ L.
    law.exponent = 2.0 / 3.0;
    law.source =
        "Nstep proportional to L^2 = N^(2/3) on spheres (the force balance's drag term; "
        "measured on FCC 256-23328 and random 500-2000 spheres, reports/scaling-3d.md; Tu & "
        "Andrade's linear law is L^2 for disks)";
  }
  return law;
}

int64_t upscale_steps(int64_t steps_rev, int64_t n_rev, int64_t n_proto, const ScalingLaw& law) {
  if (n_rev <= 0 || n_proto <= 0 || steps_rev <= 0) return steps_rev;
  const double ratio = static_cast<double>(n_proto) / static_cast<double>(n_rev);
  return std::max<int64_t>(
      1, std::llround(static_cast<double>(steps_rev) * std::pow(ratio, law.exponent)));
}

std::string below_rev_note(int64_t n_rev, int64_t n_proto, const ScalingLaw& law) {
  if (n_proto >= n_rev || n_proto <= 0) return "";
  std::ostringstream s;
  s.precision(3);
  s << "the prototype's " << n_proto << " particles are fewer than the REV's " << n_rev << ": the "
    << law.name() << " law is extrapolated below the size it was calibrated at (steps x"
    << std::pow(static_cast<double>(n_proto) / static_cast<double>(n_rev), law.exponent)
    << "); the servo error grows as L/Nstep there, faster than the law allows, so the criteria "
       "may fail: use at least the REV's particles, or check with demcal verify";
  return s.str();
}

std::string rev_size_steps_words(int64_t steps, int64_t n_rev, const char* what) {
  return std::to_string(steps) + " steps, the REV's: not upscaled (the prototype has the REV's " +
         std::to_string(n_rev) + " " + what + ", factor 1)";
}

AlgorithmSpec upscale(const AlgorithmSpec& rev, int64_t n_rev, int64_t n_proto,
                      const ScalingLaw& law) {
  AlgorithmSpec p = rev;
  p.steps = upscale_steps(rev.steps, n_rev, n_proto, law);
  return p;
}

nlohmann::json param_block(const AlgorithmSpec& p, const ParticleScales& s) {
  const double dt = p.dt_ratio * s.dt_crit;
  nlohmann::json block = to_json(p);
  // The calibrated parameters; lock_rotation is a diagnostic switch, never
  // calibrated, and not part of params.json's blocks.
  block.erase("lock_rotation");
  block.update(
      {{"particles", s.particles},
       {"dt", dt},
       {"dt_crit", s.dt_crit},
       {"damping_translation", p.damping_ratio_translation * s.damping_translation_crit},
       {"damping_rotation", p.damping_ratio_rotation * s.damping_rotation_crit},
       // The reference values behind the absolute numbers. Damping is
       // per particle (same ratio for every particle, D ∝ sqrt(m)); the
       // values above are the lightest particle's, these the mean.
       {"damping_translation_mean", p.damping_ratio_translation * s.damping_translation_crit_mean},
       {"damping_rotation_mean", p.damping_ratio_rotation * s.damping_rotation_crit_mean},
       {"damping_translation_crit", s.damping_translation_crit},
       {"damping_rotation_crit", s.damping_rotation_crit},
       {"radius_min", s.radius_min},
       {"radius_max", s.radius_max},
       {"radius_mean", s.radius_mean},
       {"mass_min", s.mass_min},
       {"mass_mean", s.mass_mean},
       {"duration", dt * static_cast<double>(p.steps)}});
  return block;
}

SceneConfig scene_of_size(const SceneConfig& config, int64_t particles) {
  if (particles < 2)
    throw InputError(config.source, "",
                     "a scene needs at least 2 particles, asked for " + std::to_string(particles));
  SceneConfig c = config;
  auto& a = c.assembly;
  if (a.type == "hexagonal" || a.type == "square") {
    const double ratio = static_cast<double>(a.columns) / static_cast<double>(a.rows);
    const int columns = std::max(
        1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(particles) * ratio))));
    const int rows =
        std::max(1, static_cast<int>(std::lround(static_cast<double>(particles) / columns)));
    a.columns = columns;
    a.rows = rows;
  } else if (a.type == "fcc") {
    // The cell aspect kept: every edge scaled by the same factor s, with
    // 4·(s·cx)(s·cy)(s·cz) = particles.
    const double cells = static_cast<double>(a.cells_x) * a.cells_y * a.cells_z;
    const double s = std::cbrt(static_cast<double>(particles) / (4.0 * cells));
    auto edge = [s](int n) { return std::max(1, static_cast<int>(std::lround(n * s))); };
    const int nx = edge(a.cells_x), ny = edge(a.cells_y), nz = edge(a.cells_z);
    if (4.0 * nx * ny * nz > static_cast<double>(kMaxParticles))
      throw InputError(config.source, "prototype.particles",
                       std::string("at most ") + kMaxParticlesWhy + " spheres");
    a.cells_x = nx, a.cells_y = ny, a.cells_z = nz;
  } else if (a.type == "random") {
    if (particles > 10000000)
      throw InputError(config.source, "assembly.count", "at most 10,000,000 particles");
    a.count = static_cast<int>(particles);
  } else {
    throw InputError(config.source, "assembly.type",
                     "a particle file has one size; cut REVs from it instead (demcal rev)");
  }
  c.name = config.name + "@" + std::to_string(particles);
  return c;
}

int64_t particles_of_size(const SceneConfig& config, int64_t particles) {
  const AssemblySpec a = scene_of_size(config, particles).assembly;
  if (a.type == "fcc") return int64_t{4} * a.cells_x * a.cells_y * a.cells_z;
  if (a.type == "hexagonal" || a.type == "square") return int64_t{a.columns} * a.rows;
  return a.count;  // random: the count asked
}

std::string size_rounding(const SceneConfig& config) {
  const std::string& type = config.assembly.type;
  if (type == "fcc") return "an FCC lattice of whole cells";
  if (type == "hexagonal" || type == "square")
    return "a " + type + " lattice of whole columns and rows";
  return "";
}

namespace {

/// Which prototype a command describes, in the order the flags and the
/// config are asked: a particle file given (--prototype), a count given
/// (--particles), the config's prototype.file, its prototype.particles,
/// else the REV itself. Disks and spheres alike.
struct PrototypeChoice {
  enum Kind { kFile, kCount, kRev } kind = kRev;
  std::string file;
  int64_t particles = 0;
};

PrototypeChoice choose_prototype(const SceneConfig& config, int64_t particles,
                                 const std::string& file) {
  if (!file.empty()) return {PrototypeChoice::kFile, file, 0};
  if (particles > 0) return {PrototypeChoice::kCount, "", particles};
  if (!config.prototype.file.empty()) return {PrototypeChoice::kFile, config.prototype.file, 0};
  if (config.prototype.particles > 0)
    return {PrototypeChoice::kCount, "", config.prototype.particles};
  return {};
}

/// What the prototype `choice` gave, `size` `noun` ("particles",
/// "spheres"); a generated one says how in `generated`.
PrototypeSource prototype_source(const PrototypeChoice& choice, int64_t size,
                                 const std::string& noun, std::string generated) {
  PrototypeSource src;
  src.particles = size;
  switch (choice.kind) {
    case PrototypeChoice::kFile:
      src.kind = "file";
      src.file = choice.file;
      src.description = std::to_string(size) + " " + noun + " read from " + choice.file;
      break;
    case PrototypeChoice::kCount:
      src.kind = "generated";
      src.description = std::move(generated);
      break;
    case PrototypeChoice::kRev:
      src.kind = "rev";
      src.description = "the REV itself (" + std::to_string(size) + " " + noun + ")";
      break;
  }
  return src;
}

/// A generated prototype is a gas of `n` particles at `aspect` (named
/// `aspect_name` in the error): refused, naming `origin`, when it never
/// consolidates, by the rule a config's assembly.count and assembly.aspect
/// are held to (gas_layers_fault). Checked before the gas is made.
void require_prototype_gas(int dimension, int64_t n, double aspect, const std::string& aspect_name,
                           const CountOrigin& origin) {
  const std::string problem = gas_layers_problem(
      dimension, static_cast<int>(std::min<int64_t>(n, kMaxParticles)), aspect, aspect_name);
  if (!problem.empty())
    throw InputError(origin.file, origin.field,
                     "a prototype generated as a gas of " + std::to_string(n) +
                         (dimension == 3 ? " spheres: " : " disks: ") + problem);
}

/// `n` disks: the config's generator resized, or for a REV read from a
/// file (no generator to resize) a gas of radii drawn from that file.
/// A random gas, or a gas of the file's radii, must consolidate
/// (require_prototype_gas, `origin`).
Assembly generated_disks(const SceneConfig& config, int64_t n, const CountOrigin& origin,
                         std::string& description) {
  if (config.assembly.type == "file") {
    require_prototype_gas(2, n, 1.0, "a square box", origin);
    require_config_file(config, "assembly.file", config.assembly.file);
    const Assembly rev = read_particle_file(config.assembly.file);
    description = std::to_string(n) + " particles with radii drawn from " + config.assembly.file;
    return gas_of_radii(resample_radii(rev.r, n, config.calibration.seed), 1.0,
                        config.calibration.seed);
  }
  if (config.assembly.type == "random")
    require_prototype_gas(2, n, config.assembly.aspect, "assembly.aspect", origin);
  const SceneConfig c = scene_of_size(config, n);
  Assembly a = make_assembly(c, "the prototype");
  description = std::to_string(a.size()) + " particles from the " + c.assembly.type +
                " generator of " + config.name;
  return a;
}

/// `n` spheres, likewise (an fcc generator names its cells).
SphereAssembly generated_spheres(const SceneConfig& config, int64_t n, const CountOrigin& origin,
                                 std::string& description) {
  if (config.assembly.type == "file") {
    require_config_file(config, "assembly.file", config.assembly.file);
    const SphereAssembly rev = read_sphere_file(config.assembly.file);
    require_prototype_gas(3, n, rev_gas_aspect(rev),
                          config.assembly.file + "'s sqrt(width*depth)/height", origin);
    SphereAssembly a = generate_rev(rev, n, config.calibration.seed);
    description =
        std::to_string(a.size()) + " spheres with radii drawn from " + config.assembly.file;
    return a;
  }
  if (config.assembly.type == "random")
    require_prototype_gas(3, n, config.assembly.aspect, "assembly.aspect", origin);
  const SceneConfig c = scene_of_size(config, n);
  SphereAssembly a = make_sphere_assembly(c, "the prototype");
  const auto& s = c.assembly;
  description =
      std::to_string(a.size()) + " spheres from the " + s.type + " generator of " + config.name +
      (s.type == "fcc" ? " (" + std::to_string(s.cells_x) + "x" + std::to_string(s.cells_y) + "x" +
                             std::to_string(s.cells_z) + " cells)"
                       : std::string());
  return a;
}

}  // namespace

namespace {

/// The prototype choose_prototype picks, disks or spheres: `read` a file,
/// `generate` a count, or `make` the REV; what it gave goes to `source`.
template <class Read, class Generate, class Make>
auto chosen_prototype(const SceneConfig& config, int64_t particles, const std::string& file,
                      PrototypeSource* source, const CountOrigin& count_origin,
                      const std::string& noun, Read read, Generate generate, Make make) {
  const PrototypeChoice choice = choose_prototype(config, particles, file);
  std::string generated;
  decltype(make(config)) a;
  if (choice.kind == PrototypeChoice::kFile) {
    // Not --prototype's (its own name says which file): the config's.
    if (file.empty()) require_config_file(config, "prototype.file", choice.file);
    a = read(choice.file);
  } else if (choice.kind == PrototypeChoice::kCount)
    // The count is the command's (--particles, or verify's and export's
    // from params.json: `count_origin`) when given, else the config's.
    a = generate(config, choice.particles,
                 particles > 0
                     ? count_origin
                     : CountOrigin{source_of(config, "prototype.particles"), "prototype.particles"},
                 generated);
  else
    a = make(config);
  if (source) *source = prototype_source(choice, a.size(), noun, std::move(generated));
  return a;
}

}  // namespace

Assembly prototype_assembly(const SceneConfig& config, int64_t particles, const std::string& file,
                            PrototypeSource* source, const CountOrigin& count_origin) {
  return chosen_prototype(
      config, particles, file, source, count_origin, "particles",
      [&config](const std::string& f) {
        Assembly a = read_particle_file(f);
        check_particle_file_scales(config, a.r, f);
        return a;
      },
      generated_disks, [](const SceneConfig& c) { return make_assembly(c); });
}

SphereAssembly prototype_spheres(const SceneConfig& config, int64_t particles,
                                 const std::string& file, PrototypeSource* source,
                                 const CountOrigin& count_origin) {
  return chosen_prototype(
      config, particles, file, source, count_origin, "spheres",
      [&config](const std::string& f) {
        SphereAssembly a = read_sphere_file(f);
        check_particle_file_scales(config, a.r, f);
        return a;
      },
      generated_spheres, [](const SceneConfig& c) { return make_sphere_assembly(c); });
}

namespace {

std::string prototype_words(const PrototypeSource& source) {
  return source.kind == "rev" ? "the scene" : "the prototype";
}
std::string prototype_file(const PrototypeSource& source) {
  return source.kind == "file" ? source.file : "";
}

}  // namespace

void check_prototype_assembly(const SceneConfig& config, const Assembly& prototype,
                              const PrototypeSource& source) {
  check_assembly(config, prototype, prototype_words(source), prototype_file(source), source.tiling);
}

void check_prototype_assembly(const SceneConfig& config, const SphereAssembly& prototype,
                              const PrototypeSource& source) {
  check_sphere_assembly(config, prototype, prototype_words(source), prototype_file(source));
}

ParticleScales sphere_scales(const SphereWorld& w, const Material& material,
                             const AlgorithmSpec& params) {
  // The sphere scales at the run's mass scaling, from the kernel's masses
  // (m = ρ(4/3)πr³, I = (2/5)mr²); the radius and mean-mass entries that
  // SphereWorld::reference_scales() leaves out are filled here.
  SphereWorld world = w;
  world.set_integration(integration_for(world, params));
  ParticleScales scales = world.reference_scales();
  const int64_t n = world.size();
  scales.particles = n;
  const auto radii = world.radius();
  double sum_r = 0.0, sum_m = 0.0;
  scales.radius_min = radii.empty() ? 0.0 : radii[0];
  for (double r : radii) {
    sum_r += r;
    sum_m += sphere_mass(material.density * params.mass_scaling, r);
    scales.radius_min = std::min(scales.radius_min, r);
    scales.radius_max = std::max(scales.radius_max, r);
  }
  if (n > 0) {
    scales.radius_mean = sum_r / static_cast<double>(n);
    scales.mass_mean = sum_m / static_cast<double>(n);
  }
  return scales;
}

nlohmann::json upscaling_block(int64_t n_rev, int64_t n_proto, const ScalingLaw& law) {
  const double ratio =
      static_cast<double>(n_proto) / static_cast<double>(std::max<int64_t>(1, n_rev));
  return {{"law", law.name()},
          {"exponent", law.exponent},
          {"factor", std::pow(ratio, law.exponent)},
          {"particles_rev", n_rev},
          {"particles_prototype", n_proto},
          {"source", law.source},
          {"formula",
           "steps_prototype = steps_rev * (particles_prototype / particles_rev)^exponent; "
           "dt_ratio, damping ratios and mass scaling unchanged; dt and damping "
           "recomputed from the prototype's particles"}};
}

nlohmann::json prototype_block(const SceneConfig& config, const AlgorithmSpec& rev, int64_t n_rev,
                               const ScalingLaw& law, int64_t particles, const std::string& file) {
  PrototypeSource src;
  nlohmann::json block;
  if (config.dimension == 3) {
    const SphereAssembly proto = prototype_spheres(config, particles, file, &src);
    const SphereWorld world(sphere_material(config.material), proto.x, proto.y, proto.z, proto.r,
                            proto.lo, proto.hi);
    const AlgorithmSpec up = upscale(rev, n_rev, proto.size(), law);
    block = param_block(up, sphere_scales(world, config.material, up));
  } else {
    const Assembly proto = prototype_assembly(config, particles, file, &src);
    const ParticleScales scales = particle_scales(proto.r, config.material, rev.mass_scaling);
    block = param_block(upscale(rev, n_rev, proto.size(), law), scales);
  }
  block["source"] = {{"kind", src.kind}, {"description", src.description}};
  if (!src.file.empty()) block["source"]["file"] = src.file;
  return block;
}

namespace {

double number_at(const nlohmann::json& block, const std::string& key, const std::string& source,
                 const std::string& where) {
  if (!block.contains(key))
    throw InputError(source, where + "." + key, "missing (not a demcal params.json?)");
  if (!block[key].is_number())
    throw InputError(source, where + "." + key, "must be a number, got " + quoted_json(block[key]));
  const double v = block[key].get<double>();
  if (!std::isfinite(v))
    throw InputError(source, where + "." + key, "must be finite, got " + block[key].dump());
  return v;
}

}  // namespace

RevParams rev_params_from_json(const nlohmann::json& params, const std::string& source) {
  if (!params.is_object() || !params.contains("rev") || !params["rev"].is_object())
    throw InputError(source, "rev", "missing (not a demcal params.json?)");
  const auto& b = params["rev"];
  RevParams out;
  auto& p = out.params;
  p.dt_ratio = number_at(b, "dt_ratio", source, "rev");
  // Counts: whole numbers (json_integer), never a double rounded (2.5).
  auto present = [&](const char* key) -> const nlohmann::json& {
    if (!b.contains(key))
      throw InputError(source, std::string("rev.") + key, "missing (not a demcal params.json?)");
    return b[key];
  };
  p.steps = json_integer(present("steps"), 1, kMaxSteps, source, "rev.steps");
  p.damping_ratio_translation = number_at(b, "damping_ratio_translation", source, "rev");
  p.damping_ratio_rotation = number_at(b, "damping_ratio_rotation", source, "rev");
  p.mass_scaling = b.contains("mass_scaling") ? number_at(b, "mass_scaling", source, "rev") : 1.0;
  out.particles = particle_count(present("particles"), 1, source, "rev.particles");
  if (!(p.dt_ratio > 0.0 && p.dt_ratio < 2.0))
    throw InputError(source, "rev.dt_ratio", "must be in (0, 2), got " + b["dt_ratio"].dump());
  if (p.damping_ratio_translation < 0.0 || p.damping_ratio_rotation < 0.0)
    throw InputError(source, "rev.damping_ratio_translation", "damping ratios must be >= 0");
  if (!(p.mass_scaling > 0.0)) throw InputError(source, "rev.mass_scaling", "must be > 0");
  auto& s = out.scales;
  s.particles = out.particles;
  s.dt_crit = number_at(b, "dt_crit", source, "rev");
  if (!(s.dt_crit > 0.0))
    throw InputError(source, "rev.dt_crit",
                     "must be > 0 (a time step), got " + b["dt_crit"].dump());
  auto crit = [&](const char* abs_key, const char* crit_key, double ratio) {
    if (b.contains(crit_key)) return number_at(b, crit_key, source, "rev");
    if (ratio > 0.0 && b.contains(abs_key)) return number_at(b, abs_key, source, "rev") / ratio;
    return 0.0;
  };
  s.damping_translation_crit =
      crit("damping_translation", "damping_translation_crit", p.damping_ratio_translation);
  s.damping_rotation_crit =
      crit("damping_rotation", "damping_rotation_crit", p.damping_ratio_rotation);
  s.damping_translation_crit_mean = s.damping_translation_crit;
  s.damping_rotation_crit_mean = s.damping_rotation_crit;
  if (s.damping_translation_crit < 0.0 || s.damping_rotation_crit < 0.0)
    throw InputError(source, "rev.damping_translation_crit", "critical dampings must be >= 0");
  if (b.contains("radius_min")) s.radius_min = number_at(b, "radius_min", source, "rev");
  if (b.contains("mass_min")) s.mass_min = number_at(b, "mass_min", source, "rev");
  if (s.radius_min < 0.0 || s.mass_min < 0.0)
    throw InputError(source, s.radius_min < 0.0 ? "rev.radius_min" : "rev.mass_min", "must be > 0");
  s.mass_mean = s.mass_min;
  return out;
}

std::optional<SceneConfig> config_from_params(const nlohmann::json& params,
                                              const std::string& source) {
  if (!params.is_object() || !params.contains("config")) return std::nullopt;
  if (!params["config"].is_object())
    throw InputError(source, "config", "must be the scene config object");
  SceneConfig c = parse_config(params["config"], source + ": config");
  c.text = params["config"].dump();
  return c;
}

LinearFit fit_linear(std::span<const double> x, std::span<const double> y) {
  LinearFit f;
  const size_t n = std::min(x.size(), y.size());
  if (n < 2) return f;
  const double mx = std::accumulate(x.begin(), x.begin() + n, 0.0) / n;
  const double my = std::accumulate(y.begin(), y.begin() + n, 0.0) / n;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (sxx <= 0.0) return f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double ss_res = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double e = y[i] - (f.slope * x[i] + f.intercept);
    ss_res += e * e;
  }
  f.r2 = syy > 0.0 ? 1.0 - ss_res / syy : 1.0;
  return f;
}

LinearFit fit_power(std::span<const double> x, std::span<const double> y) {
  std::vector<double> lx, ly;
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (x[i] <= 0.0 || y[i] <= 0.0) continue;
    lx.push_back(std::log(x[i]));
    ly.push_back(std::log(y[i]));
  }
  return fit_linear(lx, ly);
}

}  // namespace demcal

namespace demcal {

StepSearch smallest_passing_steps(const SceneConfig& config, const ConsolidatedState& state,
                                  const AlgorithmSpec& start, const Tolerances& tol, int max_runs) {
  return smallest_passing_steps(BiaxialRunner(config, state), start, tol, nullptr, max_runs);
}

StepSearch smallest_passing_steps(const TrialRunner& runner, const AlgorithmSpec& start,
                                  const Tolerances& tol, const std::atomic<bool>* stop,
                                  int max_runs, const StepSearchRecord& record) {
  const auto stopped = [stop] { return stop && stop->load(); };
  StepSearch out;
  AlgorithmSpec p = start;
  p.steps = round_steps(static_cast<double>(start.steps));
  int64_t largest_failing = 0;
  for (int k = 0; k < max_runs; ++k) {
    if (stopped()) {
      out.interrupted = true;
      break;
    }
    // An earlier search's k-th run, when it ran what this one asks (its
    // parameters compared in their one JSON form, which keeps every bit).
    const bool reuse = out.reused == k && k < static_cast<int>(record.earlier.size()) &&
                       to_json(record.earlier[static_cast<size_t>(k)].params) == to_json(p);
    TrialRecord r =
        reuse ? record.earlier[static_cast<size_t>(k)] : run_trial(runner, p, tol, stop);
    // Possibly cut short by the stop: neither a run nor a guide to the next.
    if (!reuse && stopped()) {
      out.interrupted = true;
      break;
    }
    r.id = k;
    r.phase = TrialPhase::steps_search;
    out.trials.push_back(r);
    if (reuse) ++out.reused;
    if (record.on_trial) record.on_trial(out.trials, reuse);
    out.particle_steps += r.score.particle_steps;
    if (r.score.diverged) break;
    const double excess = rate_excess(r.score.criteria, tol);
    double next;
    if (r.score.passed) {
      if (!out.found || p.steps < out.best.params.steps) out.best = r;
      out.found = true;
      if (excess > 0.93) break;  // within 7 % of the boundary
      next = static_cast<double>(p.steps) * std::max(excess, 0.3) * 1.04;
    } else {
      largest_failing = std::max(largest_failing, p.steps);
      // Rate-driven failure: the 1/Nstep model predicts; anything else
      // (oscillation) is not cured by more steps, but try twice as many once.
      next = static_cast<double>(p.steps) * (excess > 1.0 ? excess * 1.05 : 2.0);
    }
    if (out.found && next >= static_cast<double>(out.best.params.steps)) {
      // Between the largest failing and the smallest passing run.
      if (largest_failing == 0) break;
      next = std::sqrt(static_cast<double>(largest_failing) *
                       static_cast<double>(out.best.params.steps));
    }
    if (next <= static_cast<double>(largest_failing)) next = 1.05 * largest_failing;
    const int64_t n = round_steps(next);
    if (out.found &&
        (n >= out.best.params.steps || static_cast<double>(out.best.params.steps - n) <
                                           0.03 * static_cast<double>(out.best.params.steps)))
      break;
    bool seen = false;
    for (const auto& t : out.trials) seen |= t.params.steps == n;
    if (seen) break;
    p.steps = n;
  }
  return out;
}

}  // namespace demcal

namespace demcal {

nlohmann::json read_json_file(const std::string& path) {
  // The config's reader: a folder or a loop named, every nlohmann error
  // (1e999 is out_of_range, not a parse error) an InputError with its line,
  // duplicate keys refused.
  return parse_config_json(read_text_file(path), path);
}

}  // namespace demcal
