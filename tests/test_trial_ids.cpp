// trials.jsonl does not depend on --jobs (issue #13/#18 follow-up). With
// -j 2 the branches of a parallel section (the two starts' model searches,
// the certificate's runs) finish in any order, and a trial's id used to be
// its finishing rank: the same seed gave another file for -j 1 and -j 2. A
// trial's id is now its rank in the order a one-job run asks for it, and
// the file is in id order; only the wall times differ.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/process.hpp"

namespace {

namespace test = demcal::test;

/// trials.jsonl of `demcal calibrate hex_5x5 -j JOBS`, one JSON per line,
/// the wall time removed.
std::vector<nlohmann::json> trials_with_jobs(const test::TempDir& dir, const std::string& jobs) {
  const test::RunResult r = test::run_demcal({"calibrate", test::shipped_config("hex_5x5"), "-o",
                                              "j" + jobs, "-q", "-j", jobs, "--max-trials", "12"},
                                             dir.path());
  EXPECT_EQ(r.status, 0) << r.err;
  std::vector<nlohmann::json> out;
  for (const std::string& line :
       test::lines_of(test::read_text(dir / ("j" + jobs) / "trials.jsonl"))) {
    nlohmann::json j = nlohmann::json::parse(line);
    EXPECT_TRUE(j.contains("wall_time_s")) << line;
    j.erase("wall_time_s");
    out.push_back(j);
  }
  return out;
}

TEST(TrialIds, TrialsFileIsTheSameForOneAndTwoJobs) {
  const test::TempDir dir("trial_ids");
  const std::vector<nlohmann::json> one = trials_with_jobs(dir, "1");
  const std::vector<nlohmann::json> two = trials_with_jobs(dir, "2");
  // Enough trials for both branches of the first section to run several.
  ASSERT_GE(one.size(), 6u);
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].at("id"), static_cast<int>(i));  // numbered in file order
    EXPECT_EQ(one[i], two[i]) << "line " << i + 1;
  }
}

}  // namespace
