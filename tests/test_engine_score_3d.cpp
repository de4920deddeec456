// Scoring a triaxial (3D) series from another engine: demcal's own 3D
// series.csv read back scores as the run itself; the servo error of each
// lateral wall comes from its pressure when the file has no servo column;
// a 3D file missing a component is one clear InputError; `demcal score`
// on a 3D file writes its summary with the planes' criteria; on synthetic
// series, a plane's servo error and the rotational drag. (The exported
// LAMMPS 3D deck's own series is scored in test_export_3d.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/external_series.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

SceneConfig fcc3() {
  SceneConfig c = load_config(test::shipped_config("fcc_4x4x4"));
  c.assembly.cells_x = c.assembly.cells_y = c.assembly.cells_z = 3;
  c.test.monitor_points = 50;
  return c;
}

AlgorithmSpec params(int64_t steps) {
  AlgorithmSpec p;
  p.dt_ratio = 0.2;
  p.steps = steps;
  p.damping_ratio_translation = 0.4;
  p.damping_ratio_rotation = 0.4;
  return p;
}

TriaxialResult fcc3_run(int64_t steps) {
  const SceneConfig c = fcc3();
  const TriaxialState state = consolidate_triaxial(c, make_sphere_assembly(c));
  return run_triaxial_loading(state, c.test, params(steps));
}

TEST(ExternalSeries3d, DemcalsOwnSeriesScoresAsTheRun) {
  const SceneConfig c = fcc3();
  const double s3 = c.test.lateral_stress;
  // Fast and slow loading: one fails, one passes, each read back the same.
  for (int64_t steps : {2000, 20000}) {
    const TriaxialResult run = fcc3_run(steps);
    const TriaxialCriteria direct = compute_triaxial_criteria(run.series, s3);
    const ExternalSeries read = parse_external_series(series_csv(run.series), "series.csv", s3);
    ASSERT_EQ(read.dimension, 3);
    ASSERT_EQ(read.triaxial.series.size(), run.series.size());
    const ExternalScore back = score_external(read, Tolerances{});
    ASSERT_TRUE(back.planes.has_value());
    const Criteria& b = back.score.criteria;
    // The criteria the verdict reads: the rotational drag (from the power
    // columns, ζ_r = 0.4 here) folded into moment balance.
    const Criteria d = scored_criteria(direct, Tolerances{});
    // series.csv carries 10 significant digits: the criteria agree to that
    // (relative to each criterion's own scale, σ3 or the peak).
    EXPECT_NEAR(b.force_balance, d.force_balance, 1e-7) << steps;
    EXPECT_NEAR(b.moment_balance, d.moment_balance, 1e-7) << steps;
    EXPECT_NEAR(b.servo, d.servo, 1e-7) << steps;
    EXPECT_NEAR(b.oscillation, d.oscillation, 1e-7) << steps;
    for (int w = 0; w < 4; ++w)
      EXPECT_NEAR(back.planes->servo_walls[w], direct.servo_walls[w], 1e-7) << steps << " " << w;
    EXPECT_NEAR(b.peak_stress_yy / d.peak_stress_yy, 1.0, 1e-9) << steps;
    EXPECT_EQ(b.points, d.points);
    // The verdict of the criteria against the same tolerances; the file
    // has no "# steps", so the run counts as complete at its last row.
    EXPECT_EQ(back.score.passed, excesses(d, Tolerances{}).worst() <= 1.0 && !run.diverged)
        << steps;
  }
}

