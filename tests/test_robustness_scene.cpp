// Robustness of the scene layer (issue 14 §1 and §3): one regression test per
// class of bad input, each ending in one InputError that names the file and
// the key or line, and the values just inside each limit still accepted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "support/files.hpp"
#include "support/input_errors.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFile = "scene.json";
/// The keys a config must give, then `rest` (JSON members written out, so
/// that duplicate keys reach the parser).
std::string with_material(const std::string& rest) {
  return "{" + test::kMaterialMember + (rest.empty() ? "" : ", " + rest) + "}";
}

using test::input_error;

/// Parsing fails naming kFile and `field`; the message holds `words`.
void expect_rejected(const std::string& text, const std::string& field,
                     const std::string& words = "") {
  SCOPED_TRACE(text.substr(0, 200));
  const auto e = input_error([&] { parse_config_text(text, kFile); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), kFile);
  EXPECT_EQ(e->field(), field) << e->what();
  EXPECT_NE(std::string(e->what()).find(words), std::string::npos) << e->what();
}

// --- §3 messages --------------------------------------------------------------

// A wrong-typed value is named by its type and its text, quoted once: a
// string's JSON text carries its own quotes (`got string ""x""` before).
TEST(RobustScene, AWrongTypedValueIsQuotedOnce) {
  expect_rejected(with_material(R"("algorithm": {"dt_ratio": "x"})"), "algorithm.dt_ratio",
                  R"(must be a number, got string "x")");
  expect_rejected(with_material(R"("algorithm": {"lock_rotation": "yes"})"),
                  "algorithm.lock_rotation", R"(must be true or false, got string "yes")");
  expect_rejected(with_material(R"("name": 5)"), "name", R"(must be a string, got number "5")");
  expect_rejected(with_material(R"("assembly": {"type": "random", "count": "12"})"),
                  "assembly.count", R"(got string "12")");
}

// A wrong-typed 7 MB array was echoed whole: the quoted value is cut.
TEST(RobustScene, QuotedValuesAreCapped) {
  std::string big = "[";
  for (int i = 0; i < 200000; ++i) big += "12345678,";
  big += "0]";
  for (const std::string& key : {std::string("\"name\""), std::string("\"test\": {\"type\"")}) {
    const std::string text =
        with_material(key + ": " + big + (key.find('{') != std::string::npos ? "}" : ""));
    const auto e = input_error([&] { parse_config_text(text, kFile); });
    ASSERT_TRUE(e);
    const std::string what = e->what();
    EXPECT_LT(what.size(), 300u) << what.substr(0, 400);
    EXPECT_NE(what.find("characters)"), std::string::npos) << what;
  }
  // A long unknown key, and a long string among fixed choices.
  const std::string long_key(5000, 'k');
  const auto e =
      input_error([&] { parse_config_text(with_material("\"" + long_key + "\": 1"), kFile); });
  ASSERT_TRUE(e);
  EXPECT_LT(std::string(e->what()).size(), 300u);
  const auto c = input_error([&] {
    parse_config_text(with_material(R"("assembly": {"type": ")" + long_key + "\"}"), kFile);
  });
  ASSERT_TRUE(c);
  EXPECT_EQ(c->field(), "assembly.type");
  EXPECT_LT(std::string(c->what()).size(), 300u);
}

// nlohmann keeps the last of two equal keys silently: rejected, naming it.
TEST(RobustScene, DuplicateKeysAreRejectedNamingTheKey) {
  expect_rejected(R"({"name": "a", "name": "b"})", "name", "duplicate key");
  expect_rejected(
      R"({"material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3, "kn": 2e8}})",
      "material.kn", "duplicate key");
  expect_rejected(with_material(R"("test": {"lateral_stress": 1e5}, "test": {})"), "test",
                  "duplicate key");
  // The same key in two different objects is not a duplicate.
  EXPECT_NO_THROW(parse_config_text(
      with_material(R"("assembly": {"type": "random"}, "test": {"type": "biaxial"})"), kFile));
}

// --- §3 particle files --------------------------------------------------------

void expect_particles_rejected(const std::string& content, const std::string& field,
                               const std::string& words) {
  std::istringstream in(content);
  test::expect_input_error([&] { read_particles(in, "p.csv"); }, "p.csv", field, words);
}

// strtod stops at a NUL: "2\0garbage" was read as 2.
TEST(RobustScene, NulByteInAParticleLineNamesTheLine) {
  expect_particles_rejected(std::string("0,0,1\n2\0x,0,1\n5,5,1\n", 20), "line 2", "NUL byte");
  expect_particles_rejected(std::string("0,0,1\n2,0,1\0\n", 13), "line 2", "NUL byte");
}

