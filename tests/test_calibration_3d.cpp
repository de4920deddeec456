// Calibration in 3D (issue #18): the search and its certificate on a
// triaxial (sphere) REV through the TrialRunner interface; the calibrated
// peak checked against a run 8x longer; `demcal calibrate` on a 3D config
// and its --resume.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/trial_runner.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"

namespace fs = std::filesystem;
using namespace demcal;

namespace {

// FCC 2×2×2 (32 spheres), the material and test of configs/fcc_4x4x4.json.
const char* const kFcc2 = R"({
  "name": "fcc_2x2x2", "dimension": 3,
  "material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3,
               "wall": {"kn": 1e8, "kt": 5e7, "friction": 0.0}},
  "assembly": {"type": "fcc", "cells_x": 2, "cells_y": 2, "cells_z": 2, "radius": 5e-4},
  "test": {"type": "triaxial", "lateral_stress": 1e5, "vertical_strain": 1e-5,
           "monitor_points": 200},
  "calibration": {"accuracy": 0.02, "max_trials": 40, "seed": 1}})";

double relative(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The rotational-drag tests' sample: the FCC above consolidated, its runner,
// the 3D tolerances, and their run: α = 0.17, 16000 steps, ζ_t = 0.5 and
// rotational damping ζ_r.
struct DraggedFcc {
  SceneConfig config = parse_config_text(kFcc2, "fcc_2x2x2");
  TriaxialState state = consolidate_triaxial(config, make_sphere_assembly(config));
  TriaxialRunner runner{config, state};
  Tolerances t = triaxial_tolerances();
  double s3 = config.test.lateral_stress;

  AlgorithmSpec spec(double zeta_r) const {
    AlgorithmSpec p = config.algorithm;
    p.dt_ratio = 0.17;
    p.steps = 16000;
    p.damping_ratio_translation = 0.5;
    p.damping_ratio_rotation = zeta_r;
    return p;
  }
};

}  // namespace

TEST(Calibration3D, SmallFccIsCertifiedAndMatchesARunEightTimesLonger) {
  const SceneConfig config = parse_config_text(kFcc2, "fcc_2x2x2");
  const TriaxialState state = consolidate_triaxial(config, make_sphere_assembly(config));
  CalibrationOptions options = CalibrationOptions::from(config);
  options.jobs = 2;
  const CalibrationSummary s = calibrate(config, state, options);
  ASSERT_TRUE(s.success) << s.FullReport();
  EXPECT_EQ(s.dimension, 3);
  // The search never proposed a step beyond the 3D stable-step estimate.
  const TriaxialRunner runner(config, state);
  EXPECT_DOUBLE_EQ(s.dt_ratio_stable, runner.stable_dt_ratio(config.algorithm));
  for (const TrialRecord& t : s.trials) EXPECT_LE(t.params.dt_ratio, s.dt_ratio_stable);
  EXPECT_TRUE(s.best_trial.score.passed);
  EXPECT_LE(s.certificate.richardson_error, options.accuracy);
  // 3D: the certificate's third level (Nstep halved) is in its estimate.
  ASSERT_TRUE(s.certificate.steps_halved_peak_change.has_value());
  EXPECT_GE(s.certificate.richardson_error, *s.certificate.steps_halved_peak_change);
  EXPECT_GE(s.certificate.richardson_error, 2.0 * s.certificate.steps_doubled_peak_change);
  EXPECT_EQ(options.tolerances.servo, triaxial_tolerances().servo);
  EXPECT_EQ(s.certificate.peak, s.best_trial.score.criteria.peak_stress_yy);
  EXPECT_LT(s.certificate.peak, -config.test.lateral_stress);  // compressive, above σ3

  // The claim the certificate makes: the calibrated peak is within the
  // accuracy target of the converged one. Against Nstep ×8 (1/Nstep decay:
  // P(8N) is 7/8 of the way from P(N) to the limit).
  AlgorithmSpec longer = s.best;
  longer.steps *= 8;
  const TrialRun fine = runner.run(longer, options.tolerances, false, 3.0, nullptr);
  ASSERT_TRUE(fine.score.complete);
  EXPECT_LE(
      relative(s.best_trial.score.criteria.peak_stress_yy, fine.score.criteria.peak_stress_yy),
      options.accuracy)
      << s.FullReport();
}

