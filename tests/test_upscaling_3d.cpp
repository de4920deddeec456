// Upscaling on spheres (issue #18, "Upscaling, REV and verify"): the 3D
// family of scene_of_size (FCC blocks keep their cell aspect), the 3D
// prototype of a config, the prototype block of a 3D params.json, `demcal
// upscale` on 3D params (Nstep by the law, checked against the law's formula
// computed here), and 3D/2D mismatches as bad input (exit 2, file and field).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "support/files.hpp"
#include "support/params_3d.hpp"
#include "support/process.hpp"
#include "support/scenes.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;
using demcal::SceneConfig;

// FCC 2×2×2 (32 spheres) with the shipped fcc_4x4x4's test, and a
// prototype of `prototype` spheres.
std::string fcc_text(const std::string& prototype = R"({"particles": 256})") {
  return "{" + test::kMaterialMember + R"(, "name": "fcc2", "dimension": 3,
    "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
    "test": {"type": "triaxial", "lateral_stress": 1e5, "vertical_strain": 1e-5,
             "monitor_points": 50},
    "algorithm": {"steps": 3000},
    "prototype": )" +
         prototype + "}";
}

SceneConfig fcc_config(const std::string& prototype = R"({"particles": 256})") {
  return demcal::parse_config_text(fcc_text(prototype), "fcc2.json");
}

/// The REV's calibrated parameters the tests upscale (no search: the
/// upscaling is what is under test).
demcal::AlgorithmSpec rev_params() {
  demcal::AlgorithmSpec p;
  p.dt_ratio = 0.15;
  p.steps = 3000;
  p.damping_ratio_translation = 0.7;
  p.damping_ratio_rotation = 0.4;
  return p;
}

/// A 3D params.json of the 32-sphere REV, as `demcal calibrate` writes it.
nlohmann::json params_3d(const SceneConfig& config) {
  const demcal::TriaxialState state =
      demcal::consolidate_triaxial(config, demcal::make_sphere_assembly(config));
  return test::params_3d(config, state, rev_params());
}

TEST(Upscaling3D, FccFamilyKeepsTheCellAspect) {
  SceneConfig c = fcc_config();
  c.assembly.cells_x = 2, c.assembly.cells_y = 3, c.assembly.cells_z = 4;  // 96 spheres
  // Twice every edge: 8× the spheres.
  const SceneConfig big = demcal::scene_of_size(c, 8 * 96);
  EXPECT_EQ(big.assembly.cells_x, 4);
  EXPECT_EQ(big.assembly.cells_y, 6);
  EXPECT_EQ(big.assembly.cells_z, 8);
  // A cube family: 4·n³ spheres for n cells an edge, the nearest cube taken.
  const SceneConfig cube = fcc_config();
  for (const auto& [asked, n] : std::vector<std::pair<int64_t, int>>{
           {256, 4}, {500, 5}, {864, 6}, {20000, 17}, {23328, 18}}) {
    const SceneConfig s = demcal::scene_of_size(cube, asked);
    EXPECT_EQ(s.assembly.cells_x, n) << asked;
    EXPECT_EQ(s.assembly.cells_z, n) << asked;
    EXPECT_EQ(demcal::make_sphere_assembly(s).size(), 4 * n * n * n);
  }
  // A random 3D gas: the count, the distribution and seed kept.
  SceneConfig gas = demcal::parse_config_text(
      "{" + test::kMaterialMember + R"(, "dimension": 3, "assembly": {"type": "random",
         "count": 50, "radius_min": 4e-4, "radius_max": 6e-4, "seed": 7}})",
      "gas.json");
  const SceneConfig gas2 = demcal::scene_of_size(gas, 300);
  EXPECT_EQ(gas2.assembly.count, 300);
  EXPECT_EQ(gas2.assembly.seed, 7u);
  EXPECT_EQ(demcal::make_sphere_assembly(gas2).size(), 300);
}