// The combined record holds combined values under the 2D names (xx lateral,
// yy axial, shear off-diagonal), never one plane's alone: the x walls'
// oscillation_xx read as the sample's; and the planes' off-diagonal gaps
// (force_balance_xy/_yx: b_xz − σ_xz in the xz plane) are not written under
// the combined names at all.
TEST(TriaxialCriteria, TheCombinedRecordCombinesThePlanes) {
  const SceneConfig c = fcc3();
  const TriaxialResult run = fcc3_run(2000);
  const TriaxialCriteria t = compute_triaxial_criteria(run.series, c.test.lateral_stress);
  const Criteria &m = t.combined, &xz = t.xz, &yz = t.yz, &xy = t.xy;
  EXPECT_EQ(m.oscillation_xx, std::max(xz.oscillation_xx, yz.oscillation_xx));
  EXPECT_EQ(m.oscillation_yy, std::max(xz.oscillation_yy, yz.oscillation_yy));
  EXPECT_EQ(m.oscillation_shear,
            std::max({xz.oscillation_shear, yz.oscillation_shear, xy.oscillation_shear}));
  EXPECT_EQ(m.force_balance_xx_rms, std::max(xz.force_balance_xx_rms, yz.force_balance_xx_rms));
  EXPECT_EQ(m.servo_rms, std::max(xz.servo_rms, yz.servo_rms));
  EXPECT_EQ(m.servo_noise, std::max(xz.servo_noise, yz.servo_noise));
  EXPECT_EQ(m.moment_balance_trend,
            std::max({xz.moment_balance_trend, yz.moment_balance_trend, xy.moment_balance_trend}));
  // The two lateral planes differ in this run (else max() proves nothing).
  EXPECT_NE(xz.oscillation_xx, yz.oscillation_xx);
  EXPECT_FALSE(m.available("force_balance_xy"));
  EXPECT_FALSE(m.available("force_balance_yx"));
  EXPECT_TRUE(xz.available("force_balance_xy"));
  const nlohmann::json j = to_json(scored_criteria(t, Tolerances{}));
  EXPECT_FALSE(j.contains("force_balance_xy"));
  EXPECT_TRUE(j.at("not_available").contains("force_balance_xy"));
  // Not a criterion: the verdict says nothing went unchecked.
  EXPECT_TRUE(score_triaxial_run(run, c.test.lateral_stress, Tolerances{}).not_checked.empty());
}

// A synthetic triaxial series of `n` + 1 points: σ = b = the axial stress
// −kS3·(1 + 5·min(k, peak)/peak − 2·max(0, k − peak)/n) on zz, −kS3 on xx
// and yy; its most compressive b_zz at point `peak`.
std::vector<TriaxialPoint> synthetic_triaxial(int n, int peak) {
  constexpr double kS3 = 1e5;
  std::vector<TriaxialPoint> s(n + 1);
  for (int k = 0; k <= n; ++k) {
    TriaxialPoint& p = s[k];
    p.step = 100 * k;
    p.strain_zz = -1e-4 * k;
    const double axial = 1.0 + 5.0 * std::min(k, peak) / peak - 2.0 * std::max(0, k - peak) / n;
    p.b = -kS3 * Eigen::Vector3d(1.0, 1.0, axial).asDiagonal();
    p.sigma = p.b;
    p.axial_power = 1.0;
  }
  return s;
}

// A vertical plane's servo error is the mean of its two walls' (the plane's
// lateral stress is their mean): x min 1 % above σ3 and x max 1 % below
// read 0 in the xz plane, and each wall alone reads its own 1 %.
TEST(TriaxialCriteria, APlanesServoErrorIsItsTwoWallsMean) {
  auto s = synthetic_triaxial(100, 60);
  for (size_t k = 1; k < s.size(); ++k) s[k].servo_error = {0.01, -0.01, 0.0, 0.0};
  const TriaxialCriteria c = compute_triaxial_criteria(s, 1e5);
  EXPECT_NEAR(c.xz.servo, 0.0, 1e-15);
  EXPECT_NEAR(c.servo_walls[0], 0.01, 1e-12);
  EXPECT_NEAR(c.servo_walls[1], 0.01, 1e-12);
  EXPECT_NEAR(c.servo_walls[2], 0.0, 1e-15);
}

