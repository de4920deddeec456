// Config parsing and validation (issue #9 §1, bad input): every default,
// every kind of bad value, and that each error names the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include "demcal/scene/config.hpp"
#include "support/input_errors.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

constexpr const char* kFile = "scene.json";

/// `text` with the keys a config must give (the material's density, kn, kt
/// and friction: ConfigRequired.MaterialAndItsKeys) added where absent, so
/// that the tests below see only the key they are about.
using test::with_required_material;

SceneConfig parse(const std::string& text) {
  return parse_config_text(with_required_material(text), kFile);
}

using test::input_error;

/// Parsing `text` fails with an InputError naming kFile and `field`, and the
/// message (what the user sees) contains both.
void expect_rejected(const std::string& text, const std::string& field) {
  SCOPED_TRACE(text);
  const auto e = input_error([&] { parse(text); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), kFile);
  EXPECT_EQ(e->field(), field) << e->what();
  const std::string what = e->what();
  EXPECT_EQ(what.rfind(std::string(kFile) + ": ", 0), 0u) << what;
  if (!field.empty()) {
    EXPECT_NE(what.find(field), std::string::npos) << what;
  }
}

// --- defaults -----------------------------------------------------------

// The documented defaults (scene/config.hpp, README.md "Config keys"), written out once more
// so that a silent change of a default is caught here.
TEST(ConfigDefaults, EmptyObjectGivesEveryDocumentedDefault) {
  // The material's density, kn, kt and friction have no default any more
  // (with_required_material gives them): thickness still has one.
  const SceneConfig c = parse("{}");
  EXPECT_EQ(c.name, "scene");
  EXPECT_EQ(c.material.thickness, 1.0);
  EXPECT_EQ(c.material.particle.kn, 1e8);
  EXPECT_EQ(c.material.particle.kt, 5e7);
  EXPECT_EQ(c.material.particle.friction, 0.3);
  EXPECT_EQ(c.material.contact_damping_ratio, 0.0);  // global damping only
  EXPECT_EQ(c.material.wall.kn, 1e8);
  EXPECT_EQ(c.material.wall.kt, 5e7);
  EXPECT_EQ(c.material.wall.friction, 0.0);  // frictionless walls
  EXPECT_EQ(c.assembly.type, "hexagonal");
  EXPECT_EQ(c.assembly.columns, 10);
  EXPECT_EQ(c.assembly.rows, 10);
  EXPECT_EQ(c.assembly.radius, 5e-4);
  EXPECT_EQ(c.test.type, "biaxial");
  EXPECT_EQ(c.test.lateral_stress, 1e5);
  EXPECT_EQ(c.test.vertical_strain, 0.01);
  EXPECT_EQ(c.test.monitor_points, 200);
  EXPECT_EQ(c.test.servo_gain, 0.5);
  EXPECT_EQ(c.test.consolidation_tolerance, 1e-3);
  EXPECT_EQ(c.test.consolidation_unbalanced, 1e-4);
  EXPECT_EQ(c.test.consolidation_max_steps, 2000000);
  EXPECT_EQ(c.algorithm.dt_ratio, 0.2);  // the paper's start point
  EXPECT_EQ(c.algorithm.steps, 100000);
  EXPECT_EQ(c.algorithm.damping_ratio_translation, 1.0);
  EXPECT_EQ(c.algorithm.damping_ratio_rotation, 1.0);
  EXPECT_EQ(c.algorithm.mass_scaling, 1.0);
  EXPECT_FALSE(c.algorithm.lock_rotation);
  EXPECT_EQ(c.calibration.accuracy, 0.02);
  EXPECT_EQ(c.calibration.max_trials, 80);
  EXPECT_EQ(c.calibration.seed, 1u);
  EXPECT_EQ(c.prototype.particles, 0);
  EXPECT_EQ(c.prototype.file, "");
  EXPECT_TRUE(c.output.vtk);
  EXPECT_EQ(c.source, kFile);
}

