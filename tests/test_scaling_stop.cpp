// A stop (Ctrl-C: ScalingStudyOptions::stop) during each step of a scaling
// study that is not a calibration: a consolidation, a size's step search at
// fixed multipliers, the forward reference run. Each ends at its next check
// (a consolidation's, every 200 steps) or monitoring point (a run's), writes
// nothing of the step it cut (no consolidated.csv, fixed.json,
// reference.json), and --resume ends with the uninterrupted study's
// scaling.json, every number of it. The stop is set from the study's own log
// line that opens the step, so each case is deterministic. (The stop inside
// the consolidation needs a consolidation that runs: this binary runs with
// the cache off, test_consolidation_cache.cpp; a state read from the cache
// is read whole.)
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/search/trial_runner.hpp"
#include "demcal/upscaling/scaling_study.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/without_timing.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

using ::demcal::test::without_timing;

class ScalingStop : public ::testing::Test {
 protected:
  ScalingStop() : config_(load_config(test::shipped_config("hex_5x5"))) {
    config_.calibration.max_trials = 12;
  }

  /// The study 16, 25, 36 (calibrated up to 25, checked forward at 36) in
  /// `work`; with `stop_at`, the stop is set when a log line begins with it.
  ScalingStudy study(const std::string& work, bool resume, const std::string& stop_at,
                     std::vector<std::string>& log) {
    return study(work, resume, log, [stop_at](const std::string& line) {
      return !stop_at.empty() && line.rfind(stop_at, 0) == 0;
    });
  }
  /// The same with the stop set when `stop_after(line)` says so.
  ScalingStudy study(const std::string& work, bool resume, std::vector<std::string>& log,
                     const std::function<bool(const std::string&)>& stop_after) {
    ScalingStudyOptions o;
    o.sizes = parse_sizes("16,25,36");
    o.sizes_text = "16,25,36";
    o.calibrate_max = 25;
    o.work_dir = (tmp_ / work).string();
    o.jobs = 1;
    o.resume = resume;
    o.stop = &stop_;
    stop_.store(false);
    o.log = [&](const std::string& line) {
      log.push_back(line);
      if (stop_after(line)) stop_.store(true);
    };
    return run_scaling_study(config_, o);
  }

  nlohmann::json uninterrupted(std::vector<std::string>* log_out = nullptr) {
    std::vector<std::string> log;
    const ScalingStudy st = study("R", false, "", log);
    if (log_out) *log_out = log;
    EXPECT_FALSE(st.interrupted);
    return without_timing(to_json(st, config_));
  }

  SceneConfig config_;
  std::atomic<bool> stop_{false};
  const test::TempDir tmp_{"scaling_stop"};
};

/// The log lines from the first that begins with `prefix` on.
std::vector<std::string> from_line(const std::vector<std::string>& log, const std::string& prefix) {
  for (size_t i = 0; i < log.size(); ++i)
    if (log[i].rfind(prefix, 0) == 0) return {log.begin() + static_cast<long>(i), log.end()};
  return {};
}

bool any_begins(const std::vector<std::string>& lines, const std::string& prefix) {
  for (const auto& l : lines)
    if (l.rfind(prefix, 0) == 0) return true;
  return false;
}

TEST_F(ScalingStop, EachStepStopsWritesNothingOfItAndResumeEndsAsUninterrupted) {
  const nlohmann::json reference = uninterrupted();
  struct Case {
    std::string stop_at;  ///< the log line that opens the step
    std::string unwritten;
  };
  // The forward size's consolidation (in its step search: 36 is not
  // calibrated), the step search at 16 (below the REV), the forward
  // reference at 36.
  const std::vector<Case> cases = {
      {"consolidating 36 particles", "size-36/consolidated.csv"},
      {"size 16: smallest passing Nstep", "size-16/fixed.json"},
      {"forward reference at 36", "size-36/reference.json"},
  };
  int k = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.stop_at);
    const std::string work = "S" + std::to_string(k++);
    std::vector<std::string> log;
    const ScalingStudy stopped = study(work, false, c.stop_at, log);
    EXPECT_TRUE(stopped.interrupted);
    const std::vector<std::string> after = from_line(log, c.stop_at);
    ASSERT_FALSE(after.empty());
    EXPECT_EQ(after.size(), 1u) << "the step went on after the stop: " << after.back();
    EXPECT_FALSE(any_begins(after, "  consolidated in"));
    EXPECT_FALSE(fs::exists(tmp_ / work / c.unwritten)) << c.unwritten;
    // What finished before the stop stays.
    EXPECT_TRUE(fs::exists(tmp_ / work / "size-16" / "result.json"));
    EXPECT_TRUE(fs::exists(tmp_ / work / "size-25" / "result.json"));

    std::vector<std::string> resumed_log;
    const ScalingStudy resumed = study(work, true, "", resumed_log);
    EXPECT_FALSE(resumed.interrupted);
    EXPECT_TRUE(any_begins(resumed_log, "size 25: reusing"));
    EXPECT_TRUE(fs::exists(tmp_ / work / c.unwritten)) << c.unwritten;
    // Everything, the forward reference included: a resumed study
    // consolidates the forward size's sample again, to the same state.
    const nlohmann::json got = without_timing(to_json(resumed, config_)), want = reference;
    EXPECT_EQ(got, want);
  }
}