// The counts `scaling` checks its sizes on, without generating: an FCC
// block of whole cells (300 spheres asked make 256, as 256 do), a random
// gas the count asked.
TEST(Upscaling3D, ParticlesOfSizeIsTheCountTheGeneratorMakes) {
  SceneConfig c = fcc_config();
  c.assembly.cells_x = 2, c.assembly.cells_y = 3, c.assembly.cells_z = 4;
  for (const SceneConfig& family : {fcc_config(), c}) {
    for (int64_t n : {4, 32, 100, 108, 256, 300, 864, 1000}) {
      SCOPED_TRACE(n);
      EXPECT_EQ(demcal::particles_of_size(family, n),
                demcal::make_sphere_assembly(demcal::scene_of_size(family, n)).size());
    }
  }
  EXPECT_EQ(demcal::particles_of_size(fcc_config(), 300), 256);
  EXPECT_EQ(demcal::size_rounding(fcc_config()), "an FCC lattice of whole cells");
  const SceneConfig gas = demcal::parse_config_text(
      "{" + test::kMaterialMember + R"(, "dimension": 3, "assembly": {"type": "random",
         "count": 50, "radius_min": 4e-4, "radius_max": 6e-4, "seed": 7}})",
      "gas.json");
  EXPECT_EQ(demcal::particles_of_size(gas, 301), 301);
  EXPECT_EQ(demcal::make_sphere_assembly(demcal::scene_of_size(gas, 301)).size(), 301);
}

TEST(Upscaling3D, PrototypeSpheresAsTheConfigNamesThem) {
  demcal::PrototypeSource src;
  const auto a = demcal::prototype_spheres(fcc_config(), 0, "", &src);
  EXPECT_EQ(a.size(), 256);
  EXPECT_EQ(src.kind, "generated");
  EXPECT_NE(src.description.find("4x4x4 cells"), std::string::npos) << src.description;
  // No prototype key: the REV itself.
  const auto rev = demcal::prototype_spheres(fcc_config(R"({})"), 0, "", &src);
  EXPECT_EQ(rev.size(), 32);
  EXPECT_EQ(src.kind, "rev");
  // A sphere file REV has no generator to resize: a count draws the file's
  // radii into a gas of that many spheres.
  test::TempDir dir("up3d");
  std::string csv = "x,y,z,r\n";
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        csv += std::to_string(1e-3 * i) + "," + std::to_string(1e-3 * j) + "," +
               std::to_string(1e-3 * k) + ",5e-4\n";
  const std::string file = test::write_text(dir / "cube.csv", csv);
  SceneConfig from_file = fcc_config();
  from_file.assembly.type = "file";
  from_file.assembly.file = file;
  ASSERT_GT(from_file.prototype.particles, 8);
  const auto drawn = demcal::prototype_spheres(from_file, 0, "", &src);
  EXPECT_EQ(src.kind, "generated");
  EXPECT_EQ(static_cast<int64_t>(drawn.size()), from_file.prototype.particles);
  for (double r : drawn.r) EXPECT_EQ(r, 5e-4);  // the file's radii
  // The file itself is a prototype.
  const auto read = demcal::prototype_spheres(from_file, 0, file, &src);
  EXPECT_EQ(read.size(), 8);
  EXPECT_EQ(src.kind, "file");
}

// A generated prototype is a gas: a count at which it never consolidates
// was generated (and by verify, rev and export consolidated); now refused
// before it is made, in the config check's words (gas_layers_fault), naming
// --particles when the command gave the count. Lattices are unaffected.
TEST(Upscaling3D, AGeneratedPrototypeGasThatNeverConsolidatesIsBadInput) {
  const auto refusal = [](const auto& make) -> std::string {
    try {
      make();
    } catch (const demcal::InputError& e) {
      return e.file() + ": " + e.message();
    }
    return "not refused";
  };
  const SceneConfig spheres = demcal::parse_config_text(
      "{" + test::kMaterialMember + R"(, "dimension": 3, "assembly": {"type": "random",
         "count": 50, "radius_min": 4e-4, "radius_max": 6e-4, "seed": 7}})",
      "gas.json");
  EXPECT_EQ(refusal([&] { demcal::prototype_spheres(spheres, 6); }),
            "--particles: a prototype generated as a gas of 6 spheres: too few spheres for a "
            "random gas with 2 layers along every side and 3 spheres across: at least 10; got 6");
  const SceneConfig disks = demcal::parse_config_text(
      "{" + test::kMaterialMember + R"(, "assembly": {"type": "random", "count": 50,
         "radius_min": 4e-4, "radius_max": 6e-4, "aspect": 0.1}})",
      "gas2d.json");
  // The count named in the words as in the field, with the nearest count
  // that consolidates at the config's aspect (11: 0.1·11 > 1 gives 2 columns).
  EXPECT_EQ(refusal([&] { demcal::prototype_assembly(disks, 5); }),
            "--particles: a prototype generated as a gas of 5 disks: the count gives a gas of 1 "
            "columns and 5 rows of 5 disks: a sample needs at least 2 along every side (a gas one "
            "particle thick never comes to a static state between the servo walls); at "
            "assembly.aspect 0.1 the nearest count that gives a sample is 11 (or assembly.aspect "
            "above 0.2 "
            "and up to about 3.2 for count 5); got 5");
  EXPECT_EQ(demcal::prototype_spheres(spheres, 10).size(), 10);
  EXPECT_EQ(demcal::prototype_spheres(fcc_config(), 4).size(), 4);  // one FCC cell
}