TEST(RobustScene, LongBrokenParticleLineIsQuotedShort) {
  expect_particles_rejected("0,0,1\n" + std::string(100000, 'x') + "\n", "line 2", "characters)");
}

/// The sphere reader fails on `content` naming "s.csv" and `field`.
void expect_spheres_rejected(const std::string& content, const std::string& field,
                             const std::string& words) {
  std::istringstream in(content);
  const auto e = input_error([&] { read_spheres(in, "s.csv"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "s.csv");
  EXPECT_EQ(e->field(), field) << e->what();
  EXPECT_NE(std::string(e->what()).find(words), std::string::npos) << e->what();
}

// The sphere reader (3D) had neither check: "3\0x" was read as 3.
TEST(RobustScene, NulByteInASphereLineNamesTheLine) {
  using namespace std::string_literals;  // "…\0…"s keeps the NUL and what follows
  expect_spheres_rejected("0,0,0,1\n3\0x,0,0,1\n9,9,9,1\n"s, "line 2", "NUL byte at column 2");
  expect_spheres_rejected("x,y,z,r\n0,0,0,1\n3,0,0,1\0\n"s, "line 3", "NUL byte");
  expect_spheres_rejected("0,0,0,1\n" + std::string(100000, 'x') + "\n", "line 2", "characters)");
  // What the shared line preparation keeps: a BOM on line 1 and CRLF endings.
  std::istringstream in("\xEF\xBB\xBFx,y,z,r\r\n0,0,0,1\r\n3,0,0,1\r\n");
  EXPECT_EQ(read_spheres(in, "s.csv").size(), 2);
}

// A symlink loop, a folder, a device as the sphere file: one line naming
// it (a folder used to read as "needs at least two spheres, found 0").
TEST(RobustScene, UnreadableSphereFilePathsAreOneLine) {
  const test::TempDir tmp("robust_spheres");
  const fs::path& dir = tmp.path();
  fs::create_symlink(dir / "b.csv", dir / "a.csv");
  fs::create_symlink(dir / "a.csv", dir / "b.csv");
  for (const std::string& path : {(dir / "a.csv").string(), dir.string(), std::string("/dev/zero"),
                                  (dir / "missing.csv").string()}) {
    SCOPED_TRACE(path);
    const auto e = input_error([&] { read_sphere_file(path); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), path);
    EXPECT_EQ(std::string(e->what()).find('\n'), std::string::npos);
    EXPECT_EQ(std::string(e->what()).find("two spheres"), std::string::npos) << e->what();
  }
  const auto loop = input_error([&] { read_sphere_file((dir / "a.csv").string()); });
  EXPECT_NE(std::string(loop->what()).find("symbolic links"), std::string::npos) << loop->what();
}

/// The brute-force answer: does any pair overlap beyond 5 % of the smaller?
bool overlaps_brute(const std::vector<double>& x, const std::vector<double>& y,
                    const std::vector<double>& r) {
  for (size_t i = 0; i < x.size(); ++i)
    for (size_t j = i + 1; j < x.size(); ++j)
      if (r[i] + r[j] - std::hypot(x[i] - x[j], y[i] - y[j]) > 0.05 * std::min(r[i], r[j]))
        return true;
  return false;
}

// The overlap check agrees with the brute force on polydisperse sets whose
// radii span six orders of magnitude (the levels of the grid), with and
// without overlaps.
TEST(RobustScene, OverlapCheckAgreesWithBruteForceForAnyRadii) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int rejected = 0, accepted = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 2 + static_cast<int>(u(rng) * 60);
    std::vector<double> x(n), y(n), r(n);
    std::ostringstream csv;
    csv.precision(17);
    for (int i = 0; i < n; ++i) {
      r[i] = std::pow(10.0, -3.0 + 6.0 * u(rng) * u(rng));  // 1e-3 .. 1e3, mostly small
      x[i] = 4000.0 * u(rng);
      y[i] = 4000.0 * u(rng);
      csv << x[i] << "," << y[i] << "," << r[i] << "\n";
    }
    // Re-read the values as the file gives them (the text rounds).
    std::istringstream back(csv.str());
    for (int i = 0; i < n; ++i) {
      char comma;
      back >> x[i] >> comma >> y[i] >> comma >> r[i];
    }
    const bool expected = overlaps_brute(x, y, r);
    std::istringstream in(csv.str());
    bool got = false;
    try {
      read_particles(in, "p.csv");
    } catch (const InputError& e) {
      got = std::string(e.what()).find("overlaps") != std::string::npos;
      if (!got) ADD_FAILURE() << e.what();
    }
    EXPECT_EQ(got, expected) << "trial " << trial;
    (expected ? rejected : accepted) += 1;
  }
  EXPECT_GT(rejected, 20);  // both outcomes are exercised
  EXPECT_GT(accepted, 20);
}

