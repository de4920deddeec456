// A calibration's params.json as the next commands read it (the README's
// walk-through of calibrate, upscale, verify and export): a particle-file
// scene read back from any folder, a failed calibration that holds no
// parameters it never ran and is refused downstream, --max-trials as the
// search's bound, --particles and --prototype exclusive, a dt_ratio beyond
// the recorded stable step refused, and the certificate's step counts as
// run.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
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

const std::string kHex5 = test::shipped_config("hex_5x5");
const std::string kFcc = test::shipped_config("fcc_4x4x4");

/// The trials of DIR/trials.jsonl.
std::vector<nlohmann::json> trials_of(const fs::path& dir) {
  std::vector<nlohmann::json> out;
  for (const auto& line : test::lines_of(test::read_text(dir / "trials.jsonl")))
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

class ParamsFixes : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(work_); }

  Result demcal(const std::vector<std::string>& args, const fs::path& cwd) {
    return test::run_demcal(args, cwd);
  }
  Result demcal(const std::vector<std::string>& args) { return demcal(args, work_); }

  /// Bad input: exit 2, one line on stderr naming every one of `mentions`,
  /// nothing on stdout, nothing written in the working folder.
  void expect_refused(const std::vector<std::string>& args,
                      const std::vector<std::string>& mentions) {
    test::expect_refused(work_, args, mentions);
  }

  /// calibrate ARGS -j 1 -q -o DIR in the working folder; its exit status.
  int calibrate(std::vector<std::string> args, const std::string& dir) {
    args.insert(args.begin(), "calibrate");
    for (const char* a : {"-j", "1", "-q", "-o"}) args.push_back(a);
    args.push_back(dir);
    const Result r = demcal(args);
    EXPECT_NE(r.status, 2) << r.err;
    return r.status;
  }

  test::TempDir tmp_{"params-fixes"};
  const fs::path work_ = tmp_.path() / "work";
};