/// The runs a step search logged after its opening line `opening`, as they
/// finished ("  N steps: pass|fail ...").
std::vector<std::string> search_runs(const std::vector<std::string>& log,
                                     const std::string& opening) {
  std::vector<std::string> runs;
  const std::vector<std::string> after = from_line(log, opening);
  for (size_t i = 1; i < after.size() && after[i].rfind("  ", 0) == 0; ++i)
    if (after[i].find(" steps: ") != std::string::npos) runs.push_back(after[i]);
  return runs;
}

// A step search stopped after its first run keeps that run (steps_search.jsonl)
// and a resumed study takes it instead of running it again: a search at a
// large size, hours of runs, is not lost to a Ctrl-C. The resumed study ends
// with the uninterrupted one's scaling.json, every number of it.
TEST_F(ScalingStop, AStepSearchStoppedAfterARunResumesFromThatRun) {
  std::vector<std::string> reference_log;
  const nlohmann::json reference = uninterrupted(&reference_log);
  const std::string opening = "size 16: smallest passing Nstep";
  const std::vector<std::string> all_runs = search_runs(reference_log, opening);
  ASSERT_GE(all_runs.size(), 2u) << "the search at 16 should need more than one run";

  bool in_search = false;
  std::vector<std::string> log;
  const ScalingStudy stopped = study("T", false, log, [&](const std::string& line) {
    if (line.rfind(opening, 0) == 0) in_search = true;
    return in_search && line.rfind("  ", 0) == 0 && line.find(" steps: ") != std::string::npos;
  });
  EXPECT_TRUE(stopped.interrupted);
  EXPECT_FALSE(fs::exists(tmp_ / "T" / "size-16" / "fixed.json"));
  const std::vector<std::string> kept = search_runs(log, opening);
  ASSERT_EQ(kept.size(), 1u) << "a run started after the stop";
  // The same run as the uninterrupted search's first (its wall time aside).
  EXPECT_EQ(kept[0].substr(0, kept[0].find("tol)")),
            all_runs[0].substr(0, all_runs[0].find("tol)")));
  const std::string runs_text = test::read_text(tmp_ / "T" / "size-16" / "steps_search.jsonl");
  EXPECT_EQ(std::count(runs_text.begin(), runs_text.end(), '\n'), 1) << runs_text;

  std::vector<std::string> resumed_log;
  const ScalingStudy resumed = study("T", true, "", resumed_log);
  EXPECT_FALSE(resumed.interrupted);
  const std::vector<std::string> resumed_runs = search_runs(resumed_log, opening);
  ASSERT_EQ(resumed_runs.size(), all_runs.size());
  EXPECT_NE(resumed_runs[0].find("(finished before the stop, reused)"), std::string::npos)
      << resumed_runs[0];
  for (size_t i = 1; i < resumed_runs.size(); ++i)
    EXPECT_EQ(resumed_runs[i].find("reused"), std::string::npos) << resumed_runs[i];
  EXPECT_TRUE(fs::exists(tmp_ / "T" / "size-16" / "fixed.json"));
  EXPECT_EQ(without_timing(to_json(resumed, config_)), reference);
}

/// A runner that asks to stop as its first run starts: the stop must end
/// that run at its next monitoring point, not at its end.
class StopAsARunStarts final : public TrialRunner {
 public:
  StopAsARunStarts(const TrialRunner& inner, std::atomic<bool>& stop)
      : inner_(inner), stop_(stop) {}
  int dimension() const override { return inner_.dimension(); }
  int64_t particles() const override { return inner_.particles(); }
  double stable_dt_ratio(const AlgorithmSpec& base) const override {
    return inner_.stable_dt_ratio(base);
  }
  TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool early_stop,
               double early_stop_factor, const std::atomic<bool>* stop) const override {
    stop_.store(true);
    const TrialRun r = inner_.run(params, tolerances, early_stop, early_stop_factor, stop);
    runs.push_back({params.steps, r.steps_run});
    return r;
  }
  mutable std::vector<std::pair<int64_t, int64_t>> runs;  ///< (planned, run) steps

 private:
  const TrialRunner& inner_;
  std::atomic<bool>& stop_;
};

TEST(StepSearchStop, AStopEndsTheRunningRunAndTheSearchRecordsNothing) {
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  c.prototype.particles = 0;
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  const BiaxialRunner biaxial(c, state);
  std::atomic<bool> stop{false};
  const StopAsARunStarts runner(biaxial, stop);
  AlgorithmSpec p;
  p.dt_ratio = 0.2;
  p.damping_ratio_translation = 0.7;
  p.damping_ratio_rotation = 1.0;
  p.steps = 10000;  // too fast for 25 particles: uninterrupted, the search runs again
  const StepSearch s = smallest_passing_steps(runner, p, Tolerances{}, &stop);
  EXPECT_TRUE(s.interrupted);
  EXPECT_FALSE(s.found);
  EXPECT_TRUE(s.trials.empty());
  ASSERT_EQ(runner.runs.size(), 1u);
  EXPECT_LT(runner.runs[0].second, runner.runs[0].first / 10) << "the run went on after the stop";
}

}  // namespace
}  // namespace demcal
