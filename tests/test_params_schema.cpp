// params.json as upscale, verify and export read it (the first-time user's
// walk of 2026-12-04): its safety fields of the wrong type or missing, and
// unknown keys, are refused (exit 2, the file and the field named) instead
// of switching the refusals off; every params.json demcal writes is still
// read; upscale refuses a --config or --set that would write a prototype
// unlike the config it records; --law and --exponent are exclusive, and a
// law of another scene is named; upscale -o makes its folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/process.hpp"
#include "support/refusals.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;
using Result = test::RunResult;
using nlohmann::json;

const std::string kHex5 = test::shipped_config("hex_5x5");

class ParamsSchema : public ::testing::Test {
 protected:
  // One fresh calibration of hex_5x5 for the suite (a few seconds).
  static void SetUpTestSuite() {
    calibration_ = new test::TempDir("params-schema-cal");
    const Result r = test::run_demcal(
        {"calibrate", kHex5, "-j", "1", "-q", "-o", (calibration_->path() / "h5").string()},
        calibration_->path());
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete calibration_;
    calibration_ = nullptr;
  }
  void SetUp() override { fs::create_directories(work_); }

  static std::string fresh() { return (calibration_->path() / "h5" / "params.json").string(); }
  static json fresh_json() { return test::read_json(fresh()); }

  Result demcal(const std::vector<std::string>& args) { return test::run_demcal(args, work_); }

  /// `params` edited, written beside the work folder (not in it).
  std::string edited(const std::string& name, const json& params) {
    return test::write_text(tmp_.path() / name, params.dump(2));
  }

  /// Bad input: exit 2, one line on stderr naming every one of `mentions`,
  /// nothing on stdout, nothing written in the working folder.
  void expect_refused(const std::vector<std::string>& args,
                      const std::vector<std::string>& mentions) {
    test::expect_refused(work_, args, mentions);
  }

  /// The three commands that read a params.json refuse `p`, naming it and
  /// `field` (and each of `more`).
  void expect_all_refuse(const std::string& p, const std::string& field,
                         std::vector<std::string> more = {}) {
    more.push_back(p);
    more.push_back(field);
    expect_refused({"upscale", p, "--particles", "100", "-o", "x.json"}, more);
    expect_refused({"export", p, "--particles", "100", "--no-consolidate", "-o", "x/d.lammps"},
                   more);
    expect_refused({"verify", p, "--particles", "100", "-o", "v"}, more);
  }

  static test::TempDir* calibration_;
  test::TempDir tmp_{"params-schema"};
  const fs::path work_ = tmp_.path() / "work";
};

test::TempDir* ParamsSchema::calibration_ = nullptr;

// Only JSON false was refused: "false", 0, null or no "success" at all
// passed as a calibration that succeeded, --allow-failed or not.
TEST_F(ParamsSchema, SuccessOfAnotherTypeOrMissingIsRefused) {
  for (const json& value : {json("false"), json(0), json(nullptr), json("true")}) {
    json p = fresh_json();
    p["success"] = value;
    const std::string file = edited("success.json", p);
    expect_all_refuse(file, "success", {"must be true or false", value.type_name()});
    expect_refused({"upscale", file, "--particles", "100", "--allow-failed"},
                   {file, "success", "must be true or false"});
  }
  json p = fresh_json();
  p.erase("success");
  const std::string file = edited("nosuccess.json", p);
  expect_all_refuse(file, "success", {"missing"});
  expect_refused({"upscale", file, "--particles", "100", "--allow-failed"}, {file, "success"});
}

// A dt_ratio_stable as a string, or none, let a rev.dt_ratio beyond the
// stable step through: export wrote a deck that diverges.
TEST_F(ParamsSchema, StableStepOfAnotherTypeOrMissingIsRefused) {
  json base = fresh_json();
  const double stable = base["dt_ratio_stable"];
  base["rev"]["dt_ratio"] = 1.66 * stable;
  json p = base;
  p["dt_ratio_stable"] = std::to_string(stable);
  expect_all_refuse(edited("string.json", p), "dt_ratio_stable", {"must be a number"});
  p = base;
  p.erase("dt_ratio_stable");
  expect_all_refuse(edited("none.json", p), "dt_ratio_stable", {"missing"});
  for (const json& value : {json(nullptr), json(0.0), json(-1.0)}) {
    p = base;
    p["dt_ratio_stable"] = value;
    expect_all_refuse(edited("bad.json", p), "dt_ratio_stable");
  }
  // The number itself still bounds it (beyond: rev.dt_ratio named).
  expect_all_refuse(edited("beyond.json", base), "rev.dt_ratio");
}

