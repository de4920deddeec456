// Test support: `demcal run`'s exit status is its verdict, as `demcal
// score`'s is: 0 PASS, 1 FAIL (a diverged run fails), its files written
// either way (2 is bad input, nothing written). Tests that run a trial for
// another purpose (its files, the cache, the SIMD path) check the status
// against the verdict the run wrote.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/files.hpp"

namespace demcal::test {

/// `status` of a `demcal run ... -o out` against out/summary.json's
/// "passed". Fatal when there is no summary (use ASSERT_NO_FATAL_FAILURE).
inline void expect_run_status(int status, const std::filesystem::path& out,
                              const std::string& err = "") {
  ASSERT_TRUE(std::filesystem::exists(out / "summary.json")) << "status " << status << ": " << err;
  const bool passed = read_json(out / "summary.json").at("passed").get<bool>();
  EXPECT_EQ(status, passed ? 0 : 1) << err;
}

}  // namespace demcal::test
