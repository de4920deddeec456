// The demcal program end to end (issues #3 and #9 §1): bad input gives exit
// status 2, one line on stderr naming the file and the key (or line), and no
// output at all; `demcal check` prints the derived scales; `demcal run`
// writes summary.json, series.csv and a valid legacy VTK file.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/kernel/world.hpp"
#include "demcal/scene/config.hpp"
#include "support/calibrated_params.hpp"
#include "support/csv.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/run_status.hpp"
#include "support/scenes.hpp"
#include "support/vtk.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;

using test::lines_of;
using test::read_text;
using Result = test::RunResult;

const std::string kHex5 = test::shipped_config("hex_5x5");

using test::split;

/// A fresh folder per test (the working directory of the runs), removed
/// afterwards.
class CliEndToEnd : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_ / "work"); }

  /// Run `demcal ARGS` in dir_/work with stdout and stderr captured, with
  /// `env` ("NAME=VALUE") added to the environment.
  Result demcal(const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
    if (env.empty()) return test::run_demcal(args, dir_ / "work");
    std::vector<std::string> command = env;
    command.push_back(test::kDemcalBinary);
    command.insert(command.end(), args.begin(), args.end());
    return test::run_program("/usr/bin/env", command, dir_ / "work");
  }
  std::string write(const std::string& name, const std::string& content) {
    return test::write_text(dir_ / name, content);
  }
  /// Everything under dir_/work (the runs' working directory).
  std::set<std::string> work_contents() { return test::paths_under(dir_ / "work"); }

  /// `args` run twice (-o miss, -o hit) with one consolidation cache
  /// folder: "consolidating ..." (`consolidating`, the whole line) only in
  /// the fresh run, not before the cache read; both say their consolidation
  /// in a line starting `consolidated`: "N steps, T s", the read's "N steps,
  /// read from the cache in T s" (print_consolidation_time), the same N.
  void expect_said_as_the_others(const std::vector<std::string>& args,
                                 const std::string& consolidating,
                                 const std::string& consolidated) {
    const std::string cache = "DEMCAL_CACHE_DIR=" + (dir_ / "cache").string();
    auto run = [&](const std::string& out) {
      std::vector<std::string> with_out = args;
      with_out.insert(with_out.end(), {"-o", out});
      const Result r = demcal(with_out, {cache});
      EXPECT_EQ(r.status, 0) << r.err;
      return r;
    };
    const Result miss = run("miss");
    const Result hit = run("hit");
    auto line_of = [](const std::string& text, const std::string& start) {
      for (const std::string& line : lines_of(text))
        if (line.rfind(start, 0) == 0) return line;
      return std::string("no line ") + start;
    };
    EXPECT_EQ(line_of(miss.err, consolidating), consolidating) << miss.err;
    EXPECT_EQ(hit.err.find("consolidating"), std::string::npos) << hit.err;
    const std::string fresh = line_of(miss.err, consolidated);
    const std::string read = line_of(hit.err, consolidated);
    const size_t comma = fresh.find(" steps, ");
    ASSERT_NE(comma, std::string::npos) << miss.err;
    EXPECT_EQ(fresh.find("cache"), std::string::npos) << fresh;
    EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(fresh[comma + 8]))) << fresh;
    EXPECT_EQ(fresh.substr(fresh.size() - 2), " s") << fresh;
    EXPECT_EQ(read.rfind(fresh.substr(0, comma + 8) + "read from the cache in ", 0), 0u) << read;
    EXPECT_EQ(read.substr(read.size() - 2), " s") << read;
  }

  /// Bad input: exit 2, exactly one line on stderr that contains every one
  /// of `mentions`, nothing on stdout, and nothing written.
  void expect_bad_input(const std::vector<std::string>& args,
                        const std::vector<std::string>& mentions,
                        const std::vector<std::string>& env = {}) {
    std::string trace;
    for (const auto& a : env) trace += a + " ";
    for (const auto& a : args) trace += a + " ";
    SCOPED_TRACE(trace);
    const Result r = demcal(args, env);
    EXPECT_EQ(r.status, 2) << r.err;
    const auto err_lines = lines_of(r.err);
    EXPECT_EQ(err_lines.size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("demcal: error: ", 0), 0u) << r.err;
    for (const auto& m : mentions) EXPECT_NE(r.err.find(m), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(work_contents().empty()) << "left output behind: " << *work_contents().begin();
  }

  test::TempDir tmp_{"cli"};
  const fs::path dir_ = tmp_.path();
};

// --- bad input ------------------------------------------------------------

TEST_F(CliEndToEnd, BadConfigsExitTwoNameFileAndKeyAndWriteNothing) {
  const std::string out = (dir_ / "work" / "out").string();
  struct Case {
    std::string name, content, key;
  };
  const std::vector<Case> cases = {
      {"negative.json", R"({"material": {"kn": -1}})", "material.kn"},
      {"nested.json", R"({"material": {"wall": {"foo": 1}}})", "material.wall.foo"},
      {"unknown.json", R"({"foo": 1})", "foo"},
      {"type.json", R"({"algorithm": {"steps": "many"}})", "algorithm.steps"},
      {"inf.json", R"({"test": {"lateral_stress": 1e999}})", "test.lateral_stress"},
      {"bounds.json", R"({"assembly": {"type": "random", "radius_min": 1, "radius_max": 0.5}})",
       "assembly.radius_min"},
      {"required.json", R"({"assembly": {"type": "file"}})", "assembly.file"},
      {"malformed.json", "{\n  \"name\": \"x\",\n  oops\n}", "line 3"},
  };
  for (const auto& c : cases) {
    const std::string path = write(c.name, c.content);
    expect_bad_input({"run", path, "-o", out}, {path, c.key});
    // The default output folder (demcal-run-NAME in the working directory)
    // is not created either.
    expect_bad_input({"run", path}, {path, c.key});
    expect_bad_input({"check", path}, {path, c.key});
  }
}

TEST_F(CliEndToEnd, BadOverridesAndMissingFilesExitTwo) {
  const std::string out = (dir_ / "work" / "out").string();
  expect_bad_input({"run", kHex5, "--set", "algorithm.steps", "-o", out},
                   {"--set algorithm.steps", "section.key=value"});
  // A value or key a --set gave is named as the --set's (the file is fine).
  expect_bad_input({"run", kHex5, "--set", "algorithm.steps=-5", "-o", out},
                   {"--set algorithm.steps=-5: algorithm.steps"});
  expect_bad_input({"run", kHex5, "--set", "algorithm.stepz=5", "-o", out},
                   {"--set algorithm.stepz=5: algorithm.stepz"});
  expect_bad_input({"run", kHex5, "--set", "material.kn=1e999", "-o", out},
                   {"--set material.kn=1e999", "material.kn"});
  const std::string missing = (dir_ / "missing.json").string();
  expect_bad_input({"run", missing, "-o", out}, {missing});
  expect_bad_input({"run", dir_.string(), "-o", out}, {dir_.string()});  // a folder
}

// A value that passes its own range check yet makes a scale the kernel
// derives overflow or underflow (rho = 1e308: the mass is inf and the step
// "must be finite"; a radius of 1e-150: the inertia is 0, the state turns
// non-finite) is bad input found before any computing: the --set (or the
// file) and the field that pushed the scale out, what is wrong.
TEST_F(CliEndToEnd, DerivedScalesThatOverflowOrUnderflowAreBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  struct Case {
    std::string set, field, what;
  };
  const std::vector<Case> cases = {
      {"material.density=1e308", "material.density", "mass f_ms*rho*t*pi*r^2 is inf"},
      {"material.density=1e-308", "material.density", "below the smallest normal double"},
      {"algorithm.mass_scaling=1e308", "algorithm.mass_scaling", "mass f_ms*rho*t*pi*r^2 is inf"},
      {"assembly.radius=1e-150", "assembly.radius", "moment of inertia m*r^2/2 is 0"},
      {"assembly.radius=1e150", "assembly.radius", "moment of inertia m*r^2/2 is inf"},
  };
  for (const Case& c : cases) {
    expect_bad_input({"run", kHex5, "--set", c.set, "-o", out},
                     {"--set " + c.set + ": " + c.field + ": ", c.what});
    expect_bad_input({"check", kHex5, "--set", c.set}, {"--set " + c.set + ": " + c.field});
  }
  // In the file: the file is named.
  const std::string dense = write(
      "dense.json", R"({"material": {"density": 1e308, "kn": 1e8, "kt": 5e7, "friction": 0.3}})");
  expect_bad_input({"run", dense, "-o", out}, {dense + ": material.density: ", "overflows"});
}

// A wall stiffer than kn/α² (α = 0.2, the consolidation's step) cannot be
// integrated: a particle it holds alone oscillates past ω·Δt = 2, so the
// consolidation diverged ("overlap beyond limit", exit 1) within a few
// hundred steps. A user's "rigid" wall is bad input, named before any
// computing, in 2D and 3D.
TEST_F(CliEndToEnd, AWallTooStiffForTheConsolidationStepIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  for (const std::string& config : {kHex5, test::shipped_config("fcc_4x4x4")}) {
    SCOPED_TRACE(config);
    expect_bad_input({"run", config, "--set", "material.wall.kn=3e9", "-o", out},
                     {"--set material.wall.kn=3e9: material.wall.kn: 30 times kn",
                      "below kn/alpha^2 = 2.5e+09"});
  }
}

// The overlap at sigma3 grows as sigma3/kn, and the checks of it with the
// assembly (check_resolvable, check_sphere_overlap) named the config file
// and test.lateral_stress whatever was extreme and wherever it came from:
// `--set material.kn=1e300` read "configs/hex_5x5.json: test.lateral_stress:
// must be at least 2.2e+290 Pa". Now the field a --set changed (sigma3 when
// both or neither were), with the --set that gave it and both bounds.
// The round-off bound's other input, consolidation_tolerance, was never
// named: `check configs/hex_5x5.json --set test.consolidation_tolerance=1e-12`
// blamed "configs/hex_5x5.json: test.lateral_stress" (2D and 3D). Now that
// --set and the tolerance, with its own bound beside the others.
TEST_F(CliEndToEnd, AnOverlapAtSigma3OutOfRangeNamesTheExtremeFieldAndItsSet) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string fcc = test::shipped_config("fcc_4x4x4");
  struct Case {
    std::string config, set, field, what;
  };
  const std::vector<Case> cases = {
      {kHex5, "material.kn=1e300", "material.kn", "material.kn at most"},
      {kHex5, "test.lateral_stress=1e-9", "test.lateral_stress",
       "test.lateral_stress must be at least"},
      {fcc, "material.kn=1e300", "material.kn", "material.kn at most"},
      {fcc, "test.lateral_stress=1e-9", "test.lateral_stress", "not resolved"},
      {fcc, "test.lateral_stress=1e10", "test.lateral_stress", "must be at most 2.5e+09 Pa"},
      {fcc, "material.wall.kn=1e2", "material.wall.kn", "material.wall.kn at least 4000 N/m"},
      // The round-off bound is the tolerance's too: named, with its bound,
      // when a --set gave it and none gave sigma3 or the stiffness.
      {kHex5, "test.consolidation_tolerance=1e-12", "test.consolidation_tolerance",
       "or test.consolidation_tolerance at least "},
      {fcc, "test.consolidation_tolerance=1e-12", "test.consolidation_tolerance",
       "or test.consolidation_tolerance at least "},
  };
  for (const Case& c : cases) {
    expect_bad_input({"run", c.config, "--set", c.set, "-o", out},
                     {"--set " + c.set + ": " + c.field + ": ", c.what});
    expect_bad_input({"check", c.config, "--set", c.set}, {"--set " + c.set + ": " + c.field});
  }
  expect_bad_input({"check", fcc, "--set", "material.kn=1e300", "--set", "test.lateral_stress=1e5"},
                   {"--set test.lateral_stress=1e5: test.lateral_stress: ", "material.kn at most"});
  // The tolerance's bound beside sigma3's and the stiffness's (the scene's
  // 25 disks at run, the prototype's 40 000 at check); with sigma3 given
  // too, sigma3 as before.
  expect_bad_input({"run", kHex5, "--set", "test.consolidation_tolerance=1e-12", "-o", out},
                   {"test.lateral_stress must be at least ", "or material.kn at most ",
                    "or test.consolidation_tolerance at least 6.10623e-12; got 1e-12"});
  expect_bad_input({"check", kHex5, "--set", "test.consolidation_tolerance=1e-12"},
                   {"or test.consolidation_tolerance at least 2.226e-10; got 1e-12"});
  expect_bad_input({"check", fcc, "--set", "test.consolidation_tolerance=1e-12"},
                   {"or test.consolidation_tolerance at least 2.85868e-08; got 1e-12"});
  expect_bad_input({"check", kHex5, "--set", "test.consolidation_tolerance=1e-12", "--set",
                    "test.lateral_stress=1e5"},
                   {"--set test.lateral_stress=1e5: test.lateral_stress: ", "; got 100000"});
  // A file's sigma3 no tolerance below 1 resolves (1e-9 Pa: 1165.73 in 2D,
  // 660555 in 3D): the tolerance a --set changed is no culprit and no
  // alternative. It was named, "or test.consolidation_tolerance at least
  // 1165.73; got 0.01", a tolerance the config refuses; now the file's sigma3.
  const std::string material = R"("material": {"density": 2650, "kn": 1e8, "kt": 5e7,
      "friction": 0.3}, "test": {"lateral_stress": 1e-9})";
  const std::string faint = write("faint.json", "{" + material + "}");
  const std::string faint3d = write("faint3d.json", R"({"dimension": 3, )" + material + "}");
  for (const std::string& config : {faint, faint3d})
    for (const std::string command : {"run", "check"}) {
      std::vector<std::string> args = {command, config, "--set",
                                       "test.consolidation_tolerance=1e-2"};
      if (command == "run") args.insert(args.end(), {"-o", out});
      expect_bad_input(args, {config + ": test.lateral_stress: ", " N/m; got 1e-09"});
    }
}

