// Config parsing and validation. A small Reader walks one JSON object,
// converting and checking each key, and finally rejects keys it never read.
#include "demcal/scene/config.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/io/quoted_json.hpp"
#include "demcal/scene/packing.hpp"
#include "derived_scales.hpp"

namespace demcal {

namespace {

using nlohmann::json;

/// A key as the user wrote it, or quoted and cut when it is long or holds
/// control characters (the message stays one short line).
std::string shown_key(const std::string& key) {
  const bool plain = key.size() <= 80 && std::none_of(key.begin(), key.end(), [](char ch) {
                       return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f;
                     });
  return plain ? key : quoted_value(key);
}

class Reader {
 public:
  Reader(const json& object, std::string file, std::string path)
      : object_(object), file_(std::move(file)), path_(std::move(path)) {
    if (!object_.is_object()) fail("", "must be an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file_, field(key), what);
  }
  std::string field(const std::string& key) const {
    if (path_.empty()) return key;
    return key.empty() ? path_ : path_ + "." + key;
  }
  bool has(const std::string& key) const { return object_.contains(key); }

  double number(const std::string& key, double fallback) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    if (!v.is_number()) fail(key, "must be a number, got " + quoted_json(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "must be finite");
    return d;
  }
  /// A number in `range` (finite: number()).
  double in_range(const std::string& key, double fallback, const RealRange& range) {
    const double d = number(key, fallback);
    if (!range.contains(d)) fail(key, "must be " + range.text() + ", got " + format(d));
    return d;
  }
  double positive(const std::string& key, double fallback) {
    return in_range(key, fallback, kPositive);
  }
  double non_negative(const std::string& key, double fallback) {
    return in_range(key, fallback, RealRange{0.0, true});
  }
  /// A whole number, read as an integer (never through a double that could
  /// overflow the cast): 100000, or 1e5 in exponent form when that is exact.
  int64_t integer(const std::string& key, int64_t fallback, int64_t min, int64_t max) {
    used_.insert(key);
    if (!has(key)) return fallback;
    return json_integer(object_.at(key), min, max, file_, field(key));
  }
  /// A particle count: particle_count() from `min` to kMaxParticles.
  int64_t particles(const std::string& key, int64_t fallback, int64_t min) {
    used_.insert(key);
    if (!has(key)) return fallback;
    return particle_count(object_.at(key), min, file_, field(key));
  }
  bool boolean(const std::string& key, bool fallback) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    if (!v.is_boolean()) fail(key, "must be true or false, got " + quoted_json(v));
    return v.get<bool>();
  }
  std::string string(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& choices = {}) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    if (!v.is_string()) fail(key, "must be a string, got " + quoted_json(v));
    std::string s = v.get<std::string>();
    if (!choices.empty()) {
      bool ok = false;
      std::string list;
      for (const auto& c : choices) {
        ok = ok || c == s;
        list += (list.empty() ? "" : ", ") + c;
      }
      if (!ok) fail(key, "must be one of " + list + ", got " + quoted_value(s));
    }
    return s;
  }
  /// A nested object, or an empty one when absent.
  Reader child(const std::string& key) {
    used_.insert(key);
    static const json kEmpty = json::object();
    return Reader(has(key) ? object_.at(key) : kEmpty, file_, field(key));
  }
  void reject_unknown() const {
    for (auto it = object_.begin(); it != object_.end(); ++it)
      if (!used_.count(it.key())) fail(shown_key(it.key()), "unknown key");
  }
  /// Keys with no sensible default: absent is an error naming the key.
  void require(const std::vector<std::string>& keys, const std::string& why) const {
    if (!object_.is_object()) return;
    for (const auto& k : keys)
      if (!has(k)) fail(k, "required (" + why + ")");
  }

