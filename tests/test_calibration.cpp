// Calibration: the search, its cache and trials.jsonl, resume after a kill,
// determinism whatever --jobs, and diverged trials scored, never fatal.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "demcal/biaxial.hpp"
#include "demcal/calibration.hpp"
#include "demcal/packing.hpp"

namespace fs = std::filesystem;
using namespace demcal;

namespace {

fs::path fresh_dir(const std::string& name) {
  fs::path dir =
      fs::temp_directory_path() / ("demcal_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

/// Start `demcal calibrate` on a config ("" = the embedded default, a
/// 10x10 hexagonal REV); returns the pid.
pid_t spawn_calibrate(const fs::path& out, bool resume, const std::string& jobs = "2",
                      const std::string& config = DEMCAL_SOURCE_DIR "/configs/hex_5x5.json") {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<std::string> args{DEMCAL_BINARY, "calibrate", "-q", "-o",
                                  out.string(),  "--jobs",    jobs};
    if (!config.empty()) args.push_back(config);
    if (resume) args.push_back("--resume");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(DEMCAL_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

/// params.json without the one key that measures the machine, not the result.
nlohmann::json comparable(nlohmann::json j) {
  j.erase("wall_time_s");
  return j;
}

std::vector<nlohmann::json> read_trials(const fs::path& p) {
  std::vector<nlohmann::json> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    try {
      out.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::parse_error&) {
      break;  // a line cut by SIGKILL; resume drops it
    }
  }
  return out;
}

}  // namespace

TEST(Calibration, DivergedTrialIsScoredNotFatal) {
  SceneConfig config = default_config();
  config.assembly.columns = config.assembly.rows = 5;
  const ConsolidatedState state = consolidate(config, make_assembly(config));
  AlgorithmSpec p = config.algorithm;
  p.dt_ratio = 1.2;  // far beyond the stable step (α ≈ 0.29 here)
  p.damping_ratio_translation = 0.0;
  p.damping_ratio_rotation = 0.0;
  p.steps = 20000;
  const TrialRecord r = run_trial(config, state, p, Tolerances{});
  EXPECT_TRUE(r.diverged);
  EXPECT_FALSE(r.passed);
  EXPECT_LT(r.steps_run, p.steps);
}

TEST(Calibration, DefaultSceneCalibratesAndIsCertified) {
  const fs::path out = fresh_dir("cal_plain");
  ASSERT_EQ(wait_exit(spawn_calibrate(out, false, "2", "")), 0);
  const auto params = read_json(out / "params.json");
  EXPECT_TRUE(params["success"].get<bool>());
  EXPECT_TRUE(params["certificate"]["passed"].get<bool>());
  EXPECT_LE(params["certificate"]["richardson_error"].get<double>(), 0.02);
  // Never beyond the stable step estimated from the stiffnesses.
  EXPECT_LE(params["rev"]["dt_ratio"].get<double>(), params["dt_ratio_stable"].get<double>());
  // Every finished trial is in trials.jsonl, once.
  const auto trials = read_trials(out / "trials.jsonl");
  EXPECT_EQ(static_cast<int>(trials.size()), params["trials"].get<int>());
  std::set<std::string> keys;
  for (const auto& t : trials) EXPECT_TRUE(keys.insert(t["params"].dump()).second);
  fs::remove_all(out);
}

TEST(Calibration, SameResultWithAnyJobs) {
  const fs::path a = fresh_dir("cal_j1"), b = fresh_dir("cal_j2");
  ASSERT_EQ(wait_exit(spawn_calibrate(a, false, "1")), 0);
  ASSERT_EQ(wait_exit(spawn_calibrate(b, false, "2")), 0);
  EXPECT_EQ(comparable(read_json(a / "params.json")), comparable(read_json(b / "params.json")));
  fs::remove_all(a);
  fs::remove_all(b);
}

// Kill a calibration with SIGKILL at random moments, resume each time: no
// finished trial is rerun, and the result equals an uninterrupted run's.
TEST(Calibration, ResumeAfterSigkillEqualsUninterrupted) {
  const fs::path reference = fresh_dir("cal_ref"), killed = fresh_dir("cal_killed");
  ASSERT_EQ(wait_exit(spawn_calibrate(reference, false)), 0);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> delay_ms(200, 1200);
  bool resume = false;
  size_t trials_before = 0;
  for (int k = 0; k < 3; ++k) {
    const pid_t pid = spawn_calibrate(killed, resume);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    kill(pid, SIGKILL);
    wait_exit(pid);
    if (fs::exists(killed / "trials.jsonl")) {
      resume = true;
      trials_before = read_trials(killed / "trials.jsonl").size();
    }
  }
  ASSERT_TRUE(resume) << "no trial finished before the kills";
  ASSERT_EQ(wait_exit(spawn_calibrate(killed, true)), 0);
  const auto trials = read_trials(killed / "trials.jsonl");
  EXPECT_GE(trials.size(), trials_before);
  // No parameter set was run twice.
  std::set<std::string> keys;
  for (const auto& t : trials) EXPECT_TRUE(keys.insert(t["params"].dump()).second);
  EXPECT_EQ(comparable(read_json(killed / "params.json")),
            comparable(read_json(reference / "params.json")));
  fs::remove_all(reference);
  fs::remove_all(killed);
}
