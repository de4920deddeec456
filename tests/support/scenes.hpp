// Test support: the scene and config snippets the tests and benchmarks
// share. Values are those of the shipped default scene (configs/
// hex_10x10.json): r = 5e-4 m, ρ = 2650 kg/m³, t = 1 m, kn = 1e8 N/m,
// kt = kn/2, μ = 0.3 between particles, frictionless walls.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "demcal/kernel/world.hpp"

namespace demcal::test {

/// The material keys every config must give (there are no defaults for
/// them), with the default scene's values.
inline nlohmann::json required_material() {
  return {{"density", 2650}, {"kn", 1e8}, {"kt", 5e7}, {"friction", 0.3}};
}

/// The same as a JSON member, for configs written out by hand:
/// "{" + kMaterialMember + ", \"assembly\": ...}".
inline const std::string kMaterialMember =
    R"("material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3})";

/// `text` with the required material keys added where absent, so that a test
/// shows only the keys it is about. Text that is not a JSON object, or whose
/// material is not one, is returned as it is (the parser's error is then
/// the one under test).
inline std::string with_required_material(const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception&) {
    return text;
  }
  if (!j.is_object()) return text;
  nlohmann::json& m = j["material"];
  if (m.is_null()) m = nlohmann::json::object();
  if (!m.is_object()) return text;
  const nlohmann::json required = required_material();  // items() needs it alive
  for (const auto& [key, value] : required.items())
    if (!m.contains(key)) m[key] = value;
  return j.dump();
}

/// The kernel's material of the default scene, contact damping off;
/// `mu` between particles, `wall_mu` at the walls.
inline Material reference_material(double mu = 0.3, double wall_mu = 0.0) {
  Material m;
  m.density = 2650.0;
  m.thickness = 1.0;
  m.particle = {1e8, 5e7, mu};
  m.wall = {1e8, 5e7, wall_mu};
  m.contact_damping_ratio = 0.0;
  return m;
}

}  // namespace demcal::test