 private:
  static std::string format(double d) {
    std::ostringstream s;
    s << d;
    return s.str();
  }
  const json& object_;
  std::string file_, path_;
  std::set<std::string> used_;
};

ContactLaw read_contact(Reader& r, const ContactLaw& fallback) {
  ContactLaw c;
  c.kn = r.positive("kn", fallback.kn);
  c.kt = r.non_negative("kt", fallback.kt);
  c.friction = r.non_negative("friction", fallback.friction);
  return c;
}

/// The algorithm block: every key optional (missing ones keep `base`),
/// checked, unknown keys rejected. Shared by the config and every record
/// that stores an AlgorithmSpec (trials.jsonl, the scaling study's files).
AlgorithmSpec read_algorithm(Reader& a, AlgorithmSpec s) {
  s.dt_ratio = a.positive("dt_ratio", s.dt_ratio);
  if (s.dt_ratio > 2.0) a.fail("dt_ratio", "must be <= 2 (beyond the single-spring limit)");
  s.steps = a.integer("steps", s.steps, 10, kMaxSteps);
  s.damping_ratio_translation =
      a.in_range("damping_ratio_translation", s.damping_ratio_translation, kDampingRatio);
  s.damping_ratio_rotation =
      a.in_range("damping_ratio_rotation", s.damping_ratio_rotation, kDampingRatio);
  s.mass_scaling = a.in_range("mass_scaling", s.mass_scaling, kMassScaling);
  s.lock_rotation = a.boolean("lock_rotation", s.lock_rotation);
  a.reject_unknown();
  return s;
}

// The scene name becomes part of default output paths ("demcal-run-NAME"):
// it must be a plain file name, or "/../../tmp/x" writes elsewhere and
// "a/b" makes nested folders. Rejected rather than rewritten: a silently
// changed name would put the results where the user does not look.
void check_scene_name(const Reader& root, const std::string& name) {
  if (name.empty()) root.fail("name", "must not be empty");
  if (name.size() > 200)
    root.fail("name", "must be at most 200 characters (it becomes a file name), got " +
                          std::to_string(name.size()));
  for (char ch : name) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '/' || ch == '\\' || u < 0x20 || u == 0x7f)
      root.fail("name",
                "must be a plain file name (no / or \\ or control characters: it names "
                "the default output folder), got " +
                    quoted_value(name));
  }
}

// Mindlin's elastic contact has kt/kn = 2(1 - nu)/(2 - nu), between 2/3
// (nu = 0.5) and 1 (nu = 0): kt > kn means a negative Poisson ratio, no
// granular material. It is also where the run breaks: dt_ratio is relative
// to 2*sqrt(m/kn), and the tangential-rotational mode of a solid disk
// (omega^2 = 3 kt/m against kn/m for the normal one) then outruns the
// normal springs, so consolidation at dt_ratio 0.2 diverges (kt = 1.2 kn on
// hex_5x5; kt = kn runs). Walls do not rotate: their kt is not bound.
// The error names kn when a --set gave it and none gave kt (changed_field).
void check_tangential_stiffness(const Reader& m, const ContactLaw& particle,
                                const std::vector<std::string>& sets) {
  if (particle.kt <= particle.kn) return;
  const std::string why =
      "kt/kn = 2(1-nu)/(2-nu) "
      "<= 1 for an elastic contact, and beyond it the tangential-rotational mode "
      "outruns the normal step dt_ratio refers to; got ";
  if (changed_field(sets, {"material.kt", "material.kn"}) == "material.kn")
    m.fail("kn", "must be at least kt (" + num(particle.kt, 6) + "): " + why + num(particle.kn, 6));
  m.fail("kt", "must not exceed kn (" + num(particle.kn, 6) + "): " + why + num(particle.kt, 6));
}

// Overlap at sigma3: a disk of radius r carries about sigma3*2r*t per
// contact, so delta/r = 2*sigma3*t/kn whatever r. The kernel stops a run as
// diverged when an overlap exceeds half the smallest radius
// (Options::max_overlap_ratio), and at the peak sigma1 reaches several
// times sigma3: delta/r <= 5 % at sigma3 leaves a factor 10. (The lower
// bound depends on the box and is checked with the assembly:
// check_resolvable in packing.cpp.) sigma3 or t too high, or kn too low: the
// error names the one a --set changed (detail::overlap_culprit, the rule of
// the checks with the assembly), and gives both bounds (t's too when named).
void check_lateral_stress(const SceneConfig& c) {
  const Material& m = c.material;
  const double sigma3 = c.test.lateral_stress;
  const auto [kn, kn_field] = detail::softer_normal_stiffness(m);
  const double limit = kMaxOverlapAtSigma3 / 2.0 * kn / m.thickness;
  if (sigma3 <= limit) return;
  const std::string field = detail::overlap_culprit(c, kn_field);
  std::ostringstream msg;
  msg << "the overlap at sigma3, 2*sigma3*t/kn = " << 2.0 * sigma3 * m.thickness / kn
      << " of the radius (sigma3 = " << sigma3 << " Pa, thickness " << m.thickness << " m, "
      << kn_field << " = " << kn << " N/m), must stay below " << kMaxOverlapAtSigma3
      << " (the run stops at 0.5 and the peak stress is several times sigma3): "
      << "test.lateral_stress must be at most " << limit << " Pa, or " << kn_field << " at least "
      << 2.0 * sigma3 * m.thickness / kMaxOverlapAtSigma3 << " N/m";
  if (field == "material.thickness")
    msg << ", or material.thickness at most " << kMaxOverlapAtSigma3 / 2.0 * kn / sigma3
        << " m; got " << m.thickness;
  else
    msg << "; got " << (field == kn_field ? kn : sigma3);
  throw InputError(c.source, field, msg.str());
}

