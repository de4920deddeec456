// `demcal verify` on 3D params (issue #18): a small FCC prototype (256
// spheres, 4 cells an edge) run with the parameters of a 32-sphere REV
// upscaled by the law, on one thread (below kThreadsFrom spheres verify
// does not try more); the estimate is printed before the
// run, and verify.json reports the criteria, the peak against the REV's and
// the particle-steps that the law's Nstep gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "support/files.hpp"
#include "support/params_3d.hpp"
#include "support/process.hpp"
#include "support/scenes.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;

/// params.json of a 32-sphere FCC REV (2 cells an edge) whose prototype
/// is 256 spheres, in `dir`.
std::string write_fcc2_params(const fs::path& dir) {
  const demcal::SceneConfig config =
      demcal::parse_config_text("{" + test::kMaterialMember + R"(, "name": "fcc2", "dimension": 3,
        "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
        "test": {"type": "triaxial", "lateral_stress": 1e5, "vertical_strain": 1e-5,
                 "monitor_points": 50},
        "algorithm": {"steps": 2000}, "prototype": {"particles": 256}})",
                                "fcc2.json");
  const demcal::TriaxialState state =
      demcal::consolidate_triaxial(config, demcal::make_sphere_assembly(config));
  demcal::AlgorithmSpec best;
  best.dt_ratio = 0.15;
  best.steps = 2000;
  best.damping_ratio_translation = 0.7;
  best.damping_ratio_rotation = 0.5;
  const double rev_peak = -3.3e5;  // the REV's peak, as recorded
  return test::write_text(dir / "params.json",
                          test::params_3d(config, state, best, rev_peak).dump(2) + "\n");
}

TEST(Verify3D, SmallFccPrototypeRunsAndReports) {
  test::TempDir dir("verify3d");
  const std::string params = write_fcc2_params(dir.path());
  const test::RunResult r = test::run_demcal({"verify", params, "-o", "v"}, dir.path());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;  // PASS or FAIL, both reported
  // The estimate comes first, before the consolidation.
  const auto estimate = r.err.find("estimated");
  ASSERT_NE(estimate, std::string::npos) << r.err;
  EXPECT_LT(estimate, r.err.find("consolidated in")) << r.err;
  EXPECT_NE(r.err.find("N^(2/3)"), std::string::npos) << r.err;  // which law
  EXPECT_NE(r.out.find("256 spheres"), std::string::npos) << r.out;

  const nlohmann::json v = nlohmann::json::parse(test::read_text(dir / "v" / "verify.json"));
  EXPECT_EQ(v.at("dimension"), 3);
  EXPECT_EQ(v.at("prototype").at("particles"), 256);
  const int64_t steps = 2000 * 4;  // the default 3D law, ∝ L²: 2 → 4 cells an edge
  EXPECT_EQ(v.at("loading").at("steps").get<int64_t>(), steps);
  EXPECT_DOUBLE_EQ(v.at("loading").at("particle_steps").get<double>(), 256.0 * steps);
  // One thread below kThreadsFrom spheres, whatever a probe would read on a
  // loaded machine (two threads ran a 256-sphere prototype 10-28x slower).
  EXPECT_EQ(v.at("loading").at("threads").get<int>(), 1);
  EXPECT_GT(v.at("loading").at("estimated_s").get<double>(), 0.0);
  EXPECT_EQ(v.at("passed").get<bool>(), r.status == 0);
  for (const char* k : {"force_balance", "moment_balance", "servo", "oscillation"})
    EXPECT_TRUE(v.at("criteria").contains(k)) << k;
  // The peak: compressive, and against the REV's as params.json records it.
  const double peak = v.at("peak").at("stress_zz").get<double>();
  EXPECT_LT(peak, 0.0);
  EXPECT_DOUBLE_EQ(v.at("peak").at("rev_stress_zz").get<double>(), -3.3e5);
  EXPECT_NEAR(v.at("peak").at("relative_to_rev").get<double>(), (peak + 3.3e5) / 3.3e5, 1e-12);
  // series.csv: a header and the monitored points.
  EXPECT_GE(test::lines_of(test::read_text(dir / "v" / "series.csv")).size(), 50u);
  // With the metadata of its run: `demcal score` on it, no option, gives
  // verify's peak and verdict.
  const test::RunResult sc = test::run_demcal({"score", "series.csv", "-o", "scored"}, dir / "v");
  ASSERT_TRUE(sc.status == 0 || sc.status == 1) << sc.err << sc.out;
  const nlohmann::json scored =
      nlohmann::json::parse(test::read_text(dir / "v" / "scored" / "summary.json"));
  EXPECT_EQ(scored.at("criteria").at("peak_stress_yy").get<double>(), peak);
  EXPECT_EQ(scored.at("passed").get<bool>(), v.at("passed").get<bool>());
  EXPECT_EQ(sc.status, r.status);
}

// verify's 2D-only options are refused in 3D, one line naming the option
// (and the engine asked for: a refused --engine liggghts was told about
// LAMMPS), nothing written; --np was ignored.
TEST(Verify3D, TwoDimensionalOptionsAreRefusedByName) {
  test::TempDir dir("verify3d_options");
  const std::string params = write_fcc2_params(dir.path());
  struct Case {
    std::vector<std::string> args, mentions;
    std::string absent;
  };
  const std::vector<Case> cases = {
      {{"--engine", "liggghts"}, {"--engine", "\"liggghts\"", "--format liggghts"}, "LAMMPS"},
      {{"--engine", "lammps"}, {"--engine", "\"lammps\"", "demcal export"}, ""},
      {{"--np", "2"}, {"--np", "--engine lammps"}, ""},
      {{"--tile", "2x2"}, {"--tile"}, ""},
      {{"--consolidate-only"}, {"--consolidate-only"}, ""},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"verify", params, "-o", "v"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    SCOPED_TRACE(c.args.front());
    const test::RunResult r = test::run_demcal(args, dir.path());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(test::lines_of(r.err).size(), 1u) << r.err;
    for (const std::string& m : c.mentions) EXPECT_NE(r.err.find(m), std::string::npos) << r.err;
    if (!c.absent.empty()) {
      EXPECT_EQ(r.err.find(c.absent), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "v"));
  }
}

// An -o that cannot be made (a path under a regular file) is bad input
// found before anything is printed or run: one line naming the folder,
// exit 2 (test_cli.cpp has the 2D twin).
TEST(Verify3D, AnUnusableOutputFolderFailsBeforeAnythingIsPrinted) {
  test::TempDir dir("verify3d-folder");
  const std::string params = write_fcc2_params(dir.path());
  test::write_text(dir.path() / "blocker", "a file\n");
  const std::string out = (dir.path() / "blocker" / "v").string();
  const test::RunResult r = test::run_demcal({"verify", params, "-o", out}, dir.path());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("demcal: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(out), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