// Defect 1: `rev` writes rev-config.json naming rev.csv relative to itself;
// calibrating it by a relative path wrote that path, relative to the
// working folder, into params.json, which upscale and export then joined to
// params.json's folder again ("calrev/rev2/rev.csv: no such file").
TEST_F(ParamsFixes, ParticleFileCalibrationReadsBackFromAnyFolder) {
  ASSERT_EQ(demcal({"rev", kHex5, "--particles", "25", "-o", "rev2"}).status, 0);
  ASSERT_EQ(calibrate({"rev2/rev-config.json"}, "calrev"), 0);
  const nlohmann::json params = test::read_json(work_ / "calrev/params.json");
  const std::string file = params["config"]["assembly"]["file"];
  EXPECT_TRUE(fs::path(file).is_absolute()) << file;
  EXPECT_TRUE(fs::equivalent(file, work_ / "rev2/rev.csv")) << file;

  // From the working folder, from inside the calibration folder, and after
  // the calibration folder has moved.
  Result r = demcal({"upscale", "calrev/params.json", "--particles", "100", "-o", "up.json"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = demcal({"export", "calrev/params.json", "--particles", "100", "-o", "d/d.lammps"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(work_ / "d/d.lammps"));
  r = demcal({"upscale", "params.json", "--particles", "100"}, work_ / "calrev");
  EXPECT_EQ(r.status, 0) << r.err;
  fs::create_directories(tmp_.path() / "moved");
  fs::rename(work_ / "calrev", tmp_.path() / "moved/calrev");
  r = demcal({"upscale", "moved/calrev/params.json", "--particles", "100"}, tmp_.path());
  EXPECT_EQ(r.status, 0) << r.err;
  // upscale -o elsewhere copies the config: it reads back there too.
  r = demcal({"upscale", "work/up.json", "--particles", "64"}, tmp_.path());
  EXPECT_EQ(r.status, 0) << r.err;
}

// The same config by another path, from another folder: --resume reuses
// every trial (the resume key is the config's text, not its path), and
// params.json comes out byte for byte the same (the file is named
// absolutely, not relative to the working folder).
TEST_F(ParamsFixes, ResumeFromAnotherFolderReusesTrialsAndWritesTheSameParams) {
  ASSERT_EQ(demcal({"rev", kHex5, "--particles", "25", "-o", "rev2"}).status, 0);
  ASSERT_EQ(calibrate({"rev2/rev-config.json"}, "calrev"), 0);
  const std::string first = test::read_text(work_ / "calrev/params.json");
  const Result r = demcal(
      {"calibrate", "work/rev2/rev-config.json", "-j", "1", "-q", "--resume", "-o", "work/calrev"},
      tmp_.path());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json run = test::read_json(work_ / "calrev/run.json");
  EXPECT_EQ(run["trials_run"], 0);
  EXPECT_GT(run["trials_reused"].get<int>(), 0);
  const std::string again = test::read_text(work_ / "calrev/params.json");
  EXPECT_TRUE(again == first) << "params.json changed; its config's file is now "
                              << test::read_json(work_ /
                                                 "calrev/params.json")["config"]["assembly"];
}

// Defect 2, no trial passed: params.json held the built-in defaults (α 0.2,
// Nstep 100000, ζ 1) as "best found", and export used them silently.
TEST_F(ParamsFixes, FailedCalibrationHoldsNoParametersAndIsRefused) {
  // auglag within 12 trials finds no passing trial on hex_5x5.
  ASSERT_EQ(calibrate({kHex5, "--max-trials", "12", "--strategy", "auglag"}, "calfail"), 1);
  const nlohmann::json params = test::read_json(work_ / "calfail/params.json");
  EXPECT_EQ(params["success"], false);
  EXPECT_TRUE(params["rev"].is_null()) << params["rev"].dump();
  EXPECT_TRUE(params["prototype"].is_null());
  const std::string report = test::read_text(work_ / "calfail/report.md");
  EXPECT_EQ(report.find("best found"), std::string::npos);

  const std::string p = "calfail/params.json";
  expect_refused({"upscale", p, "--particles", "25", "-o", "x.json"}, {p, "success"});
  expect_refused({"export", p, "--particles", "25", "-o", "x/d.lammps"}, {p, "success"});
  expect_refused({"verify", p, "--particles", "25", "-o", "v"}, {p, "success"});
  // The override cannot make parameters out of none, so the message does
  // not offer it.
  expect_refused({"upscale", p, "--particles", "25", "--allow-failed"}, {p, "rev"});
  const Result none = demcal({"upscale", p, "--particles", "25", "-o", "x.json"});
  EXPECT_EQ(none.err.find("--allow-failed"), std::string::npos) << none.err;
}

// Defect 2, passing trials but no certificate (an accuracy no Nstep meets):
// the result is the passing trial whose certificate failed, as run, and it
// is used only with --allow-failed.
TEST_F(ParamsFixes, UncertifiedCalibrationHoldsATrialItRanAndNeedsAllowFailed) {
  ASSERT_EQ(calibrate({kHex5, "--accuracy", "0.00001"}, "uncert"), 1);
  const nlohmann::json params = test::read_json(work_ / "uncert/params.json");
  EXPECT_EQ(params["success"], false);
  ASSERT_TRUE(params["rev"].is_object()) << params["rev"].dump();
  const auto& rev = params["rev"];
  bool ran = false;
  for (const auto& t : trials_of(work_ / "uncert"))
    ran = ran ||
          (t["params"]["dt_ratio"] == rev["dt_ratio"] && t["params"]["steps"] == rev["steps"] &&
           t["params"]["damping_ratio_translation"] == rev["damping_ratio_translation"] &&
           t["passed"] == true);
  EXPECT_TRUE(ran) << "rev is no passing trial of trials.jsonl: " << rev.dump();
  EXPECT_FALSE(params["certificate"]["passed"]);
  EXPECT_NE(test::read_text(work_ / "uncert/report.md").find("REV (passed, NOT certified)"),
            std::string::npos);

  const std::string p = "uncert/params.json";
  expect_refused({"upscale", p, "--particles", "25", "-o", "x.json"}, {p, "success"});
  expect_refused({"export", p, "--particles", "25", "-o", "x/d.lammps"}, {p, "success"});
  const Result refused = demcal({"upscale", p, "--particles", "25", "-o", "x.json"});
  EXPECT_NE(refused.err.find("--allow-failed"), std::string::npos) << refused.err;
  const Result r = demcal({"upscale", p, "--particles", "25", "--allow-failed", "-o", "x.json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(work_ / "x.json"));
}

// Defect 3: --max-trials 3 ran 12 search trials ("trial 4/3" ... "15/3").
TEST_F(ParamsFixes, MaxTrialsBelowTheSearchMinimumIsRefused) {
  expect_refused({"calibrate", kHex5, "--max-trials", "3", "-o", "out"}, {"--max-trials", "12"});
  const std::string config =
      test::write_text(tmp_.path() / "three.json",
                       R"({"material": {"density": 2600, "kn": 1e7, "kt": 1e7, "friction": 0.5},)"
                       R"( "calibration": {"max_trials": 3}})");
  expect_refused({"calibrate", config, "-o", "out"}, {config, "calibration.max_trials", "12"});
  expect_refused({"scaling", kHex5, "--max-trials", "3"}, {"--max-trials", "12"});
  // Only a calibration needs the budget: the config stays valid for the
  // other commands (and in params.json files made from it).
  const Result checked = demcal({"check", config});
  EXPECT_EQ(checked.status, 0) << checked.err;
}

// A relative particle file is found as the system finds it: through a
// symbolic link to the config's folder, "../p.csv" is beside the link's
// target, not beside the link (the text is not normalised).
TEST_F(ParamsFixes, ARelativeParticleFileIsResolvedThroughALinkedFolder) {
  const fs::path real = tmp_.path() / "b" / "real", linked = tmp_.path() / "a" / "link";
  fs::create_directories(real);
  fs::create_directories(linked.parent_path());
  fs::create_directory_symlink(real, linked);
  test::write_text(real.parent_path() / "p.csv",
                   "x,y,r\n0.001,0.001,0.0005\n0.002,0.001,0.0005\n"
                   "0.001,0.002,0.0005\n0.002,0.002,0.0005\n");
  const std::string config = test::write_text(
      real / "cfg.json", R"({"material": {"density": 2600, "kn": 1e7, "kt": 1e7, "friction": 0.5},)"
                         R"( "assembly": {"type": "file", "file": "../p.csv"}})");
  const Result r = demcal({"check", (linked / "cfg.json").string()});
  EXPECT_EQ(r.status, 0) << r.err;
}

// --max-trials N bounds the search's trials, and the progress line counts
// them against N; verification and the certificate come on top, without a
// denominator they would overrun.
TEST_F(ParamsFixes, MaxTrialsBoundsTheSearchAndItsProgressCount) {
  for (const std::string strategy : {"model", "cobyla", "direct"}) {
    SCOPED_TRACE(strategy);
    const std::string dir = "mt-" + strategy;
    const Result r = demcal(
        {"calibrate", kHex5, "--max-trials", "12", "--strategy", strategy, "-j", "1", "-o", dir});
    ASSERT_NE(r.status, 2) << r.err;
    int search = 0;
    for (const auto& t : trials_of(work_ / dir)) search += t["phase"] == "search";
    EXPECT_GE(search, 1);
    EXPECT_LE(search, 12);
    const std::regex line(R"(trial (\d+) \(([a-z-]+)(?: (\d+)/(\d+))?\):)");
    int progress = 0;
    for (const auto& l : test::lines_of(r.err)) {
      std::smatch m;
      if (!std::regex_search(l, m, line)) continue;
      ++progress;
      if (m[2] == "search") {
        ASSERT_TRUE(m[3].matched) << l;
        EXPECT_EQ(m[4], "12") << l;
        EXPECT_LE(std::stoi(m[3]), 12) << l;
      } else {
        EXPECT_FALSE(m[3].matched) << l;
      }
    }
    EXPECT_GT(progress, search) << r.err;  // verify/certificate lines matched too
  }
}

class ParamsOfACalibration : public ParamsFixes {
 protected:
  void SetUp() override {
    ParamsFixes::SetUp();
    ASSERT_EQ(calibrate({kHex5}, "good"), 0);
  }
};

// Defect 8: --particles with --prototype used the file and ignored the count.
TEST_F(ParamsOfACalibration, ParticlesAndPrototypeAreExclusive) {
  const std::string proto = test::write_text(tmp_.path() / "proto.csv",
                                             "x,y,r\n0,0,0.0005\n0.001,0,0.0005\n0,0.001,0.0005\n");
  const std::string p = "good/params.json";
  for (const std::string command : {"upscale", "export", "verify"})
    expect_refused({command, p, "--particles", "400", "--prototype", proto},
                   {"--particles", "--prototype"});
}

// Defect 7b: a params.json whose rev.dt_ratio exceeds the stable step it
// records (dt_ratio_stable) exported a deck without complaint.
TEST_F(ParamsOfACalibration, DtRatioBeyondTheRecordedStableStepIsRefused) {
  nlohmann::json params = test::read_json(work_ / "good/params.json");
  const double stable = params["dt_ratio_stable"];
  ASSERT_LT(params["rev"]["dt_ratio"].get<double>(), stable);
  params["rev"]["dt_ratio"] = 1.5 * stable;
  const std::string p = test::write_text(tmp_.path() / "edited.json", params.dump(2));
  expect_refused({"upscale", p, "--particles", "100", "-o", "x.json"}, {p, "rev.dt_ratio"});
  expect_refused({"export", p, "--particles", "100", "-o", "x/d.lammps"}, {p, "rev.dt_ratio"});
  expect_refused({"verify", p, "--particles", "100", "-o", "v"}, {p, "rev.dt_ratio"});
  // At the stable step itself it is accepted.
  params["rev"]["dt_ratio"] = stable;
  const std::string q = test::write_text(tmp_.path() / "at.json", params.dump(2));
  EXPECT_EQ(demcal({"upscale", q, "--particles", "100"}).status, 0);
}

// Defect 14a: the 3D certificate table printed Nstep/2 = 14,785 for a trial
// that ran 14,790 steps (each trial's Nstep is rounded): the rows name the
// step counts of the certificate trials as run.
TEST_F(ParamsFixes, CertificateRowsNameTheStepsRun) {
  ASSERT_EQ(demcal({"calibrate", kFcc, "-j", "2", "-q", "-o", "fcc"}).status, 0);
  std::set<int64_t> certificate;
  for (const auto& t : trials_of(work_ / "fcc"))
    if (t["phase"] == "certificate") certificate.insert(t["params"]["steps"].get<int64_t>());
  const std::string report = test::read_text(work_ / "fcc/report.md");
  int rows = 0;
  const std::regex row(R"(at (2·Nstep|Nstep/2) = ([0-9,]+))");
  for (auto it = std::sregex_iterator(report.begin(), report.end(), row);
       it != std::sregex_iterator(); ++it) {
    std::string digits = (*it)[2];
    digits.erase(std::remove(digits.begin(), digits.end(), ','), digits.end());
    EXPECT_TRUE(certificate.count(std::stoll(digits))) << (*it)[0];
    ++rows;
  }
  EXPECT_EQ(rows, 2) << report;
}

}  // namespace