// The servo removes at most the fraction `gain` of the wall-stress error per
// step (the true stiffness is lower than the one it assumes), and a packing
// starts unstressed (error 1): reaching consolidation_tolerance takes at
// least ln(1/tol)/(-ln(1 - gain)) steps. A gain that needs more than
// consolidation_max_steps can never consolidate. The error names the key a
// --set changed (changed_field: the gain when one changed it, else the
// budget, else the tolerance), with that key's own bound; a budget whose
// bound is beyond the largest it may be (kMaxConsolidationSteps) is no
// culprit: the gain is named then.
void check_servo_gain(const Reader& t, const TestSpec& test, const std::vector<std::string>& sets) {
  const double per_step = -std::log1p(-test.servo_gain);  // -ln(1 - gain): the log-decrement a step
  const double needed = std::log(1.0 / test.consolidation_tolerance) / per_step;
  const auto budget = static_cast<double>(test.consolidation_max_steps);
  if (needed <= budget) return;
  std::ostringstream why;
  why << "the servo removes at most the fraction gain of the stress error per step, so reaching "
         "consolidation_tolerance "
      << test.consolidation_tolerance << " at servo_gain " << test.servo_gain
      << " takes at least ln(1/tol)/(-ln(1-gain)) = ";
  // A whole number of steps where it is one to type (a stream's 6 digits
  // would say 1.38154e+06).
  if (needed < 1e18)
    why << static_cast<int64_t>(std::ceil(needed));
  else
    why << needed;
  why << " steps, more than consolidation_max_steps " << test.consolidation_max_steps;
  if (needed > static_cast<double>(kMaxConsolidationSteps))
    why << " (and than the largest it may be, " << kMaxConsolidationSteps << ")";
  const std::string key = changed_field(
      sets, {"test.servo_gain", "test.consolidation_max_steps", "test.consolidation_tolerance"});
  std::ostringstream msg;
  if (key == "test.consolidation_max_steps" &&
      needed <= static_cast<double>(kMaxConsolidationSteps)) {
    // The smallest budget that passes, as the integer to type (a stream's
    // 6 digits would say 1.38154e+06).
    msg << "must be at least " << static_cast<int64_t>(std::ceil(needed)) << ": " << why.str()
        << "; got " << test.consolidation_max_steps;
    t.fail("consolidation_max_steps", msg.str());
  }
  if (key == "test.consolidation_tolerance") {
    msg << "must be at least " << std::exp(-budget * per_step) << ": " << why.str() << "; got "
        << test.consolidation_tolerance;
    t.fail("consolidation_tolerance", msg.str());
  }
  msg << "must be at least " << -std::expm1(-std::log(1.0 / test.consolidation_tolerance) / budget)
      << ": " << why.str() << "; got " << test.servo_gain;
  t.fail("servo_gain", msg.str());
}

// The material is the physics being calibrated: a default density,
// stiffness or friction would be a calibration of a material the user never
// gave. thickness (2D: per metre, 1 by convention), contact_damping_ratio
// (a model option, off unless asked) and the walls (boundary conditions,
// frictionless by default) keep their documented defaults. Checked after
// every other key, so that a wrong value is named before a missing one.
void require_material(const Reader& root, const json& root_json, const std::string& source) {
  const std::string why = "the material is the physics being calibrated; no default stands in";
  if (!root.has("material")) root.fail("material", "required (" + why + ")");
  Reader(root_json.at("material"), source, "material")
      .require({"density", "kn", "kt", "friction"}, why);
}

// A particle file named in `source`: a relative name is relative to the
// folder of the file that names it (a config; for params.json's "config"
// object, "DIR/params.json: config", the params.json's folder), and is made
// absolute here. An absolute name reads the same from any working
// directory, and to_json() writes it so into params.json: calibrate,
// upscale -o and a calibration folder moved elsewhere all leave it naming
// the same file (a relative one would be joined to params.json's folder
// again on reading, or break when the folder moves without the data).
// "<embedded default ...>" has no folder: the working directory.
std::string resolved_file(const std::string& file, const std::string& source) {
  namespace fs = std::filesystem;
  fs::path path(file);
  if (path.is_relative() && source.rfind('<', 0) != 0) path = fs::path(source).parent_path() / path;
  // Not lexically_normal(): "link/../p.csv" is for the system to resolve
  // (through the link), not for the text to cancel.
  return fs::absolute(path).string();
}

}  // namespace