// Rotational drag (reports/atlas-3d.md): in an FCC crystal the damping
// torques cancel between symmetric spheres, so moment balance (their sum)
// does not see ζ_r; the rotational-drag criterion (the damping's share of
// the axial wall's power) does. The same run with ζ_r = 0 passes every
// criterion; with ζ_r = 2 it fails on the drag alone, is diagnosed as
// rotational damping, and its peak is raised by at least the share (energy
// balance: the power the damping takes must come from the axial wall).
TEST(Calibration3D, RotationalDragFailsTheDraggedRunAndPassesTheUndampedOne) {
  const DraggedFcc fcc;
  const Tolerances& t = fcc.t;
  const double s3 = fcc.s3;
  TriaxialResult free_run, dragged_run;
  const TrialRun free = fcc.runner.run(fcc.spec(0.0), t, false, 3.0, nullptr, &free_run);
  const TrialRun dragged = fcc.runner.run(fcc.spec(2.0), t, false, 3.0, nullptr, &dragged_run);
  const TriaxialCriteria cf = compute_triaxial_criteria(free_run, s3);
  const TriaxialCriteria cd = compute_triaxial_criteria(dragged_run, s3);

  EXPECT_TRUE(free.score.passed) << free.score.worst_excess;
  EXPECT_EQ(cf.rotational_drag, 0.0);  // no rotational damping, no drag
  EXPECT_GT(cd.rotational_drag, kRotationalDragTolerance);
  EXPECT_FALSE(dragged.score.passed);
  // Every other criterion passes: moment balance (the torques' sum) alone
  // would not have seen it.
  EXPECT_LE(excesses(cd.combined, t).worst(), 1.0);
  EXPECT_DOUBLE_EQ(dragged.score.criteria.moment_balance,
                   t.moment_balance * cd.rotational_drag / kRotationalDragTolerance);
  EXPECT_EQ(dragged.score.diagnosis.parameter, "damping_rotation");
  EXPECT_EQ(dragged.score.diagnosis.direction, "decrease");
  const double rise =
      (free_run.peak_stress_zz - dragged_run.peak_stress_zz) / std::abs(free_run.peak_stress_zz);
  EXPECT_GT(rise, cd.rotational_drag);
}

// The early stop's rotational-drag bound (TriaxialEarlyFailure) is a lower
// bound of the final criterion whatever the rest of the run does: after
// each point of the dragged run, the run ended there in the way that gives
// the smallest final drag (b_zz released at once, so the peak is the
// running one, and no drag afterwards) still has at least the bound. It
// reaches the final drag once the peak is kTrendHalfWidth points back, and
// stops a trial once beyond factor × kRotationalDragTolerance.
TEST(Calibration3D, RotationalDragEarlyStopIsALowerBound) {
  const DraggedFcc fcc;
  const TriaxialRunner& runner = fcc.runner;
  const Tolerances& t = fcc.t;
  const double s3 = fcc.s3;
  const int m = fcc.config.test.monitor_points;
  const AlgorithmSpec p = fcc.spec(2.0);
  TriaxialResult run;
  runner.run(p, t, false, 3.0, nullptr, &run);
  const std::vector<TriaxialPoint>& series = run.series;
  const double drag = compute_triaxial_criteria(series, s3).rotational_drag;
  ASSERT_GT(drag, kRotationalDragTolerance);  // the run of the test above

  // Factor large enough that nothing stops: the bound alone is watched.
  TriaxialEarlyFailure watch(t, 1e9, m, s3);
  double previous = 0.0;
  for (size_t j = 0; j < series.size(); ++j) {
    EXPECT_FALSE(watch.add(series[j]));
    const double bound = watch.rotational_drag_bound();
    EXPECT_GE(bound, previous);
    previous = bound;
    std::vector<TriaxialPoint> ended(series.begin(), series.begin() + j + 1);
    for (int k = 0; k <= 2 * kTrendHalfWidth + 1; ++k) {
      TriaxialPoint q = series[j];
      q.step += k + 1;
      q.b(2, 2) = 0.0;      // released: never more compressive
      q.axial_power = 0.0;  // no drag share
      q.damping_power_rotation = 0.0;
      ended.push_back(q);
    }
    EXPECT_LE(bound, compute_triaxial_criteria(ended, s3).rotational_drag) << "point " << j;
  }
  EXPECT_LE(previous, drag);
  size_t peak = 0;
  for (size_t k = 1; k < series.size(); ++k)
    if (series[k].b(2, 2) < series[peak].b(2, 2)) peak = k;
  if (peak + kTrendHalfWidth < series.size() - 1) {
    EXPECT_EQ(previous, drag);
  }
  EXPECT_GT(previous, 0.5 * drag);

  // The stop: a factor that the bound passes stops the trial before its end
  // (the planes alone do not: every other criterion is within tolerance),
  // one above the final drag never does.
  const double reached = previous / kRotationalDragTolerance;
  ASSERT_GT(reached, 1.0);
  const TrialRun stopped = runner.run(p, t, true, 0.999 * reached, nullptr);
  EXPECT_FALSE(stopped.score.complete);
  EXPECT_LT(stopped.steps_run, p.steps);
  const TrialRun whole = runner.run(p, t, true, 1.001 * drag / kRotationalDragTolerance, nullptr);
  EXPECT_TRUE(whole.score.complete);
  EXPECT_EQ(whole.steps_run, p.steps);
}

