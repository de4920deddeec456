// Config parsing and validation. A small Reader walks one JSON object,
// converting and checking each key, and finally rejects keys it never read.
#include "demcal/scene/config.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace demcal {

namespace {

using nlohmann::json;

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
    if (!v.is_number()) fail(key, "must be a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "must be finite");
    return d;
  }
  double positive(const std::string& key, double fallback) {
    const double d = number(key, fallback);
    if (!(d > 0.0)) fail(key, "must be > 0, got " + format(d));
    return d;
  }
  double non_negative(const std::string& key, double fallback) {
    const double d = number(key, fallback);
    if (!(d >= 0.0)) fail(key, "must be >= 0, got " + format(d));
    return d;
  }
  int64_t integer(const std::string& key, int64_t fallback, int64_t min, int64_t max) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    double d = 0.0;
    if (v.is_number_integer()) {
      d = static_cast<double>(v.get<int64_t>());
    } else if (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>()) {
      d = v.get<double>();  // 1e5 written in exponent form is still a whole number
    } else {
      fail(key, "must be a whole number, got " + v.dump());
    }
    if (d < static_cast<double>(min) || d > static_cast<double>(max))
      fail(key, "must be between " + std::to_string(min) + " and " + std::to_string(max) +
                    ", got " + v.dump());
    return static_cast<int64_t>(d);
  }
  bool boolean(const std::string& key, bool fallback) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    if (!v.is_boolean()) fail(key, "must be true or false, got " + v.dump());
    return v.get<bool>();
  }
  std::string string(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& choices = {}) {
    used_.insert(key);
    if (!has(key)) return fallback;
    const json& v = object_.at(key);
    if (!v.is_string()) fail(key, "must be a string, got " + v.dump());
    std::string s = v.get<std::string>();
    if (!choices.empty()) {
      bool ok = false;
      std::string list;
      for (const auto& c : choices) {
        ok = ok || c == s;
        list += (list.empty() ? "" : ", ") + c;
      }
      if (!ok) fail(key, "must be one of " + list + ", got \"" + s + "\"");
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
      if (!used_.count(it.key())) fail(it.key(), "unknown key");
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
  s.steps = a.integer("steps", s.steps, 10, 10000000000LL);
  s.damping_ratio_translation =
      a.non_negative("damping_ratio_translation", s.damping_ratio_translation);
  s.damping_ratio_rotation = a.non_negative("damping_ratio_rotation", s.damping_ratio_rotation);
  s.mass_scaling = a.positive("mass_scaling", s.mass_scaling);
  s.lock_rotation = a.boolean("lock_rotation", s.lock_rotation);
  a.reject_unknown();
  return s;
}

}  // namespace

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

SceneConfig parse_config(const nlohmann::json& root_json, const std::string& source) {
  SceneConfig c;
  c.source = source;
  Reader root(root_json, source, "");
  c.name = root.string("name", c.name);
  if (c.name.empty()) root.fail("name", "must not be empty");

  {
    Reader m = root.child("material");
    c.material.density = m.positive("density", c.material.density);
    c.material.thickness = m.positive("thickness", c.material.thickness);
    c.material.particle = read_contact(m, c.material.particle);
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
    s.type = a.string("type", s.type, {"hexagonal", "square", "random", "file"});
    if (s.type == "hexagonal" || s.type == "square") {
      s.columns = static_cast<int>(a.integer("columns", s.columns, 1, 100000));
      s.rows = static_cast<int>(a.integer("rows", s.rows, 1, 100000));
      s.radius = a.positive("radius", s.radius);
    } else if (s.type == "random") {
      s.count = static_cast<int>(a.integer("count", s.count, 2, 10000000));
      s.distribution = a.string("distribution", s.distribution, {"uniform", "lognormal"});
      if (s.distribution == "uniform") {
        s.radius_min = a.positive("radius_min", s.radius_min);
        s.radius_max = a.positive("radius_max", s.radius_max);
        if (s.radius_min > s.radius_max) a.fail("radius_min", "must not exceed radius_max");
      } else {
        s.radius_mean = a.positive("radius_mean", s.radius_mean);
        s.radius_std = a.non_negative("radius_std", s.radius_std);
      }
      s.aspect = a.positive("aspect", s.aspect);
      s.seed = static_cast<uint64_t>(
          a.integer("seed", static_cast<int64_t>(s.seed), 0, std::numeric_limits<int64_t>::max()));
    } else {
      s.file = a.string("file", "");
      if (s.file.empty()) a.fail("file", "required for type \"file\"");
      const auto dir = std::filesystem::path(source).parent_path();
      if (std::filesystem::path(s.file).is_relative() && !dir.empty())
        s.file = (dir / s.file).string();
    }
    a.reject_unknown();
  }
  {
    Reader t = root.child("test");
    auto& s = c.test;
    s.type = t.string("type", s.type, {"biaxial"});
    s.lateral_stress = t.positive("lateral_stress", s.lateral_stress);
    s.vertical_strain = t.positive("vertical_strain", s.vertical_strain);
    if (s.vertical_strain >= 0.5) t.fail("vertical_strain", "must be < 0.5");
    s.monitor_points = static_cast<int>(t.integer("monitor_points", s.monitor_points, 2, 100000));
    s.servo_gain = t.positive("servo_gain", s.servo_gain);
    if (s.servo_gain > 1.0) t.fail("servo_gain", "must be <= 1 (a larger gain overshoots)");
    s.consolidation_tolerance = t.positive("consolidation_tolerance", s.consolidation_tolerance);
    s.consolidation_unbalanced = t.positive("consolidation_unbalanced", s.consolidation_unbalanced);
    s.consolidation_max_steps =
        t.integer("consolidation_max_steps", s.consolidation_max_steps, 1000, 1000000000);
    t.reject_unknown();
  }
  {
    Reader a = root.child("algorithm");
    c.algorithm = read_algorithm(a, c.algorithm);
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
    c.prototype.particles = p.integer("particles", 0, 0, 100000000000LL);
    c.prototype.file = p.string("file", "");
    if (!c.prototype.file.empty()) {
      const auto dir = std::filesystem::path(source).parent_path();
      if (std::filesystem::path(c.prototype.file).is_relative() && !dir.empty())
        c.prototype.file = (dir / c.prototype.file).string();
    }
    p.reject_unknown();
  }
  {
    Reader o = root.child("output");
    c.output.vtk = o.boolean("vtk", c.output.vtk);
    o.reject_unknown();
  }
  root.reject_unknown();
  return c;
}