std::string RealRange::text() const {
  std::ostringstream s;
  s << (lo_included ? ">= " : "> ") << lo;
  if (std::isfinite(hi)) s << " and <= " << hi;
  return s.str();
}

int64_t particle_count(const nlohmann::json& value, int64_t min, const std::string& file,
                       const std::string& field) {
  try {
    return json_integer(value, min, kMaxParticles);
  } catch (const std::logic_error& e) {  // invalid_argument, out_of_range
    throw InputError(
        file, field,
        std::string(e.what()) + " (a particle count: at most " + kMaxParticlesWhy + ")");
  }
}

void require_calibration_budget(const SceneConfig& config) {
  if (config.calibration.max_trials >= kMinSearchTrials) return;
  throw InputError(config.source, "calibration.max_trials",
                   "must be at least " + std::to_string(kMinSearchTrials) + " (" +
                       kMinSearchTrialsWhy + "), got " +
                       std::to_string(config.calibration.max_trials));
}

void require_stable_dt_ratio(double dt_ratio, double stable, const std::string& file,
                             const std::string& field, const std::string& remedy) {
  if (dt_ratio <= stable) return;
  std::ostringstream s;
  s << std::setprecision(4) << dt_ratio
    << " is beyond the stable step estimated from the consolidated contact network, " << stable
    << " (" << remedy << ")";
  throw InputError(file, field, s.str());
}

nlohmann::json to_json(const AlgorithmSpec& g) {
  return {{"dt_ratio", g.dt_ratio},
          {"steps", g.steps},
          {"damping_ratio_translation", g.damping_ratio_translation},
          {"damping_ratio_rotation", g.damping_ratio_rotation},
          {"mass_scaling", g.mass_scaling},
          {"lock_rotation", g.lock_rotation}};
}

AlgorithmSpec algorithm_from_json(const nlohmann::json& json, const std::string& source,
                                  const std::string& field, const AlgorithmSpec& base) {
  Reader a(json, source, field);
  return read_algorithm(a, base);
}

namespace {

// Uniform radii need radius_min <= radius_max; the error names the bound a
// --set changed (changed_field), with both values.
void check_radius_bounds(const Reader& a, const AssemblySpec& s,
                         const std::vector<std::string>& sets) {
  if (s.radius_min <= s.radius_max) return;
  if (changed_field(sets, {"assembly.radius_min", "assembly.radius_max"}) == "assembly.radius_max")
    a.fail("radius_max", "must not be below radius_min (" + num(s.radius_min, 6) + "), got " +
                             num(s.radius_max, 6));
  a.fail("radius_min",
         "must not exceed radius_max (" + num(s.radius_max, 6) + "), got " + num(s.radius_min, 6));
}

// A lattice (fcc: 4 spheres a cell; hexagonal, square: a disk a column and
// row) of at most kMaxParticles. The product's limit is the only bound, named
// by the key a --set changed (changed_field: cells_x, or columns, when none
// or several did).
void check_lattice_size(const Reader& a, const AssemblySpec& s,
                        const std::vector<std::string>& sets) {
  if (s.type == "fcc") {
    const double spheres = 4.0 * s.cells_x * static_cast<double>(s.cells_y) * s.cells_z;
    if (spheres <= static_cast<double>(kMaxParticles)) return;
    const std::string key =
        changed_field(sets, {"assembly.cells_x", "assembly.cells_y", "assembly.cells_z"});
    // The count as a whole number (std::to_string(double) wrote
    // "64000000.000000"); a double, since the product can pass int64.
    std::ostringstream count;
    count << std::fixed << std::setprecision(0) << spheres;
    a.fail(key.substr(key.find('.') + 1), "4 x cells_x x cells_y x cells_z = " + count.str() +
                                              " particles, more than the limit " +
                                              kMaxParticlesWhy);
  }
  if (int64_t{s.columns} * s.rows <= kMaxParticles) return;
  const std::string key = changed_field(sets, {"assembly.columns", "assembly.rows"});
  a.fail(key.substr(key.find('.') + 1),
         "columns x rows = " + std::to_string(int64_t{s.columns} * s.rows) +
             " particles, more than the limit " + kMaxParticlesWhy);
}

// M points of the curve need at least M steps: more would repeat steps in
// series.csv and slow every run by the extra measurements. The error names
// the one a --set changed (changed_field).
void check_monitor_points(const SceneConfig& c, const std::string& source,
                          const std::vector<std::string>& sets) {
  if (c.test.monitor_points <= c.algorithm.steps) return;
  if (changed_field(sets, {"test.monitor_points", "algorithm.steps"}) == "algorithm.steps")
    throw InputError(source, "algorithm.steps",
                     "must be at least test.monitor_points (" +
                         std::to_string(c.test.monitor_points) + "), got " +
                         std::to_string(c.algorithm.steps));
  throw InputError(source, "test.monitor_points",
                   "must not exceed algorithm.steps (" + std::to_string(c.algorithm.steps) +
                       "), got " + std::to_string(c.test.monitor_points));
}

}  // namespace