TEST(Calibration3D, CommandWritesParamsWithTheDimensionAndResumeReusesEveryTrial) {
  test::TempDir dir("calib3d");
  const std::string config = test::write_text(dir / "fcc_2x2x2.json", kFcc2);
  const fs::path out = dir / "out";
  const test::RunResult first =
      test::run_demcal({"calibrate", config, "-q", "-o", out.string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(first.status, 0) << first.err;
  const nlohmann::json params = test::read_json(out / "params.json");
  EXPECT_EQ(params.at("dimension"), 3);
  EXPECT_EQ(params.at("schema"), "demcal.params/1");
  EXPECT_TRUE(params.at("success").get<bool>());
  EXPECT_TRUE(params.at("certificate").at("passed").get<bool>());
  EXPECT_GT(params.at("rev").at("dt").get<double>(), 0.0);
  EXPECT_EQ(params.at("rev").at("particles"), 32);
  EXPECT_TRUE(fs::exists(out / "report.html"));  // the 3D report (tests/test_report.cpp)
  const std::string bytes = test::read_text(out / "params.json");
  const size_t trials = test::lines_of(test::read_text(out / "trials.jsonl")).size();
  ASSERT_GT(trials, 0u);

  const test::RunResult again = test::run_demcal(
      {"calibrate", config, "-o", out.string(), "--jobs", "1", "--resume"}, dir.path());
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.out.find("0 trials run, " + std::to_string(trials) + " reused"),
            std::string::npos)
      << again.out;
  EXPECT_EQ(test::read_text(out / "params.json"), bytes);  // --jobs and --resume change nothing
}

// --evidence on a 3D config: the paper's recipe done mechanically (α 0.2,
// ζ 1, Nstep doubled from 500 per sphere until it passes) and the converged
// reference 2·P(16N) − P(8N) of the calibrated multipliers, in params.json,
// evidence.jsonl and the report, as in 2D; the calibrated peak is within
// the accuracy target of the reference (what the certificate claims).
TEST(Calibration3D, EvidenceRunsTheRecipeAndTheReference) {
  test::TempDir dir("evidence3d");
  const std::string config = test::write_text(dir / "fcc_2x2x2.json", kFcc2);
  const fs::path out = dir / "out";
  const test::RunResult run = test::run_demcal(
      {"calibrate", config, "-q", "-o", out.string(), "--jobs", "2", "--evidence"}, dir.path());
  ASSERT_EQ(run.status, 0) << run.err;
  const nlohmann::json params = test::read_json(out / "params.json");
  const nlohmann::json& ref = params.at("evidence").at("reference");
  const int64_t n = params.at("rev").at("steps").get<int64_t>();
  EXPECT_EQ(ref.at("steps_8x").get<int64_t>(), 8 * n);
  EXPECT_EQ(ref.at("steps_16x").get<int64_t>(), 16 * n);
  const double p8 = ref.at("peak_stress_yy_8x").get<double>(),
               p16 = ref.at("peak_stress_yy_16x").get<double>(),
               reference = ref.at("peak_stress_yy").get<double>();
  EXPECT_NEAR(reference, 2.0 * p16 - p8, 1e-9 * std::abs(reference));
  EXPECT_LT(reference, -1e5);  // the axial peak b_zz, compressive, above σ3
  EXPECT_LE(std::abs(ref.at("calibrated_peak_error").get<double>()),
            params.at("accuracy").get<double>());

  const std::vector<std::string> lines = test::lines_of(test::read_text(out / "evidence.jsonl"));
  const nlohmann::json& baseline = params.at("evidence").at("baseline");
  const int recipe_trials = baseline.at("trials").get<int>();
  ASSERT_EQ(lines.size(), static_cast<size_t>(2 + recipe_trials));
  EXPECT_EQ(baseline.at("start_steps").get<int64_t>(), 500 * 32);
  for (int k = 0; k < recipe_trials; ++k) {
    const nlohmann::json t = nlohmann::json::parse(lines[2 + k]);
    EXPECT_EQ(t.at("phase"), "baseline");
    EXPECT_EQ(t.at("params").at("dt_ratio").get<double>(), 0.2);
    EXPECT_EQ(t.at("params").at("damping_ratio_rotation").get<double>(), 1.0);
    EXPECT_EQ(t.at("params").at("steps").get<int64_t>(), (int64_t{500} * 32) << k);
    // Doubled until it passes: only the last may pass.
    EXPECT_EQ(t.at("passed").get<bool>(),
              baseline.at("passed").get<bool>() && k == recipe_trials - 1);
  }
  const std::string md = test::read_text(out / "report.md");
  EXPECT_NE(md.find("peak b_zz at 8·Nstep"), std::string::npos);
  EXPECT_NE(md.find("Evidence: the paper's recipe (--evidence)"), std::string::npos);
}

// `demcal export` on a 3D params.json: the deck of the calibrated REV with
// params.json's α, Nstep and ζ_t (the library's deck against demcal is
// tests/test_export_3d.cpp; this checks the command carries the calibrated
// parameters through). A size to scale to is refused: the 3D Nstep law is
// not measured yet.
TEST(Calibration3D, ExportWritesTheRevsDeckAndAnUpscaledPrototypesDeck) {
  test::TempDir dir("export3d");
  const std::string config = test::write_text(dir / "fcc_2x2x2.json", kFcc2);
  const fs::path out = dir / "out";
  const test::RunResult cal =
      test::run_demcal({"calibrate", config, "-q", "-o", out.string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(cal.status, 0) << cal.err;
  const std::string params = (out / "params.json").string();

  const fs::path deck = dir / "deck" / "fcc.lammps";
  const test::RunResult exported =
      test::run_demcal({"export", params, "-o", deck.string()}, dir.path());
  ASSERT_EQ(exported.status, 0) << exported.err;
  ASSERT_TRUE(fs::exists(deck));
  ASSERT_TRUE(fs::exists(dir / "deck" / "fcc.lammps.data"));
  EXPECT_NE(exported.out.find("32 spheres"), std::string::npos) << exported.out;

  // A larger prototype (FCC 3x3x3, 108 spheres): the lattice resized, Nstep
  // scaled by the default 3D law, ∝ L² = N^(2/3): the deck's steps (3/2)²
  // times the REV deck's (same Δt, same factor f).
  const test::RunResult big = test::run_demcal(
      {"export", params, "--particles", "108", "-o", (dir / "big" / "fcc.lammps").string()},
      dir.path());
  ASSERT_EQ(big.status, 0) << big.err;
  EXPECT_NE(big.out.find("108 spheres"), std::string::npos) << big.out;
  EXPECT_NE(big.err.find("power law, exponent 0.666"), std::string::npos) << big.err;
  const auto steps_of = [](const std::string& out) {
    const std::string tag = " steps, ";
    const size_t end = out.find(tag);
    const size_t begin = out.rfind(", ", end) + 2;
    return std::stod(out.substr(begin, end - begin));
  };
  // Each deck rounds Nstep/f (f ≈ 0.68, the damping factor) after the law
  // rounded N·(3/2)²: the ratio is exact to (0.5·(1 + 1/f) + 0.5·(3/2)²)
  // steps over the REV deck's, below 3.
  EXPECT_NEAR(steps_of(big.out) / steps_of(exported.out), 2.25, 3.0 / steps_of(exported.out));

  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "deck not run");
  const test::RunResult ran =
      test::run_program(lmp, {"-in", "fcc.lammps", "-screen", "none"}, dir / "deck");
  ASSERT_EQ(ran.status, 0) << ran.err;
  // The deck appends its axial peak to its series at the end, in demcal's
  // key: "# peak_stress_zz = -P".
  const std::string series = test::read_text(dir / "deck" / "fcc.lammps.series.csv");
  const std::string tag = "# peak_stress_zz = ";
  const size_t at = series.rfind(tag);
  ASSERT_NE(at, std::string::npos) << "no peak in the deck's series";
  const double lammps_peak = -std::stod(series.substr(at + tag.size()));

  // demcal with the same parameters and ζ_r = 0 (LAMMPS 2021 has no
  // rotational viscous fix; the deck says so).
  const nlohmann::json rev = test::read_json(out / "params.json").at("rev");
  const auto set = [&](const char* key, const nlohmann::json& v) {
    return std::string("algorithm.") + key + "=" + v.dump();
  };
  const test::RunResult run = test::run_demcal(
      {"run", config, "-o", (dir / "run").string(), "--set", set("dt_ratio", rev.at("dt_ratio")),
       "--set", set("steps", rev.at("steps")), "--set",
       set("damping_ratio_translation", rev.at("damping_ratio_translation")), "--set",
       "algorithm.damping_ratio_rotation=0"},
      dir.path());
  ASSERT_EQ(run.status == 0 || run.status == 1, true) << run.err;
  const double demcal_peak =
      -test::read_json(dir / "run" / "summary.json").at("peak").at("stress_zz").get<double>();
  // Same sample, same law, same loading time: the two integrators differ in
  // the damping scheme (explicit in LAMMPS, at α·f for Nstep/f steps), which
  // moves the peak by well under the 1 % the issue asks (−0.09 % on
  // fcc_4x4x4, reports/engines-3d.md).
  EXPECT_LT(relative(lammps_peak, demcal_peak), 0.01)
      << "LAMMPS " << lammps_peak << " Pa, demcal " << demcal_peak << " Pa";
}