namespace {

// JSON text to a tree. Every nlohmann error becomes an InputError: a syntax
// error names the line and column, a number that overflows a double
// (1e999: nlohmann throws out_of_range, not parse_error) names its key.
nlohmann::json parse_json_text(std::string_view text, const std::string& source) {
  std::vector<std::string> keys;  // the key being read in each open object
  auto track = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        keys.emplace_back();
        break;
      case json::parse_event_t::object_end:
        if (!keys.empty()) keys.pop_back();
        break;
      case json::parse_event_t::key:
        if (!keys.empty()) keys.back() = parsed.get<std::string>();
        break;
      default:
        break;
    }
    return true;
  };
  auto key_path = [&]() {
    std::string path;
    for (const auto& k : keys)
      if (!k.empty()) path += (path.empty() ? "" : ".") + k;
    return path;
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
    throw InputError(source, "line " + std::to_string(line) + ", column " + std::to_string(column),
                     std::string("malformed JSON") +
                         (near.empty() ? "" : " (after key " + near + ")") + ": " + e.what());
  } catch (const json::exception& e) {
    throw InputError(source, key_path(),
                     std::string("number out of range (not a finite double): ") + e.what());
  }
}

}  // namespace

SceneConfig parse_config_text(std::string_view text, const std::string& source) {
  const nlohmann::json j = parse_json_text(text, source);
  SceneConfig c = parse_config(j, source);
  c.text = std::string(text);
  return c;
}

SceneConfig load_config(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw InputError(path, "", "is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open file");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw InputError(path, "", "cannot read file");
  return parse_config_text(s.str(), path);
}

SceneConfig default_config() {
  return parse_config_text(default_config_text(), "<embedded default: configs/hex_10x10.json>");
}

void apply_overrides(nlohmann::json& j, const std::vector<std::string>& sets,
                     const std::string& source) {
  for (const auto& set : sets) {
    const auto eq = set.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(source, "--set " + set, "wants section.key=value");
    const std::string key = set.substr(0, eq), value = set.substr(eq + 1);
    nlohmann::json v;
    try {
      v = nlohmann::json::parse(value);
    } catch (const nlohmann::json::parse_error&) {
      v = value;  // a bare word is a string
    } catch (const nlohmann::json::exception& e) {
      throw InputError(source, key, "--set value " + value + " is out of range: " + e.what());
    }
    nlohmann::json* node = &j;
    std::string rest = key;
    for (;;) {
      const auto dot = rest.find('.');
      const std::string part = rest.substr(0, dot);
      if (part.empty()) throw InputError(source, "--set " + set, "key has an empty part");
      if (dot == std::string::npos) {
        (*node)[part] = v;
        break;
      }
      if (!node->contains(part)) (*node)[part] = nlohmann::json::object();
      node = &(*node)[part];
      if (!node->is_object())
        throw InputError(source, key.substr(0, key.size() - rest.size() + part.size()),
                         "--set " + set + ": not a section (holds " + node->dump() + ")");
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
  material["thickness"] = c.material.thickness;
  material["contact_damping_ratio"] = c.material.contact_damping_ratio;
  material["wall"] = law(c.material.wall);
  const auto& a = c.assembly;
  json assembly{{"type", a.type}};
  if (a.type == "hexagonal" || a.type == "square") {
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
  return json{{"name", c.name},
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
