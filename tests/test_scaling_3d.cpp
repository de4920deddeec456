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

#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/scaling_study.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "support/files.hpp"
#include "support/params_3d.hpp"
#include "support/process.hpp"

namespace {

namespace fs = std::filesystem;
namespace test = demcal::test;

/// The tiny study in its own folder, run once for check_fit() and
/// check_default_law() (one TEST: ctest runs each in a process of its own).
struct TinyStudy {
  test::TempDir dir{"scaling3d"};
  test::RunResult r;
  TinyStudy() {
    r = test::run_demcal(
        {"scaling", test::shipped_config("fcc_4x4x4"), "--sizes", "32,108,256", "--calibrate-max",
         "108", "--max-trials", "20", "-j", "1", "-q", "-o", "out", "--work", "work"},
        dir.path());
  }
};
/// scaling.json and scaling.md carry the 3D exponent fit.
void check_fit(const TinyStudy& study) {
  const test::TempDir& dir = study.dir;
  const test::RunResult& r = study.r;
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
  // The forward check ran the candidate law's Nstep, the first run of the
  // step search at 256 spheres.
  EXPECT_EQ(j.at("forward").at("run").at("params").at("steps").get<int64_t>(),
            fixed.at("runs")[0].at("params").at("steps").get<int64_t>());
  const std::string md = test::read_text(dir / "out" / "scaling.md");
  EXPECT_NE(md.find("(3D)"), std::string::npos);
  EXPECT_NE(md.find("N^(1/3)"), std::string::npos);
  EXPECT_NE(md.find("## 4. Verdict"), std::string::npos);
}

// The 3D study checks and chooses the 3D default law, Nstep ∝ N^(2/3)
// (default_law(3), reports/scaling-3d.md §4), beside its fitted exponent,
// as the 2D study does the linear law: the forward run at 256 spheres is
// the REV's Nstep × (256/108)^(2/3) (rounded as the step search rounds
// it), and the law scaling.json carries goes through `demcal upscale
// --law` to the Nstep the default law gives. (It used to check and choose
// the linear law, which asks N/N_REV where L² needs (N/N_REV)^(2/3).)
void check_default_law(const TinyStudy& study) {
  const test::TempDir& dir = study.dir;
  const test::RunResult& r = study.r;
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(dir / "out" / "scaling.json"));
  const demcal::ScalingLaw two_thirds = demcal::default_law(3);
  EXPECT_DOUBLE_EQ(two_thirds.exponent, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(j.at("candidate_law").at("exponent").get<double>(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(j.at("forward").at("law").at("exponent").get<double>(), 2.0 / 3.0);
  const auto& rev = j.at("results")[1];
  ASSERT_TRUE(rev.at("success")) << r.err;
  const demcal::AlgorithmSpec rev_best = demcal::algorithm_from_json(rev.at("best"), "rev");
  const int64_t by_law = demcal::upscale_steps(rev_best.steps, 108, 256, two_thirds);
  EXPECT_EQ(by_law, std::llround(rev_best.steps * std::pow(256.0 / 108.0, 2.0 / 3.0)));
  // The step search runs Nstep rounded as the search rounds it.
  EXPECT_EQ(j.at("forward").at("run").at("params").at("steps").get<int64_t>(),
            demcal::round_steps(static_cast<double>(by_law)));

  // The forward check passes on this family: the law chosen is the default
  // one, exactly (2/3 through JSON), and says where it was checked.
  ASSERT_TRUE(j.at("forward").at("passed")) << j.at("forward").dump(2);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(j.at("law").at("exponent").get<double>(), two_thirds.exponent);
  EXPECT_NE(j.at("law").at("source").get<std::string>().find("checked forward at 256 spheres"),
            std::string::npos)
      << j.at("law").dump();
  const std::string md = test::read_text(dir / "out" / "scaling.md");
  EXPECT_NE(md.find("Forward check of the default law Nstep ∝ N^0.667"), std::string::npos) << md;
  EXPECT_NE(md.find("Upscaling uses: **Nstep ∝ N^0.667**"), std::string::npos) << md;

  // --law scaling.json on a params.json of the study's REV (108 spheres,
  // its calibrated multipliers and Nstep): 256 spheres get the Nstep the
  // default law gives them.
  const demcal::SceneConfig config =
      demcal::scene_of_size(demcal::load_config(test::shipped_config("fcc_4x4x4")), 108);
  const demcal::TriaxialState state =
      demcal::consolidate_triaxial(config, demcal::make_sphere_assembly(config));
  ASSERT_EQ(state.world.size(), 108);
  const std::string params = test::write_text(
      dir / "params.json", test::params_3d(config, state, rev_best).dump(2) + "\n");
  for (const bool with_law : {true, false}) {
    SCOPED_TRACE(with_law ? "--law scaling.json" : "the default");
    std::vector<std::string> args{"upscale", params, "--particles", "256", "-o", "up.json"};
    if (with_law) args.insert(args.end(), {"--law", (dir / "out" / "scaling.json").string()});
    const test::RunResult u = test::run_demcal(args, dir.path());
    ASSERT_EQ(u.status, 0) << u.err;
    const nlohmann::json up = nlohmann::json::parse(test::read_text(dir / "up.json"));
    EXPECT_EQ(up.at("prototype").at("particles"), 256);
    EXPECT_EQ(up.at("prototype").at("steps").get<int64_t>(), by_law);
    EXPECT_EQ(up.at("upscaling").at("exponent").get<double>(), two_thirds.exponent);
  }
}

// A 3D study recorded the 2D tolerances (force balance 0.008, servo
// 0.0025) in scaling.json and scaling.md, and scored its step searches and
// forward reference with them, while its calibrations used the 3D ones.
// Every run (the calibrations' trials, the fixed-multiplier runs, the
// forward run and its reference) is now scored with triaxial_tolerances(),
// and both files say so: each run's worst excess is its criteria against
// them.
void check_tolerances(const TinyStudy& study) {
  const test::TempDir& dir = study.dir;
  ASSERT_TRUE(study.r.status == 0 || study.r.status == 1) << study.r.err;
  const demcal::Tolerances t = demcal::triaxial_tolerances();
  const nlohmann::json j = nlohmann::json::parse(test::read_text(dir / "out" / "scaling.json"));
  EXPECT_EQ(j.at("tolerances"), demcal::to_json(t));
  const std::string md = test::read_text(dir / "out" / "scaling.md");
  EXPECT_NE(md.find("the 3D default tolerances (force balance 0.0064, moment balance 1e-05 with "
                    "the rotational drag folded in at 0.003, servo 0.002, oscillation 0.001)"),
            std::string::npos)
      << md;
  int runs = 0;
  const auto scored_with_3d = [&](const demcal::TrialRecord& run, const std::string& what) {
    ++runs;
    EXPECT_DOUBLE_EQ(run.score.worst_excess, demcal::excesses(run.score.criteria, t).worst())
        << what << ", " << run.params.steps << " steps";
  };
  for (const auto& size : j.at("results")) {
    const int64_t n = size.at("requested");
    if (size.at("calibrated"))
      for (const auto& trial : demcal::read_trials_text(
               test::read_text(dir / "work" / ("size-" + std::to_string(n)) / "trials.jsonl"),
               "trials.jsonl"))
        scored_with_3d(trial, "calibration trial at " + std::to_string(n));
    if (size.contains("fixed_multipliers"))
      for (const auto& run : size.at("fixed_multipliers").at("runs"))
        scored_with_3d(demcal::trial_from_json(run, "fixed"),
                       "fixed-multiplier run at " + std::to_string(n));
  }
  scored_with_3d(demcal::trial_from_json(j.at("forward").at("run"), "forward"), "forward run");
  scored_with_3d(demcal::trial_from_json(j.at("forward").at("reference"), "reference"),
                 "forward reference");
  EXPECT_GT(runs, 4);
}

TEST(Scaling3D, TinyFccFamilyFitsTheExponentChoosesTheDefaultLawScoredWith3DTolerances) {
  const TinyStudy study;
  {
    SCOPED_TRACE("the fit");
    check_fit(study);
  }
  {
    SCOPED_TRACE("the tolerances");
    check_tolerances(study);
  }
  SCOPED_TRACE("the default law");
  check_default_law(study);
}

}  // namespace