SceneConfig parse_config(const nlohmann::json& root_json, const std::string& source,
                         const std::vector<std::string>& sets) {
  SceneConfig c;
  c.source = source;
  c.sets = sets;  // for the checks across keys (check_lateral_stress) and errors found later
  Reader root(root_json, source, "");
  c.name = root.string("name", c.name);
  check_scene_name(root, c.name);
  c.dimension = static_cast<int>(root.integer("dimension", c.dimension, 2, 3));
  const bool three_d = c.dimension == 3;

  {
    Reader m = root.child("material");
    c.material.density = m.positive("density", c.material.density);
    if (c.dimension == 3 && m.has("thickness"))
      m.fail("thickness", "has no meaning in 3D (spheres of mass rho*(4/3)*pi*r^3); remove it");
    c.material.thickness = m.positive("thickness", c.material.thickness);
    c.material.particle = read_contact(m, c.material.particle);
    check_tangential_stiffness(m, c.material.particle, sets);
    c.material.contact_damping_ratio =
        m.non_negative("contact_damping_ratio", c.material.contact_damping_ratio);
    Reader w = m.child("wall");
    c.material.wall = read_contact(w, c.material.wall);
    w.reject_unknown();
    m.reject_unknown();
  }
  {
    Reader a = root.child("assembly");
    auto& s = c.assembly;
    s.type = a.string("type", three_d ? kDefaultAssembly3D : s.type,
                      {"hexagonal", "square", "fcc", "random", "file"});
    if (three_d && (s.type == "hexagonal" || s.type == "square"))
      a.fail("type", "\"" + s.type +
                         "\" is a 2D (disk) assembly; with \"dimension\": 3 use fcc, random or "
                         "file");
    if (!three_d && s.type == "fcc")
      a.fail("type",
             "\"fcc\" is a 3D (sphere) assembly: set \"dimension\": 3, or use hexagonal, "
             "square, random or file");
    if (s.type == "fcc") {
      constexpr int64_t kIntMax = std::numeric_limits<int>::max();
      s.cells_x = static_cast<int>(a.integer("cells_x", s.cells_x, 1, kIntMax));
      s.cells_y = static_cast<int>(a.integer("cells_y", s.cells_y, 1, kIntMax));
      s.cells_z = static_cast<int>(a.integer("cells_z", s.cells_z, 1, kIntMax));
      check_lattice_size(a, s, sets);
      s.radius = a.positive("radius", s.radius);
    } else if (s.type == "hexagonal" || s.type == "square") {
      constexpr int64_t kIntMax = std::numeric_limits<int>::max();
      s.columns = static_cast<int>(a.integer("columns", s.columns, 1, kIntMax));
      s.rows = static_cast<int>(a.integer("rows", s.rows, 1, kIntMax));
      check_lattice_size(a, s, sets);
      s.radius = a.positive("radius", s.radius);
    } else if (s.type == "random") {
      s.count = static_cast<int>(a.integer("count", s.count, 2, std::numeric_limits<int>::max()));
      if (s.count > kMaxParticles)
        a.fail("count",
               std::to_string(s.count) + " particles, more than the limit " + kMaxParticlesWhy);
      s.distribution = a.string("distribution", s.distribution, {"uniform", "lognormal"});
      if (s.distribution == "uniform") {
        s.radius_min = a.positive("radius_min", s.radius_min);
        s.radius_max = a.positive("radius_max", s.radius_max);
        check_radius_bounds(a, s, sets);
      } else {
        s.radius_mean = a.positive("radius_mean", s.radius_mean);
        s.radius_std = a.non_negative("radius_std", s.radius_std);
      }
      s.aspect = a.positive("aspect", s.aspect);
      // A gas that never consolidates to a static state (packing.cpp,
      // gas_layers_fault: measured), named by the key to change: the count
      // when a --set changed it and none the aspect (changed_field).
      const bool count_changed =
          changed_field(sets, {"assembly.aspect", "assembly.count"}) == "assembly.count";
      if (const auto fault = gas_layers_fault(c.dimension, s.count, s.aspect, count_changed))
        a.fail(fault->key, fault->message);
      s.seed = static_cast<uint64_t>(
          a.integer("seed", static_cast<int64_t>(s.seed), 0, std::numeric_limits<int64_t>::max()));
    } else {
      s.file = a.string("file", "");
      if (s.file.empty()) a.fail("file", "required for type \"file\"");
      s.file = resolved_file(s.file, source);
    }
    a.reject_unknown();
  }
  {
    Reader t = root.child("test");
    auto& s = c.test;
    s.type = t.string("type", three_d ? kDefaultTest3D : s.type, {"biaxial", "triaxial"});
    if (three_d && s.type != "triaxial")
      t.fail("type", "\"" + s.type + "\" is a 2D test; with \"dimension\": 3 use triaxial");
    if (!three_d && s.type != "biaxial")
      t.fail("type",
             "\"" + s.type + "\" is the 3D test: set \"dimension\": 3 (spheres), or use biaxial");
    s.lateral_stress = t.positive("lateral_stress", s.lateral_stress);
    s.vertical_strain = t.positive("vertical_strain", s.vertical_strain);
    if (s.vertical_strain >= 0.5) t.fail("vertical_strain", "must be < 0.5");
    s.monitor_points = static_cast<int>(t.integer("monitor_points", s.monitor_points, 2, 100000));
    s.servo_gain = t.positive("servo_gain", s.servo_gain);
    if (s.servo_gain > 1.0) t.fail("servo_gain", "must be <= 1 (a larger gain overshoots)");
    s.consolidation_tolerance = t.positive("consolidation_tolerance", s.consolidation_tolerance);
    if (s.consolidation_tolerance >= kConsolidationToleranceBelow)
      t.fail("consolidation_tolerance",
             "must be < " + num(kConsolidationToleranceBelow) + " (a fraction of lateral_stress)");
    s.consolidation_unbalanced = t.positive("consolidation_unbalanced", s.consolidation_unbalanced);
    s.consolidation_max_steps = t.integer("consolidation_max_steps", s.consolidation_max_steps,
                                          1000, kMaxConsolidationSteps);
    // 3D: the overlap at sigma3 depends on the radii, checked with the
    // assembly (check_sphere_overlap in triaxial.cpp).
    if (!three_d) check_lateral_stress(c);
    check_servo_gain(t, s, sets);
    t.reject_unknown();
  }
  {
    Reader a = root.child("algorithm");
    c.algorithm = read_algorithm(a, c.algorithm);
    check_monitor_points(c, source, sets);
  }
  {
    Reader k = root.child("calibration");
    auto& s = c.calibration;
    s.accuracy = k.positive("accuracy", s.accuracy);
    if (s.accuracy >= 1.0) k.fail("accuracy", "must be < 1 (a fraction, 0.02 = 2 %)");
    s.max_trials = static_cast<int>(k.integer("max_trials", s.max_trials, 1, 100000));
    s.seed = static_cast<uint64_t>(
        k.integer("seed", static_cast<int64_t>(s.seed), 0, std::numeric_limits<int64_t>::max()));
    k.reject_unknown();
  }
  {
    Reader p = root.child("prototype");
    // 0: the REV itself. The limit params.json's prototype.particles has:
    // the prototype is generated, consolidated and verified by our kernel.
    c.prototype.particles = p.particles("particles", 0, 0);
    c.prototype.file = p.string("file", "");
    if (!c.prototype.file.empty()) c.prototype.file = resolved_file(c.prototype.file, source);
    p.reject_unknown();
  }
  {
    Reader o = root.child("output");
    c.output.vtk = o.boolean("vtk", c.output.vtk);
    o.reject_unknown();
  }
  root.reject_unknown();
  require_material(root, root_json, source);
  return c;
}