// One disk 100x larger than 160 000 others made the check quadratic (187 s):
// cells were sized by the largest disk. Finishes, and finds the overlaps.
TEST(RobustScene, OneHugeDiskAmongManySmallOnesIsChecked) {
  std::string lattice;
  lattice.reserve(160000 * 16);
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 400; ++j)
      lattice += std::to_string(2 * i) + "," + std::to_string(2 * j) + ",1\n";
  // The big disk just clear of the lattice's right edge (x = 798 + 1).
  {
    std::istringstream in(lattice + "900,400,100\n");
    EXPECT_EQ(read_particles(in, "p.csv").size(), 160001);
  }
  // Moved 10 to the left it covers lattice disks: the first one it
  // overlaps is named with its line.
  expect_particles_rejected(lattice + "890,400,100\n", "line 160001", "overlaps the one on line");
  // A small disk overlapping the big one (checked from the small one's side).
  expect_particles_rejected(lattice + "900,400,100\n1001,400,1.5\n", "line 160002",
                            "overlaps the one on line 160001");
}

// The same in 3D: the sphere reader sized its cells by the largest sphere,
// so one sphere 100x the others made the check quadratic. It shares the
// 2D reader's levelled grids now; finishes, and finds the overlaps.
TEST(RobustScene, OneHugeSphereAmongManySmallOnesIsChecked) {
  std::string lattice;
  lattice.reserve(64000 * 20);
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      for (int k = 0; k < 40; ++k)
        lattice += std::to_string(2 * i) + "," + std::to_string(2 * j) + "," +
                   std::to_string(2 * k) + ",1\n";
  // The big sphere just clear of the lattice's face x = 78 + 1.
  {
    std::istringstream in(lattice + "180,40,40,100\n");
    EXPECT_EQ(read_spheres(in, "s.csv").size(), 64001);
  }
  // Moved 10 towards the lattice it covers spheres: named with its line.
  expect_spheres_rejected(lattice + "170,40,40,100\n", "line 64001", "overlaps the one on line");
  // A small sphere overlapping the big one (checked from the small one's side).
  expect_spheres_rejected(lattice + "180,40,40,100\n281,40,40,1.5\n", "line 64002",
                          "overlaps the one on line 64001");
}

// --- §3 limits ------------------------------------------------------------------

// columns = rows = 1e5 asked for 1e10 particles and died in bad_alloc.
TEST(RobustScene, ParticleCountsAreBoundedUpFront) {
  expect_rejected(with_material(R"("assembly": {"columns": 100000, "rows": 100000})"),
                  "assembly.columns", "10000000");
  expect_rejected(with_material(R"("assembly": {"type": "square", "columns": 5000, "rows": 2001})"),
                  "assembly.columns", "1 kB");
  expect_rejected(with_material(R"("assembly": {"type": "random", "count": 1e8})"),
                  "assembly.count", "1 kB");
  EXPECT_NO_THROW(parse_config_text(
      with_material(R"("assembly": {"columns": 1000, "rows": 10000})"), kFile));  // the limit
}