TEST(ConfigDefaults, RandomAssemblyDefaults) {
  const SceneConfig u = parse(R"({"assembly": {"type": "random"}})");
  EXPECT_EQ(u.assembly.count, 400);
  EXPECT_EQ(u.assembly.distribution, "uniform");
  EXPECT_EQ(u.assembly.radius_min, 3.75e-4);
  EXPECT_EQ(u.assembly.radius_max, 6.25e-4);
  EXPECT_EQ(u.assembly.aspect, 1.0);
  EXPECT_EQ(u.assembly.seed, 1u);
  const SceneConfig l = parse(R"({"assembly": {"type": "random", "distribution": "lognormal"}})");
  EXPECT_EQ(l.assembly.radius_mean, 5e-4);
  EXPECT_EQ(l.assembly.radius_std, 1e-4);
}

// Every key the parser accepts (as to_json writes it back, for every
// assembly type) is named in the README's "Config keys and defaults".
TEST(ConfigDefaults, EveryKeyIsNamedInTheReadme) {
  std::ifstream in(std::string(DEMCAL_SOURCE_DIR) + "/README.md");
  ASSERT_TRUE(in);
  std::stringstream s;
  s << in.rdbuf();
  const std::string readme = s.str();
  std::set<std::string> keys;
  std::function<void(const nlohmann::json&)> collect = [&](const nlohmann::json& j) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      keys.insert(it.key());
      if (it->is_object()) collect(*it);
    }
  };
  for (const char* text :
       {R"({})", R"({"assembly": {"type": "random"}, "prototype": {"file": "p.csv"}})",
        R"({"assembly": {"type": "random", "distribution": "lognormal"}})",
        R"({"assembly": {"type": "file", "file": "a.csv"}})"})
    collect(to_json(parse(text)));
  // The README sums these three up as "consolidation tolerances".
  const std::set<std::string> summed_up = {"consolidation_tolerance", "consolidation_unbalanced",
                                           "consolidation_max_steps"};
  for (const auto& key : keys) {
    if (summed_up.count(key)) continue;
    EXPECT_NE(readme.find(key), std::string::npos) << "README does not name the key " << key;
  }
}

TEST(ConfigDefaults, ToJsonRoundTrips) {
  for (const char* text :
       {R"({})", R"({"assembly": {"type": "random", "count": 60, "seed": 7}})",
        R"({"assembly": {"type": "random", "distribution": "lognormal", "radius_std": 0}})",
        R"({"name": "x", "algorithm": {"steps": 1e5, "lock_rotation": true}})"}) {
    const nlohmann::json once = to_json(parse(text));
    EXPECT_EQ(to_json(parse_config(once, kFile)), once) << text;
  }
}

TEST(ConfigDefaults, EmbeddedDefaultIsTheShippedHex10x10) {
  const SceneConfig d = default_config();
  const SceneConfig f = load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/hex_10x10.json");
  EXPECT_EQ(d.name, "hex_10x10");
  EXPECT_EQ(to_json(d), to_json(f));
}

TEST(ConfigDefaults, ShippedConfigsAreValid) {
  // Every shipped config (the random gases pass gas_layers_fault).
  for (const char* name : {"hex_5x5", "hex_10x10", "hex_20x20", "random_400", "fcc_4x4x4",
                           "random_500_3d", "poly_uniform_400", "poly_lognormal_500"}) {
    const SceneConfig c =
        load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/" + name + ".json");
    EXPECT_EQ(c.name, name);
  }
}

TEST(ConfigDefaults, WholeNumbersInExponentFormAreIntegers) {
  const SceneConfig c =
      parse(R"({"algorithm": {"steps": 2.5e5}, "test": {"monitor_points": 1e2}})");
  EXPECT_EQ(c.algorithm.steps, 250000);
  EXPECT_EQ(c.test.monitor_points, 100);
}

TEST(ConfigDefaults, FileRelativeToTheConfigFolder) {
  const SceneConfig c = parse_config_text(
      with_required_material(R"({"assembly": {"type": "file", "file": "p.csv"}})"),
      "dir/sub/scene.json");
  // Made absolute: params.json holds the config, and is read from anywhere.
  EXPECT_EQ(std::filesystem::path(c.assembly.file),
            std::filesystem::current_path() / "dir/sub/p.csv");
  const SceneConfig abs = parse_config_text(
      with_required_material(R"({"assembly": {"type": "file", "file": "/x/p.csv"}})"),
      "dir/s.json");
  EXPECT_EQ(abs.assembly.file, "/x/p.csv");
}

