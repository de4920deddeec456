// The small pool behind trials, scans and reruns (demcal/parallel.hpp).
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "demcal/search/parallel.hpp"

namespace demcal {
namespace {

TEST(Parallel, EveryIndexOnceForAnyJobs) {
  for (const int jobs : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> hits(37);
    for_each_parallel(37, jobs, [&](int k) { ++hits[k]; });
    for (const auto& h : hits) EXPECT_EQ(h.load(), 1) << "jobs " << jobs;
  }
  std::vector<int> order;
  for_each_parallel(5, 1, [&](int k) { order.push_back(k); });  // one job: in order
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_GE(resolve_jobs(0), 1);
  EXPECT_EQ(resolve_jobs(3), 3);
}

TEST(Parallel, FirstExceptionIsRethrownAfterTheOthersEnd) {
  for (const int jobs : {1, 2}) {
    std::atomic<int> ran{0};
    EXPECT_THROW(run_parallel({[&] { ++ran; }, [] { throw std::runtime_error("x"); }}, jobs),
                 std::runtime_error);
    EXPECT_EQ(ran.load(), 1);
  }
}

}  // namespace
}  // namespace demcal
