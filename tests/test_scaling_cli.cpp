// `demcal scaling` on the command line: a plan of sizes without a forward
// size, or with a size twice, is a usage error before any work; the per-size
// work goes to the -o folder unless --work says otherwise; a second study on
// a work folder in use is refused; SIGINT stops the study cleanly (finished
// sizes and trials kept, the resume command shown) and --resume ends with
// the uninterrupted study's scaling.json.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/process.hpp"
#include "support/without_timing.hpp"

namespace {

namespace fs = std::filesystem;

using Result = demcal::test::RunResult;
using demcal::test::read_text;

const std::string kHex5 = demcal::test::shipped_config("hex_5x5");

/// The lines of a trials.jsonl, each parsed; a cut last line left out.
std::vector<nlohmann::json> read_trials(const fs::path& path) {
  std::vector<nlohmann::json> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    try {
      out.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::exception&) {
    }
  }
  return out;
}

using ::demcal::test::without_timing;

class ScalingCli : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(work()); }
  fs::path work() const { return dir_ / "work"; }

  Result demcal(const std::vector<std::string>& args) {
    return ::demcal::test::run_demcal(args, work());
  }

  /// `demcal ARGS` refused as a usage error of --sizes: exit 2, one line
  /// that mentions `mention`, nothing on stdout, nothing left in work().
  void expect_sizes_refused(const std::vector<std::string>& args, const std::string& mention) {
    std::string trace = "demcal";
    for (const auto& a : args) trace += " " + a;
    SCOPED_TRACE(trace);
    const Result r = demcal(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("demcal: error: --sizes: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(fs::is_empty(work())) << "left output behind";
  }

  /// `demcal ARGS` started in work(), stdout and stderr to files beside it.
  pid_t spawn(const std::vector<std::string>& args) {
    std::vector<std::string> all{demcal::test::kDemcalBinary};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    // Everything the child needs is made before the fork (a threaded
    // parent's child may only make async-signal-safe calls until exec).
    const std::string cwd = work().string(), out = (dir_ / "out.txt").string(),
                      err = (dir_ / "err.txt").string();
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (o < 0 || e < 0 || ::dup2(o, STDOUT_FILENO) < 0 || ::dup2(e, STDERR_FILENO) < 0 ||
          ::chdir(cwd.c_str()) != 0)
        ::_exit(127);
      ::execv(demcal::test::kDemcalBinary, argv.data());
      ::_exit(127);
    }
    return pid;
  }
  std::string spawned_err() const { return read_text(dir_ / "err.txt"); }

  const demcal::test::TempDir tmp_{"scaling_cli"};
  const fs::path dir_ = tmp_.path();
};