TEST(ConfigDefaults, Sha256) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

// --- malformed JSON and wrong types -----------------------------------------

TEST(ConfigErrors, MalformedJsonNamesTheLineAndColumn) {
  const auto e =
      input_error([] { parse("{\n  \"name\": \"x\",\n  \"material\": {\"kn\": 1e8,,}\n}"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), kFile);
  EXPECT_EQ(e->field(), "line 3, column 26");
  EXPECT_NE(std::string(e->what()).find("malformed JSON"), std::string::npos);
  EXPECT_NE(std::string(e->what()).find("after key material.kn"), std::string::npos) << e->what();
  expect_rejected("", "line 1, column 1");
  expect_rejected("{\"name\": \"x\"", "line 1, column 13");  // unterminated object
  expect_rejected("{\"a\": NaN}", "line 1, column 7");       // JSON has no NaN
}

TEST(ConfigErrors, WrongTypesNameTheKey) {
  expect_rejected(R"({"material": {"kn": "1e8"}})", "material.kn");
  expect_rejected(R"({"material": {"wall": {"friction": null}}})", "material.wall.friction");
  expect_rejected(R"({"assembly": {"columns": 2.5}})", "assembly.columns");
  expect_rejected(R"({"assembly": {"columns": "10"}})", "assembly.columns");
  expect_rejected(R"({"assembly": {"type": 3}})", "assembly.type");
  expect_rejected(R"({"assembly": {"type": "cubic"}})", "assembly.type");
  expect_rejected(R"({"assembly": {"type": "random", "distribution": "normal"}})",
                  "assembly.distribution");
  expect_rejected(R"({"algorithm": {"lock_rotation": 1}})", "algorithm.lock_rotation");
  expect_rejected(R"({"algorithm": {"steps": true}})", "algorithm.steps");
  expect_rejected(R"({"output": {"vtk": "yes"}})", "output.vtk");
  expect_rejected(R"({"test": {"type": "triaxial"}})", "test.type");
  expect_rejected(R"({"name": 5})", "name");
  expect_rejected(R"({"name": ""})", "name");
  expect_rejected(R"({"material": 5})", "material");
  expect_rejected(R"({"material": {"wall": [1, 2]}})", "material.wall");
  expect_rejected(R"([1, 2])", "");
}

TEST(ConfigErrors, UnknownKeysAtEveryLevel) {
  expect_rejected(R"({"foo": 1})", "foo");
  expect_rejected(R"({"material": {"foo": 1}})", "material.foo");
  expect_rejected(R"({"material": {"wall": {"foo": 1}}})", "material.wall.foo");
  expect_rejected(R"({"algorithm": {"Steps": 1000}})", "algorithm.Steps");  // case matters
  expect_rejected(R"({"test": {"servo": 0.5}})", "test.servo");
  expect_rejected(R"({"calibration": {"trials": 5}})", "calibration.trials");
  expect_rejected(R"({"prototype": {"count": 5}})", "prototype.count");
  expect_rejected(R"({"output": {"png": true}})", "output.png");
  // A key of another assembly type is not silently ignored.
  expect_rejected(R"({"assembly": {"type": "hexagonal", "count": 400}})", "assembly.count");
  expect_rejected(R"({"assembly": {"type": "random", "radius_mean": 5e-4}})",
                  "assembly.radius_mean");
}

TEST(ConfigErrors, MissingRequiredKey) {
  expect_rejected(R"({"assembly": {"type": "file"}})", "assembly.file");
  expect_rejected(R"({"assembly": {"type": "file", "file": ""}})", "assembly.file");
}

// --- values out of range --------------------------------------------------

TEST(ConfigErrors, ZeroAndNegativeValues) {
  for (const char* key : {"density", "thickness", "kn"}) {
    expect_rejected(std::string(R"({"material": {")") + key + R"(": 0}})",
                    std::string("material.") + key);
    expect_rejected(std::string(R"({"material": {")") + key + R"(": -1}})",
                    std::string("material.") + key);
  }
  expect_rejected(R"({"material": {"kt": -1}})", "material.kt");
  expect_rejected(R"({"material": {"friction": -0.1}})", "material.friction");
  expect_rejected(R"({"material": {"contact_damping_ratio": -1}})",
                  "material.contact_damping_ratio");
  expect_rejected(R"({"material": {"wall": {"kn": 0}}})", "material.wall.kn");
  expect_rejected(R"({"assembly": {"radius": 0}})", "assembly.radius");
  expect_rejected(R"({"assembly": {"columns": 0}})", "assembly.columns");
  expect_rejected(R"({"assembly": {"rows": -3}})", "assembly.rows");
  expect_rejected(R"({"assembly": {"type": "random", "count": 1}})", "assembly.count");
  expect_rejected(R"({"assembly": {"type": "random", "radius_min": 0}})", "assembly.radius_min");
  expect_rejected(R"({"assembly": {"type": "random", "aspect": 0}})", "assembly.aspect");
  expect_rejected(R"({"assembly": {"type": "random", "seed": -1}})", "assembly.seed");
  expect_rejected(
      R"({"assembly": {"type": "random", "distribution": "lognormal", "radius_std": -1e-4}})",
      "assembly.radius_std");
  expect_rejected(R"({"test": {"lateral_stress": 0}})", "test.lateral_stress");
  expect_rejected(R"({"test": {"lateral_stress": -1e5}})", "test.lateral_stress");
  expect_rejected(R"({"test": {"vertical_strain": 0}})", "test.vertical_strain");
  expect_rejected(R"({"test": {"vertical_strain": 0.5}})", "test.vertical_strain");
  expect_rejected(R"({"test": {"monitor_points": 1}})", "test.monitor_points");
  expect_rejected(R"({"test": {"servo_gain": 0}})", "test.servo_gain");
  expect_rejected(R"({"test": {"servo_gain": 1.5}})", "test.servo_gain");
  expect_rejected(R"({"test": {"consolidation_max_steps": 10}})", "test.consolidation_max_steps");
  expect_rejected(R"({"algorithm": {"dt_ratio": 0}})", "algorithm.dt_ratio");
  expect_rejected(R"({"algorithm": {"dt_ratio": 2.5}})", "algorithm.dt_ratio");
  expect_rejected(R"({"algorithm": {"steps": 0}})", "algorithm.steps");
  expect_rejected(R"({"algorithm": {"steps": -100000}})", "algorithm.steps");
  expect_rejected(R"({"algorithm": {"damping_ratio_translation": -1}})",
                  "algorithm.damping_ratio_translation");
  expect_rejected(R"({"algorithm": {"mass_scaling": 0}})", "algorithm.mass_scaling");
  expect_rejected(R"({"calibration": {"accuracy": 0}})", "calibration.accuracy");
  expect_rejected(R"({"calibration": {"accuracy": 1}})", "calibration.accuracy");
  expect_rejected(R"({"calibration": {"max_trials": 0}})", "calibration.max_trials");
  expect_rejected(R"({"prototype": {"particles": -1}})", "prototype.particles");
  // Zero where zero means "none" is fine.
  const SceneConfig ok = parse(
      R"({"material": {"kt": 0, "friction": 0}, "algorithm": {"damping_ratio_translation": 0,
          "damping_ratio_rotation": 0}})");
  EXPECT_EQ(ok.material.particle.kt, 0.0);
  EXPECT_EQ(ok.algorithm.damping_ratio_rotation, 0.0);
}

// JSON has no NaN or Infinity. nlohmann (3.11) rejects a literal NaN as a
// syntax error and reports a number that overflows a double (1e999) as
// json::out_of_range (406), not as a parse error; 1e-999 underflows to 0.
// Each must come out as an InputError naming the key, never an uncaught
// json exception.
TEST(ConfigErrors, InfiniteAndUnderflowingNumbers) {
  expect_rejected(R"({"material": {"kn": 1e999}})", "material.kn");
  expect_rejected(R"({"material": {"wall": {"kn": -1e999}}})", "material.wall.kn");
  expect_rejected(R"({"algorithm": {"steps": 1e999}})", "algorithm.steps");
  expect_rejected(R"({"material": {"kn": 1e-999}})", "material.kn");  // underflows to 0
  const auto e = input_error([] { parse(R"({"material": {"kn": 1e999}})"); });
  ASSERT_TRUE(e);
  EXPECT_NE(std::string(e->what()).find("out of range"), std::string::npos) << e->what();
  // And through parse_config on an already-built tree (the --set path).
  nlohmann::json j = {{"material", {{"kn", std::numeric_limits<double>::infinity()}}}};
  const auto e2 = input_error([&] { parse_config(j, kFile); });
  ASSERT_TRUE(e2);
  EXPECT_EQ(e2->field(), "material.kn");
}

// Aspect 1e6 made 400 disks one row in a box of 20 000 cells (2 000 000
// steps, then exit 1), 1e-6 one column. The shipped aspect (1) and the
// measured 60 and 0.02 stay valid.
// A gas one particle thick along a side (one row, column or layer) never
// consolidates (packing.cpp, gas_layers_fault: measured); two layers do.
TEST(ConfigErrors, AGasAspectTooFlatOrTooTallToConsolidateIsRejected) {
  for (const char* aspect : {"1e6", "1e-6", "1000", "0.001"}) {
    SCOPED_TRACE(aspect);
    for (const char* dimension : {"2", "3"}) {
      const std::string text = std::string(R"({"dimension": )") + dimension +
                               R"(, "assembly": {"type": "random", "count": 400, "aspect": )" +
                               aspect + "}}";
      expect_rejected(text, "assembly.aspect");
      const auto e = input_error([&] { parse(text); });
      ASSERT_TRUE(e);
      EXPECT_NE(e->message().find("at least 2 along every side"), std::string::npos) << e->what();
    }
  }
  // Measured to consolidate, two layers among them (20 x 2 disks, 4 x 4 x 2
  // and 16 x 16 x 2 spheres).
  for (auto [count, aspect] :
       {std::pair{"400", "1"}, {"400", "60"}, {"400", "0.02"}, {"100", "25"}, {"40", "10"}})
    EXPECT_NO_THROW(parse(std::string(R"({"assembly": {"type": "random", "count": )") + count +
                          R"(, "aspect": )" + aspect + "}}"))
        << count << " " << aspect;
  for (auto [count, aspect] :
       {std::pair{"400", "1"}, {"400", "0.05"}, {"400", "5"}, {"500", "8"}, {"30", "1"}})
    EXPECT_NO_THROW(parse(std::string(R"({"dimension": 3, "assembly": {"type": "random", )") +
                          R"("count": )" + count + R"(, "aspect": )" + aspect + "}}"))
        << count << " " << aspect;
  // Too few particles for any aspect: the count is named.
  expect_rejected(R"({"assembly": {"type": "random", "count": 2}})", "assembly.count");
  expect_rejected(R"({"dimension": 3, "assembly": {"type": "random", "count": 4}})",
                  "assembly.count");
}

// A 3D gas 2 x 2 spheres across is a column of corner spheres, a chain
// that creeps at isotropic sigma3 (gas_layers_fault in packing.cpp, measured:
// random_500_3d at aspect 0.01, 2 x 2 x 125, failed its 2e6-step
// consolidation after 63 s, seeds 1-4, and an 8e6-step one): refused up
// front, naming assembly.aspect, the bound and why. Slabs two layers thick,
// a 3 x 3 column and the 2D column two disks wide stay valid.
TEST(ConfigErrors, A3DGasTwoSpheresAcrossIsRejected) {
  for (auto [count, aspect] : {std::pair{"500", "0.01"}, {"500", "0.016"}, {"60", "0.1"}}) {
    const std::string text = std::string(R"({"dimension": 3, "assembly": {"type": "random", )") +
                             R"("count": )" + count + R"(, "aspect": )" + aspect + "}}";
    expect_rejected(text, "assembly.aspect");
    const auto e = input_error([&] { parse(text); });
    ASSERT_TRUE(e);
    const std::string m = e->message();
    EXPECT_NE(m.find("gives a gas of 2 x 2 cells across"), std::string::npos) << m;
    EXPECT_NE(m.find("3 spheres across"), std::string::npos) << m;
    EXPECT_NE(m.find("creeps at isotropic sigma3"), std::string::npos) << m;
    EXPECT_NE(m.find("got " + std::string(aspect)), std::string::npos) << m;
  }
  // The bound: 3 across for 500 spheres from aspect above 2^3/500 = 0.016.
  const auto e = input_error([] {
    parse(R"({"dimension": 3, "assembly": {"type": "random", "count": 500, "aspect": 0.01}})");
  });
  ASSERT_TRUE(e);
  EXPECT_NE(e->message().find("aspect above 0.016 and up to about 21.296 for count 500"),
            std::string::npos)
      << e->message();
  // Fewer than 10 spheres are 2 across or 1 layer at any aspect: the count.
  expect_rejected(R"({"dimension": 3, "assembly": {"type": "random", "count": 9}})",
                  "assembly.count");
  for (auto [count, aspect] : {std::pair{"500", "0.03"}, {"10", "2"}, {"30", "1"}, {"500", "8"}})
    EXPECT_NO_THROW(parse(std::string(R"({"dimension": 3, "assembly": {"type": "random", )") +
                          R"("count": )" + count + R"(, "aspect": )" + aspect + "}}"))
        << count << " " << aspect;
  EXPECT_NO_THROW(parse(R"({"assembly": {"type": "random", "count": 400, "aspect": 0.01}})"));
}

// The values in a message read as given: kn = 1e-300 printed with %f was
// "must not exceed kn (0.000000) ... got 50000000.000000".
TEST(ConfigErrors, TheTangentialStiffnessMessageShowsSmallAndLargeValues) {
  const auto e = input_error([] { parse(R"({"material": {"kn": 1e-300, "kt": 5e7}})"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field(), "material.kt");
  EXPECT_NE(e->message().find("must not exceed kn (1e-300)"), std::string::npos) << e->what();
  EXPECT_NE(e->message().find("got 5e+07"), std::string::npos) << e->what();
  EXPECT_EQ(e->message().find("000000"), std::string::npos) << e->what();
}

TEST(ConfigErrors, IntegersOutOfRange) {
  expect_rejected(R"({"algorithm": {"steps": 1e20}})", "algorithm.steps");
  expect_rejected(R"({"algorithm": {"steps": 18446744073709551615}})", "algorithm.steps");
  expect_rejected(R"({"assembly": {"columns": 1e9}})", "assembly.columns");
  expect_rejected(R"({"calibration": {"seed": 0.5}})", "calibration.seed");
}

TEST(ConfigErrors, ImpossibleBounds) {
  expect_rejected(R"({"assembly": {"type": "random", "radius_min": 6e-4, "radius_max": 5e-4}})",
                  "assembly.radius_min");
  // Equal bounds are a monodisperse gas, not an error.
  const SceneConfig c =
      parse(R"({"assembly": {"type": "random", "radius_min": 5e-4, "radius_max": 5e-4}})");
  EXPECT_EQ(c.assembly.radius_min, c.assembly.radius_max);
}

TEST(ConfigErrors, MissingFileAndFolder) {
  const auto e = input_error([] { load_config("/nonexistent/scene.json"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "/nonexistent/scene.json");
  const auto d = input_error([] { load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs"); });
  ASSERT_TRUE(d);
  EXPECT_NE(std::string(d->what()).find("folder"), std::string::npos) << d->what();
}

// --- --set overrides --------------------------------------------------------

SceneConfig with_sets(const std::string& text, const std::vector<std::string>& sets) {
  nlohmann::json j = nlohmann::json::parse(with_required_material(text));
  return parse_config_with_overrides(j, sets, kFile);
}

TEST(ConfigOverrides, NestedTypedAndNewSections) {
  const SceneConfig c =
      with_sets(R"({"material": {"wall": {"kn": 1e8}}})",
                {"material.wall.kn=2e8", "algorithm.steps=5000", "algorithm.lock_rotation=true",
                 "name=probe", "output.vtk=false", "test.servo_gain=0.25", "assembly.columns=3"});
  EXPECT_EQ(c.material.wall.kn, 2e8);
  EXPECT_EQ(c.algorithm.steps, 5000);
  EXPECT_TRUE(c.algorithm.lock_rotation);
  EXPECT_EQ(c.name, "probe");  // a bare word is a string
  EXPECT_FALSE(c.output.vtk);  // a section that was absent
  EXPECT_EQ(c.test.servo_gain, 0.25);
  EXPECT_EQ(c.assembly.columns, 3);
  // A key given twice is refused (the last was read silently), naming the
  // second --set; a section and a key in it are two keys, applied in order.
  test::expect_input_error(
      [] {
        with_sets("{}", {"algorithm.steps=1000", "algorithm.steps=2000"});
      },
      "--set algorithm.steps=2000", "algorithm.steps", R"(given twice, "1000" then "2000")");
  EXPECT_EQ(
      with_sets("{}", {R"(algorithm={"steps": 1000})", "algorithm.steps=2000"}).algorithm.steps,
      2000);
}

// Every error of a --set names it in the file's place (the config file is
// fine), and the field where there is one.
void expect_set_rejected(const std::string& set, const std::string& field) {
  SCOPED_TRACE(set);
  const auto e = input_error([&] { with_sets(R"({"name": "x"})", {set}); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "--set " + set);
  EXPECT_EQ(e->field(), field) << e->what();
}

TEST(ConfigOverrides, BadFormsNameTheOverride) {
  expect_set_rejected("algorithm.steps", "");  // no '='
  expect_set_rejected("=5", "");
  expect_set_rejected("algorithm..steps=5", "");
  expect_set_rejected(".steps=5", "");
  expect_set_rejected("name.first=5", "name");  // name is not a section
  // Well-formed overrides with bad values fail validation, naming the key.
  expect_set_rejected("algorithm.steps=abc", "algorithm.steps");
  expect_set_rejected("algorithm.steps=", "algorithm.steps");
  expect_set_rejected("algorithm.stepz=5", "algorithm.stepz");
  expect_set_rejected("material.kn=-1", "material.kn");
  expect_set_rejected("material.kn=1e999", "material.kn");  // nlohmann out_of_range
  expect_set_rejected("material=5", "material");
  // Of two --set of one key the last one's value is read, and named.
  const auto e = input_error([] {
    with_sets(R"({"name": "x"})", {"algorithm.steps=7000", "algorithm.steps=-5"});
  });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "--set algorithm.steps=-5");
}

// prototype.particles had a limit of 1e11 here and 1e7 in params.json: one
// limit (kMaxParticles, what the kernel and the export hold), one message
// (particle_count) for both files.
TEST(ConfigErrors, PrototypeParticlesHaveTheKernelsLimit) {
  const std::string at_limit =
      R"({"prototype": {"particles": )" + std::to_string(kMaxParticles) + "}}";
  EXPECT_EQ(parse(at_limit).prototype.particles, kMaxParticles);
  for (const std::string& v : {std::to_string(kMaxParticles + 1), std::string("1e11"),
                               std::string("2.5"), std::string("\"100\"")}) {
    const std::string text = R"({"prototype": {"particles": )" + v + "}}";
    expect_rejected(text, "prototype.particles");
    const auto e = input_error([&] { parse(text); });
    ASSERT_TRUE(e);
    EXPECT_NE(std::string(e->what()).find(kMaxParticlesWhy), std::string::npos) << e->what();
  }
  // params.json's prototype.particles and rev.particles: the same reader.
  const auto p = input_error([] {
    particle_count(nlohmann::json(kMaxParticles + 1), 1, "params.json", "prototype.particles");
  });
  ASSERT_TRUE(p);
  EXPECT_EQ(std::string(p->what()), "params.json: prototype.particles: must be between 1 and " +
                                        std::to_string(kMaxParticles) +
                                        ", got \"10000001\" (a particle count: at most " +
                                        kMaxParticlesWhy + ")");
}

}  // namespace
}  // namespace demcal