// The seed went through a double: UB for 9.223372036854775807e18.
TEST(RobustScene, IntegersAreReadAsIntegers) {
  const SceneConfig c = parse_config_text(
      with_material(R"("assembly": {"type": "random", "seed": 9223372036854775807})"), kFile);
  EXPECT_EQ(c.assembly.seed, 9223372036854775807ull);
  expect_rejected(
      with_material(R"("assembly": {"type": "random", "seed": 9.223372036854775807e18})"),
      "assembly.seed", "2^53");
  expect_rejected(with_material(R"("assembly": {"type": "random", "seed": 9223372036854775808})"),
                  "assembly.seed", "between 0 and 9223372036854775807");
  expect_rejected(with_material(R"("calibration": {"seed": 1e300})"), "calibration.seed", "2^53");
  // Not a whole number, or not a number at all: named as such.
  expect_rejected(with_material(R"("assembly": {"type": "random", "count": 2.5})"),
                  "assembly.count", "whole number");
  expect_rejected(with_material(R"("assembly": {"type": "random", "count": "400"})"),
                  "assembly.count", "whole number");
  expect_rejected(with_material(R"("assembly": {"type": "random", "count": -400})"),
                  "assembly.count", "between 2 and");
  expect_rejected(with_material(R"("prototype": {"particles": 5.9e110})"), "prototype.particles",
                  "2^53");
  // Whole numbers in exponent form within 2^53 are still integers.
  const SceneConfig e = parse_config_text(
      with_material(R"("assembly": {"type": "random", "seed": 4e15}, "algorithm": {"steps": 1e5})"),
      kFile);
  EXPECT_EQ(e.assembly.seed, 4000000000000000ull);
  EXPECT_EQ(e.algorithm.steps, 100000);
}

// A config without its material was calibrated for the default material.
TEST(RobustScene, MaterialAndItsPhysicalKeysAreRequired) {
  expect_rejected("{}", "material", "required");
  expect_rejected(R"({"name": "x", "assembly": {"type": "random"}})", "material", "required");
  for (const char* key : {"density", "kn", "kt", "friction"}) {
    nlohmann::json j = nlohmann::json::parse(with_material(""));
    j["material"].erase(key);
    expect_rejected(j.dump(), std::string("material.") + key, "required");
  }
  // A wrong value is named before a missing one.
  expect_rejected(R"({"material": {"kn": -1}})", "material.kn", "> 0");
  // thickness, contact damping and the walls keep their defaults.
  const SceneConfig c = parse_config_text(with_material(""), kFile);
  EXPECT_EQ(c.material.thickness, 1.0);
  EXPECT_EQ(c.material.contact_damping_ratio, 0.0);
  EXPECT_EQ(c.material.wall.kn, 1e8);
}

// A symlink loop, a folder, a device as the config: one line naming it.
TEST(RobustScene, UnreadableConfigPathsAreOneLine) {
  const test::TempDir tmp("robust_cfg");
  const fs::path& dir = tmp.path();
  fs::create_symlink(dir / "b.json", dir / "a.json");
  fs::create_symlink(dir / "a.json", dir / "b.json");
  for (const std::string& path : {(dir / "a.json").string(), dir.string(), std::string("/dev/zero"),
                                  (dir / "missing.json").string()}) {
    SCOPED_TRACE(path);
    const auto e = input_error([&] { load_config(path, {}); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), path);
    EXPECT_EQ(std::string(e->what()).find('\n'), std::string::npos);
    const auto f = input_error([&] { load_config(path); });
    ASSERT_TRUE(f);
    EXPECT_EQ(f->file(), path);
  }
  const auto loop = input_error([&] { load_config((dir / "a.json").string(), {}); });
  EXPECT_NE(std::string(loop->what()).find("symbolic links"), std::string::npos) << loop->what();
}