// JSON text to a tree. Every nlohmann error becomes an InputError: a syntax
// error names the line and column, a number that overflows a double
// (1e999: nlohmann throws out_of_range, not parse_error) names its key, and
// a key given twice in one object (nlohmann would keep the last silently)
// names the key.
nlohmann::json parse_config_json(std::string_view text, const std::string& source) {
  struct Open {
    std::string key;             // the key being read
    std::set<std::string> seen;  // the keys of this object so far
  };
  std::vector<Open> open;  // one per object being read
  auto key_path = [&]() {
    std::string path;
    for (const auto& o : open)
      if (!o.key.empty()) path += (path.empty() ? "" : ".") + shown_key(o.key);
    return path;
  };
  auto track = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        open.emplace_back();
        break;
      case json::parse_event_t::object_end:
        if (!open.empty()) open.pop_back();
        break;
      case json::parse_event_t::key:
        if (!open.empty()) {
          open.back().key = parsed.get<std::string>();
          if (!open.back().seen.insert(open.back().key).second)
            throw InputError(source, key_path(), "duplicate key (given twice in one object)");
        }
        break;
      default:
        break;
    }
    return true;
  };
  try {
    return json::parse(text, track);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the offending character.
    const size_t at = std::min(e.byte > 0 ? e.byte - 1 : 0, text.size());
    size_t line = 1, column = 1;
    for (size_t i = 0; i < at; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    std::string near = key_path();
    // nlohmann quotes the last token read, which can be megabytes: cut it.
    throw InputError(source, "line " + std::to_string(line) + ", column " + std::to_string(column),
                     std::string("malformed JSON") +
                         (near.empty() ? "" : " (after key " + near + ")") + ": " +
                         quoted_value(e.what(), 160));
  } catch (const json::exception& e) {
    throw InputError(source, key_path(),
                     "number out of range (not a finite double): " + quoted_value(e.what(), 160));
  }
}

