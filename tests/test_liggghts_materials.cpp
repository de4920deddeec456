// The LIGGGHTS decks' contact dashpots with more than one radius class
// (deck_sections.cpp liggghts_materials, reports/engines.md §20): the
// `gamman_abs` peratomtypepair matrix of the 2D and the 3D deck, every
// entry against ζ_c·2·sqrt(kn·m_eff) with m_eff = m_i·m_j/(m_i + m_j)
// between classes and m_i against a wall (the wall's kn), the masses
// computed here from each type's radius (read from the deck's data file)
// and the density; and `limitForce on` (the normal force never pulls, as
// demcal's max(0, kn·δ − c·v_n)) on the pair style and every wall fix
// exactly when there is contact damping. No engine needed (the engine runs
// of the monodisperse decks are Export3dLiggghts.TheDecksContactDashpots…).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

/// The matrix of `fix ... property/global NAME peratomtypepair N v11 v12
/// ... vNN` in a deck, row by row (empty when the deck has none or the
/// line does not hold N² numbers).
std::vector<std::vector<double>> type_pair_matrix(const std::string& deck,
                                                  const std::string& name) {
  const std::string key = " property/global " + name + " peratomtypepair ";
  const auto at = deck.find(key);
  if (at == std::string::npos) return {};
  const auto from = at + key.size();
  std::istringstream line(deck.substr(from, deck.find('\n', from) - from));
  int n = 0;
  if (!(line >> n) || n < 1) return {};
  std::vector<std::vector<double>> m(n, std::vector<double>(n));
  for (auto& row : m)
    for (double& v : row)
      if (!(line >> v)) return {};
  std::string rest;
  if (line >> rest) return {};
  return m;
}

/// Each atom type's radius, from the data file's Atoms lines ("id type
/// diameter density x y z" in both dimensions); 0 for a type whose atoms
/// have different radii (the samples below give each class one radius).
std::map<int, double> type_radius(const std::string& data) {
  std::map<int, double> radius;
  std::istringstream lines(data.substr(data.find("\nAtoms")));
  std::string line;
  std::getline(lines, line);  // "", the line break before "Atoms"
  std::getline(lines, line);  // "Atoms" (and a comment)
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    int id = 0, type = 0;
    double diameter = 0.0;
    if (!(fields >> id >> type >> diameter)) continue;
    const auto [it, fresh] = radius.emplace(type, 0.5 * diameter);
    if (!fresh && it->second != 0.5 * diameter) it->second = 0.0;
  }
  return radius;
}

/// The deck's lines (not comments) that hold `needle`.
std::vector<std::string> deck_lines_with(const std::string& deck, const std::string& needle) {
  std::vector<std::string> out;
  std::istringstream lines(deck);
  for (std::string line; std::getline(lines, line);)
    if (!line.starts_with("#") && line.find(needle) != std::string::npos) out.push_back(line);
  return out;
}

/// Every gamman_abs entry of `deck` against ζ_c·2·sqrt(kn·m_eff), each
/// type's mass m(r) from its radius in the data file; type K + 1 is the
/// walls' (kn_wall, m_eff = m_i; wall against wall 0), the type of every
/// wall fix and mesh. `relative` is the tolerance the deck's printed
/// digits allow.
void expect_dashpots(const ExportResult& r, const std::string& data_name, const Material& mat,
                     const std::function<double(double)>& mass, int classes, double relative) {
  const auto gamma = type_pair_matrix(r.deck, "gamman_abs");
  const std::map<int, double> radius = type_radius(r.files.at(data_name));
  ASSERT_EQ(r.types, classes);
  ASSERT_EQ(radius.size(), static_cast<size_t>(classes));
  ASSERT_EQ(gamma.size(), static_cast<size_t>(classes + 1)) << r.deck;
  const int wall = classes + 1;
  EXPECT_NE(r.deck.find("# type " + std::to_string(wall) + " is the walls' material"),
            std::string::npos);
  for (const char* fix : {" wall/gran ", " mesh/surface/"})
    for (const std::string& line : deck_lines_with(r.deck, fix))
      if (const auto at = line.find(" type "); at != std::string::npos) {
        int type = 0;
        std::istringstream(line.substr(at + 6)) >> type;
        EXPECT_EQ(type, wall) << line;
      }
  const double zeta = mat.contact_damping_ratio;
  int checked = 0;
  for (int i = 1; i <= wall; ++i)
    for (int j = 1; j <= wall; ++j) {
      SCOPED_TRACE("types " + std::to_string(i) + " " + std::to_string(j));
      double expected = 0.0;
      if (i != wall && j != wall) {
        ASSERT_GT(radius.at(i), 0.0);
        ASSERT_GT(radius.at(j), 0.0);
        const double mi = mass(radius.at(i)), mj = mass(radius.at(j));
        expected = zeta * 2.0 * std::sqrt(mat.particle.kn * (mi * mj / (mi + mj)));
      } else if (i != j) {
        expected = zeta * 2.0 * std::sqrt(mat.wall.kn * mass(radius.at(std::min(i, j))));
      }
      const double printed = gamma[i - 1][j - 1];
      if (expected == 0.0)
        EXPECT_EQ(printed, 0.0);
      else
        EXPECT_NEAR(printed, expected, relative * expected);
      ++checked;
    }
  EXPECT_EQ(checked, wall * wall);
}