TEST(Upscaling3D, ParamsFileCarriesThePrototypeBlock) {
  const SceneConfig config = fcc_config();
  const nlohmann::json p = params_3d(config);
  const auto& rev = p.at("rev");
  const auto& proto = p.at("prototype");
  EXPECT_EQ(p.at("dimension"), 3);
  EXPECT_EQ(rev.at("particles"), 32);
  EXPECT_EQ(proto.at("particles"), 256);
  // Nstep by the default 3D law, ∝ L²: 2 → 4 cells an edge doubles L, so
  // 4 × 3000 (= 3000·(256/32)^(2/3)).
  EXPECT_EQ(proto.at("steps").get<int64_t>(), 4 * 3000);
  // Multipliers unchanged; uniform spheres of one radius: the same Δt_crit,
  // Δt and damping as the REV's.
  for (const char* k : {"dt_ratio", "damping_ratio_translation", "damping_ratio_rotation",
                        "mass_scaling", "dt_crit", "dt", "damping_translation", "radius_min"})
    EXPECT_DOUBLE_EQ(proto.at(k).get<double>(), rev.at(k).get<double>()) << k;
  // Δt_crit = 2·sqrt(m/kn), m = ρ(4/3)πr³.
  const double m = 2650.0 * 4.0 / 3.0 * M_PI * std::pow(5e-4, 3);
  EXPECT_NEAR(proto.at("dt_crit").get<double>(), 2.0 * std::sqrt(m / 1e8), 1e-15);
  EXPECT_EQ(proto.at("source").at("kind"), "generated");
  const auto& up = p.at("upscaling");
  EXPECT_EQ(up.at("particles_prototype"), 256);
  EXPECT_NEAR(up.at("factor").get<double>(), 4.0, 1e-12);  // (256/32)^(2/3): L doubled
  // The law and where it was measured.
  EXPECT_EQ(up.at("law"), "power");
  EXPECT_DOUBLE_EQ(up.at("exponent").get<double>(), 2.0 / 3.0);
  EXPECT_NE(up.at("source").get<std::string>().find("reports/scaling-3d.md"), std::string::npos);
}

// The default law is Nstep ∝ L² in both dimensions (reports/scaling-3d.md:
// the force balance's drag term, ~ ζ·L²/Nstep, is what the steps must
// beat at large sizes): linear in N for disks (L ∝ N^(1/2), Tu & Andrade),
// N^(2/3) for spheres (L ∝ N^(1/3)). Checked on FCC blocks, whose edge is
// known exactly: c → k·c cells an edge multiplies Nstep by k².
TEST(Upscaling3D, DefaultLawIsNstepProportionalToLSquared) {
  EXPECT_EQ(demcal::default_law(2).name(), "linear");
  EXPECT_EQ(demcal::default_law(3).name(), "power");
  const auto fcc = [](int64_t cells) { return 4 * cells * cells * cells; };
  for (int64_t c : {2, 3, 4, 5})
    for (int64_t k : {2, 3, 9}) {
      const int64_t steps = demcal::upscale_steps(3000, fcc(c), fcc(k * c), demcal::default_law(3));
      EXPECT_EQ(steps, 3000 * k * k) << c << " cells, edge x" << k;
    }
  // Disks: N ∝ L², so the same law is linear in N.
  EXPECT_EQ(demcal::upscale_steps(3000, 400, 1600, demcal::default_law(2)), 4 * 3000);
}

class Upscale3DCli : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "work");
    params_ = test::write_text(dir_ / "params.json", params_3d(fcc_config()).dump(2) + "\n");
  }
  test::RunResult demcal(const std::vector<std::string>& args) {
    return test::run_demcal(args, dir_ / "work");
  }
  test::TempDir tmp_{"upscale3d"};
  const fs::path dir_ = tmp_.path();
  std::string params_;
};