// The 2D bound on the overlap at sigma3, 2*sigma3*t/kn, is checked when the
// config is read (check_lateral_stress), and it named the config file and
// test.lateral_stress whatever had made it too large: `--set material.kn=1e3`
// read "configs/hex_5x5.json: test.lateral_stress: must be at most 25 Pa".
// Now the rule of the checks with the assembly (above): the field a --set
// changed (sigma3 when both or neither were), its --set, both bounds.
// `--set material.thickness=1e3` (the overlap grows with the out-of-plane
// thickness t) and 1e-12 (check_resolvable) blamed sigma3 and the file
// too, until 2026-12-05 evening: the thickness is named, with its bound.
TEST_F(CliEndToEnd, TheParseTimeOverlapAtSigma3NamesTheFieldASetChanged) {
  const std::string out = (dir_ / "work" / "out").string();
  struct Case {
    std::vector<std::string> sets;
    std::string named, what;
  };
  const std::vector<Case> cases = {
      {{"material.kn=1e3", "material.kt=1e2"},
       "--set material.kn=1e3: material.kn: ",
       "test.lateral_stress must be at most 25 Pa, or material.kn at least 4e+06 N/m; got 1000"},
      {{"material.wall.kn=1e3"},
       "--set material.wall.kn=1e3: material.wall.kn: ",
       "test.lateral_stress must be at most 25 Pa, or material.wall.kn at least 4e+06 N/m"},
      {{"test.lateral_stress=1e9"},
       "--set test.lateral_stress=1e9: test.lateral_stress: ",
       "test.lateral_stress must be at most 2.5e+06 Pa, or material.kn at least 4e+10 N/m; got "
       "1e+09"},
      {{"material.kn=1e3", "material.kt=1e2", "test.lateral_stress=1e4"},
       "--set test.lateral_stress=1e4: test.lateral_stress: ",
       "test.lateral_stress must be at most 25 Pa, or material.kn at least 400000 N/m"},
      // The thickness (2D: the force on a disk per unit stress is
      // sigma3*2r*t), named with its bound when a --set gave it and none gave
      // sigma3 or the stiffness; 1e-12 is an overlap round-off cannot resolve
      // (check_resolvable).
      {{"material.thickness=1e3"},
       "--set material.thickness=1e3: material.thickness: ",
       "test.lateral_stress must be at most 2500 Pa, or material.kn at least 4e+09 N/m, or "
       "material.thickness at most 25 m; got 1000"},
      {{"material.thickness=25.1"},
       "--set material.thickness=25.1: material.thickness: ",
       "or material.thickness at most 25 m; got 25.1"},
      {{"material.thickness=1e-12"},
       "--set material.thickness=1e-12: material.thickness: ",
       "is not resolved by positions"},
      // sigma3 or the stiffness given too: named as before.
      {{"material.thickness=1e3", "test.lateral_stress=1e5"},
       "--set test.lateral_stress=1e5: test.lateral_stress: ",
       "test.lateral_stress must be at most 2500 Pa, or material.kn at least 4e+09 N/m; got "
       "100000"},
      {{"material.thickness=1e3", "material.kn=1e8"},
       "--set material.kn=1e8: material.kn: ",
       "test.lateral_stress must be at most 2500 Pa, or material.kn at least 4e+09 N/m; got "
       "1e+08"},
  };
  for (const Case& c : cases) {
    for (const std::string command : {"run", "check"}) {
      std::vector<std::string> args = {command, kHex5};
      for (const std::string& set : c.sets) args.insert(args.end(), {"--set", set});
      if (command == "run") args.insert(args.end(), {"-o", out});
      expect_bad_input(args, {c.named, c.what});
    }
  }
  // In the file, with no --set: the file and sigma3.
  const std::string high = write("high.json", R"({"material": {"density": 2650, "kn": 1e3,
      "kt": 1e2, "friction": 0.3}, "test": {"lateral_stress": 1e5}})");
  expect_bad_input({"check", high}, {high + ": test.lateral_stress: ",
                                     "test.lateral_stress must be at most 25 Pa, or material.kn "
                                     "at least 4e+06 N/m; got 100000"});
  expect_bad_input({"check", kHex5, "--set", "material.thickness=1e-12"},
                   {"thickness 1e-12 m", "or material.thickness at least ", " m; got 1e-12"});
  // At the bound it runs.
  const Result ok = demcal({"check", kHex5, "--set", "material.thickness=25"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// `check` builds the prototype's assembly (prototype.particles: 40 000
// disks on hex_5x5) before the scene's, and the round-off bound on sigma3
// depends on the assembly's extent: `check configs/hex_5x5.json --set
// test.lateral_stress=1e-3` said "positions up to 0.2005 m ... must be at
// least 0.02226 Pa for this assembly" where `run` (the scene's 25 disks,
// 0.0055 m) accepts 1e-3 and asks 0.000610623 Pa of 1e-4: two bounds for
// "this assembly", the prototype never named. Now the assembly is named,
// with its count (make_assembly's and make_sphere_assembly's `which`).
TEST_F(CliEndToEnd, AnUnresolvableSigma3NamesThePrototypesAssembly) {
  const std::string out = (dir_ / "work" / "out").string();
  expect_bad_input(
      {"check", kHex5, "--set", "test.lateral_stress=1e-3"},
      {"--set test.lateral_stress=1e-3: test.lateral_stress: ", "positions up to 0.2005 m",
       "at least 0.02226 Pa for the prototype's assembly (40000 particles)"});
  expect_bad_input({"check", test::shipped_config("fcc_4x4x4"), "--set", "test.lateral_stress=1"},
                   {"at least 2.85868 Pa for the prototype's assembly (23328 spheres)"});
  // The scene's own, and the REV as its own prototype: the scene's.
  expect_bad_input({"run", kHex5, "--set", "test.lateral_stress=1e-4", "-o", out},
                   {"positions up to 0.0055 m",
                    "at least 0.000610623 Pa for the scene's assembly (25 particles)"});
  expect_bad_input(
      {"check", kHex5, "--set", "test.lateral_stress=1e-4", "--set", "prototype.particles=0"},
      {"at least 0.000610623 Pa for the scene's assembly (25 particles)"});
}

// A prototype read from a particle file (--prototype, prototype.file, a
// params.json's prototype) never went through check_resolvable, which
// make_assembly applies to a generated one: `verify PARAMS --prototype
// far.csv` (25 disks at x ~ 1e6 m: round-off 1.1e-10 m, above a tenth of
// the tolerance of the 1e-6 m overlap at sigma3) consolidated and loaded
// them, exit 0. Now the commands that consolidate the prototype (verify,
// export) or a REV cut from it (rev: the file's positions) refuse it
// before any work, in check_resolvable's (3D check_sphere_overlap's)
// words, naming the file and how near the origin its positions must be.
// upscale only counts the file's particles: accepted.
TEST_F(CliEndToEnd, AnUnresolvablePrototypeFileIsRefusedBeforeItIsRun) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string params = test::example_params("hex_10x10");
  const std::string params3d = test::example_params("fcc_4x4x4");
  // Touching disks and spheres (r = 5e-4 m) far from the origin: 5x5 at
  // x ~ 1e6 m, 3x3x3 at x ~ 1e4 m (fcc_4x4x4's overlap is 1e-9 m).
  std::string disks = "x,y,r\n", spheres = "x,y,z,r\n";
  for (int i = 0; i < 27; ++i) {
    const std::string x = std::to_string(i % 3), y = std::to_string(i / 3 % 3);
    spheres += "10000.00" + x + ",0.00" + y + ",0.00" + std::to_string(i / 9) + ",0.0005\n";
  }
  for (int i = 0; i < 25; ++i)
    disks += "1000000.00" + std::to_string(i % 5) + ",0.00" + std::to_string(i / 5) + ",0.0005\n";
  const std::string far = write("far.csv", disks), far3d = write("far3d.csv", spheres);
  struct Case {
    std::vector<std::string> args;
    std::string file, assembly;
  };
  const std::vector<Case> cases = {
      {{"verify", params, "--prototype", far, "-o", out},
       far,
       "prototype's assembly (25 particles"},
      {{"export", params, "--prototype", far, "-o", out + "/deck.lammps"},
       far,
       "prototype's assembly (25 particles"},
      {{"rev", kHex5, "--prototype", far, "--particles", "16", "-o", out}, far, "REV's assembly ("},
      {{"verify", params3d, "--prototype", far3d, "-o", out},
       far3d,
       "prototype's assembly (27 spheres"},
      {{"export", params3d, "--prototype", far3d, "-o", out + "/deck.lammps"},
       far3d,
       "prototype's assembly (27 spheres"},
      {{"rev", test::shipped_config("fcc_4x4x4"), "--prototype", far3d, "--particles", "8", "-o",
        out},
       far3d,
       "REV's assembly ("},
  };
  for (const Case& c : cases)
    expect_bad_input(c.args, {": test.lateral_stress: ", "is not resolved by positions up to",
                              "for the " + c.assembly, ", from " + c.file + "), or material.kn",
                              ", or " + c.file + "'s positions within "});
  // verify --tile checks the tiled packing, whose positions are not the
  // file's: said so (it read "or FILE's positions within ... m").
  expect_bad_input({"verify", params, "--prototype", far, "--tile", "2x2", "-o", out},
                   {"prototype's assembly (100 particles, from " + far + " mirror-tiled 2x2)",
                    ", or the tiled positions of " + far + " within "});
  const Result counted = demcal({"upscale", params, "--prototype", far, "-o", out});
  EXPECT_EQ(counted.status, 0) << counted.err;
}

// A cubic lattice of side^dim touching particles of radius `scale` (x,y,r or
// x,y,z,r), for the checks of a particle file's radii below.
std::string touching_lattice(int dim, int side, const std::string& scale) {
  const double r = std::stod(scale);
  std::string csv = dim == 2 ? "x,y,r\n" : "x,y,z,r\n";
  const int count = dim == 2 ? side * side : side * side * side;
  char value[32];
  for (int i = 0; i < count; ++i) {
    for (int k = 0, rest = i; k < dim; ++k, rest /= side) {
      std::snprintf(value, sizeof value, "%.17g,", (2 * (rest % side) + 1) * r);
      csv += value;
    }
    csv += scale + "\n";
  }
  return csv;
}

// A prototype file's radii never went through check_derived_scales, which
// make_assembly applies to a config's. 2D: a 10x10 lattice of touching
// disks of r = 1e-150 m (masses underflow to 0) or 1e150 m (they
// overflow) passed check_resolvable (the round-off and the overlap at
// sigma3 both scale with r), and verify, export, rev and a scaling study
// cut from it consolidated into "consolidation diverged: non-finite
// state", exit 1. 3D: a 3x3x3 cube of such spheres was refused by the
// overlap at sigma3 alone ("test.lateral_stress ... at least 2.8e146 Pa"),
// a stress no user could mean. Now both are refused before any work by
// their radii (check_assembly, check_sphere_assembly: make_assembly's and
// make_sphere_assembly's checks), naming the file and its column r. So
// are upscale and calibrate (a config's prototype.file, before its
// search), which never run the prototype but derive its Δt and damping
// from these radii: upscale wrote a params.json with "damping_rotation":
// null (2D, 1e150 m) or a Δt of 5e-153 s, exit 0, and in 3D stopped on
// "SphereWorld: dt must be finite and >= 0", exit 1.
TEST_F(CliEndToEnd, APrototypeFileWhoseRadiiGiveNoNormalMassIsRefusedBeforeItIsRun) {
  const std::string out = (dir_ / "work" / "out").string();
  // A scaling study cuts its REVs from prototype.file beside a file REV.
  write("rev.csv", "x,y,r\n0.0005,0.0005,0.0005\n0.0015,0.0005,0.0005\n");
  for (const int dim : {2, 3})
    for (const std::string scale : {"1e-150", "1e+150"}) {
      SCOPED_TRACE(std::to_string(dim) + "D, r = " + scale);
      const std::string file = write(std::to_string(dim) + "d" + scale + ".csv",
                                     touching_lattice(dim, dim == 2 ? 10 : 3, scale));
      const std::string params = test::example_params(dim == 2 ? "hex_10x10" : "fcc_4x4x4");
      const std::string config = dim == 2 ? kHex5 : test::shipped_config("fcc_4x4x4");
      std::vector<std::vector<std::string>> commands = {
          {"verify", params, "--prototype", file, "-o", out},
          {"export", params, "--prototype", file, "-o", out + "/deck.lammps"},
          {"upscale", params, "--prototype", file, "-o", out + "/params.json"},
          {"calibrate", config, "--set", "prototype.file=" + file, "-o", out}};
      if (dim == 2) {
        const std::string family =
            write("family" + scale + ".json",
                  R"({"material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3},)"
                  R"( "assembly": {"type": "file", "file": "rev.csv"},)"
                  R"( "prototype": {"particles": 0, "file": ")" +
                      file + R"("}})");
        commands.push_back({"verify", params, "--prototype", file, "--tile", "2x1", "-o", out});
        commands.push_back({"rev", kHex5, "--prototype", file, "--particles", "16", "-o", out});
        commands.push_back({"scaling", family, "--sizes", "9,16,36", "--calibrate-max", "16",
                            "--max-trials", "12", "-o", out});
      } else {
        commands.push_back({"rev", config, "--prototype", file, "--particles", "8", "-o", out});
      }
      const std::string what = dim == 2 ? "disk's" : "sphere's";
      const std::string flow = scale == "1e+150" ? "(it overflows)" : "(it underflows to 0)";
      for (const auto& args : commands)
        expect_bad_input(args, {"demcal: error: " + file + ": r: the smallest " + what +
                                    " (r = " + scale + " m) ",
                                flow, "; got " + scale});
    }
}