/// `limitForce on` on the pair style and every wall fix of a deck exactly
/// when `damped`; returns the number of wall fixes.
int expect_limit_force(const std::string& deck, bool damped) {
  const auto pair_style = deck_lines_with(deck, "pair_style gran ");
  EXPECT_EQ(pair_style.size(), 1u) << deck;
  const auto walls = deck_lines_with(deck, " wall/gran ");
  EXPECT_FALSE(walls.empty()) << deck;
  for (const auto& lines : {pair_style, walls})
    for (const std::string& line : lines)
      EXPECT_EQ(line.find(" limitForce on") != std::string::npos, damped) << line;
  if (!damped) {
    EXPECT_EQ(deck.find("limitForce"), std::string::npos);
  }
  return static_cast<int>(walls.size());
}

/// Three radius classes of one radius each: every third particle at its
/// radius, the others shrunk to 0.8 and 0.6 of it.
template <class Radii>
void three_classes(Radii& r) {
  const double factor[3] = {1.0, 0.8, 0.6};
  for (size_t i = 0; i < r.size(); ++i) r[i] *= factor[i % 3];
}

/// The options of a LIGGGHTS deck (2D ExportOptions, 3D Export3dOptions)
/// named kDeckName (it reads its particles from kDeckName.data).
constexpr const char* kDeckName = "proto";
template <class Options>
Options liggghts_options() {
  Options o;
  o.format = "liggghts";
  o.deck_name = kDeckName;
  return o;
}

/// The deck `make(config)` writes with contact damping (ζ_c 0.3) and
/// without: its dashpots (the masses f_ms·ρ·volume(r), f_ms 4) and
/// limitForce on the pair style and its `wall_fixes` wall fixes.
void expect_materials(
    SceneConfig c,
    const std::function<ExportResult(const SceneConfig&, const AlgorithmSpec&)>& make,
    const std::function<double(double)>& volume, double relative, int wall_fixes) {
  AlgorithmSpec p;
  p.mass_scaling = 4.0;
  for (const double zeta : {0.3, 0.0}) {
    SCOPED_TRACE("zeta_c " + std::to_string(zeta));
    c.material.contact_damping_ratio = zeta;
    const ExportResult r = make(c, p);
    const double density = p.mass_scaling * c.material.density;
    expect_dashpots(
        r, deck_files(kDeckName).data, c.material,
        [&](double radius) { return density * volume(radius); }, 3, relative);
    EXPECT_EQ(expect_limit_force(r.deck, zeta > 0.0), wall_fixes);
  }
}

// The 2D deck prints 10 significant digits (num): each entry within half a
// unit of the tenth digit, 5e-10 relative (and a few ulp of the
// computation's order).
TEST(LiggghtsMaterials, TheTwoDimensionalDecksDashpotsPerTypePairWithThreeClasses) {
  const SceneConfig c = default_config();
  Assembly a = hexagonal_packing(6, 5, 5e-4);
  three_classes(a.r);
  const auto o = liggghts_options<ExportOptions>();
  expect_materials(
      c, [&](const SceneConfig& s, const AlgorithmSpec& p) { return export_deck(s, p, a, o); },
      [&](double r) { return c.material.thickness * std::numbers::pi * r * r; }, 5e-10 + 1e-15,
      2);  // the bottom wall, the meshes
}

// The 3D deck prints 17 significant digits (exact, round-trips): 1e-12
// relative covers the computation's order.
TEST(LiggghtsMaterials, TheThreeDimensionalDecksDashpotsPerTypePairWithThreeClasses) {
  const SceneConfig c = load_config(test::shipped_config("fcc_4x4x4"));
  SphereAssembly a = make_sphere_assembly(c);
  three_classes(a.r);
  const auto o = liggghts_options<Export3dOptions>();
  expect_materials(
      c, [&](const SceneConfig& s, const AlgorithmSpec& p) { return export_3d_decks(s, p, a, o); },
      [](double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r; }, 1e-12,
      1);  // the six meshes
}

}  // namespace
}  // namespace demcal