TEST_F(Upscale3DCli, NstepByTheMeasuredLawOrTheDefault) {
  // A 3D study's law (scaling.json, dimension 3, exponent 0.4).
  const std::string law = test::write_text(dir_ / "scaling.json",
                                           R"({"schema": "demcal.scaling/1", "dimension": 3,
          "law": {"law": "power", "exponent": 0.4, "source": "a 3D study"}})");
  const auto r = demcal({"upscale", params_, "--particles", "864", "--law", law, "-o", "up.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json up = nlohmann::json::parse(test::read_text(dir_ / "work" / "up.json"));
  EXPECT_EQ(up.at("prototype").at("particles"), 864);  // FCC 6×6×6
  EXPECT_EQ(up.at("prototype").at("steps").get<int64_t>(),
            std::llround(3000.0 * std::pow(864.0 / 32.0, 0.4)));
  EXPECT_DOUBLE_EQ(up.at("upscaling").at("exponent").get<double>(), 0.4);
  EXPECT_NE(r.err.find("a 3D study"), std::string::npos) << r.err;  // which law, said

  // No law given: the params.json's, the default 3D law N^(2/3); 500
  // spheres are FCC 5×5×5 (L 2.5× the REV's): 3000 × 2.5². The output says
  // which law and where it was measured.
  const auto d = demcal({"upscale", params_, "--particles", "500", "-o", "up2.json"});
  ASSERT_EQ(d.status, 0) << d.err;
  const nlohmann::json up2 = nlohmann::json::parse(test::read_text(dir_ / "work" / "up2.json"));
  EXPECT_EQ(up2.at("prototype").at("steps").get<int64_t>(), 18750);
  EXPECT_NE(d.err.find("N^(2/3)"), std::string::npos) << d.err;
  EXPECT_NE(d.err.find("reports/scaling-3d.md"), std::string::npos) << d.err;

  // Tu & Andrade's linear law on request.
  const auto l =
      demcal({"upscale", params_, "--particles", "500", "--exponent", "1", "-o", "up3.json"});
  ASSERT_EQ(l.status, 0) << l.err;
  const nlohmann::json up3 = nlohmann::json::parse(test::read_text(dir_ / "work" / "up3.json"));
  EXPECT_EQ(up3.at("prototype").at("steps").get<int64_t>(), std::llround(3000.0 * 500.0 / 32.0));
}

// A count the generator cannot make exactly is said, not silently changed:
// 300 spheres asked for, FCC 4×4×4 = 256 made; 500 (5×5×5) is made as asked.
TEST_F(Upscale3DCli, ACountTheGeneratorCannotMakeIsSaid) {
  const auto r = demcal({"upscale", params_, "--particles", "300", "-o", "up.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json up = nlohmann::json::parse(test::read_text(dir_ / "work" / "up.json"));
  EXPECT_EQ(up.at("prototype").at("particles"), 256);
  EXPECT_NE(r.err.find("demcal upscale: note: 300 particles asked for, 256 made"),
            std::string::npos)
      << r.err;
  const auto exact = demcal({"upscale", params_, "--particles", "500", "-o", "up2.json"});
  ASSERT_EQ(exact.status, 0) << exact.err;
  EXPECT_EQ(exact.err.find("asked for"), std::string::npos) << exact.err;
}

TEST_F(Upscale3DCli, DimensionMismatchesAreBadInput) {
  // A 2D params.json (no "dimension", no embedded config) of the same REV.
  nlohmann::json p2 = nlohmann::json::parse(test::read_text(params_));
  p2.erase("dimension");
  p2.erase("config");
  const std::string params_2d = test::write_text(dir_ / "p2.json", p2.dump(2));
  const std::string fcc = test::write_text(dir_ / "fcc2.json", fcc_text());
  const std::string law_2d = test::write_text(
      dir_ / "scaling2d.json", R"({"schema": "demcal.scaling/1", "law": {"exponent": 1.0}})");
  struct Case {
    std::vector<std::string> args;
    std::string file, field;
  };
  const std::string hex = test::shipped_config("hex_5x5");
  const Case cases[] = {
      // 3D params on a 2D config, and the reverse.
      {{"upscale", params_, "--config", hex, "--particles", "100"}, params_, "dimension"},
      {{"verify", params_, "--config", hex}, params_, "dimension"},
      {{"upscale", params_2d, "--config", fcc, "--particles", "100"}, params_2d, "dimension"},
      // A law measured on disks for 3D params.
      {{"upscale", params_, "--particles", "100", "--law", law_2d}, law_2d, "dimension"},
      // A bad "dimension" in params.json.
      {{"upscale",
        test::write_text(dir_ / "p4.json",
                         [&] {
                           nlohmann::json j = nlohmann::json::parse(test::read_text(params_));
                           j["dimension"] = 4;
                           return j.dump();
                         }()),
        "--particles", "100"},
       (dir_ / "p4.json").string(),
       "dimension"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.args[0] + " " + k.args[1]);
    const test::RunResult r = demcal(k.args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(test::lines_of(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find(k.file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(k.field), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir_ / "work"));
  }
}

}  // namespace