// A check across two keys named the file and its own field whatever a
// --set had changed: `check configs/hex_5x5.json --set material.kn=1e6`
// (the file's kt is 5e7) read "configs/hex_5x5.json: material.kt: must not
// exceed kn (1e+06)", blaming a value the user never touched; and likewise
// `--set algorithm.steps=100` (the file's monitor_points 200) and `--set
// assembly.radius_max=3e-4` (radius_min 3.75e-4). Now the key a --set
// changed, with that --set and both values (changed_field, the rule of the
// overlap at sigma3); with both or neither changed, the check's own field.
// Likewise check_servo_gain (the gain against the consolidation's tolerance
// and step budget) named "test.servo_gain" and the file when a --set had
// changed consolidation_max_steps or the tolerance: now that key, with its
// own bound (the gain when a --set gave it too).
TEST_F(CliEndToEnd, ACheckAcrossTwoKeysNamesTheKeyASetChanged) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string random = test::shipped_config("random_400");
  const std::string fcc = test::shipped_config("fcc_4x4x4");
  // servo_gain 1e-5 needs 690 772 steps to 1e-3 (check_servo_gain), 1e-9
  // about 6.9e9: more than any budget (at most 1e9).
  const std::string slow = write("slow_servo.json", R"({"material": {"density": 2650,
      "kn": 1e8, "kt": 5e7, "friction": 0.3}, "test": {"servo_gain": 1e-5}})");
  const std::string damped = write("damped.json", R"({"material": {"density": 2650,
      "kn": 1e8, "kt": 5e7, "friction": 0.3, "contact_damping_ratio": 300}})");
  // Random gases one layer thick at a count a --set gave (gas_layers_fault,
  // packing.cpp): the file's aspect was named, a key the user never touched.
  const std::string flat_2d = write("flat_2d.json", R"({"material": {"density": 2650,
      "kn": 1e8, "kt": 5e7, "friction": 0.3}, "assembly": {"type": "random", "count": 40,
      "aspect": 10}})");
  const std::string flat_3d = write("flat_3d.json", R"({"dimension": 3, "material":
      {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3}, "assembly": {"type": "random",
      "count": 30, "aspect": 1.79}})");
  const std::string stalled = write("stalled_servo.json", R"({"material": {"density": 2650,
      "kn": 1e8, "kt": 5e7, "friction": 0.3}, "test": {"servo_gain": 1e-9}})");
  struct Case {
    std::string config;
    std::vector<std::string> sets;
    std::string named, what;
  };
  const std::vector<Case> cases = {
      {kHex5,
       {"material.kn=1e6"},
       "--set material.kn=1e6: material.kn: ",
       "must be at least kt (5e+07): kt/kn = 2(1-nu)/(2-nu) <= 1"},
      {kHex5,
       {"material.kn=1e6", "material.kt=2e6"},
       "--set material.kt=2e6: material.kt: ",
       "must not exceed kn (1e+06)"},
      {kHex5,
       {"algorithm.steps=100"},
       "--set algorithm.steps=100: algorithm.steps: ",
       "must be at least test.monitor_points (200), got 100"},
      {kHex5,
       {"algorithm.steps=100", "test.monitor_points=150"},
       "--set test.monitor_points=150: test.monitor_points: ",
       "must not exceed algorithm.steps (100), got 150"},
      {random,
       {"assembly.radius_max=3e-4"},
       "--set assembly.radius_max=3e-4: assembly.radius_max: ",
       "must not be below radius_min (0.000375), got 0.0003"},
      {random,
       {"assembly.radius_min=7e-4"},
       "--set assembly.radius_min=7e-4: assembly.radius_min: ",
       "must not exceed radius_max (0.000625), got 0.0007"},
      // The servo's budget and tolerance (check_servo_gain named the gain
      // and the file whichever a --set had changed).
      {slow,
       {"test.consolidation_max_steps=100000"},
       "--set test.consolidation_max_steps=100000: test.consolidation_max_steps: ",
       "must be at least 690773: "},
      // Above 10^6 steps the budget's bound is the exact integer to type
      // (it read "must be at least 1.38154e+06", six digits).
      {slow,
       {"test.consolidation_max_steps=100000", "test.consolidation_tolerance=1e-6"},
       "--set test.consolidation_max_steps=100000: test.consolidation_max_steps: ",
       "must be at least 1381545: the servo removes at most the fraction gain of the stress "
       "error per step, so reaching consolidation_tolerance 1e-06 at servo_gain 1e-05 takes at "
       "least ln(1/tol)/(-ln(1-gain)) = 1381545 steps, more than consolidation_max_steps 100000"},
      // A budget no valid one can meet is no culprit: the file's gain, with
      // its bound (it asked for consolidation_max_steps 6907755276).
      {stalled,
       {"test.consolidation_max_steps=100000"},
       stalled + ": test.servo_gain: must be at least 6.90752e-05: ",
       "(and than the largest it may be, 1000000000); got 1e-09"},
      {slow,
       {"test.consolidation_tolerance=1e-12"},
       "--set test.consolidation_tolerance=1e-12: test.consolidation_tolerance: ",
       "must be at least 2.06095e-09: "},
      {slow,
       {"test.consolidation_max_steps=100000", "test.servo_gain=2e-5"},
       "--set test.servo_gain=2e-5: test.servo_gain: ",
       "must be at least 6.90752e-05"},
      // Contact dashpots against the consolidation's budget named the ratio
      // and the file whichever a --set had changed: now the budget, with
      // the smallest that covers the ratio (342 at 2e6 steps, 242 at 1e6).
      {damped,
       {"test.consolidation_max_steps=1000000"},
       "--set test.consolidation_max_steps=1000000: test.consolidation_max_steps: ",
       "must be at least 1536204 for material.contact_damping_ratio 300, which over-damps every "
       "contact"},
      {damped,
       {"test.consolidation_max_steps=1000000", "material.contact_damping_ratio=300"},
       "--set material.contact_damping_ratio=300: material.contact_damping_ratio: ",
       "must stay below 242.045 for this budget"},
      // A lattice's size (the product's limit) named cells_x, or columns,
      // and the file whichever a --set had changed.
      {fcc,
       {"assembly.cells_y=1000000"},
       "--set assembly.cells_y=1000000: assembly.cells_y: ",
       "4 x cells_x x cells_y x cells_z = 64000000 particles"},
      {kHex5,
       {"assembly.rows=10000000"},
       "--set assembly.rows=10000000: assembly.rows: ",
       "columns x rows = 50000000 particles, more than the limit 10000000"},
      // A gas one layer thick named the file's assembly.aspect when a --set
      // had changed the count alone: now the count, with the nearest counts
      // that consolidate at the file's aspect (none below 10 disks at aspect
      // 10; in 3D 16 spheres at aspect 1.79 fall into a hole between 15 and
      // 17, where gas_grid's cells across step from 3 to 4).
      {flat_2d,
       {"assembly.count=10"},
       "--set assembly.count=10: assembly.count: gives a gas of 10 columns and 1 rows of 10 disks",
       "; at aspect 10 the nearest count that gives a sample is 12 (or aspect above 0.1 and up to "
       "about 8.1 "
       "for count 10); got 10"},
      {flat_3d,
       {"assembly.count=16"},
       "--set assembly.count=16: assembly.count: gives a gas of 4 x 4 cells across and 1 layers "
       "of 16 spheres",
       "; at aspect 1.79 the nearest counts that give a sample are 15 and 17 (or aspect above 0.5 "
       "and up to "
       "about 1.6875 for count 16); got 16"},
      // The aspect too: the aspect, as before.
      {flat_2d,
       {"assembly.count=10", "assembly.aspect=10"},
       "--set assembly.aspect=10: assembly.aspect: gives a gas of 10 columns and 1 rows",
       "i.e. aspect above 0.1 and up to about 8.1 for count 10; got 10"},
  };
  for (const Case& c : cases) {
    for (const std::string command : {"run", "check"}) {
      std::vector<std::string> args = {command, c.config};
      for (const std::string& set : c.sets) args.insert(args.end(), {"--set", set});
      if (command == "run") args.insert(args.end(), {"-o", out});
      expect_bad_input(args, {c.named, c.what});
    }
  }
  // In the file, with no --set: the file and kt, as before.
  const std::string soft = write("soft.json", R"({"material": {"density": 2650, "kn": 1e8,
      "kt": 2e8, "friction": 0.3}})");
  expect_bad_input({"check", soft}, {soft + ": material.kt: must not exceed kn (1e+08)"});
}