SceneConfig parse_config_text(std::string_view text, const std::string& source) {
  const nlohmann::json j = parse_config_json(text, source);
  SceneConfig c = parse_config(j, source);
  c.text = std::string(text);
  return c;
}

SceneConfig load_config(const std::string& path) {
  return parse_config_text(read_text_file(path), path);
}

SceneConfig load_config(const std::string& path, const std::vector<std::string>& sets) {
  const bool embedded = path.empty();
  const std::string source = embedded ? "<embedded default: configs/hex_10x10.json>" : path;
  const std::string text = embedded ? std::string(default_config_text()) : read_text_file(path);
  nlohmann::json j = parse_config_json(text, source);
  SceneConfig config = parse_config_with_overrides(j, sets, source);
  config.text = sets.empty() ? text : j.dump();
  return config;
}

SceneConfig parse_config_with_overrides(nlohmann::json& j, const std::vector<std::string>& sets,
                                        const std::string& source) {
  apply_overrides(j, sets);
  try {
    return parse_config(j, source, sets);
  } catch (const InputError& e) {
    // A value a --set gave is the --set's fault, not the file's: the error
    // names it (a check across keys still names the file).
    if (const auto set = set_source(sets, e.field()))
      throw InputError(*set, e.field(), e.message());
    throw;
  }
}

std::optional<std::string> set_source(const std::vector<std::string>& sets,
                                      const std::string& field) {
  if (field.empty()) return std::nullopt;
  for (auto set = sets.rbegin(); set != sets.rend(); ++set) {
    const std::string key = set->substr(0, set->find('='));
    if (field == key || field.rfind(key + ".", 0) == 0) return "--set " + *set;
  }
  return std::nullopt;
}

std::string changed_field(const std::vector<std::string>& sets,
                          const std::vector<std::string>& fields) {
  for (const auto& field : fields)
    if (set_source(sets, field)) return field;
  return fields.front();
}

std::string source_of(const SceneConfig& config, const std::string& field) {
  return set_source(config.sets, field).value_or(config.source);
}

void require_config_file(const SceneConfig& config, const std::string& field,
                         const std::string& path) {
  try {
    require_readable_file(path);
  } catch (const InputError& e) {
    throw InputError(source_of(config, field), field,
                     quoted_value(path, path.size()) + ": " + e.message());  // the whole path
  }
}

SceneConfig default_config() {
  return parse_config_text(default_config_text(), "<embedded default: configs/hex_10x10.json>");
}

namespace {

// A --set's key: else an InputError naming the --set, "wants
// section.key=value" (no '=' or nothing before it) or "key has an empty
// part" ("material..kn", "material."). Every --set is checked so before
// any two are compared (require_distinct_set_keys): a malformed key is
// said as such, not as a duplicate or a section of another.
std::string set_key(const std::string& set) {
  const auto eq = set.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + set, "", "wants section.key=value");
  const std::string key = set.substr(0, eq);
  for (size_t start = 0;;) {
    const auto dot = key.find('.', start);
    if (dot == start || start == key.size())
      throw InputError("--set " + set, "", "key has an empty part");
    if (dot == std::string::npos) return key;
    start = dot + 1;
  }
}

}  // namespace