// "bogus": 1 at the top or in a block was accepted without a word.
TEST_F(ParamsSchema, UnknownKeysAndWrongTypesAreRefused) {
  const std::vector<std::pair<std::function<void(json&)>, std::string>> edits = {
      {[](json& p) { p["bogus"] = 1; }, "bogus"},
      {[](json& p) { p["rev"]["bogus"] = 1; }, "rev.bogus"},
      {[](json& p) { p["prototype"]["bogus"] = 1; }, "prototype.bogus"},
      {[](json& p) { p["prototype"]["source"]["bogus"] = 1; }, "prototype.source.bogus"},
      {[](json& p) { p["upscaling"]["bogus"] = 1; }, "upscaling.bogus"},
      {[](json& p) { p["rev"]["dt"] = "1e-7"; }, "rev.dt"},
      {[](json& p) { p["prototype"]["source"]["file"] = 3; }, "prototype.source.file"},
      {[](json& p) { p["message"] = false; }, "message"},
      {[](json& p) { p["upscaling"] = "linear"; }, "upscaling"},
      {[](json& p) { p["prototype"] = nullptr; }, "prototype"},
      {[](json& p) { p["trials"] = -3; }, "trials"},
  };
  for (const auto& [edit, field] : edits) {
    json p = fresh_json();
    edit(p);
    expect_all_refuse(edited("edited.json", p), field);
  }
}