// Contact dashpots beyond critical make every contact creep, and the
// consolidation's step shrinks for them: beyond the ratio at which the
// quickest contact's time constant outlasts test.consolidation_max_steps,
// no contact settles (hex_5x5 ran all 2e6 steps and failed, exit 1, at
// 1e6; at 1e4 it "consolidated" in 600 steps into a creeping state whose
// loading diverged). Refused before any computing, naming the field, in 2D
// and 3D; a larger budget moves the bound, and an over-damped 5 still runs.
TEST_F(CliEndToEnd, AContactDampingThatOutlastsTheConsolidationBudgetIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  for (const std::string& config : {kHex5, test::shipped_config("fcc_4x4x4")}) {
    SCOPED_TRACE(config);
    for (const std::string set :
         {"material.contact_damping_ratio=1e6", "material.contact_damping_ratio=1e100"})
      expect_bad_input(
          {"run", config, "--set", set, "-o", out},
          {"--set " + set + ": material.contact_damping_ratio: over-damps every contact",
           "more than test.consolidation_max_steps = 2000000",
           "material.contact_damping_ratio must stay below"});
  }
  // hex_5x5: the bound is 342 at the default budget, 766 at 1e7 steps.
  expect_bad_input({"check", kHex5, "--set", "material.contact_damping_ratio=400"},
                   {"--set material.contact_damping_ratio=400", "must stay below 342.3"});
  expect_bad_input({"check", kHex5, "--set", "material.contact_damping_ratio=800", "--set",
                    "test.consolidation_max_steps=10000000"},
                   {"--set material.contact_damping_ratio=800", "must stay below 765.4"});
  const Result ok = demcal({"check", kHex5, "--set", "material.contact_damping_ratio=5", "--set",
                            "algorithm.dt_ratio=0.005"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// The loading's global damping, semi-implicit: c = D*dt/(2m) = 2*ratio*alpha.
// A ratio of 1e306 made D inf and (1 - c)/(1 + c) NaN: the loading
// "diverged: non-finite state" (exit 1, "decrease dt_ratio"). Any ratio
// that keeps D finite and 1/(1 + c) normal is the overdamped limit, which
// runs and the criteria judge (1e300 here).
TEST_F(CliEndToEnd, AGlobalDampingBeyondTheKernelsDoublesIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  expect_bad_input({"run", kHex5, "--set", "algorithm.damping_ratio_translation=1e306", "-o", out},
                   {"--set algorithm.damping_ratio_translation=1e306: "
                    "algorithm.damping_ratio_translation: ",
                    "global damping damping_ratio_translation*2*sqrt(kn*m) is inf"});
  expect_bad_input({"run", kHex5, "--set", "algorithm.damping_ratio_rotation=1.7e308", "-o", out},
                   {"--set algorithm.damping_ratio_rotation=1.7e308: "
                    "algorithm.damping_ratio_rotation: ",
                    "damped rotation's factor 1/(1 + D_r*dt/(2I))"});
  // Spheres: the kernel's coefficients are the disks' (sphere_world.cpp).
  expect_bad_input({"run", test::shipped_config("fcc_4x4x4"), "--set",
                    "algorithm.damping_ratio_translation=1e308", "-o", out},
                   {"--set algorithm.damping_ratio_translation=1e308: "
                    "algorithm.damping_ratio_translation: ",
                    "the smallest sphere's", "is inf"});
  const Result ok = demcal({"check", kHex5, "--set", "algorithm.damping_ratio_translation=1e300"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// strtod, the particle files' number reader, took "0x1p-1" for 0.5, and
// getline dropped the empty field after a trailing comma ("0,0,0.5,"):
// both files were read as valid. A DEM tool never writes a hexadecimal
// number, and a trailing comma usually means a missing column: refused,
// naming the file, the line and the column, in 2D and 3D. Decimal forms
// (sign, exponent, -0.0, ".5"), comments and the header read as before.
// A header with a trailing comma ("x,y,r,") was still read as the header
// until 2026-12-05 evening: refused as a particle line's.
TEST_F(CliEndToEnd, AParticleFileWithAHexNumberOrATrailingCommaIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string fcc = test::shipped_config("fcc_4x4x4");
  const auto from_file = [](const std::string& csv) {
    return R"(assembly={"type": "file", "file": ")" + csv + "\"}";
  };
  struct Case {
    std::string config, name, text, where, what;
  };
  const std::vector<Case> cases = {
      {kHex5, "hex.csv", "x,y,r\n0,0,0.5\n1,0,0x1p-1\n0,1,0.5\n1,1,0.5\n", "line 3, column 5",
       "a hexadecimal number for r"},
      {kHex5, "hex_x.csv", "0,0,0.5\n -0X1P0,0,0.5\n0,1,0.5\n", "line 2, column 2",
       "a hexadecimal number for x"},
      {kHex5, "comma.csv", "x,y,r\n0,0,0.5\n1,0,0.5,\n0,1,0.5\n", "line 3, column 8",
       "a trailing comma after r: expected three numbers x,y,r"},
      {fcc, "hex_3d.csv", "0,0,0,0.5\n1,0,+0x0p0,0.5\n0,1,0,0.5\n", "line 2, column 5",
       "a hexadecimal number for z"},
      {fcc, "comma_3d.csv", "x,y,z,r\n0,0,0,0.5\n1,0,0,0.5,\n", "line 3, column 10",
       "a trailing comma after r: expected four numbers x,y,z,r"},
      // The header's trailing comma too (after comments, in any case, with
      // the radius called radius, as headers are read).
      {kHex5, "header.csv", "x,y,r,\n0,0,0.5\n1,0,0.5\n0,1,0.5\n1,1,0.5\n", "line 1, column 6",
       "a trailing comma in the header: expected the columns x,y,r"},
      {kHex5, "radius.csv", "# exported\n\nX, Y, Radius,\r\n0,0,0.5\n1,0,0.5\n",
       "line 3, column 13", "a trailing comma in the header: expected the columns x,y,r"},
      {fcc, "header_3d.csv", "x,y,z,r,\n0,0,0,0.5\n1,0,0,0.5\n", "line 1, column 8",
       "a trailing comma in the header: expected the columns x,y,z,r"},
  };
  for (const Case& c : cases) {
    const std::string csv = write(c.name, c.text);
    expect_bad_input({"run", c.config, "--set", from_file(csv), "-o", out},
                     {csv + ": " + c.where + ": " + c.what});
    expect_bad_input({"check", c.config, "--set", from_file(csv)},
                     {csv + ": " + c.where + ": " + c.what});
  }
  const std::string decimal = write("decimal.csv",
                                    "# 0x1p-3,1,2,\nx,y,r\n  # a comment,\n+0,-0.0,5e-1\n"
                                    "1e0,0,0.5\n0,1.0E+0,.5\n1,1,1.5E-1\n");
  const Result ok = demcal({"check", kHex5, "--set", from_file(decimal)});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("4 particles"), std::string::npos) << ok.out;
  // A header without the comma reads as before.
  const std::string plain = write("plain.csv", "# exported\nX, Y, Radius\r\n0,0,0.5\n1,0,0.5\n");
  const Result plain_ok = demcal({"check", kHex5, "--set", from_file(plain)});
  EXPECT_EQ(plain_ok.status, 0) << plain_ok.err;
  EXPECT_NE(plain_ok.out.find("2 particles"), std::string::npos) << plain_ok.out;
}

// A key two --set give was read as the last, silently (the first looked
// applied): `run cfg --set algorithm.steps=2000 --set algorithm.steps=3000`
// ran 3000 steps, exit 0. Bad input now, naming the key and both values,
// for every command that takes --set; in verify and export too, where a
// --set of a calibrated algorithm key is dropped (without effect) before
// the config is read.
TEST_F(CliEndToEnd, ASetKeyGivenTwiceIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string params = test::example_params("hex_10x10");
  const std::vector<std::vector<std::string>> commands = {
      {"check", kHex5},
      {"run", kHex5, "-o", out},
      {"sweep", kHex5, "-o", out},
      {"calibrate", kHex5, "-o", out},
      {"stability", kHex5, "-o", out},
      {"scaling", kHex5, "--sizes", "16,25,36", "--calibrate-max", "25", "-o", out},
      {"rev", kHex5, "--particles", "16", "-o", out},
      {"upscale", params, "--particles", "100", "-o", out},
      {"verify", params, "--particles", "100", "-o", out},
      {"export", params, "--particles", "100", "-o", out},
  };
  for (std::vector<std::string> args : commands) {
    args.insert(args.end(), {"--set", "algorithm.steps=2000", "--set", "algorithm.steps=3000"});
    expect_bad_input(args, {"--set algorithm.steps=3000: algorithm.steps: given twice, \"2000\" "
                            "then \"3000\""});
  }
  // A section, then a key in it: two keys, both applied.
  const Result ok = demcal(
      {"check", kHex5, "--set", R"(algorithm={"steps": 2000})", "--set", "algorithm.dt_ratio=0.1"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// verify and export (and upscale) read a failed params.json first: its
// "success" error (with --allow-failed, its warning) came before a key two
// --set gave, a command-line mistake known before any file is read. The
// --set now, first and alone, with the message of the other commands.
TEST_F(CliEndToEnd, ASetKeyGivenTwiceIsSaidBeforeAFailedParamsJson) {
  const std::string out = (dir_ / "work" / "out").string();
  nlohmann::json params = nlohmann::json::parse(read_text(test::example_params("hex_10x10")));
  params["success"] = false;
  const std::string failed = write("failed.json", params.dump());
  const std::vector<std::string> twice = {"--set", "algorithm.steps=2000", "--set",
                                          "algorithm.steps=3000"};
  for (const std::string command : {"verify", "export", "upscale"}) {
    for (const bool allow_failed : {false, true}) {
      std::vector<std::string> args = {command, failed, "--particles", "100", "-o", out};
      if (allow_failed) args.push_back("--allow-failed");
      args.insert(args.end(), twice.begin(), twice.end());
      expect_bad_input(args, {"--set algorithm.steps=3000: algorithm.steps: given twice, "
                              "\"2000\" then \"3000\""});
    }
  }
  // Without the --set mistake, the failed params.json is said as before.
  expect_bad_input({"verify", failed, "--particles", "100", "-o", out},
                   {failed + ": success: is false"});
}

// A section a --set gave after a key in it (`--set material.kn=1e6 --set
// material={...}`) replaced the section, and the key with it: the earlier
// --set was lost, silently (exit 0). Bad input now, naming both --sets, in
// every command that takes --set, a section deeper in too (material.wall).
// The prefix is one at a dot: material.k holds no material.kn (an unknown
// key, as before). A section, then a key in it, still applies both in
// order.
TEST_F(CliEndToEnd, ASetSectionAfterAKeyInItIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string params = test::example_params("hex_10x10");
  const std::string material =
      R"(material={"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3})";
  const std::vector<std::vector<std::string>> commands = {
      {"check", kHex5},
      {"run", kHex5, "-o", out},
      {"calibrate", kHex5, "-o", out},
      {"verify", params, "--particles", "100", "-o", out},
      {"export", params, "--particles", "100", "-o", out},
  };
  for (std::vector<std::string> args : commands) {
    args.insert(args.end(), {"--set", "material.kn=1e6", "--set", material});
    expect_bad_input(args, {"--set " + material + ": material: replaces the section",
                            "--set material.kn=1e6 given before it"});
  }
  expect_bad_input({"check", kHex5, "--set", "material.wall.kn=1e7", "--set",
                    "algorithm.steps=3000", "--set", R"(material.wall={"kn": 1e8})"},
                   {R"(--set material.wall={"kn": 1e8}: material.wall: replaces the section)",
                    "--set material.wall.kn=1e7 given before it"});
  expect_bad_input({"check", kHex5, "--set", "material.wall.kn=1e7", "--set", material},
                   {"--set " + material + ": material: ", "--set material.wall.kn=1e7 given"});
  // Not a section of material.kn: the unknown key it is.
  expect_bad_input({"check", kHex5, "--set", "material.kn=1e8", "--set", "material.k=1"},
                   {"--set material.k=1: material.k: unknown key"});
  // The section, then a key in it: the key is read (kt above the section's kn).
  expect_bad_input({"check", kHex5, "--set", material, "--set", "material.kt=2e8"},
                   {"--set material.kt=2e8: material.kt: must not exceed kn (1e+08)"});
  const Result ok = demcal({"check", kHex5, "--set", material, "--set", "material.kn=2e8", "--set",
                            "material.wall.kn=2e8"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// A malformed --set key (an empty part: "material.", "material..kn") was
// compared with the other --sets before apply_overrides refused it, and
// could be said as something else: `--set material.=1 --set material={...}`
// read "--set material={...}: material: replaces the section, and with it
// --set material.=1 given before it", `--set material..kn=1 --set
// material..kn=2` "given twice". Now every --set's key is checked first
// (set_key, apply_overrides' wording), in every command that takes --set.
TEST_F(CliEndToEnd, AMalformedSetKeyIsSaidBeforeItIsComparedWithOthers) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string params = test::example_params("hex_10x10");
  const std::string material =
      R"(material={"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3})";
  struct Case {
    std::vector<std::string> sets;
    std::string named;
  };
  const std::vector<Case> cases = {
      {{"material.=1", material}, "--set material.=1: key has an empty part"},
      {{"material..kn=1", "material..kn=2"}, "--set material..kn=1: key has an empty part"},
      {{"material.kn=1e6", "material.kn=1e7", ".kn=2"}, "--set .kn=2: key has an empty part"},
  };
  const std::vector<std::vector<std::string>> commands = {
      {"check", kHex5},
      {"run", kHex5, "-o", out},
      {"verify", params, "--particles", "100", "-o", out},
  };
  for (const Case& c : cases) {
    for (std::vector<std::string> args : commands) {
      for (const std::string& set : c.sets) args.insert(args.end(), {"--set", set});
      expect_bad_input(args, {c.named});
    }
  }
}

// Usage errors (CLI11's checks) are bad input too: one line, exit 2.
TEST_F(CliEndToEnd, UsageErrorsExitTwo) {
  const std::string out = (dir_ / "work" / "out").string();
  expect_bad_input({"calibrate", kHex5, "--strategy", "bogus", "-o", out}, {"--strategy", "bogus"});
  expect_bad_input({"stability", kHex5, "--points", "1", "-o", out}, {"--points"});
  expect_bad_input({"stability", kHex5, "--from", "2", "--to", "1", "-o", out}, {"--to"});
  expect_bad_input({"frobnicate"}, {"unknown command \"frobnicate\""});
  const Result help = demcal({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("stability"), std::string::npos);
}

// A SIMD path (DEMCAL_SIMD) the kernel does not know, or one this CPU cannot
// run, is bad input: one line naming the variable, the value and the paths,
// before anything is written (it used to be ignored: the kernel ran its
// default path, and a comparison of two paths compared one with itself).
// Empty is unset.
TEST_F(CliEndToEnd, AnUnknownSimdPathIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::vector<std::string> paths = {"sse2", "avx2", "avx512"};
  for (const std::string value : {"bogus", "AVX2", "avx2 ", "generic"}) {
    std::vector<std::string> mentions = {"DEMCAL_SIMD", "\"" + value + "\"", "this CPU runs"};
    mentions.insert(mentions.end(), paths.begin(), paths.end());
    const std::vector<std::string> env = {"DEMCAL_SIMD=" + value};
    expect_bad_input({"run", kHex5, "-o", out}, mentions, env);
    expect_bad_input({"run", kHex5}, mentions, env);  // nor the default folder
    expect_bad_input({"check", kHex5}, mentions, env);
  }
  // A path this CPU lacks (the widest path the kernel chose tells which).
  const std::string best = demcal::kernel_simd();
  for (const std::string path : {"avx2", "avx512"})
    if (best == "sse2" || (best == "avx2" && path == "avx512"))
      expect_bad_input({"run", kHex5, "-o", out}, {"DEMCAL_SIMD", path, "this CPU"},
                       {"DEMCAL_SIMD=" + path});
  const Result unset = demcal({"check", kHex5}, {"DEMCAL_SIMD="});
  EXPECT_EQ(unset.status, 0) << unset.err;
  EXPECT_EQ(unset.err, "");
}

// A way to gather (DEMCAL_GATHER) that is none, hardware gathers on a path
// without them or in a build without them (Clang) are bad input too, named
// the same way; the ways a path has run.
TEST_F(CliEndToEnd, AnUnknownWayToGatherIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  for (const std::string value : {"bogus", "Hardware", "hardware "})
    expect_bad_input({"run", kHex5, "-o", out},
                     {"DEMCAL_GATHER", "\"" + value + "\"", "hardware|emulated"},
                     {"DEMCAL_GATHER=" + value});
  expect_bad_input({"run", kHex5, "-o", out},
                   {"DEMCAL_GATHER", "hardware", "only the avx512 path", "sse2"},
                   {"DEMCAL_SIMD=sse2", "DEMCAL_GATHER=hardware"});
  const Result sse2 = demcal({"check", kHex5}, {"DEMCAL_SIMD=sse2", "DEMCAL_GATHER=emulated"});
  EXPECT_EQ(sse2.status, 0) << sse2.err;
  if (std::string(demcal::kernel_simd()) != "avx512") return;
#if defined(__x86_64__) && !defined(__clang__)
  const std::vector<std::string> ways = {"hardware", "emulated"};
#else
  const std::vector<std::string> ways = {"emulated"};
  expect_bad_input({"run", kHex5, "-o", out}, {"DEMCAL_GATHER", "hardware", "Clang"},
                   {"DEMCAL_GATHER=hardware"});
#endif
  for (const std::string& way : ways) {
    const Result r = demcal({"check", kHex5}, {"DEMCAL_SIMD=avx512", "DEMCAL_GATHER=" + way});
    EXPECT_EQ(r.status, 0) << way << ": " << r.err;
    EXPECT_EQ(r.err, "") << way;
  }
}

// The refusal quotes the environment's value: its control characters and
// bytes beyond ASCII are shown as \xNN, so the message stays one line of
// text (a newline in the value made it two, an escape sequence drove the
// terminal).
TEST_F(CliEndToEnd, ASimdPathWithControlCharactersIsShownEscaped) {
  const std::string value = "avx2\nnext line \x1b[2J\x7f\xc3\xa9\x01\t";
  const Result r = demcal({"check", kHex5}, {"DEMCAL_SIMD=" + value});
  EXPECT_EQ(r.status, 2) << r.err;
  ASSERT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("DEMCAL_SIMD=\"avx2\\x0anext line \\x1b[2J\\x7f\\xc3\\xa9\\x01\\x09\""),
            std::string::npos)
      << r.err;
  for (const char c : r.err.substr(0, r.err.size() - 1))  // all printable before the newline
    EXPECT_TRUE(c >= 0x20 && c < 0x7f) << static_cast<int>(static_cast<unsigned char>(c));
  EXPECT_EQ(r.out, "");
}

// `demcal verify --consolidate-only` consolidates and stops: what it says on
// stderr announces no loading (it said "loading now, about … min", then
// stopped).
TEST_F(CliEndToEnd, VerifyConsolidateOnlyAnnouncesNoLoading) {
  demcal::AlgorithmSpec p;
  p.steps = 20000;
  const std::string params = test::write_default_scene_params(dir_, p);
  const Result r = demcal({"verify", params, "--particles", "25", "--consolidate-only", "-o", "v"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "work" / "v" / "prototype.csv"));
  EXPECT_NE(r.out.find("consolidated prototype of 25 particles"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("consolidated in"), std::string::npos) << r.err;
  for (const char* announce : {"loading now", "loading =", " min"})
    EXPECT_EQ(r.err.find(announce), std::string::npos) << announce << " in " << r.err;
}

// verify's options that the run would not use are refused, one line naming
// the option, nothing written: --np without --engine lammps (it was
// ignored), --threads in 2D (3D only: ignored too), and --engine liggghts
// is pointed to export.
TEST_F(CliEndToEnd, VerifyRefusesTheOptionsItWouldIgnore) {
  demcal::AlgorithmSpec p;
  p.steps = 20000;
  const std::string params = test::write_default_scene_params(dir_, p);
  const std::vector<std::string> verify{"verify", params, "--particles", "25", "-o", "v"};
  auto with = [&](const std::vector<std::string>& more) {
    std::vector<std::string> args = verify;
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  expect_bad_input(with({"--np", "2"}), {"--np", "--engine lammps"});
  expect_bad_input(with({"--engine", "demcal", "--np", "2"}), {"--np", "--engine lammps"});
  expect_bad_input(with({"--threads", "2"}), {"--threads", "3D only"});
  expect_bad_input(with({"--engine", "liggghts"}),
                   {"--engine", "\"liggghts\"", "export --format liggghts"});
}

// An -o that cannot be made (a path under a regular file) is bad input
// found before anything is printed or run, as in 3D (test_verify_3d.cpp):
// 2D verify printed its prototype and estimate lines first, the error after.
TEST_F(CliEndToEnd, VerifyAnUnusableOutputFolderFailsBeforeAnythingIsPrinted) {
  demcal::AlgorithmSpec p;
  p.steps = 20000;
  const std::string params = test::write_default_scene_params(dir_, p);
  test::write_text(dir_ / "blocker", "a file\n");
  const std::string out = (dir_ / "blocker" / "v").string();
  for (const std::vector<std::string>& more :
       {std::vector<std::string>{}, std::vector<std::string>{"--consolidate-only"}})
    for (const char* particles : {"25", "100"}) {
      std::vector<std::string> args{"verify", params, "--particles", particles, "-o", out};
      args.insert(args.end(), more.begin(), more.end());
      expect_bad_input(args, {out});
    }
}

// `demcal stability`: the limit against the estimate, both files written.
TEST_F(CliEndToEnd, StabilityScanWritesItsReport) {
  const fs::path out = dir_ / "work" / "scan";
  const Result r = demcal({"stability", kHex5, "--steps", "5000", "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("x the estimate"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(read_text(out / "stability.json"));
  EXPECT_NEAR(j["measured_over_estimate"].get<double>(), 1.0, 0.03);
  for (const auto& t : j["trials"])
    if (t["diverged"].get<bool>()) {
      EXPECT_GT(t["divergence_step"].get<int>(), 0);
    }
  EXPECT_NE(read_text(out / "stability.md").find("| alpha |"), std::string::npos);
}

TEST_F(CliEndToEnd, BadParticleFileNamesFileAndLine) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string csv = write("p.csv", "x,y,r\n0,0,5e-4\n1e-3,0,-5e-4\n");
  const std::string config =
      write("file.json",
            "{" + test::kMaterialMember + R"(, "assembly": {"type": "file", "file": "p.csv"}})");
  expect_bad_input({"run", config, "-o", out}, {csv, "line 3", "radius"});
  const std::string overlap = write("o.csv", "# two\n0,0,5e-4\n5e-4,0,5e-4\n");
  expect_bad_input({"run", config, "--set", "assembly.file=" + overlap, "-o", out},
                   {overlap, "line 3"});
  expect_bad_input({"check", config, "--set", "assembly.file=nothere.csv"}, {"nothere.csv"});
}

// An output path that cannot be written is bad input too, found before the
// run (it would otherwise fail after all the computing), and leaves nothing.
TEST_F(CliEndToEnd, UnwritableOutputExitsTwoBeforeRunning) {
  const std::string file = write("work/plain.txt", "not a folder\n");
  const std::set<std::string> before = work_contents();
  for (const std::string& out : {file + "/out", file + "/deeper/out", file}) {
    SCOPED_TRACE(out);
    const Result r = demcal({"run", kHex5, "--set", "algorithm.steps=2000", "-o", out});
    EXPECT_EQ(r.status, 2) << r.err;
    // The other commands that write a folder check it first too (the
    // calibration would otherwise fail after its search).
    for (const char* command : {"calibrate", "stability", "sweep"}) {
      const Result c = demcal({command, kHex5, "-o", out});
      EXPECT_EQ(c.status, 2) << command << ": " << c.err;
      EXPECT_NE(c.err.find("output folder unusable"), std::string::npos) << c.err;
      EXPECT_EQ(c.out, "");
    }
    EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find(out), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");  // nothing ran
    EXPECT_EQ(work_contents(), before);
    EXPECT_EQ(read_text(file), "not a folder\n");
  }
  // A folder the kernel refuses (as root too).
  const Result r = demcal({"run", kHex5, "-o", "/proc/demcal-forbidden/out"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("/proc/demcal-forbidden/out"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists("/proc/demcal-forbidden"));
}

// `-o ''` (an unset variable in a script) is bad input, not the default
// folder: it ran and wrote demcal-run-NAME in the working directory.
TEST_F(CliEndToEnd, AnEmptyOutputIsBadInput) {
  for (const char* command : {"run", "calibrate", "stability", "sweep", "rev"})
    expect_bad_input({command, kHex5, "-o", ""}, {"--output", "must not be empty"});
  // scaling's work folder too: '' ran the study in the -o folder.
  const std::string out = (dir_ / "work" / "out").string();
  expect_bad_input(
      {"scaling", kHex5, "--work", "", "-o", out, "--sizes", "25,36,100", "--calibrate-max", "36"},
      {"--work", "must not be empty"});
}

// --- check ----------------------------------------------------------------

double number_after(const std::string& text, const std::string& label) {
  const auto at = text.find(label);
  if (at == std::string::npos) return NAN;
  return std::strtod(text.c_str() + at + label.size(), nullptr);
}

TEST_F(CliEndToEnd, CheckPrintsTheDerivedScales) {
  const Result r = demcal({"check", kHex5});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("valid"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("25 particles"), std::string::npos) << r.out;
  // Δt_crit = 2·sqrt(m/kn), m = ρπr²t; D_t^crit = 2·sqrt(kn·m);
  // D_r^crit = 2·sqrt(kt·r²·I), I = m r²/2 (printed to 6 digits).
  const double r0 = 5e-4, m = 2650.0 * M_PI * r0 * r0, kn = 1e8, kt = 5e7;
  EXPECT_NEAR(number_after(r.out, "dt_crit"), 2 * std::sqrt(m / kn), 1e-5 * 2 * std::sqrt(m / kn))
      << r.out;
  EXPECT_NEAR(number_after(r.out, "damping_translation_crit"), 2 * std::sqrt(kn * m),
              1e-5 * 2 * std::sqrt(kn * m));
  const double dr = 2 * std::sqrt(kt * r0 * r0 * m * r0 * r0 / 2);
  EXPECT_NEAR(number_after(r.out, "damping_rotation_crit"), dr, 1e-5 * dr);
  const double stable = number_after(r.out, "stable dt_ratio (Lanczos, rotation coupled)");
  EXPECT_GT(stable, 0.2);
  EXPECT_LT(stable, 1.0);
  EXPECT_NEAR(number_after(r.out, "analytical peak sigma1/sigma3"), 7.725, 1e-3) << r.out;
  EXPECT_TRUE(work_contents().empty());  // check writes nothing
}

TEST_F(CliEndToEnd, CheckAcceptsAParticleFile) {
  std::string csv = "# hexagonal 4x3, r = 5e-4\nx,y,r\n";
  const double r = 5e-4, h = std::sqrt(3.0) * r;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i) {
      std::ostringstream line;
      line.precision(17);
      line << r + (k % 2 ? r : 0.0) + 2 * r * i << "," << r + h * k << "," << r << "\r\n";
      csv += line.str();
    }
  write("hex.csv", csv);
  const std::string config =
      write("file.json",
            "{" + test::kMaterialMember + R"(, "assembly": {"type": "file", "file": "hex.csv"}})");
  const Result res = demcal({"check", config});
  EXPECT_EQ(res.status, 0) << res.err;
  EXPECT_NE(res.out.find("12 particles"), std::string::npos) << res.out;
}

// A particle file that is not there is the config's error: it names the
// config and its key, then the path (2D and 3D; the particle file's own
// errors name that file and its line).
TEST_F(CliEndToEnd, AMissingParticleFileNamesTheConfigAndKey) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string config =
      write("gone.json",
            "{" + test::kMaterialMember + R"(, "assembly": {"type": "file", "file": "gone.csv"}})");
  const std::string csv = (dir_ / "gone.csv").string();
  expect_bad_input({"check", config}, {config + ": assembly.file: \"" + csv + "\": no such file"});
  expect_bad_input({"run", config, "-o", out},
                   {config + ": assembly.file: \"" + csv + "\": no such file"});
  // calibrate keys its resume file on the file's contents, before anything
  // else reads it; scaling cuts its family from it.
  expect_bad_input({"calibrate", config, "-o", out},
                   {config + ": assembly.file: \"" + csv + "\": no such file"});
  expect_bad_input({"scaling", config, "--sizes", "12,24,800", "-o", out},
                   {config + ": assembly.file: \"" + csv + "\": no such file"});
  const std::string spheres = write(
      "gone3d.json", "{" + test::kMaterialMember +
                         R"(, "dimension": 3, "assembly": {"type": "file", "file": "gone.csv"},
                                  "test": {"type": "triaxial"}})");
  expect_bad_input({"run", spheres, "-o", out},
                   {spheres + ": assembly.file: \"" + csv + "\": no such file"});
}

// The prototype the config names is read after calibrate's search (for
// params.json's prototype block): a missing or malformed prototype file, or
// a count no scene can have, ran the whole search, then failed with exit 2
// having removed the earlier calibration's results from the folder, and
// `check` called the config valid. Now check and calibrate refuse it before
// any work, and the folder keeps every file, byte for byte (2D and 3D).
TEST_F(CliEndToEnd, APrototypeTheConfigCannotMakeIsRefusedBeforeAnyWork) {
  const std::string out = (dir_ / "work" / "out").string();
  auto with_prototype = [&](const std::string& shipped, const std::string& name,
                            const nlohmann::json& prototype) {
    nlohmann::json config = nlohmann::json::parse(read_text(test::shipped_config(shipped)));
    config["prototype"] = prototype;
    return write(name, config.dump(2));
  };
  const std::string nope = with_prototype("hex_5x5", "nope.json", {{"file", "nope.csv"}});
  const std::string missing = nope + ": prototype.file: \"" + (dir_ / "nope.csv").string() + "\"";
  expect_bad_input({"check", nope}, {missing, "no such file"});
  expect_bad_input({"calibrate", nope, "-o", out}, {missing, "no such file"});
  const std::string bad_csv = write("bad.csv", "x,y,r\n0,0,5e-4\n1e-3,0\n");
  const std::string bad = with_prototype("hex_5x5", "bad.json", {{"file", "bad.csv"}});
  expect_bad_input({"check", bad}, {bad_csv, "line 3"});
  expect_bad_input({"calibrate", bad, "-o", out}, {bad_csv, "line 3"});
  expect_bad_input({"check", kHex5, "--set", "prototype.particles=1"}, {"at least 2 particles"});
  expect_bad_input({"calibrate", kHex5, "--set", "prototype.particles=1", "-o", out},
                   {"at least 2 particles"});
  const std::string spheres = with_prototype("fcc_4x4x4", "nope3d.json", {{"file", "nope.csv"}});
  const std::string missing3d =
      spheres + ": prototype.file: \"" + (dir_ / "nope.csv").string() + "\"";
  expect_bad_input({"check", spheres}, {missing3d});
  expect_bad_input({"calibrate", spheres, "-o", out}, {missing3d});

  // Into the folder of an earlier calibration: refused as above, nothing
  // of that calibration removed or changed.
  const Result first =
      demcal({"calibrate", kHex5, "-o", out, "-q", "-j", "1", "--max-trials", "12"});
  ASSERT_EQ(first.status, 0) << first.err;
  auto contents = [&] {
    std::map<std::string, std::string> files;
    for (const std::string& name : test::names_in(out))
      files[name] = read_text(fs::path(out) / name);
    return files;
  };
  const auto before = contents();
  ASSERT_TRUE(before.count("params.json") && before.count("report.md"));
  const Result r = demcal({"calibrate", nope, "-o", out, "-q", "-j", "1", "--max-trials", "12"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  EXPECT_EQ(contents(), before);
}

// --- run outputs ------------------------------------------------------------

/// The run's VTK (support/vtk.hpp) with the 2D fields.
void expect_valid_vtk(const std::string& text, int particles, bool contacts = true) {
  const std::set<std::string> names = test::check_vtk_polydata(text, particles, contacts);
  for (const char* field : {"radius", "rotation", "velocity", "normal_force", "tangential_force"})
    EXPECT_TRUE(names.count(field)) << field;
}

TEST_F(CliEndToEnd, RunWritesSummarySeriesAndVtk) {
  const fs::path out = dir_ / "work" / "a" / "b";  // parents are made
  const Result r = demcal({"run", kHex5, "--set", "algorithm.steps=2000", "-o", out.string()});
  ASSERT_NO_FATAL_FAILURE(test::expect_run_status(r.status, out, r.err));
  // The peak is the axial boundary stress b_yy (the criteria's, the
  // report's, params.json's), so the line names b, not sigma.
  const size_t at = r.out.find("peak b_yy ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const double printed = std::stod(r.out.substr(at + 10));
  // Exactly the three files: no temporary or probe file left behind.
  EXPECT_EQ(test::names_in(out),
            (std::set<std::string>{"summary.json", "series.csv", "final.vtk"}));

  const auto s = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(s.at("schema"), "demcal.run/1");  // not a calibration's run.json
  EXPECT_EQ(s.at("particles"), 25);
  const double peak = s.at("criteria").at("peak_stress_yy").get<double>();
  EXPECT_NEAR(printed, peak, 1e-3 * std::abs(peak));  // printed to 4 digits
  const auto& p = s.at("params");
  for (const char* key :
       {"dt", "dt_ratio", "steps", "damping_translation", "damping_ratio_translation",
        "damping_rotation", "damping_ratio_rotation", "mass_scaling"})
    EXPECT_TRUE(p.contains(key)) << key;
  EXPECT_EQ(p.at("steps"), 2000);
  EXPECT_EQ(p.at("dt_ratio"), 0.2);
  EXPECT_NEAR(p.at("dt").get<double>(), 0.2 * 2 * std::sqrt(2650.0 * M_PI * 25e-8 / 1e8), 1e-15);
  EXPECT_NEAR(p.at("damping_translation").get<double>(), 2 * std::sqrt(1e8 * 2650.0 * M_PI * 25e-8),
              1e-6);
  EXPECT_EQ(p.at("mass_scaling"), 1.0);
  EXPECT_TRUE(s.at("criteria").at("force_balance").is_number());
  EXPECT_TRUE(s.at("criteria").at("moment_balance").is_number());
  EXPECT_LT(s.at("peak").at("stress_yy").get<double>(), -1e5);  // beyond σ3, compressive
  EXPECT_LT(s.at("peak").at("strain_yy").get<double>(), 0.0);
  EXPECT_NEAR(s.at("analytical_peak").at("ratio").get<double>(), 7.725, 1e-3);
  EXPECT_NEAR(s.at("analytical_peak").at("ratio_periodic").get<double>(), 7.3267, 1e-4);
  EXPECT_EQ(s.at("diverged"), false);
  EXPECT_GT(s.at("wall_time_s").get<double>(), 0.0);
  EXPECT_GT(s.at("particle_steps_per_s").get<double>(), 0.0);

  // The metadata `demcal score` reads, then the table.
  const std::string series = read_text(out / "series.csv");
  const auto meta = test::series_metadata(series);
  EXPECT_EQ(std::stod(meta.at("lateral_stress")), 1e5);
  EXPECT_EQ(meta.at("steps"), "2000");
  EXPECT_EQ(meta.at("particles"), "25");
  EXPECT_EQ(std::stod(meta.at("dt")), p.at("dt").get<double>());
  const auto rows = test::series_table(series);
  ASSERT_EQ(rows.size(), 202u);  // header + monitor_points + 1
  const std::vector<std::string> expected = {"step",
                                             "strain_yy",
                                             "b_xx",
                                             "b_xy",
                                             "b_yx",
                                             "b_yy",
                                             "s_xx",
                                             "s_xy",
                                             "s_yx",
                                             "s_yy",
                                             "kinetic_energy",
                                             "unbalanced_force_ratio",
                                             "lateral_stress_error"};
  const auto header = split(rows[0], ',');
  ASSERT_GE(header.size(), expected.size());
  EXPECT_EQ(std::vector<std::string>(header.begin(), header.begin() + expected.size()), expected);
  ASSERT_NO_FATAL_FAILURE(test::expect_numeric_rows(rows));
  EXPECT_EQ(split(rows[1], ',')[0], "0");
  EXPECT_EQ(split(rows.back(), ',')[0], "2000");

  expect_valid_vtk(read_text(out / "final.vtk"), 25);
}

/// `demcal score` on the series.csv of the run `run` wrote into `out`,
/// with no option but -o: the run's criteria (to the file's digits), steps,
/// verdict, diagnosis and divergence, from the file's metadata alone, and
/// the same verdict line on stdout.
void expect_scores_as_the_run(const fs::path& out, const Result& run) {
  const Result r = test::run_demcal({"score", "series.csv", "-o", "scored"}, out);
  const auto ran = nlohmann::json::parse(read_text(out / "summary.json"));
  ASSERT_EQ(r.status, ran.at("passed").get<bool>() ? 0 : 1) << r.err;
  const auto scored = nlohmann::json::parse(read_text(out / "scored" / "summary.json"));
  test::expect_same_criteria(ran.at("criteria"), scored.at("criteria"));
  // A diverged run's series ends at its last monitoring point before the
  // divergence: its steps run are that point's.
  if (!ran.at("diverged").get<bool>()) {
    EXPECT_EQ(scored.at("steps_run"), ran.at("steps_run"));
  }
  EXPECT_EQ(scored.at("steps_planned"), ran.at("params").at("steps"));
  EXPECT_EQ(scored.at("passed"), ran.at("passed"));
  // The diagnosis: its confidence is a function of the criteria (to the
  // file's digits), the rest is the same text.
  auto diagnosis = [](nlohmann::json d) {
    d.erase("confidence");
    return d;
  };
  EXPECT_EQ(diagnosis(scored.at("diagnosis")), diagnosis(ran.at("diagnosis")));
  EXPECT_NEAR(scored.at("diagnosis").at("confidence").get<double>(),
              ran.at("diagnosis").at("confidence").get<double>(), 1e-8);
  EXPECT_EQ(scored.at("diverged"), ran.at("diverged"));
  if (ran.contains("divergence")) {
    EXPECT_EQ(scored.at("divergence").at("step"), ran.at("divergence").at("step"));
  }
  auto verdict = [](const std::string& out) {
    for (const std::string& line : lines_of(out))
      if (line.rfind("  PASS: ", 0) == 0 || line.rfind("  FAIL: ", 0) == 0) return line;
    return std::string("no verdict line");
  };
  EXPECT_EQ(verdict(r.out), verdict(run.out));
  // A diverged run's criteria are said to be unscored by both, in the same
  // words, not printed as numbers (the trend ones read 0).
  auto unscored = [](const std::string& out) {
    for (const std::string& line : lines_of(out))
      if (line.rfind("  criteria not scored: ", 0) == 0) return line;
    return std::string("no such line");
  };
  if (ran.at("diverged").get<bool>()) {
    EXPECT_EQ(unscored(r.out), unscored(run.out)) << r.out;
    EXPECT_EQ(r.out.find("  force balance "), std::string::npos) << r.out;
  }
}

// The run's series.csv carries what the run was scored with (σ3, Nstep,
// Δt and Δt_crit, the damping ratios, the mass scaling, the step-level peak
// and the analytical reference): `demcal score` gives its criteria, verdict
// and diagnosis, on a passing and a failing run.
TEST_F(CliEndToEnd, ScoreOnARunsSeriesGivesTheRunsVerdict) {
  bool seen[2] = {false, false};
  for (const char* steps : {"algorithm.steps=2000", "algorithm.steps=100000"}) {
    SCOPED_TRACE(steps);
    const fs::path out = dir_ / "work" / ("run" + std::string(steps).substr(16));
    const Result r =
        demcal({"run", kHex5, "--set", steps, "--set", "output.vtk=false", "-o", out.string()});
    ASSERT_NO_FATAL_FAILURE(
        test::expect_run_status(r.status, out, r.err));  // as `demcal score`'s, below
    const auto ran = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_TRUE(ran.at("criteria").contains("peak_error"));  // against the analytical peak
    seen[ran.at("passed").get<bool>()] = true;
    expect_scores_as_the_run(out, r);
  }
  EXPECT_TRUE(seen[0] && seen[1]) << "wanted a failing and a passing run";
}

TEST_F(CliEndToEnd, RunIntoAnExistingFolderAndWithoutVtk) {
  const fs::path out = dir_ / "work" / "out";
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "mine\n";
  const Result r = demcal({"run", kHex5, "--set", "algorithm.steps=2000", "--set",
                           "output.vtk=false", "-o", out.string()});
  ASSERT_NO_FATAL_FAILURE(test::expect_run_status(r.status, out, r.err));
  EXPECT_EQ(test::names_in(out), (std::set<std::string>{"keep.txt", "summary.json", "series.csv"}));
  // The default folder is demcal-run-NAME in the working directory.
  const Result d = demcal({"run", kHex5, "--set", "algorithm.steps=2000", "--set", "name=tiny"});
  test::expect_run_status(d.status, dir_ / "work" / "demcal-run-tiny", d.err);
}

// A calibration into a folder of an earlier one: the files it names on its
// "wrote" line are all it leaves of demcal's (every one it writes is named,
// resume.json too), so an earlier run's final.vtk (a 3D report's, beside a
// 2D one) does not survive looking like this run's; the user's own files
// stay.
TEST_F(CliEndToEnd, CalibrateNamesWhatItWroteAndLeavesNoEarlierResult) {
  const fs::path out = dir_ / "work" / "out";
  fs::create_directories(out);
  std::ofstream(out / "final.vtk") << "an earlier 3D calibration's\n";
  std::ofstream(out / "run.json") << "{}\n";  // that calibration's
  std::ofstream(out / "evidence.jsonl") << "{}\n";
  std::ofstream(out / "keep.txt") << "mine\n";
  const Result r =
      demcal({"calibrate", kHex5, "-o", out.string(), "-q", "-j", "1", "--max-trials", "12"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::set<std::string> named{"keep.txt"};
  for (const std::string& line : lines_of(r.out)) {
    const auto at = line.find("  wrote ");
    if (at != 0) continue;
    for (std::string path : split(line.substr(8), ',')) {
      if (path.front() == ' ') path.erase(0, 1);
      EXPECT_EQ(path.rfind(out.string() + "/", 0), 0u) << path;
      named.insert(fs::path(path).filename().string());
    }
  }
  EXPECT_TRUE(named.count("resume.json")) << r.out;
  EXPECT_EQ(test::names_in(out), named) << r.out;
  EXPECT_FALSE(fs::exists(out / "final.vtk"));
  // run.json is this invocation's record (wall time, jobs, trials), not a
  // run's summary.json ("demcal.run/1"): its own schema (both said
  // demcal.run/1 with different contents).
  const auto record = test::read_json(out / "run.json");
  EXPECT_EQ(record.at("schema"), "demcal.calibration-run/1");
  for (const char* key : {"wall_time_s", "consolidation_wall_time_s", "consolidation_from_cache",
                          "jobs", "trials_run", "trials_reused"})
    EXPECT_TRUE(record.contains(key)) << key;

  // A final.vtk with no calibration's run.json beside it is a `demcal run`'s
  // (or the user's): a calibration does not write it in 2D, so it stays.
  const fs::path ran = dir_ / "work" / "ran";
  fs::create_directories(ran);
  std::ofstream(ran / "final.vtk") << "a run's\n";
  const Result c =
      demcal({"calibrate", kHex5, "-o", ran.string(), "-q", "-j", "1", "--max-trials", "12"});
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(read_text(ran / "final.vtk"), "a run's\n");
}

// The progress lines count as trials finish: with two jobs the trial asked
// for fourth can finish third, and its line said "trial 3 (search 4/12)".
// Trial numbers and search counts both go up by one, line after line
// (whatever order the jobs finish in; on the earlier count two of three
// runs of this calibration broke it).
TEST_F(CliEndToEnd, ProgressCountsTrialsInTheOrderTheyFinish) {
  for (int round = 0; round < 3; ++round) {
    const Result r = demcal({"calibrate", kHex5, "-o", "out", "-j", "2"});
    ASSERT_EQ(r.status, 0) << r.err;
    int next = 0, search = 0;
    for (const std::string& line : lines_of(r.err)) {
      int t = 0, k = 0, n = 0;
      if (std::sscanf(line.c_str(), "trial %d (search %d/%d)", &t, &k, &n) == 3) {
        EXPECT_EQ(k, search + 1) << line;
        search = k;
      }
      if (std::sscanf(line.c_str(), "trial %d (", &t) == 1) {
        EXPECT_EQ(t, next) << line;
        next = t + 1;
      }
    }
    EXPECT_GE(search, 12) << r.err;
  }
}

// With one job the trials finish in the order asked, so a progress line's
// trial number is the id trials.jsonl and the report give that trial (the
// lines counted from 1 and the files from 0: "trial 58 (verify)" was the
// report's "57 (chosen)").
TEST_F(CliEndToEnd, ProgressTrialNumbersAreTheFilesIdsWithOneJob) {
  const fs::path out = dir_ / "work" / "one";
  const Result r = demcal({"calibrate", kHex5, "-o", out.string(), "-j", "1"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<int, int64_t> steps_of;
  for (const std::string& line : lines_of(read_text(out / "trials.jsonl"))) {
    const auto j = nlohmann::json::parse(line);
    steps_of[j.at("id").get<int>()] = j.at("params").at("steps").get<int64_t>();
  }
  int lines = 0;
  for (const std::string& line : lines_of(r.err)) {
    int t = -1;
    long long steps = 0;
    if (std::sscanf(line.c_str(), "trial %d (", &t) != 1) continue;
    const size_t at = line.find(", steps ");
    ASSERT_NE(at, std::string::npos) << line;
    steps = std::stoll(line.substr(at + 8));
    ASSERT_TRUE(steps_of.count(t)) << line;
    EXPECT_EQ(steps_of.at(t), steps) << line;
    ++lines;
  }
  EXPECT_EQ(lines, static_cast<int>(steps_of.size())) << r.err;
}

// A computation that fails (consolidation gives up) is not bad input: exit
// 1, one line, and again nothing written.
TEST_F(CliEndToEnd, FailedConsolidationExitsOneAndWritesNothing) {
  const std::string config = write(
      "gas.json",
      "{" + test::kMaterialMember +
          R"(, "assembly": {"type": "random", "count": 60}, "test": {"consolidation_max_steps": 1000}})");
  const Result r = demcal({"run", config, "-o", (dir_ / "work" / "out").string()});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("consolidation"), std::string::npos) << r.err;
  EXPECT_TRUE(work_contents().empty());
}

// A Δt beyond the estimated stable step is bad input for `run` and
// `check` (issue #9 §1), named with the estimate; for `sweep` too, whose
// benchmark is the config's algorithm block (it wrote an atlas around a
// diverging benchmark).
// The error names where the value came from: the --set that gave it, else
// the file.
TEST_F(CliEndToEnd, DtBeyondTheStableStepIsBadInput) {
  const std::string out = (dir_ / "work" / "out").string();
  const std::string set = "--set algorithm.dt_ratio=0.4";
  expect_bad_input({"run", kHex5, "--set", "algorithm.dt_ratio=0.4", "-o", out},
                   {set + ": algorithm.dt_ratio: 0.4", "stable step", "0.30"});
  expect_bad_input({"check", kHex5, "--set", "algorithm.dt_ratio=0.4"},
                   {set + ": algorithm.dt_ratio"});
  expect_bad_input({"sweep", kHex5, "--set", "algorithm.dt_ratio=0.4", "-o", out},
                   {set + ": algorithm.dt_ratio: 0.4", "stable step", "0.30"});
  expect_bad_input({"sweep", kHex5, "--set", "algorithm.dt_ratio=0.4"},
                   {set + ": algorithm.dt_ratio"});  // nor the default folder
  nlohmann::json j = nlohmann::json::parse(read_text(kHex5));
  j["algorithm"]["dt_ratio"] = 0.4;
  const std::string file = write("fast.json", j.dump());
  expect_bad_input({"run", file, "-o", out},
                   {file + ": algorithm.dt_ratio: 0.4", "stable step", "0.30"});
  // Another key's --set does not take the blame.
  expect_bad_input({"run", file, "--set", "algorithm.steps=3000", "-o", out},
                   {file + ": algorithm.dt_ratio: 0.4", "stable step"});
}

// A diverged trial is a result, not a crash: written and flagged, and
// judged as `demcal score` judges its series, FAIL, exit 1. The headline
// says how far it got against the steps asked, and its criteria (the trend
// ones read 0 on a few points) are said to be unscored, not printed as a
// perfect run's.
TEST_F(CliEndToEnd, DivergedRunIsReportedNotFatal) {
  const fs::path out = dir_ / "work" / "out";
  const Result r = demcal({"run", kHex5, "--allow-unstable", "--set", "algorithm.dt_ratio=1.5",
                           "--set", "algorithm.damping_ratio_translation=0", "--set",
                           "algorithm.damping_ratio_rotation=0", "--set", "algorithm.steps=20000",
                           "-o", out.string()});
  ASSERT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.out.find("  force balance "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  FAIL: "), std::string::npos) << r.out;
  const auto s = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(s.at("diverged"), true);
  EXPECT_TRUE(s.at("divergence").at("reason").is_string());
  EXPECT_LT(s.at("steps_run").get<int>(), 20000);
  // One numbering in every line (it said "15 of 20000 steps (diverged)"
  // above "diverged at step 16").
  test::expect_one_divergence_numbering(r.out, out, 20000);
  expect_valid_vtk(read_text(out / "final.vtk"), 25, false);  // finite, counts consistent
  // Its series.csv (finite rows up to the divergence) scores as diverged,
  // with the run's diagnosis.
  expect_scores_as_the_run(out, r);
}

// A consolidated state read from the cache has the reading's wall time, not
// the consolidation's: `check` (2D and 3D) and a 3D `run` say so ("read
// from the cache in T s"; they printed "(T s, from the cache)", as if the
// consolidation had taken T), a fresh one's line unchanged.
TEST_F(CliEndToEnd, AConsolidationFromTheCacheIsSaidToBeRead) {
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir_ / "cache").string();
  auto line_of = [](const std::string& out, const std::string& start) {
    for (const std::string& line : lines_of(out))
      if (line.rfind(start, 0) == 0) return line;
    return std::string("no line ") + start;
  };
  for (const std::string& config : {kHex5, test::shipped_config("fcc_4x4x4")}) {
    SCOPED_TRACE(config);
    const Result miss = demcal({"check", config}, {cache});
    const Result hit = demcal({"check", config}, {cache});
    ASSERT_EQ(miss.status, 0) << miss.err;
    ASSERT_EQ(hit.status, 0) << hit.err;
    const std::string fresh = line_of(miss.out, "  consolidated in ");
    const std::string read = line_of(hit.out, "  consolidated in ");
    const size_t open = fresh.find(" steps (");
    ASSERT_NE(open, std::string::npos) << fresh;
    // The same steps, then the fresh one's time, the cached one's reading.
    const std::string steps = fresh.substr(0, open + 8);
    EXPECT_EQ(fresh.find("cache"), std::string::npos) << fresh;
    EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(fresh[open + 8]))) << fresh;
    EXPECT_EQ(read.rfind(steps + "read from the cache in ", 0), 0u) << read;
    EXPECT_NE(read.find(" s), box "), std::string::npos) << read;
  }
  // run, 2D and 3D: "wall time T s (consolidation read from the cache in
  // T s, N steps)" (the 2D run once said no word of its consolidation).
  for (const std::string& config : {kHex5, test::shipped_config("fcc_4x4x4")}) {
    SCOPED_TRACE(config);
    const Result run =
        demcal({"run", config, "--set", "algorithm.steps=2000", "-o", "run-out"}, {cache});
    ASSERT_NO_FATAL_FAILURE(
        test::expect_run_status(run.status, dir_ / "work" / "run-out", run.err));
    const std::string wall = line_of(run.out, "  wall time ");
    EXPECT_NE(wall.find(" s (consolidation read from the cache in "), std::string::npos) << run.out;
    EXPECT_NE(wall.find(" steps), "), std::string::npos) << run.out;
  }
}

// `demcal calibrate` says its consolidation as check, run, verify and export
// do (print_consolidation_time): a fresh one's "(T s)", a cache read's
// "(read from the cache in T s)" (it printed "(read from the consolidation
// cache)" of its own, no time), and "consolidating ..." only before a
// consolidation (it was printed before the cache read too). run.json's
// flat consolidation_from_cache records it.
TEST_F(CliEndToEnd, CalibrateSaysItsConsolidationAsTheOtherCommands) {
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir_ / "cache").string();
  auto calibrate = [&](const std::string& out) {
    const Result r =
        demcal({"calibrate", kHex5, "-o", out, "-j", "1", "--max-trials", "12"}, {cache});
    EXPECT_EQ(r.status, 0) << r.err;
    return r;
  };
  auto line_of = [](const std::string& text, const std::string& start) {
    for (const std::string& line : lines_of(text))
      if (line.rfind(start, 0) == 0) return line;
    return std::string("no line ") + start;
  };
  const Result miss = calibrate("miss");
  const Result hit = calibrate("hit");
  const std::string consolidating = "demcal: consolidating 25 particles of hex_5x5";
  EXPECT_EQ(line_of(miss.err, consolidating).rfind(consolidating, 0), 0u) << miss.err;
  EXPECT_EQ(hit.err.find("demcal: consolidating"), std::string::npos) << hit.err;
  const std::string fresh = line_of(miss.err, "demcal: consolidated in ");
  const std::string read = line_of(hit.err, "demcal: consolidated in ");
  const size_t open = fresh.find(" steps (");
  ASSERT_NE(open, std::string::npos) << fresh;
  // The same steps, then the fresh one's time, the cached one's reading.
  const std::string steps = fresh.substr(0, open + 8);
  EXPECT_EQ(fresh.find("cache"), std::string::npos) << fresh;
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(fresh[open + 8]))) << fresh;
  EXPECT_EQ(fresh.substr(fresh.size() - 3), " s)") << fresh;
  EXPECT_EQ(read.rfind(steps + "read from the cache in ", 0), 0u) << read;
  EXPECT_EQ(read.substr(read.size() - 3), " s)") << read;
  const auto run_fresh = test::read_json(dir_ / "work" / "miss" / "run.json");
  const auto run_read = test::read_json(dir_ / "work" / "hit" / "run.json");
  EXPECT_FALSE(run_fresh["consolidation_from_cache"].get<bool>());
  EXPECT_TRUE(run_read["consolidation_from_cache"].get<bool>());
  // run.json's flat record is the others' (add_consolidation_flat): the
  // steps too, the same either way.
  EXPECT_GT(run_fresh.at("consolidation_steps").get<int64_t>(), 0);
  EXPECT_EQ(run_read.at("consolidation_steps"), run_fresh.at("consolidation_steps"));
}

// `demcal rev`'s rev.json recorded the REV's consolidation (steps, wall
// time) without saying that it was read from the cache: its "consolidation"
// is consolidation_json's record, from_cache added, as in summary.json and
// verify.json; the REV is the same either way.
TEST_F(CliEndToEnd, RevRecordsAConsolidationFromTheCache) {
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir_ / "cache").string();
  for (const char* out : {"miss", "hit"}) {
    const Result r = demcal({"rev", kHex5, "--particles", "25", "-o", out}, {cache});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const auto fresh = test::read_json(dir_ / "work" / "miss" / "rev.json").at("consolidation");
  const auto read = test::read_json(dir_ / "work" / "hit" / "rev.json").at("consolidation");
  ASSERT_TRUE(fresh.contains("from_cache")) << fresh.dump();
  EXPECT_FALSE(fresh["from_cache"].get<bool>());
  EXPECT_TRUE(read.at("from_cache").get<bool>());
  EXPECT_GT(fresh.at("steps").get<int64_t>(), 0);
  EXPECT_EQ(read.at("steps"), fresh.at("steps"));
  EXPECT_TRUE(read.contains("wall_time_s"));
  EXPECT_EQ(read_text(dir_ / "work" / "hit" / "rev.csv"),
            read_text(dir_ / "work" / "miss" / "rev.csv"));
}

// `demcal stability` and `demcal rev` said "consolidating ..." before a read
// from the consolidation cache too, and no consolidation time: now they say
// it as calibrate, export, sweep and scaling do (expect_said_as_the_others).
TEST_F(CliEndToEnd, StabilitySaysItsConsolidationAsTheOtherCommands) {
  expect_said_as_the_others({"stability", kHex5, "--points", "2", "--steps", "2048"},
                            "stability hex_5x5: consolidating 25 particles",
                            "stability hex_5x5: consolidated in ");
}
TEST_F(CliEndToEnd, RevSaysItsConsolidationAsTheOtherCommands) {
  expect_said_as_the_others({"rev", kHex5, "--particles", "16"},
                            "demcal rev: consolidating the REV of 16 particles to sigma3",
                            "demcal rev: consolidated the REV in ");
}

// Every command that consolidates prints its progress lines, with
// --progress S setting the interval (add_progress_option): calibrate,
// stability, rev, verify and scaling consolidated silently, however long it
// took, and check, run and sweep printed every 2 s with no option. --progress 0
// prints at every check (the default, 2 s, keeps these short consolidations
// quiet): each consolidation's first check, step 200, is on a line; scaling
// consolidates each of its 3 sizes. calibrate -q and scaling -q print none.
TEST_F(CliEndToEnd, EveryCommandThatConsolidatesPrintsItsProgress) {
  const std::string hex10 = test::example_params("hex_10x10");
  const std::string fcc = test::example_params("fcc_4x4x4");
  auto progress_lines = [](const std::string& err) {
    std::vector<std::string> lines;
    for (const std::string& line : lines_of(err))
      if (line.rfind("consolidating (", 0) == 0) lines.push_back(line);
    return lines;
  };
  auto first_checks = [](const std::vector<std::string>& lines) {
    int n = 0;
    for (const std::string& line : lines)
      n += line.rfind("consolidating (frictionless): step 200 of at most ", 0) == 0 ? 1 : 0;
    return n;
  };
  const std::vector<std::string> scaling = {
      "scaling", kHex5,          "--sizes", "16,25,36", "--calibrate-max",
      "25",      "--max-trials", "12",      "-j",       "1"};
  struct Case {
    std::vector<std::string> args;
    int consolidations;
  };
  std::vector<Case> cases = {
      {{"check", kHex5}, 1},
      {{"run", kHex5, "-o", "run"}, 1},
      {{"sweep", kHex5, "--set", "algorithm.steps=2000", "-j", "1", "-o", "sweep"}, 1},
      {{"calibrate", kHex5, "-j", "1", "--max-trials", "12", "-o", "cal"}, 1},
      {{"stability", kHex5, "--points", "2", "--steps", "2048", "-o", "stab"}, 1},
      {{"rev", kHex5, "--particles", "16", "-o", "rev"}, 1},
      {{"verify", hex10, "--particles", "100", "-o", "verify2d"}, 1},
      {{"verify", fcc, "--particles", "256", "-o", "verify3d"}, 1},
      {scaling, 3},
  };
  cases.back().args.insert(cases.back().args.end(), {"-o", "scaling"});
  for (Case& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + c.args[1]);
    c.args.insert(c.args.end(), {"--progress", "0"});
    const Result r = demcal(c.args, {"DEMCAL_CACHE_DIR=off"});
    // run: 1 when its verdict fails (summary.json says so); scaling: 1 when
    // the forward check of its 3 tiny sizes fails.
    if (c.args[0] == "run")
      ASSERT_NO_FATAL_FAILURE(test::expect_run_status(r.status, dir_ / "work" / "run", r.err));
    else if (c.args[0] == "scaling" && r.status == 1)
      EXPECT_NE(r.out.find("forward check of the linear law at 36: FAILED"), std::string::npos)
          << r.out;
    else
      ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<std::string> lines = progress_lines(r.err);
    EXPECT_EQ(first_checks(lines), c.consolidations) << r.err;
    ASSERT_FALSE(lines.empty()) << r.err;
    EXPECT_EQ(lines.back().rfind("consolidating (friction on)", 0), 0u) << lines.back();
  }
  std::vector<std::string> quiet_scaling = scaling;
  quiet_scaling.insert(quiet_scaling.end(), {"-q", "--progress", "0", "-o", "scaling-q"});
  const std::vector<std::vector<std::string>> quiet_runs = {
      {"calibrate", kHex5, "-j", "1", "--max-trials", "12", "-q", "--progress", "0", "-o", "q"},
      quiet_scaling};
  for (const std::vector<std::string>& args : quiet_runs) {
    SCOPED_TRACE(args[0]);
    const Result quiet = demcal(args, {"DEMCAL_CACHE_DIR=off"});
    EXPECT_TRUE(quiet.status == 0 || (args[0] == "scaling" && quiet.status == 1)) << quiet.err;
    EXPECT_TRUE(progress_lines(quiet.err).empty()) << quiet.err;
  }
  for (const char* bad : {"-1", "nan", "inf", "1e10", "two"})
    EXPECT_EQ(demcal({"stability", kHex5, "--progress", bad}, {}).status, 2) << bad;
}

// `demcal export` says how the deck's Nstep was upscaled, 2D and 3D in
// one line: the prototype's Nstep (the one `demcal upscale` writes), from
// the REV's particles and steps, by which law (the 2D export said nothing).
TEST_F(CliEndToEnd, ExportSaysHowItsStepsWereUpscaledIn2dAnd3d) {
  struct Case {
    std::string params;
    const char* particles;  // the 3D FCC prototype: 4·n³ spheres
    const char* what;
    const char* law;
    const char* deck;
  };
  const std::vector<Case> cases = {
      {test::example_params("hex_10x10"), "150", "particles", "linear", "d2/deck.lammps"},
      {test::example_params("fcc_4x4x4"), "500", "spheres", "power", "d3/deck.lammps"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.params);
    const Result r = demcal(
        {"export", c.params, "--particles", c.particles, "--consolidate-in", "deck", "-o", c.deck});
    ASSERT_EQ(r.status, 0) << r.err;
    const Result u = demcal({"upscale", c.params, "--particles", c.particles});
    ASSERT_EQ(u.status, 0) << u.err;
    const auto upscaled = nlohmann::json::parse(u.out);
    const auto rev = test::read_json(c.params).at("rev");
    const std::string line =
        "demcal export: " + std::to_string(upscaled.at("prototype").at("steps").get<int64_t>()) +
        " steps upscaled from " + std::to_string(rev.at("particles").get<int64_t>()) + " " +
        c.what + " / " + std::to_string(rev.at("steps").get<int64_t>()) + " steps (" + c.law +
        " law, exponent ";
    int said = 0;
    for (const std::string& l : lines_of(r.err)) said += l.rfind(line, 0) == 0;
    EXPECT_EQ(said, 1) << line << "\n" << r.err;
  }
}

}  // namespace
