// `demcal scaling` on a 3D family (issue #18): the same study as in 2D on
// FCC blocks of spheres. A tiny family (32, 108, 256 spheres: 2, 3 and 4
// cells an edge) calibrated at the two smaller sizes and checked forward at
// the largest; scaling.json and scaling.md carry the 3D exponent fit, which
// is checked here against the log-log slope of the Nstep it records.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/files.hpp"
#include "support/process.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;

TEST(Scaling3D, TinyFccFamilyFitsTheExponent) {
  test::TempDir dir("scaling3d");
  const test::RunResult r = test::run_demcal(
      {"scaling", test::shipped_config("fcc_4x4x4"), "--sizes", "32,108,256", "--calibrate-max",
       "108", "--max-trials", "20", "-j", "1", "-q", "-o", "out", "--work", "work"},
      dir.path());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;  // 1: the forward check failed
  const nlohmann::json j = nlohmann::json::parse(test::read_text(dir / "out" / "scaling.json"));
  EXPECT_EQ(j.at("dimension"), 3);
  const auto& results = j.at("results");
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(results[0].at("particles"), 32);
  EXPECT_EQ(results[1].at("particles"), 108);
  EXPECT_EQ(results[2].at("particles"), 256);
  EXPECT_TRUE(results[0].at("calibrated"));
  EXPECT_TRUE(results[1].at("calibrated"));
  EXPECT_FALSE(results[2].at("calibrated"));
  // From the REV (108) up: two sizes, the exponent is their log-log slope.
  ASSERT_TRUE(results[1].at("success")) << r.err;
  const double steps_rev = results[1].at("best").at("steps").get<double>();
  const auto& fixed = results[2].at("fixed_multipliers");
  if (fixed.at("found")) {
    const double steps_fwd = fixed.at("steps").get<double>();
    const double p = std::log(steps_fwd / steps_rev) / std::log(256.0 / 108.0);
    const double measured = j.at("measured_law").at("exponent").get<double>();
    EXPECT_NEAR(measured, p, 1e-9);
    EXPECT_NEAR(j.at("fit_fixed_multipliers_from_rev").at("power").at("exponent").get<double>(), p,
                1e-9);
    // In the sample's linear size L ∝ N^(1/3): Nstep ∝ L^(3p).
    EXPECT_NEAR(j.at("exponent_linear_size").get<double>(), 3.0 * p, 1e-9);
  }
  // The forward check ran the linear law's Nstep: 108-sphere REV's × 256/108.
  EXPECT_EQ(j.at("forward").at("linear").at("params").at("steps").get<int64_t>(),
            fixed.at("runs")[0].at("params").at("steps").get<int64_t>());
  const std::string md = test::read_text(dir / "out" / "scaling.md");
  EXPECT_NE(md.find("(3D)"), std::string::npos);
  EXPECT_NE(md.find("N^(1/3)"), std::string::npos);
  EXPECT_NE(md.find("## 4. Verdict"), std::string::npos);
}

}  // namespace
