// Test support: a demcal command refused as bad input, the way every
// command refuses one (exit 2, one line on stderr, nothing written).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal::test {

/// Bad input: `demcal ARGS` run in `work` exits 2 with one line on stderr
/// naming every one of `mentions`, nothing on stdout, and nothing written
/// in `work`.
inline void expect_refused(const std::filesystem::path& work, const std::vector<std::string>& args,
                           const std::vector<std::string>& mentions) {
  std::string trace;
  for (const auto& a : args) trace += a + " ";
  SCOPED_TRACE(trace);
  const std::set<std::string> before = paths_under(work);
  const RunResult r = run_demcal(args, work);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  for (const auto& m : mentions) EXPECT_NE(r.err.find(m), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(paths_under(work), before) << "wrote something";
}

}  // namespace demcal::test
