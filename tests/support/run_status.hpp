// Test support: `demcal run`'s exit status is its verdict, as `demcal
// score`'s is: 0 PASS, 1 FAIL (a diverged run fails), its files written
// either way (2 is bad input, nothing written). Tests that run a trial for
// another purpose (its files, the cache, the SIMD path) check the status
// against the verdict the run wrote.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
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

/// A diverged run's lines in `out` (`demcal run`'s stdout) against its
/// out_dir/summary.json: one numbering of the divergence. The headline, the
/// criteria line and the last line name the step that diverged of the
/// `planned` in the same words, the headline also the steps completed
/// before it (the step that diverged is the first not completed).
inline void expect_one_divergence_numbering(const std::string& out,
                                            const std::filesystem::path& out_dir, int64_t planned) {
  const nlohmann::json s = read_json(out_dir / "summary.json");
  ASSERT_TRUE(s.at("diverged").get<bool>()) << out;
  const int64_t ran = s.at("steps_run").get<int64_t>();
  const int64_t at = s.at("divergence").at("step").get<int64_t>();
  EXPECT_EQ(ran, at - 1) << out;
  const std::string diverged =
      "diverged at step " + std::to_string(at) + " of " + std::to_string(planned);
  EXPECT_NE(out.find(", " + diverged + " (" + std::to_string(ran) + " steps completed), dt "),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("\n  criteria not scored: the run " + diverged + ", "), std::string::npos)
      << out;
  EXPECT_NE(out.find("\n  DIVERGED at step " + std::to_string(at) + ": "), std::string::npos)
      << out;
  // Before: "15 of 20000 steps (diverged)" above "diverged at step 16".
  EXPECT_EQ(out.find(" of " + std::to_string(planned) + " steps"), std::string::npos) << out;
}

}  // namespace demcal::test