// Every params.json demcal writes is read: a fresh calibration, the shipped
// examples (2D with its evidence block, 3D), upscale's own output (with and
// without a config), and the first schema (no config, wall_time_s, an
// upscaling block of law and factor) with --config.
TEST_F(ParamsSchema, EveryParamsJsonDemcalWritesIsRead) {
  for (const std::string& p :
       {fresh(), test::example_params("hex_10x10"), test::example_params("fcc_4x4x4")}) {
    SCOPED_TRACE(p);
    const Result r = demcal({"upscale", p, "--particles", "100", "-o", "up.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const Result again = demcal({"upscale", "up.json", "--particles", "200"});
    EXPECT_EQ(again.status, 0) << again.err;
    const Result ex =
        demcal({"export", "up.json", "--consolidate-in", "deck", "-o", "d/deck.lammps"});
    EXPECT_EQ(ex.status, 0) << ex.err;
  }
  json old = test::read_json(test::example_params("hex_10x10"));
  for (const char* k : {"config", "evidence", "particle_steps_run", "analytical_peak_stress_yy"})
    old.erase(k);
  old["wall_time_s"] = 12.5;
  old["upscaling"] = {{"law", "linear"}, {"factor", 1.0}};
  old["prototype"].erase("source");
  old["scene"] = "older";  // not the embedded default's name: no config at all
  const std::string first = edited("first.json", old);
  const Result r = demcal({"upscale", first, "--config", test::shipped_config("hex_10x10"),
                           "--particles", "100", "-o", "noconfig.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  // Its output (a prototype without the generator's sizes) reads back too.
  const json out = test::read_json(work_ / "noconfig.json");
  const Result plain = demcal({"upscale", first, "--particles", "100", "-o", "plain.json"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(demcal({"upscale", "plain.json", "--particles", "300"}).status, 0);
  EXPECT_EQ(out.at("prototype").at("particles"), 100);
}

// upscale --config OTHER took the prototype from OTHER under the scene of
// the params.json, which keeps its own config: refused; the config itself
// is accepted. verify and export run what they are given, with a warning.
TEST_F(ParamsSchema, UpscaleRefusesAConfigUnlikeTheOneItCarries) {
  const std::string p = fresh();
  const std::string other = test::shipped_config("random_400");
  expect_refused({"upscale", p, "--particles", "100", "--config", other},
                 {p, "config", other, "random_400", "hex_5x5"});
  const Result same = demcal({"upscale", p, "--particles", "100", "--config", kHex5});
  EXPECT_EQ(same.status, 0) << same.err;
  EXPECT_EQ(same.out, demcal({"upscale", p, "--particles", "100"}).out);
  const Result ex = demcal({"export", p, "--particles", "100", "--config", other,
                            "--no-consolidate", "-o", "d/x.lammps"});
  EXPECT_EQ(ex.status, 0) << ex.err;
  EXPECT_NE(ex.err.find("warning: --config " + other + " (scene random_400)"), std::string::npos)
      << ex.err;
  EXPECT_NE(ex.err.find("(scene hex_5x5)"), std::string::npos) << ex.err;
}

// upscale --set material.kn=1e9 wrote a prototype.dt for kn 1e9 under a
// config that still says 1e8 and the same config_sha256: refused.
TEST_F(ParamsSchema, UpscaleRefusesSetOnTheConfigItCarries) {
  const std::string p = fresh();
  for (const std::string set : {"material.kn=1e9", "test.lateral_stress=2e5",
                                "algorithm.dt_ratio=0.1", "assembly.columns=9"})
    expect_refused({"upscale", p, "--particles", "100", "--set", set}, {"--set", set});
  const Result ex = demcal({"export", p, "--particles", "100", "--set", "material.kn=1e9",
                            "--no-consolidate", "-o", "d/x.lammps"});
  EXPECT_EQ(ex.status, 0) << ex.err;
  EXPECT_NE(ex.err.find("warning: --set material.kn=1e9 changes the material"), std::string::npos)
      << ex.err;
  // The config's algorithm is never used (the rev's, upscaled): said.
  const Result alg = demcal({"export", p, "--particles", "100", "--set", "algorithm.steps=30000",
                             "--no-consolidate", "-o", "e/x.lammps"});
  EXPECT_EQ(alg.status, 0) << alg.err;
  EXPECT_NE(alg.err.find("warning: --set algorithm.steps=30000 has no effect"), std::string::npos)
      << alg.err;
  // Without effect, not applied either: a value the config would refuse
  // (fewer steps than test.monitor_points) is no error ("has no effect",
  // then an error blaming params.json's config, before).
  const Result few = demcal({"export", p, "--particles", "100", "--set", "algorithm.steps=10",
                             "--no-consolidate", "-o", "g/x.lammps"});
  EXPECT_EQ(few.status, 0) << few.err;
  EXPECT_NE(few.err.find("warning: --set algorithm.steps=10 has no effect"), std::string::npos)
      << few.err;
  // A mistyped algorithm key is no key without effect: refused, as in a
  // config (it was dropped with a "has no effect" warning for a while).
  const Result typo =
      demcal({"export", p, "--particles", "100", "--set", "algorithm.lock_rotaton=true",
              "--no-consolidate", "-o", "h/x.lammps"});
  EXPECT_EQ(typo.status, 2) << typo.err;
  EXPECT_NE(typo.err.find("lock_rotaton"), std::string::npos) << typo.err;
  // lock_rotation is the consolidation's: used, not warned about.
  const Result lock =
      demcal({"export", p, "--particles", "100", "--set", "algorithm.lock_rotation=true",
              "--no-consolidate", "-o", "f/x.lammps"});
  EXPECT_EQ(lock.status, 0) << lock.err;
  EXPECT_EQ(lock.err.find("no effect"), std::string::npos) << lock.err;
}

// --law FILE was ignored when --exponent was given, even a FILE that does
// not exist; a law measured on another scene was taken without a word.
TEST_F(ParamsSchema, LawAndExponentAreExclusiveAndAnotherScenesLawIsNamed) {
  const std::string p = fresh();
  for (const std::string command : {"upscale", "export", "verify"})
    expect_refused({command, p, "--particles", "100", "--law", "nothere.json", "--exponent", "1"},
                   {"--law", "--exponent"});
  const std::string law = (fs::path(test::kSourceDir) / "reports" / "scaling.json").string();
  ASSERT_EQ(test::read_json(law).at("scene"), "random_400");
  const Result r = demcal({"upscale", p, "--particles", "100", "--law", law});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("note: " + law + " is the law measured on scene random_400, and " + p +
                       " was calibrated on scene hex_5x5"),
            std::string::npos)
      << r.err;
  // The law of the scene itself: no note.
  json own = test::read_json(law);
  own["scene"] = "hex_5x5";
  const Result quiet =
      demcal({"upscale", p, "--particles", "100", "--law", edited("own.json", own)});
  EXPECT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("note:"), std::string::npos) << quiet.err;
}

// upscale -o nodir/x/up.json failed with exit 1 and a message about a
// temporary file; export and verify make their folders.
TEST_F(ParamsSchema, UpscaleMakesTheOutputFolder) {
  const std::string p = fresh();
  const Result r = demcal({"upscale", p, "--particles", "100", "-o", "nodir/x/up.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(test::read_text(work_ / "nodir/x/up.json"),
            demcal({"upscale", p, "--particles", "100"}).out);
  EXPECT_EQ(test::names_in(work_ / "nodir/x"), std::set<std::string>{"up.json"});
  fs::create_directories(work_ / "folder");
  expect_refused({"upscale", p, "--particles", "100", "-o", "folder"}, {"folder", "is a folder"});
  test::write_text(work_ / "file", "x");
  expect_refused({"upscale", p, "--particles", "100", "-o", "file/up.json"}, {"file"});
}

}  // namespace