// The rotational drag, the damping's share of the axial power, counts up
// to the axial peak (as every gap: after it the failure mechanism moves
// fast against the damping): 1 % before the peak at point 60, 50 % after.
// The trend at the peak (point 60, the last that counts) averages the 9
// points 56-64, 4 of them after it: (5·0.01 + 4·0.5)/9 = 0.2278, not the
// 0.5 after it.
// Each drag is its own damping's share of the axial power alone: the
// translational damping's 30 % beside it changes nothing of it.
TEST(TriaxialCriteria, RotationalDragCountsUpToThePeak) {
  auto s = synthetic_triaxial(100, 60);
  for (size_t k = 1; k < s.size(); ++k) {
    s[k].damping_power_rotation = k <= 60 ? 0.01 : 0.5;
    s[k].damping_power_translation = 0.3;
  }
  const TriaxialCriteria c = compute_triaxial_criteria(s, 1e5);
  EXPECT_NEAR(c.rotational_drag, (5 * 0.01 + 4 * 0.5) / 9, 1e-12);
  EXPECT_NEAR(c.translational_drag, 0.3, 1e-12);
}

TEST(ExternalSeries3d, ServoErrorsComeFromThePressuresWhenNotGiven) {
  std::string csv = "# lateral_stress = 100000\n# steps = 10\nstep,strain_zz";
  for (const char* t : {"b_", "s_"})
    for (const char* ij : {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"})
      csv += std::string(",") + t + ij;
  csv += ",p_xmin,p_xmax,p_ymin,p_ymax\n";
  for (int row = 0; row < 2; ++row) {
    csv += std::to_string(10 * row) + ",-0.001";
    for (int k = 0; k < 18; ++k) csv += k % 4 == 0 ? ",-100000" : ",0";
    csv += ",101000,99000,100000,102000\n";
  }
  const ExternalSeries s = parse_external_series(csv, "t.csv");
  ASSERT_EQ(s.dimension, 3);
  ASSERT_EQ(s.triaxial.series.size(), 2u);
  const TriaxialPoint& p = s.triaxial.series.back();
  EXPECT_DOUBLE_EQ(p.servo_error[0], 0.01);
  EXPECT_DOUBLE_EQ(p.servo_error[1], -0.01);
  EXPECT_DOUBLE_EQ(p.servo_error[2], 0.0);
  EXPECT_DOUBLE_EQ(p.servo_error[3], 0.02);
  EXPECT_DOUBLE_EQ(p.lateral_stress_error, 0.005);  // their mean
  EXPECT_EQ(p.b(2, 2), -100000);
  EXPECT_EQ(s.triaxial.steps_planned, 10);
}

TEST(ExternalSeries3d, AMissingComponentIsOneClearError) {
  std::string csv = "# lateral_stress = 100000\nstep,strain_zz";
  for (const char* t : {"b_", "s_"})
    for (const char* ij : {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy"})  // no zz
      csv += std::string(",") + t + ij;
  csv += "\n";
  for (int row = 0; row < 2; ++row) {
    csv += std::to_string(row) + ",0";
    for (int k = 0; k < 16; ++k) csv += ",0";
    csv += "\n";
  }
  try {
    parse_external_series(csv, "t.csv");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("b_zz"), std::string::npos) << e.what();
  }
}

TEST(ScoreCli3d, ScoresATriaxialSeries) {
  const test::TempDir dir("score_cli_3d");
  const SceneConfig c = fcc3();
  test::write_text(dir / "series.csv", series_csv(fcc3_run(20000).series));
  const auto r = test::run_demcal(
      {"score", "series.csv", "--lateral-stress", std::to_string(c.test.lateral_stress), "-o", "s"},
      dir.path());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.out;  // a verdict, not an error
  EXPECT_NE(r.out.find("3D (triaxial)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("peak b_zz"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(dir / "s" / "summary.json"));
  EXPECT_EQ(j.at("dimension"), 3);
  EXPECT_TRUE(j.at("criteria_planes").contains("servo_walls"));
  EXPECT_LT(j.at("peak").at("stress_zz").get<double>(), 0.0);
  EXPECT_EQ(j.at("passed").get<bool>(), r.status == 0);
}

}  // namespace
}  // namespace demcal
