// The command line against hostile-but-realistic input (issue 14, round
// two): every numeric option of every subcommand at 0, -1, nan and values
// that do not fit; --resume with other settings; two calibrations into one
// folder; a damaged trials.jsonl; a params.json that lies. Each must end
// with exit status 2, one line naming the option, file, key or line, and
// nothing written or changed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/process.hpp"

namespace {

namespace fs = std::filesystem;

using Result = demcal::test::RunResult;
using demcal::test::read_text;

const std::string kHex5 = demcal::test::shipped_config("hex_5x5");

/// Path → content of every file under `dir` (folders as "<dir>").
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    out[fs::relative(e.path(), dir).string()] =
        e.is_regular_file() ? std::to_string(std::hash<std::string>{}(read_text(e.path())))
                            : std::string("<dir>");
  return out;
}

class RobustCli : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(work()); }
  fs::path work() const { return dir_ / "work"; }

  /// demcal ARGS run in work(); its output captured outside it.
  Result demcal(const std::vector<std::string>& args) {
    return ::demcal::test::run_demcal(args, work());
  }

  /// Exit 2, one line on stderr naming `mention`, the work folder unchanged.
  void expect_refused(const std::vector<std::string>& args, const std::string& mention) {
    std::string trace = "demcal";
    for (const auto& a : args) trace += " " + a;
    SCOPED_TRACE(trace);
    const auto before = snapshot(work());
    const Result r = demcal(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(snapshot(work()), before);
  }

  /// A small finished calibration in work()/A (under a second).
  void calibrate_a() {
    const Result r = demcal({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--max-trials", "12"});
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(fs::exists(work() / "A" / "resume.json"));
  }

  const demcal::test::TempDir tmp_{"robust_cli"};
  const fs::path dir_ = tmp_.path();
};

// Every numeric option of every subcommand, at values that are never
// meant: each names the option, exit 2, nothing written.
TEST_F(RobustCli, EveryNumericOptionOutOfRangeIsRefused) {
  std::ofstream(work() / "series.csv") << "# not read: the options fail first\n";
  const std::vector<std::pair<std::vector<std::string>, std::vector<std::string>>> commands = {
      {{"sweep", kHex5}, {"--jobs"}},
      {{"calibrate", kHex5}, {"--jobs", "--max-trials", "--accuracy"}},
      {{"stability", kHex5}, {"--jobs", "--from", "--to", "--points", "--steps"}},
      {{"score", "series.csv"}, {"--lateral-stress", "--reference-peak"}},
      {{"upscale", "params.json"}, {"--particles", "--exponent"}},
      {{"verify", "params.json"}, {"--particles", "--exponent", "--max-minutes", "--np"}},
      {{"scaling", kHex5}, {"--jobs", "--max-trials", "--calibrate-max"}},
      {{"export", "params.json"}, {"--particles", "--exponent"}},
      {{"rev", kHex5}, {"--particles"}},
  };
  const std::vector<std::string> values = {
      "0", "-1", "-5", "nan", "inf", "1e999", "1e300", "1e9", "99999999999999999999"};
  for (const auto& [head, options] : commands)
    for (const auto& option : options)
      for (const auto& value : values) {
        // Values that are in range for this option (1e9 steps, a 1e9 Pa
        // reference peak) are not the point here.
        if (value == "1e9" && option != "--particles" && option != "--calibrate-max") continue;
        std::vector<std::string> args = head;
        args.insert(args.end(), {option, value, "-o", "out"});
        expect_refused(args, option);
      }
}

TEST_F(RobustCli, StabilityRefusesTooFewStepsToSeeADivergence) {
  expect_refused({"stability", kHex5, "--steps", "100", "-o", "out"}, "energy ledger");
}

TEST_F(RobustCli, UnknownCommandIsNamed) { expect_refused({"frobnicate"}, "\"frobnicate\""); }

TEST_F(RobustCli, ResumeWithOtherSettingsIsRefusedAndChangesNothing) {
  calibrate_a();
  expect_refused({"calibrate", kHex5, "--set", "material.friction=0.5", "-o", "A", "-q", "-j", "1",
                  "--resume"},
                 "config_sha256");
  expect_refused({"calibrate", kHex5, "--accuracy", "0.05", "-o", "A", "-q", "-j", "1", "--resume"},
                 "accuracy");
  expect_refused(
      {"calibrate", kHex5, "--strategy", "cobyla", "-o", "A", "-q", "-j", "1", "--resume"},
      "strategy");
  // Trials of another build (a law or only the rounding changed; the
  // version is not bumped for each) are not reused either.
  {
    auto key = nlohmann::json::parse(read_text(work() / "A" / "resume.json"));
    ASSERT_EQ(key.at("program_sha256").get<std::string>().size(), 64u);
    key["program_sha256"] = std::string(64, '0');
    std::ofstream(work() / "A" / "resume.json") << key.dump(2) << "\n";
  }
  expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--resume"}, "program_sha256");
  // Without the record of its settings a folder's trials cannot be reused.
  fs::remove(work() / "A" / "resume.json");
  expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--resume"}, "resume.json");
}

// The config names its particle file, not what it holds: a REV file edited
// under the same name gives other trials, so --resume refuses the earlier
// ones (assembly_file_sha256 in resume.json) and takes them again once the
// file is back as it was; a scaling study, whose REVs are cut from the
// file, too.
TEST_F(RobustCli, ResumeAfterTheParticleFileChangedIsRefused) {
  const fs::path csv = work() / "rev.csv";
  // A hexagonal n x n, not touching; the last disk's radius `last`.
  const auto write_rev = [&](int n, double last) {
    std::ofstream out(csv);
    out << "x,y,r\n";
    const double r = 5e-4, gap = 1.001;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        out << (2 * i + (j % 2)) * r * gap << "," << j * std::sqrt(3.0) * r * gap << ","
            << (i == n - 1 && j == n - 1 ? last : r) << "\n";
  };
  write_rev(5, 5e-4);
  const std::string from_file = R"(assembly={"type": "file", "file": ")" + csv.string() + "\"}";
  const std::vector<std::string> calibrate = {
      "calibrate", kHex5, "--set", from_file, "-o", "F", "-q", "-j", "1", "--max-trials", "12"};
  const auto resumed = [&] {
    std::vector<std::string> args = calibrate;
    args.push_back("--resume");
    return args;
  };
  const Result first = demcal(calibrate);
  ASSERT_EQ(first.status, 0) << first.err;
  ASSERT_TRUE(nlohmann::json::parse(read_text(work() / "F" / "resume.json"))
                  .contains("assembly_file_sha256"));
  write_rev(5, 4.5e-4);
  expect_refused(resumed(), "assembly_file_sha256");
  write_rev(5, 5e-4);
  const Result r = demcal(resumed());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto run = nlohmann::json::parse(read_text(work() / "F" / "run.json"));
  EXPECT_EQ(run["trials_run"].get<int>(), 0);
  EXPECT_GT(run["trials_reused"].get<int>(), 0);

  write_rev(7, 5e-4);
  std::vector<std::string> study = {
      "scaling", kHex5,          "--set", from_file, "--sizes", "16,25,36", "--calibrate-max",
      "25",      "--max-trials", "12",    "-j",      "1",       "-q",       "--work",
      "S",       "-o",           "R"};
  const Result scaled = demcal(study);
  ASSERT_TRUE(scaled.status == 0 || scaled.status == 1) << scaled.err;  // 1: the forward check
  write_rev(7, 4.5e-4);
  study.push_back("--resume");
  expect_refused(study, "family_file_sha256");

  // A generated family reads no file: a prototype file named but not made
  // yet (verify writes one later) keys nothing and stops nothing.
  const Result generated = demcal({"scaling", kHex5, "--set", R"(prototype={"file": "later.csv"})",
                                   "--sizes", "16,25,36", "--calibrate-max", "25", "--max-trials",
                                   "12", "-j", "1", "-q", "--work", "G", "-o", "RG"});
  EXPECT_TRUE(generated.status == 0 || generated.status == 1) << generated.err;
  EXPECT_FALSE(nlohmann::json::parse(read_text(work() / "G" / "resume.json"))
                   .contains("family_file_sha256"));
}

// `demcal scaling --resume` reuses the per-size results of its --work
// folder only when they were made with the same config (and --set),
// --max-trials and build (S/resume.json); a fresh start clears the earlier
// study's sizes, so that a later resume cannot take them for its own.
TEST_F(RobustCli, ScalingResumeWithOtherSettingsIsRefusedAndAFreshStartClearsTheSizes) {
  const std::vector<std::string> study = {
      "scaling", kHex5, "--sizes", "16,25,36", "--calibrate-max", "25", "--max-trials",
      "12",      "-j",  "1",       "-q",       "--work",          "S"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = study;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  fs::create_directories(work() / "S" / "size-99");
  std::ofstream(work() / "S" / "size-99" / "result.json") << "{}\n";  // an earlier study's
  const Result first = demcal(study);
  ASSERT_TRUE(first.status == 0 || first.status == 1) << first.err;  // 1: the forward check
  // Without -o the report goes to demcal-scaling-NAME, as every command's
  // does: not to reports/, which from the repository's root is the shipped
  // study's.
  EXPECT_FALSE(fs::exists(work() / "reports"));
  EXPECT_TRUE(fs::exists(work() / "demcal-scaling-hex_5x5" / "scaling.md"));
  EXPECT_FALSE(fs::exists(work() / "S" / "size-99"));
  ASSERT_TRUE(fs::exists(work() / "S" / "size-25" / "result.json"));
  expect_refused(with({"--resume", "--set", "material.friction=0.5"}), "config_sha256");
  std::vector<std::string> more_trials = study;
  more_trials[7] = "13";  // --max-trials
  more_trials.push_back("--resume");
  expect_refused(more_trials, "max_trials");
  {
    auto key = nlohmann::json::parse(read_text(work() / "S" / "resume.json"));
    key["program_sha256"] = std::string(64, '0');
    std::ofstream(work() / "S" / "resume.json") << key.dump(2) << "\n";
  }
  expect_refused(with({"--resume"}), "program_sha256");
  fs::remove(work() / "S" / "resume.json");
  expect_refused(with({"--resume"}), "resume.json");
}

TEST_F(RobustCli, ResumeWithTheSameSettingsReusesEveryTrial) {
  calibrate_a();
  const Result r =
      demcal({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--max-trials", "12", "--resume"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto run = nlohmann::json::parse(read_text(work() / "A" / "run.json"));
  EXPECT_EQ(run["trials_run"].get<int>(), 0);
  EXPECT_GT(run["trials_reused"].get<int>(), 0);
}

TEST_F(RobustCli, SecondCalibrationIntoALockedFolderIsRefused) {
  calibrate_a();
  // This process holds the lock a running calibration would hold.
  const int fd = ::open((work() / "A").c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1"}, "another demcal command");
  ::close(fd);
}

TEST_F(RobustCli, DamagedTrialLineIsRefusedWithItsNumber) {
  calibrate_a();
  const fs::path trials = work() / "A" / "trials.jsonl";
  std::string text = read_text(trials);
  const size_t second = text.find('\n') + 1;
  text.replace(second, text.find('\n', second) - second, "{\"garbage");
  std::ofstream(trials, std::ios::binary) << text;
  expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--resume"}, "line 2");
}

// The trials.jsonl fuzzer's find: an id of 5.9e110 was a float-to-int cast
// out of range; now the line is refused like any damaged one.
TEST_F(RobustCli, TrialCountThatIsNoWholeNumberIsRefused) {
  calibrate_a();
  const fs::path trials = work() / "A" / "trials.jsonl";
  const std::string text = read_text(trials);
  const size_t end = text.find('\n');
  for (const auto& [key, value] : std::vector<std::pair<std::string, nlohmann::json>>{
           {"id", 5.9e110}, {"id", -1}, {"steps_run", 2.5}, {"steps_run", "7"}}) {
    auto line = nlohmann::json::parse(text.substr(0, end));
    line[key] = value;
    std::ofstream(trials, std::ios::binary) << line.dump() << text.substr(end);
    expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--resume"}, "line 1");
  }
}

// An engine's series.csv: a step or a count of 1e300 went through
// static_cast<int64_t> (undefined behaviour); now the file and the column or
// metadata key are named.
TEST_F(RobustCli, SeriesCountThatIsNoWholeNumberIsRefused) {
  const auto series = [&](const std::string& meta, const std::string& second_step,
                          const std::string& last = "2,-0.02,1,0,0,1,1,0,0,1") {
    std::ofstream(work() / "series.csv")
        << "# lateral_stress = 1e5\n"
        << meta << "step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy\n"
        << "0,0,1,0,0,1,1,0,0,1\n"
        << second_step << ",-0.01,1,0,0,1,1,0,0,1\n"
        << last << "\n";
    return std::vector<std::string>{"score", "series.csv", "-o", "out"};
  };
  for (const char* step : {"1e300", "2.5", "-1"})
    expect_refused(series("", step), "series.csv: line 4: step");
  expect_refused(series("# steps = 1e300\n", "1"), "series.csv: line 2: # steps");
  expect_refused(series("# particles = 1e20\n", "1"), "series.csv: line 2: # particles");
  // The row where the run diverged: its step is read the same way.
  expect_refused(series("", "1", "1e300,nan,1,0,0,1,1,0,0,1"), "series.csv: line 5: step");
  // The same file with whole counts is scored.
  const Result r = demcal(series("# steps = 2\n# particles = 25\n", "1"));
  EXPECT_EQ(r.status, 0) << r.err;
}

// `demcal score` on what is no series file: a device that never ends
// (/dev/zero, /dev/urandom) or a folder is one line, exit 2, as the other
// readers say it (require_readable_file), not an allocation that runs out.
TEST_F(RobustCli, ScoreRefusesADeviceOrAFolder) {
  expect_refused({"score", "/dev/zero", "-o", "out"}, "/dev/zero: is a device node, not a file");
  expect_refused({"score", "/dev/urandom", "-o", "out"},
                 "/dev/urandom: is a device node, not a file");
  fs::create_directories(work() / "folder");
  expect_refused({"score", "folder", "-o", "out"}, "folder: is a folder, not a file");
}

// The series' metadata out of range, given twice, among the rows, and a
// row beyond the steps planned: exit 2 naming the file, the line and the
// key, nothing written; a UTF-8 BOM before the first line is dropped.
TEST_F(RobustCli, ScoreRefusesBadMetadataAndRowsBeyondTheSteps) {
  const std::string table =
      "step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy\n"
      "0,0,1,0,0,1,1,0,0,1\n1,-0.01,1,0,0,1,1,0,0,1\n2,-0.02,1,0,0,1,1,0,0,1\n";
  const auto series = [&](const std::string& text) {
    std::ofstream(work() / "series.csv") << text;
    return std::vector<std::string>{"score", "series.csv", "-o", "out"};
  };
  const std::string head = "# lateral_stress = 1e5\n# steps = 2\n";
  expect_refused(series(head + table + "3,-0.03,1,0,0,1,1,0,0,1\n"),
                 "series.csv: line 7: step 3 is beyond the 2 steps planned");
  expect_refused(series("# lateral_stress = 1e5\n# steps = 0\n" + table),
                 "series.csv: line 2: # steps");
  expect_refused(series(head + "# lateral_stress = 2e5\n" + table),
                 "series.csv: line 3: # lateral_stress: given twice");
  expect_refused(series(head + table + "# lateral_stress = 5e5\n"),
                 "series.csv: line 7: # lateral_stress: after the column header");
  expect_refused(series("# lateral_stress = inf\n" + table),
                 "series.csv: line 1: # lateral_stress");
  expect_refused(series(head + "# dt = -1\n" + table), "series.csv: line 3: # dt: must be > 0");
  expect_refused(series(head + "# mass_scaling = 0\n" + table),
                 "series.csv: line 3: # mass_scaling: must be > 0");
  expect_refused(series(head + "# reference_peak = 0\n" + table),
                 "series.csv: line 3: # reference_peak");
  // With a BOM before its first line the file scores as without.
  const Result r = demcal(series("\xEF\xBB\xBF" + head + table));
  EXPECT_EQ(r.status, 0) << r.err;
  // demcal's own series at a sigma3 above --lateral-stress's cap (a config
  // bounds sigma3 by its stiffness only) is scored, not refused.
  const Result run =
      demcal({"run", kHex5, "--set", "material.kn=2e15", "--set", "material.kt=1e15", "--set",
              "material.wall.kn=2e15", "--set", "material.wall.kt=1e15", "--set",
              "test.lateral_stress=2e12", "--set", "algorithm.steps=4000", "-o", "stiff"});
  ASSERT_TRUE(run.status == 0 || run.status == 1) << run.err;
  const Result own = demcal({"score", "stiff/series.csv", "-o", "stiff-score"});
  EXPECT_TRUE(own.status == 0 || own.status == 1) << own.err;
}

TEST_F(RobustCli, CutLastTrialLineIsRepaired) {
  calibrate_a();
  const fs::path trials = work() / "A" / "trials.jsonl";
  const std::string whole = read_text(trials);
  std::ofstream(trials, std::ios::binary | std::ios::app) << "{\"id\": 9";
  const Result r =
      demcal({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--max-trials", "12", "--resume"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_text(trials), whole);  // the cut line gone, no trial rerun
}

TEST_F(RobustCli, TrialsFileThatIsAFolderIsOneLine) {
  calibrate_a();
  fs::remove(work() / "A" / "trials.jsonl");
  fs::create_directory(work() / "A" / "trials.jsonl");
  expect_refused({"calibrate", kHex5, "-o", "A", "-q", "-j", "1", "--resume"}, "is a folder");
}

// params.json is checked like a config: file and key named, exit 2.
TEST_F(RobustCli, ParamsFileIsValidated) {
  calibrate_a();
  const auto good = nlohmann::json::parse(read_text(work() / "A" / "params.json"));
  auto write_params = [&](const std::string& text) {
    std::ofstream(dir_ / "bad.json", std::ios::binary) << text;
    return (dir_ / "bad.json").string();
  };
  auto with = [&](const nlohmann::json::json_pointer& at, const nlohmann::json& v) {
    nlohmann::json j = good;
    j[at] = v;
    return write_params(j.dump());
  };
  using ptr = nlohmann::json::json_pointer;
  for (const std::string cmd : {"upscale", "export"}) {
    expect_refused({cmd, with(ptr("/rev/dt_crit"), -1e-6), "--particles", "100"}, "rev.dt_crit");
    expect_refused({cmd, with(ptr("/rev/particles"), 1e300), "--particles", "100"},
                   "rev.particles");
    expect_refused({cmd, with(ptr("/schema"), "other.tool/7"), "--particles", "100"}, "schema");
    expect_refused({cmd, with(ptr("/version"), nlohmann::json::array()), "--particles", "100"},
                   "version");
    std::string text = good.dump();
    text.insert(1, "\"huge\": 1e999, ");
    expect_refused({cmd, write_params(text), "--particles", "100"}, "bad.json");
    // Counts are read as whole numbers: 5.9e110 through get<int64_t>() was a
    // float-to-int cast out of range (undefined behaviour), 2.5 particles
    // and a dimension of 2^32 + 2 (read as an int: 2) passed.
    for (const nlohmann::json& v :
         {nlohmann::json(5.9e110), nlohmann::json(-3), nlohmann::json(2.5), nlohmann::json("7")})
      expect_refused({cmd, with(ptr("/prototype/particles"), v), "--particles", "100"},
                     "bad.json: prototype.particles");
    for (const nlohmann::json& v : {nlohmann::json(5.9e110), nlohmann::json(4294967298u)})
      expect_refused({cmd, with(ptr("/dimension"), v), "--particles", "100"},
                     "bad.json: dimension");
  }
  // A scaling.json's dimension is read the same way.
  const std::string params = (work() / "A" / "params.json").string();
  for (const char* dimension : {"5.9e110", "4294967298", "2.5"}) {
    std::ofstream(dir_ / "law.json")
        << R"({"law": {"exponent": 1.0}, "dimension": )" << dimension << "}";
    expect_refused({"upscale", params, "--particles", "100", "--law", (dir_ / "law.json").string()},
                   "law.json: dimension");
  }
  // The good file passes the same reader.
  const Result r =
      demcal({"upscale", (work() / "A" / "params.json").string(), "--particles", "100"});
  EXPECT_EQ(r.status, 0) << r.err;
}

}  // namespace

namespace {

// A rev that fails after its checks (a REV larger than the prototype)
// leaves no empty output folder behind.
TEST_F(RobustCli, FailedRevLeavesNoFolder) {
  const Result r = demcal(
      {"rev", kHex5, "--set", "prototype.particles=100", "--particles", "1000", "-o", "out"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("prototype has only 100"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(work() / "out"));
}

// A random gas at another count than the config's never went through the
// config's check of assembly.count and assembly.aspect: `rev
// random_500_3d.json --particles 6 --method generate` consolidated the
// 20000-sphere prototype and then a 6-sphere gas for minutes, and a
// prototype.particles of 6 was generated and consolidated as well. Each
// is refused before any consolidation, in the config check's words
// (gas_layers_fault), naming what gave the count: --particles, or
// prototype.particles (here the --set that gave it).
TEST_F(RobustCli, AGasAtACountThatNeverConsolidatesIsRefusedBeforeAnyWork) {
  const std::string random_3d = demcal::test::shipped_config("random_500_3d");
  const std::string random_2d = demcal::test::shipped_config("random_400");
  // A prototype one row of 20 disks: its box 20 times as wide as high.
  std::string row = "x,y,r\n";
  for (int i = 0; i < 20; ++i) row += std::to_string((2 * i + 1) * 5e-4) + ",5e-4,5e-4\n";
  const std::string strip = demcal::test::write_text(dir_ / "strip.csv", row);
  const std::string too_few_spheres =
      "too few spheres for a random gas with 2 layers along every side and 3 spheres across: at "
      "least 10; got 6";
  struct Case {
    std::vector<std::string> args;
    std::string mention;
  };
  const Case cases[] = {
      {{"rev", random_3d, "--particles", "6", "--method", "generate", "-o", "out"},
       "--particles: a REV generated as a gas of 6 spheres: " + too_few_spheres},
      {{"rev", random_3d, "--set", "assembly.aspect=8", "--particles", "100", "--method",
        "generate", "-o", "out"},
       "--particles: a REV generated as a gas of 100 spheres: the count gives a gas of 10 x 10 "
       "cells across and 1 layers of 100 spheres"},
      {{"rev", random_2d, "--prototype", strip, "--particles", "10", "--method", "generate", "-o",
        "out"},
       "--particles: a REV generated as a gas of 10 disks: the count gives a gas of 10 columns and "
       "1 rows of 10 disks"},
      {{"rev", random_2d, "--particles", "2", "--method", "generate", "-o", "out"},
       "--particles: a REV generated as a gas of 2 disks: too few disks for a random gas with 2 "
       "layers along every side: at least 3; got 2"},
      {{"check", random_3d, "--set", "prototype.particles=6"},
       "--set prototype.particles=6: prototype.particles: a prototype generated as a gas of 6 "
       "spheres: " +
           too_few_spheres},
      {{"check", random_2d, "--set", "prototype.particles=2"},
       "prototype.particles: a prototype generated as a gas of 2 disks: too few disks for a "
       "random gas with 2 layers along every side: at least 3; got 2"},
      {{"check", random_2d, "--set", "assembly.aspect=0.01", "--set", "prototype.particles=40"},
       "prototype.particles: a prototype generated as a gas of 40 disks: the count gives a gas of "
       "1 columns and 40 rows of 40 disks: a sample needs at least 2 along every side (a gas one "
       "particle thick never comes to a static state between the servo walls); at "
       "assembly.aspect 0.01 the nearest count that gives a sample is 101 (or assembly.aspect "
       "above 0.025 "
       "and up to about 38.025 for count 40); got 40"},
  };
  for (const Case& c : cases) expect_refused(c.args, c.mention);
  // verify's and export's count from a params.json's prototype block is
  // that file's prototype.particles: it was named "--particles", a flag
  // nobody gave. (The example calibration on random_400's scene, its
  // prototype 2 disks.)
  nlohmann::json params =
      nlohmann::json::parse(read_text(demcal::test::example_params("hex_10x10")));
  params["config"] = nlohmann::json::parse(read_text(random_2d));
  params["prototype"]["particles"] = 2;
  const std::string two = demcal::test::write_text(dir_ / "params.json", params.dump());
  const std::string from_params = two +
                                  ": prototype.particles: a prototype generated as a gas "
                                  "of 2 disks: too few disks for a random gas";
  expect_refused({"verify", two, "-o", "out"}, from_params);
  expect_refused({"export", two, "-o", "out/deck.lammps"}, from_params);
  // --particles given: named so, as before.
  expect_refused({"verify", two, "--particles", "2", "-o", "out"},
                 "--particles: a prototype generated as a gas of 2 disks");
}

// A bad value given by --set is named as the --set's, not the config
// file's (the file is fine); a check across keys still names the file.
TEST_F(RobustCli, ABadSetValueIsNamedAsTheSets) {
  expect_refused({"check", kHex5, "--set", "algorithm.dt_ratio=-1"},
                 "--set algorithm.dt_ratio=-1: algorithm.dt_ratio: must be > 0");
  expect_refused({"check", kHex5, "--set", "algorithm.nosuch=1"},
                 "--set algorithm.nosuch=1: algorithm.nosuch: unknown key");
  const Result r = demcal({"check", kHex5, "--set", "algorithm.dt_ratio=-1"});
  EXPECT_EQ(r.err.find("hex_5x5.json"), std::string::npos) << r.err;
}

}  // namespace