void require_distinct_set_keys(const std::vector<std::string>& sets) {
  for (const auto& set : sets) set_key(set);  // a malformed key first
  std::map<std::string, std::string> given;   // key -> its value
  // The keys before, in order, with their --set.
  std::vector<std::pair<std::string, std::string>> before;
  for (const auto& set : sets) {
    const std::string key = set_key(set), value = set.substr(key.size() + 1);
    const auto [first, fresh] = given.emplace(key, value);
    if (!fresh)
      throw InputError("--set " + set, key,
                       "given twice, " + quoted_value(first->second) + " then " +
                           quoted_value(value) +
                           " (only the last would be read, silently): give each key once");
    // A section after a key in it replaces the section, and the key with
    // it: the earlier --set would be lost. Keys split at every dot
    // (apply_overrides): "material" holds "material.kn" and
    // "material.wall.kn", "material.k" neither. A key after its section
    // is a change to the section given: applied in order.
    for (const auto& [earlier_key, earlier] : before)
      if (earlier_key.rfind(key + ".", 0) == 0)
        throw InputError("--set " + set, key,
                         "replaces the section, and with it --set " + earlier +
                             " given before it (which would be lost, silently): give the "
                             "section first, then the keys in it");
    before.emplace_back(key, set);
  }
}

void apply_overrides(nlohmann::json& j, const std::vector<std::string>& sets) {
  require_distinct_set_keys(sets);
  for (const auto& set : sets) {
    const std::string source = "--set " + set;  // what the errors name
    const std::string key = set_key(set), value = set.substr(key.size() + 1);
    nlohmann::json v;
    try {
      v = nlohmann::json::parse(value);
    } catch (const nlohmann::json::parse_error&) {
      v = value;  // a bare word is a string
    } catch (const nlohmann::json::exception& e) {
      throw InputError(source, key, "value " + quoted_value(value) + " is out of range");
    }
    nlohmann::json* node = &j;
    std::string rest = key;
    for (;;) {
      const auto dot = rest.find('.');
      const std::string part = rest.substr(0, dot);  // not empty: set_key
      if (dot == std::string::npos) {
        (*node)[part] = v;
        break;
      }
      if (!node->contains(part)) (*node)[part] = nlohmann::json::object();
      node = &(*node)[part];
      if (!node->is_object())
        throw InputError(source, key.substr(0, key.size() - rest.size() + part.size()),
                         "not a section (holds " + quoted_json(*node) + ")");
      rest = rest.substr(dot + 1);
    }
  }
}

nlohmann::json to_json(const SceneConfig& c) {
  using nlohmann::json;
  auto law = [](const ContactLaw& l) {
    return json{{"kn", l.kn}, {"kt", l.kt}, {"friction", l.friction}};
  };
  json material = law(c.material.particle);
  material["density"] = c.material.density;
  if (c.dimension == 2) material["thickness"] = c.material.thickness;
  material["contact_damping_ratio"] = c.material.contact_damping_ratio;
  material["wall"] = law(c.material.wall);
  const auto& a = c.assembly;
  json assembly{{"type", a.type}};
  if (a.type == "fcc") {
    assembly.update({{"cells_x", a.cells_x},
                     {"cells_y", a.cells_y},
                     {"cells_z", a.cells_z},
                     {"radius", a.radius}});
  } else if (a.type == "hexagonal" || a.type == "square") {
    assembly.update({{"columns", a.columns}, {"rows", a.rows}, {"radius", a.radius}});
  } else if (a.type == "random") {
    assembly.update({{"count", a.count},
                     {"distribution", a.distribution},
                     {"aspect", a.aspect},
                     {"seed", a.seed}});
    if (a.distribution == "uniform")
      assembly.update({{"radius_min", a.radius_min}, {"radius_max", a.radius_max}});
    else
      assembly.update({{"radius_mean", a.radius_mean}, {"radius_std", a.radius_std}});
  } else {
    assembly["file"] = a.file;
  }
  const auto& t = c.test;
  json prototype{{"particles", c.prototype.particles}};
  if (!c.prototype.file.empty()) prototype["file"] = c.prototype.file;
  json out{{"name", c.name},
           {"material", material},
           {"assembly", assembly},
           {"test",
            {{"type", t.type},
             {"lateral_stress", t.lateral_stress},
             {"vertical_strain", t.vertical_strain},
             {"monitor_points", t.monitor_points},
             {"servo_gain", t.servo_gain},
             {"consolidation_tolerance", t.consolidation_tolerance},
             {"consolidation_unbalanced", t.consolidation_unbalanced},
             {"consolidation_max_steps", t.consolidation_max_steps}}},
           {"algorithm", to_json(c.algorithm)},
           {"calibration",
            {{"accuracy", c.calibration.accuracy},
             {"max_trials", c.calibration.max_trials},
             {"seed", c.calibration.seed}}},
           {"prototype", prototype},
           {"output", {{"vtk", c.output.vtk}}}};
  // 2D configs read back as they always have (no key they never had).
  if (c.dimension != 2) out["dimension"] = c.dimension;
  return out;
}

std::string sha256_hex(std::string_view data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(data.data(), data.size(), digest, &length, EVP_sha256(), nullptr);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

}  // namespace demcal