// Every size up to --calibrate-max: nothing would check the law forward,
// and the study printed "FAILED" for a check it never ran. A size given
// twice is a typo, not a plan. Both are usage errors (exit 2, one line
// naming --sizes) before any folder is made.
TEST_F(ScalingCli, SizesWithoutAForwardSizeOrRepeatedAreUsageErrors) {
  struct Case {
    std::vector<std::string> args;
    std::string mention;
  };
  const std::vector<Case> cases = {
      {{"--sizes", "25,100"}, "the forward check needs a size above --calibrate-max (400)"},
      {{"--sizes", "9,16,25", "--calibrate-max", "25"},
       "the forward check needs a size above --calibrate-max (25)"},
      {{"--sizes", "25,25,100,800"}, "25 given twice"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"scaling", kHex5, "-o", "out", "-q", "-j", "1"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    expect_sizes_refused(args, c.mention);
  }
}

// Sizes that make one particle count passed: the FCC generator makes whole
// cells, so `--sizes 256,300,864 --calibrate-max 300` calibrated the
// 256-sphere sample twice (fit "linear Nstep = 0·N + 0", exit 0), and
// `--sizes 108,256,300 --calibrate-max 256` "checked forward" the REV's own
// sample (exponent 0, `--exponent 0` suggested). Hexagonal lattices round
// too (5x5: 26 makes 25), and so do REVs cut from a lattice file (whole
// rings of particles). Refused before any work (exit 2, one line naming
// --sizes and the counts), from the counts the generator makes without
// consolidating.
//
// A random family's sizes are gases at the config's aspect, which the
// config's check of assembly.count never saw: random_500_3d `--sizes
// 5,9,40 --calibrate-max 9` ran 5- and 9-sphere gases that never come to
// rest and printed a negative slope and "worst 0x tol", exit 0. A size
// that gives too few particles, or at the config's aspect one layer or (3D)
// 2 spheres across, is refused in the config check's words, naming --sizes
// and the size.
TEST_F(ScalingCli, SizesThatMakeOneCountOrNoSampleAreUsageErrors) {
  // A 10x10 square lattice in a file: windows centred on it hold 4, 16,
  // 36, ... particles (5 and 6 both cut 4).
  std::string csv = "x,y,r\n";
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      csv +=
          std::to_string((2 * i + 1) * 5e-4) + "," + std::to_string((2 * j + 1) * 5e-4) + ",5e-4\n";
  demcal::test::write_text(dir_ / "lattice.csv", csv);
  const std::string file_config = demcal::test::write_text(
      dir_ / "lattice.json",
      R"({"material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3},)"
      R"( "assembly": {"type": "file", "file": "lattice.csv"}})");
  const std::string fcc = demcal::test::shipped_config("fcc_4x4x4");
  const std::string random_3d = demcal::test::shipped_config("random_500_3d");
  const std::string random_2d = demcal::test::shipped_config("random_400");
  struct Case {
    std::vector<std::string> args;
    std::string mention;
  };
  const std::vector<Case> cases = {
      {{fcc, "--sizes", "256,300,864", "--calibrate-max", "300"},
       "--sizes: 256 and 300 both make 256 spheres (an FCC lattice of whole cells): each size "
       "must make a count of its own"},
      {{fcc, "--sizes", "108,256,300", "--calibrate-max", "256"},
       "--sizes: 256 and 300 both make 256 spheres (an FCC lattice of whole cells): the forward "
       "size must make more than the REV"},
      {{kHex5, "--sizes", "25,26,36", "--calibrate-max", "26"},
       "--sizes: 25 and 26 both make 25 particles (a hexagonal lattice of whole columns and "
       "rows)"},
      {{file_config, "--sizes", "5,6,50", "--calibrate-max", "6"},
       "--sizes: 5 and 6 both make 4 particles (REVs cut from"},
      {{random_3d, "--sizes", "5,9,40", "--calibrate-max", "9"},
       "--sizes: size 5: too few spheres for a random gas with 2 layers along every side and 3 "
       "spheres across: at least 10; got 5"},
      {{random_3d, "--set", "assembly.aspect=8", "--sizes", "100,500,2000", "--calibrate-max",
        "500"},
       "--sizes: size 100: the count gives a gas of 10 x 10 cells across and 1 layers of 100 "
       "spheres: a sample needs at least 2 along every side and 3 spheres across"},
      {{random_3d, "--set", "assembly.aspect=8", "--sizes", "100,500,2000", "--calibrate-max",
        "500"},
       "; at assembly.aspect 8 the nearest counts that give a sample are 91 and 101 (or "
       "assembly.aspect "
       "above 0.08 and up to about 7.29 for count 100); got 100"},
      {{random_2d, "--set", "assembly.aspect=0.01", "--sizes", "40,100,400", "--calibrate-max",
        "100"},
       "--sizes: size 40: the count gives a gas of 1 columns and 40 rows of 40 disks: a sample "
       "needs at least 2 along every side (a gas one particle thick"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"scaling", "-o", "out", "-q", "-j", "1"};
    args.insert(args.begin() + 1, c.args.begin(), c.args.end());
    expect_sizes_refused(args, c.mention);
  }
}