// load_config(path, sets) is what the commands use: the file's duplicates
// are caught there too, and the overrides apply.
TEST(RobustScene, LoadConfigWithOverrides) {
  const test::TempDir dir("robust");
  const fs::path path = dir / "scene.json";
  test::write_text(path, with_material(R"("name": "x", "name": "y")"));
  const auto e = input_error([&] { load_config(path.string(), {}); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field(), "name");
  test::write_text(path, with_material(R"("name": "x")"));
  const SceneConfig c = load_config(path.string(), {"algorithm.steps=5000"});
  EXPECT_EQ(c.algorithm.steps, 5000);
  EXPECT_NE(c.text.find("5000"), std::string::npos);  // the hash covers the override
  EXPECT_EQ(load_config(path.string(), {}).text, with_material(R"("name": "x")"));
  EXPECT_EQ(load_config("", {}).name, "hex_10x10");  // the embedded default
}

// §2: the name becomes the default output folder "demcal-run-NAME".
TEST(RobustScene, SceneNameMustBeAPlainFileName) {
  expect_rejected(with_material(R"("name": "/../../../tmp/x")"), "name", "plain file name");
  expect_rejected(with_material(R"("name": "a/b/c")"), "name", "plain file name");
  expect_rejected(with_material(R"("name": "a\\b")"), "name", "plain file name");
  expect_rejected(with_material(R"("name": "a\nb")"), "name", "plain file name");
  expect_rejected(with_material("\"name\": \"" + std::string(201, 'n') + "\""), "name", "200");
  EXPECT_EQ(parse_config_text(with_material(R"x("name": "hex 5x5@2 (v1)")x"), kFile).name,
            "hex 5x5@2 (v1)");
}

// --- §1 values the kernel cannot run ---------------------------------------

TEST(RobustScene, MonitorPointsBeyondStepsAreRejected) {
  expect_rejected(with_material(R"("algorithm": {"steps": 100}, "test": {"monitor_points": 200})"),
                  "test.monitor_points", "must not exceed algorithm.steps (100)");
  EXPECT_NO_THROW(parse_config_text(
      with_material(R"("algorithm": {"steps": 200}, "test": {"monitor_points": 200})"), kFile));
}

SceneConfig hex5(const std::string& material_extra, const std::string& test = "") {
  std::string m = R"("material": {"density": 2650, "kn": 1e8, "friction": 0.3)";
  m += material_extra.empty() ? ", \"kt\": 5e7" : ", " + material_extra;
  m += "}";
  return parse_config_text("{" + m + R"(, "assembly": {"columns": 5, "rows": 5, "radius": 5e-4})" +
                               (test.empty() ? "" : ", \"test\": {" + test + "}") + "}",
                           kFile);
}

// kt >= 1.2 kn diverged in consolidation with "energy created".
TEST(RobustScene, TangentialStiffnessAboveNormalIsRejected) {
  const auto e = input_error([] { hex5(R"("kt": 1.2e8)"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field(), "material.kt");
  EXPECT_NE(std::string(e->what()).find("must not exceed kn"), std::string::npos);
  // kt = kn is accepted, and runs: consolidation reaches a static state.
  const SceneConfig c = hex5(R"("kt": 1e8)");
  EXPECT_TRUE(consolidate(c, make_assembly(c)).converged);
  // Wall contacts do not rotate: their kt is not bound.
  EXPECT_NO_THROW(hex5(R"("kt": 5e7, "wall": {"kn": 1e8, "kt": 1.2e8})"));
}

// lateral_stress 1e9 gave "overlap beyond limit", 1e-9 "energy created".
TEST(RobustScene, LateralStressBeyondWhatTheKernelResolvesIsRejected) {
  // Upper: overlap at sigma3, 2 sigma3 t/kn, at most 5 % of r: 2.5e6 Pa here.
  const auto high = input_error([] { hex5("", R"("lateral_stress": 1e9)"); });
  ASSERT_TRUE(high);
  EXPECT_EQ(high->field(), "test.lateral_stress");
  EXPECT_NE(std::string(high->what()).find("at most 2.5e+06 Pa"), std::string::npos)
      << high->what();
  EXPECT_NO_THROW(hex5("", R"("lateral_stress": 2.4e6)"));
  EXPECT_THROW(hex5("", R"("lateral_stress": 2.6e6)"), InputError);
  // Lower: the overlap must be resolved by the positions' round-off; it
  // depends on the box, so it is checked with the assembly.
  for (const char* low : {R"("lateral_stress": 1e-9)", R"("lateral_stress": 1e-4)"}) {
    const SceneConfig c = hex5("", low);
    const auto e = input_error([&] { make_assembly(c); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), kFile);
    EXPECT_EQ(e->field(), "test.lateral_stress");
    EXPECT_NE(std::string(e->what()).find("round-off"), std::string::npos) << e->what();
  }
  // Just above the bound (6.1e-4 Pa for hex_5x5) the consolidation runs.
  const SceneConfig ok = hex5("", R"("lateral_stress": 1e-3)");
  EXPECT_TRUE(consolidate(ok, make_assembly(ok)).converged);
}

// servo_gain 1e-300 gave "diverged: energy created".
TEST(RobustScene, ServoGainTooSmallToConsolidateIsRejected) {
  const auto e = input_error([] { hex5("", R"("servo_gain": 1e-300)"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field(), "test.servo_gain");
  EXPECT_NE(std::string(e->what()).find("consolidation_max_steps"), std::string::npos);
  // The bound: ln(1/tol)/max_steps = ln(1000)/2e6 = 3.45e-6 with the defaults.
  EXPECT_THROW(hex5("", R"("servo_gain": 3.4e-6)"), InputError);
  EXPECT_NO_THROW(hex5("", R"("servo_gain": 3.5e-6)"));
  // More steps allow a smaller gain.
  EXPECT_NO_THROW(hex5("", R"("servo_gain": 3.4e-6, "consolidation_max_steps": 2100000)"));
}

}  // namespace
}  // namespace demcal