// A size's assembly is built when the study comes to it, and its errors
// said "the scene's": the sigma3 round-off bound (positions up to the
// size's extent) said "for the scene's assembly" of a 400-disk or
// 2048-sphere size whose config holds 25 or 256. Now they name the size.
// hex_5x5 at sigma3 1e-3 Pa and fcc_4x4x4 at 1 Pa pass the bound at the
// config's size and fail it at the study's first.
//
// And a size was refused only when the study came to it: after resume.json
// and the smaller sizes' folders and calibrations were written (hex_5x5 at
// 4e-3 Pa passes the bound at 400 and 900 disks, not at 3600; fcc_4x4x4 at
// 2 Pa at 2048 spheres, not at 16384). REVs cut from a particle file were
// never checked at all: they keep the file's positions, and a lattice at
// x ~ 1e6 m ran. Every size's assembly is now built and checked before any
// folder is made (exit 2, nothing written), a cut naming the file.
TEST_F(ScalingCli, ASizesAssemblyErrorNamesTheSize) {
  const std::string fcc = demcal::test::shipped_config("fcc_4x4x4");
  // A 10x10 square lattice of touching disks at x ~ 1e6 m (the round-off
  // of its positions, 1.1e-10 m, above a tenth of the tolerance of the
  // 1e-6 m overlap at sigma3).
  std::string csv = "x,y,r\n";
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      csv += "1000000.00" + std::to_string(i) + ",0.00" + std::to_string(j) + ",0.0005\n";
  const std::string far = demcal::test::write_text(dir_ / "far.csv", csv);
  const std::string far_config = demcal::test::write_text(
      dir_ / "far.json", R"({"material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3},)"
                         R"( "assembly": {"type": "file", "file": "far.csv"}})");
  struct Case {
    std::vector<std::string> args;
    std::string mention;
  };
  const std::vector<Case> cases = {
      {{kHex5, "--set", "test.lateral_stress=1e-3", "--sizes", "400,900,3600", "--calibrate-max",
        "900", "-o", "hex"},
       " Pa for size 400's assembly (400 particles)"},
      {{fcc, "--set", "test.lateral_stress=1", "--sizes", "2048,4000,16384", "--calibrate-max",
        "4000", "-o", "fcc"},
       " Pa for size 2048's assembly (2048 spheres)"},
      {{kHex5, "--set", "test.lateral_stress=4e-3", "--sizes", "400,900,3600", "--calibrate-max",
        "900", "-o", "hex"},
       " Pa for size 3600's assembly (3600 particles)"},
      {{fcc, "--set", "test.lateral_stress=2", "--sizes", "2048,4000,16384", "--calibrate-max",
        "4000", "-o", "fcc"},
       " Pa for size 16384's assembly (16384 spheres)"},
      {{far_config, "--sizes", "16,36,64", "--calibrate-max", "36", "-o", "far"},
       " Pa for size 16's assembly (16 particles, from " + far + "), or material.kn"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"scaling", "-q", "-j", "1"};
    args.insert(args.begin() + 1, c.args.begin(), c.args.end());
    SCOPED_TRACE(c.mention);
    const Result r = demcal(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("test.lateral_stress: the overlap at sigma3"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(fs::is_empty(work())) << "left output behind";
  }
}

// Without --work the per-size work goes to the -o folder (README: "default
// the same folder"): two studies of one scene with different -o do not
// share, and a fresh start of one leaves the other's sizes alone.
TEST_F(ScalingCli, WorkDefaultsToTheOutputFolder) {
  const std::vector<std::string> study = {
      "scaling", kHex5, "--sizes",      "16,25,36", "--calibrate-max", "25", "-q",
      "-j",      "1",   "--max-trials", "12"};
  const auto into = [&](const std::string& out) {
    std::vector<std::string> args = study;
    args.insert(args.end(), {"-o", out});
    return args;
  };
  const Result a = demcal(into("A"));
  ASSERT_TRUE(a.status == 0 || a.status == 1) << a.err;  // 1: the forward check
  for (const char* f : {"scaling.json", "scaling.md", "resume.json", "size-16/result.json",
                        "size-25/result.json", "size-36/fixed.json"})
    EXPECT_TRUE(fs::exists(work() / "A" / f)) << f;
  EXPECT_FALSE(fs::exists(work() / "demcal-scaling-hex_5x5"));
  const std::string a_result = read_text(work() / "A" / "size-16" / "result.json");
  const Result b = demcal(into("B"));
  ASSERT_TRUE(b.status == 0 || b.status == 1) << b.err;
  EXPECT_TRUE(fs::exists(work() / "B" / "size-16" / "result.json"));
  EXPECT_EQ(read_text(work() / "A" / "size-16" / "result.json"), a_result);
  // The report in one folder, the work in another, as before.
  const Result c = demcal([&] {
    std::vector<std::string> args = into("C");
    args.insert(args.end(), {"--work", "W"});
    return args;
  }());
  ASSERT_TRUE(c.status == 0 || c.status == 1) << c.err;
  EXPECT_TRUE(fs::exists(work() / "C" / "scaling.json"));
  EXPECT_FALSE(fs::exists(work() / "C" / "resume.json"));
  EXPECT_TRUE(fs::exists(work() / "W" / "size-16" / "result.json"));
}

// A study begun when --work defaulted to demcal-scaling-NAME whatever -o
// said: --resume with that -o points there (exit 2, nothing made) rather
// than start afresh in the -o folder.
TEST_F(ScalingCli, ResumeOfAStudyWhoseWorkIsInTheOldDefaultFolderSaysWhere) {
  demcal::test::write_text(work() / "demcal-scaling-hex_5x5" / "resume.json", "{}\n");
  const Result r = demcal({"scaling", kHex5, "--sizes", "16,25,36", "--calibrate-max", "25", "-q",
                           "-o", "X", "--resume"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("add --work demcal-scaling-hex_5x5"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(work() / "X"));
}

/// Path → content of every file under `dir` (folders as "<dir>").
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    out[fs::relative(e.path(), dir).string()] =
        e.is_regular_file() ? read_text(e.path()) : std::string("<dir>");
  return out;
}

// Two studies on one work folder at once interleaved their sizes' files
// (the second's fresh start even cleared the first's). The study holds an
// exclusive lock on its work folder (calibrate's FolderLock): a second one,
// whatever its -o or --resume, is refused before it reads or writes
// anything (exit 2, one line naming the folder). A study killed outright
// leaves no lock behind: --resume continues it.
TEST_F(ScalingCli, ASecondStudyOnALockedWorkFolderIsRefusedAndAKilledOneLeavesNoLock) {
  const std::vector<std::string> study = {
      "scaling", kHex5, "--sizes",      "16,100,144", "--calibrate-max", "100", "-q",
      "-j",      "1",   "--max-trials", "12"};
  const auto with = [&](const std::vector<std::string>& more) {
    std::vector<std::string> args = study;
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  const pid_t pid = spawn(with({"-o", "A"}));
  const fs::path trials = work() / "A" / "size-16" / "trials.jsonl";
  bool running = false;
  for (int k = 0; k < 12000 && !running; ++k) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) break;
    running = fs::exists(trials) && !read_trials(trials).empty();
    if (!running) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(running) << "the study ended before the second began: " << spawned_err();
  for (const auto& more : std::vector<std::vector<std::string>>{
           {"-o", "A"}, {"-o", "A", "--resume"}, {"-o", "B", "--work", "A"}}) {
    const std::vector<std::string> args = with(more);
    std::string trace = "demcal";
    for (const auto& a : args) trace += " " + a;
    SCOPED_TRACE(trace);
    const Result r = demcal(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(
        r.err.rfind("demcal: error: A: another demcal command is writing into this folder", 0), 0u)
        << r.err;
    EXPECT_NE(r.err.find("give another --work"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(work() / "B"));
  }
  ::kill(pid, SIGKILL);
  EXPECT_EQ(demcal::test::wait_exit(pid), -1);
  EXPECT_TRUE(fs::exists(work() / "A" / "resume.json"));

  // The kill dropped the lock with the process.
  const Result resumed = demcal(with({"-o", "A", "--resume"}));
  EXPECT_TRUE(resumed.status == 0 || resumed.status == 1) << resumed.err;
  EXPECT_TRUE(fs::exists(work() / "A" / "scaling.json"));
}

// While a study holds the lock, the refused one changes nothing in the
// work folder, also under --resume (which would otherwise read it) and
// with another -o (which would otherwise be made).
TEST_F(ScalingCli, ARefusedStudyWritesNothing) {
  demcal::test::write_text(work() / "W" / "resume.json", "{}\n");
  demcal::test::write_text(work() / "W" / "size-16" / "result.json", "{}\n");
  const int fd = ::open((work() / "W").c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // as a running study holds it
  const auto before = snapshot(work());
  for (const auto& more : std::vector<std::vector<std::string>>{
           {"-o", "W"}, {"-o", "W", "--resume"}, {"-o", "B", "--work", "W"}}) {
    std::vector<std::string> args = {"scaling", kHex5, "--sizes", "16,25,36", "--calibrate-max",
                                     "25",      "-q",  "-j",      "1"};
    args.insert(args.end(), more.begin(), more.end());
    const Result r = demcal(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("W: another demcal command"), std::string::npos) << r.err;
    EXPECT_EQ(snapshot(work()), before);
  }
  ::close(fd);
}

// A size's consolidation read from the consolidation cache was recorded in
// scaling.json as if consolidated (consolidation_wall_time_s, the reading's,
// unlabelled), and the log said "consolidating" before the read: each size
// now records consolidation_json's record flat (consolidation_steps,
// consolidation_wall_time_s, consolidation_from_cache), a cache read's log
// line says so, and the study is otherwise the same (wall times apart).
TEST_F(ScalingCli, AConsolidationFromTheCacheIsLabelledInScalingJson) {
  const std::string cache = "DEMCAL_CACHE_DIR=" + (dir_ / "cache").string();
  auto study = [&](const std::string& out) {
    const Result r = demcal::test::run_program(
        "/usr/bin/env",
        {cache, demcal::test::kDemcalBinary, "scaling", kHex5, "--sizes", "16,25,36",
         "--calibrate-max", "25", "-j", "1", "--max-trials", "12", "-o", out},
        work());
    EXPECT_TRUE(r.status == 0 || r.status == 1) << r.err;  // 1: the forward check
    return r;
  };
  const Result miss = study("miss");
  const Result hit = study("hit");
  nlohmann::json fresh = demcal::test::read_json(work() / "miss" / "scaling.json");
  nlohmann::json read = demcal::test::read_json(work() / "hit" / "scaling.json");
  ASSERT_EQ(fresh.at("results").size(), 3u);
  ASSERT_EQ(read.at("results").size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    nlohmann::json& f = fresh["results"][i];
    nlohmann::json& r = read["results"][i];
    SCOPED_TRACE(f.at("requested").dump());
    ASSERT_TRUE(f.contains("consolidation_from_cache")) << f.dump(1);
    ASSERT_TRUE(r.contains("consolidation_from_cache")) << r.dump(1);
    // Every size records its consolidation: the calibrated ones (16, 25)
    // their calibration's, the forward size (36) its step search's (it
    // recorded none, 0 steps and 0 s, and from_cache false on a cache read).
    EXPECT_EQ(f.at("calibrated").get<bool>(), i < 2);
    EXPECT_FALSE(f["consolidation_from_cache"].get<bool>());
    EXPECT_TRUE(r["consolidation_from_cache"].get<bool>());
    EXPECT_GT(f.at("consolidation_steps").get<int64_t>(), 0);
    EXPECT_GT(f.at("consolidation_wall_time_s").get<double>(), 0.0);
    EXPECT_EQ(r.at("consolidation_steps"), f.at("consolidation_steps"));
    EXPECT_TRUE(r.contains("consolidation_wall_time_s"));
    f.erase("consolidation_from_cache");
    r.erase("consolidation_from_cache");
  }
  EXPECT_EQ(without_timing(read), without_timing(fresh));
  // stderr: a fresh size's "consolidating ..." and "  consolidated in N
  // steps, T s"; a read one's "size 16: consolidated in N steps, read from
  // the cache in T s", no "consolidating".
  EXPECT_NE(miss.err.find("demcal scaling: consolidating 16 particles (size 16)\n"),
            std::string::npos)
      << miss.err;
  EXPECT_EQ(miss.err.find("cache"), std::string::npos) << miss.err;
  EXPECT_EQ(hit.err.find("consolidating"), std::string::npos) << hit.err;
  const std::string steps =
      std::to_string(fresh["results"][0]["consolidation_steps"].get<int64_t>());
  EXPECT_NE(hit.err.find("demcal scaling: size 16: consolidated in " + steps +
                         " steps, read from the cache in "),
            std::string::npos)
      << hit.err;
}

// SIGINT during a size's calibration: exit 130, the sizes finished before
// kept, the size's finished trials kept, no scaling.json, the resume command
// on stderr. --resume reruns no finished trial and writes the uninterrupted
// study's scaling.json (wall times apart).
TEST_F(ScalingCli, SigintStopsCleanlyAndResumeEndsAsAnUninterruptedStudy) {
  const std::vector<std::string> study = {
      "scaling", kHex5, "--sizes",      "16,100,144", "--calibrate-max", "100", "-q",
      "-j",      "1",   "--max-trials", "12"};
  // Report and work in one folder, named (not left to the default: this
  // test is about the stop alone).
  const auto into = [&](const std::string& out) {
    std::vector<std::string> args = study;
    args.insert(args.end(), {"-o", out, "--work", out});
    return args;
  };
  const Result reference = demcal(into("R"));
  ASSERT_TRUE(reference.status == 0 || reference.status == 1) << reference.err;

  const pid_t pid = spawn(into("S"));
  const fs::path trials = work() / "S" / "size-100" / "trials.jsonl";
  bool seen = false;
  for (int k = 0; k < 12000 && !seen; ++k) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) break;
    seen = fs::exists(trials) && read_trials(trials).size() >= 2;
    if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(seen) << "the study ended before the signal: " << spawned_err();
  ::kill(pid, SIGINT);
  EXPECT_EQ(demcal::test::wait_exit(pid), 130) << spawned_err();
  const std::string err = spawned_err();
  EXPECT_NE(err.find("interrupted"), std::string::npos) << err;
  EXPECT_NE(err.find("Continue with:\n  demcal scaling " + kHex5 +
                     " --sizes 16,100,144 --calibrate-max 100 --max-trials 12 -o S --work S "
                     "--resume\n"),
            std::string::npos)
      << err;
  EXPECT_TRUE(fs::exists(work() / "S" / "size-16" / "result.json"));
  EXPECT_FALSE(fs::exists(work() / "S" / "size-100" / "result.json"));
  EXPECT_FALSE(fs::exists(work() / "S" / "scaling.json"));
  EXPECT_FALSE(fs::exists(work() / "S" / "scaling.md"));
  std::vector<nlohmann::json> kept = read_trials(trials);
  ASSERT_GE(kept.size(), 2u);

  std::vector<std::string> resume = into("S");
  resume.push_back("--resume");
  const Result resumed = demcal(resume);
  ASSERT_EQ(resumed.status, reference.status) << resumed.err;
  // The trials finished before the stop were reused, not rerun: the size's
  // file begins with them.
  std::vector<nlohmann::json> all = read_trials(trials);
  ASSERT_GE(all.size(), kept.size());
  for (size_t i = 0; i < kept.size(); ++i)
    EXPECT_EQ(without_timing(all[i]), without_timing(kept[i])) << "line " << i + 1;
  EXPECT_EQ(without_timing(demcal::test::read_json(work() / "S" / "scaling.json")),
            without_timing(demcal::test::read_json(work() / "R" / "scaling.json")));
}

}  // namespace
