// The records' one JSON form each (AlgorithmSpec, TrialRecord, a scaling
// size, the certificate), the enums parsed with a clear error, Richardson
// extrapolation against an exact 1/N law, and the library pieces the CLI
// used to hold: params.json's schema, the search's start point, the scaling
// study's plan and report.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "demcal/io/input_error.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/scaling_study.hpp"
#include "support/files.hpp"
#include "support/input_errors.hpp"

using namespace demcal;
using nlohmann::json;

namespace {

/// The message of the InputError `f` throws (the test fails when there is
/// none, and this is "").
std::string input_error_of(const std::function<void()>& f) {
  const auto e = test::input_error(f);
  return e ? e->what() : "";
}

AlgorithmSpec sample_params() {
  AlgorithmSpec p;
  p.dt_ratio = 0.137;
  p.steps = 12345;
  p.damping_ratio_translation = 0.71;
  p.damping_ratio_rotation = 0.0;
  p.mass_scaling = 2.0;
  p.lock_rotation = true;
  return p;
}

TrialRecord sample_trial() {
  TrialRecord t;
  t.id = 7;
  t.phase = TrialPhase::search_tightened;
  t.params = sample_params();
  t.steps_run = 12345;
  t.wall_time_s = 0.25;
  Score& s = t.score;
  s.criteria.force_balance = 0.0031;
  s.criteria.moment_balance = 2.5e-6;
  s.criteria.servo = 0.0012;
  s.criteria.oscillation = 4e-4;
  s.criteria.zigzag = 0.02;
  s.criteria.peak_stress_yy = -6.1e5;
  s.criteria.peak_strain_yy = -0.004;
  s.criteria.points = 199;
  s.criteria.peak_error = 0.013;
  s.passed = true;
  s.worst_excess = 0.4;
  s.completed_fraction = 1.0;
  s.particle_steps = 25.0 * 12345;
  s.diagnosis.message = "quasi-static";
  return t;
}

}  // namespace

TEST(Records, AlgorithmSpecRoundTripsThroughItsOneJsonForm) {
  const AlgorithmSpec p = sample_params();
  const json j = to_json(p);
  EXPECT_EQ(j.size(), 6u);
  const AlgorithmSpec q = algorithm_from_json(j, "x.json");
  EXPECT_EQ(to_json(q), j);
  // The config's block is the same form.
  SceneConfig c = default_config();
  c.algorithm = p;
  EXPECT_EQ(to_json(c).at("algorithm"), j);
}

TEST(Records, AlgorithmSpecReaderNamesFileAndField) {
  json j = to_json(sample_params());
  j["dt_ratio"] = "fast";
  EXPECT_NE(input_error_of([&] {
              algorithm_from_json(j, "trials.jsonl", "params");
            }).find("params.dt_ratio"),
            std::string::npos);
  j = to_json(sample_params());
  j["bogus"] = 1;
  const std::string e = input_error_of([&] { algorithm_from_json(j, "f.json", "params"); });
  EXPECT_NE(e.find("f.json"), std::string::npos);
  EXPECT_NE(e.find("params.bogus"), std::string::npos);
  // Missing keys keep the base (older files without lock_rotation).
  j = to_json(sample_params());
  j.erase("lock_rotation");
  EXPECT_FALSE(algorithm_from_json(j, "f.json").lock_rotation);
}

TEST(Records, StrategiesParseAndUnknownNamesAreBadInput) {
  for (Strategy s : kStrategies) EXPECT_EQ(parse_strategy(to_string(s)), s);
  const std::string e = input_error_of([] { parse_strategy("bogus", "--strategy"); });
  EXPECT_NE(e.find("--strategy"), std::string::npos);
  EXPECT_NE(e.find("bogus"), std::string::npos);
  EXPECT_NE(e.find("cobyla"), std::string::npos);  // the valid names are listed
}

TEST(Records, TrialPhasesParseAndUnknownNamesAreBadInput) {
  for (TrialPhase p : {TrialPhase::search, TrialPhase::search_tightened, TrialPhase::verify,
                       TrialPhase::certificate, TrialPhase::baseline, TrialPhase::reference,
                       TrialPhase::steps_search})
    EXPECT_EQ(parse_trial_phase(to_string(p), "t"), p);
  EXPECT_EQ(to_string(TrialPhase::search_tightened), "search-tightened");
  EXPECT_NE(input_error_of([] { parse_trial_phase("warmup", "t.jsonl"); }).find("warmup"),
            std::string::npos);
}

TEST(Records, TrialRecordRoundTripsAndKeepsItsScore) {
  const TrialRecord t = sample_trial();
  const json j = to_json(t);
  const TrialRecord u = trial_from_json(j, "trials.jsonl: line 1");
  EXPECT_EQ(to_json(u), j);
  EXPECT_EQ(u.phase, TrialPhase::search_tightened);
  EXPECT_EQ(u.score.criteria.peak_error, t.score.criteria.peak_error);
  EXPECT_EQ(u.score.criteria.zigzag, t.score.criteria.zigzag);
  // The score read back drives the search and ranks the trial as the
  // original would.
  const Tolerances tol;
  EXPECT_EQ(constraint_values(u.score, tol), constraint_values(t.score, tol));
  EXPECT_EQ(objective(u.score, tol), objective(t.score, tol));
  EXPECT_EQ(u.score.completed_fraction, t.score.completed_fraction);
  EXPECT_EQ(u.score.diagnosis.message, t.score.diagnosis.message);
}

TEST(Records, ATrialsJsonlLineOfTheEarlierFormatStillResumes) {
  // A line as the previous version wrote it (criteria without the newer
  // fields): it must read, and the missing fields stay at their defaults.
  const json line = json::parse(R"({"complete":true,"criteria":{"force_balance":0.004,
    "moment_balance":1e-6,"servo":0.001,"oscillation":0.0002,"points":199},
    "diagnosis":"quasi-static","diverged":false,"id":3,"params":{"damping_ratio_rotation":1.0,
    "damping_ratio_translation":1.0,"dt_ratio":0.2,"lock_rotation":false,"mass_scaling":1.0,
    "steps":50000},"particle_steps":1250000.0,"passed":true,"peak_strain_yy":-0.004,
    "peak_stress_yy":-612000.0,"phase":"certificate","steps_run":50000,"wall_time_s":0.4,
    "worst_excess":0.5})");
  const TrialRecord t = trial_from_json(line, "old.jsonl");
  EXPECT_EQ(t.params.steps, 50000);
  EXPECT_EQ(t.score.criteria.peak_stress_yy, -612000.0);
  EXPECT_EQ(t.score.criteria.zigzag, 0.0);
  EXPECT_EQ(t.phase, TrialPhase::certificate);
  json bad = line;
  bad["phase"] = "warmup";
  EXPECT_THROW(trial_from_json(bad, "old.jsonl"), InputError);
}

TEST(Records, ACountThatIsNoWholeNumberIsBadInputNotAnOverflow) {
  // The trials.jsonl fuzzer's find: an id of 5.9e110 went through
  // get<int>(), a float-to-int cast out of range (undefined behaviour).
  json line = to_json(sample_trial());
  for (const json& v : {json(5.9e110), json(-1), json(2.5), json("7")}) {
    json bad = line;
    bad["id"] = v;
    EXPECT_THROW(trial_from_json(bad, "t.jsonl"), InputError) << v.dump();
  }
  json steps = line;
  steps["steps_run"] = 1e300;
  EXPECT_THROW(trial_from_json(steps, "t.jsonl"), InputError);
  json points = line;
  points["criteria"]["points"] = -1e20;
  EXPECT_THROW(trial_from_json(points, "t.jsonl"), InputError);
  json whole = line;
  whole["id"] = 12.0;  // a whole number written as a float reads
  EXPECT_EQ(trial_from_json(whole, "t.jsonl").id, 12);
}

TEST(Records, RichardsonRecoversAnExactOneOverNLaw) {
  // P(N) = P∞ + c/N exactly: the extrapolation gives P∞, and the error
  // estimate of the coarse run is its true error.
  const double p_inf = -6.0e5, c = 3.0e9;
  auto P = [&](double n) { return p_inf + c / n; };
  for (double r : {2.0, 4.0}) {
    const double n = 1.0e5;
    EXPECT_NEAR(richardson_limit(n, P(n), r * n, P(r * n)), p_inf, 1e-9 * std::abs(p_inf));
    const double change = std::abs(P(n) - P(r * n)) / std::abs(P(r * n));
    const double true_error = std::abs(P(n) - p_inf) / std::abs(P(r * n));
    EXPECT_NEAR(richardson_error(change, r), true_error, 1e-12);
  }
  EXPECT_EQ(richardson_error(0.01), 0.02);  // Nstep doubled: twice the change
}

TEST(Records, CalibrationOptionsTakeTheirDefaultsFromTheConfigBlock) {
  const CalibrationSpec spec;
  const CalibrationOptions o;
  EXPECT_EQ(o.max_trials, spec.max_trials);
  EXPECT_EQ(o.accuracy, spec.accuracy);
  EXPECT_EQ(o.seed, spec.seed);
  CalibrationSpec custom;
  custom.max_trials = 12;
  custom.accuracy = 0.05;
  custom.seed = 9;
  const CalibrationOptions f = CalibrationOptions::from(custom);
  EXPECT_EQ(f.max_trials, 12);
  EXPECT_EQ(f.accuracy, 0.05);
  EXPECT_EQ(f.seed, 9u);
}

// The search's α range: [dt_ratio_min, 0.95 α_stable] while that is not
// empty (as before 2026-12-04, so those calibrations are unchanged), and
// [½ u, u] with u = 0.95 α_stable where u is below dt_ratio_min (stiff
// contact dashpots): never beyond the stable step.
TEST(Records, TheAlphaRangeNeverPassesTheStableStep) {
  const CalibrationOptions o;
  for (double f : {0.5, 1.0, 1.5, 2.5}) {
    const double u = f * o.dt_ratio_min;
    const double stable = u / o.dt_ratio_safety;
    SCOPED_TRACE(f);
    EXPECT_DOUBLE_EQ(dt_ratio_max(o, stable), u);
    EXPECT_LE(dt_ratio_max(o, stable), stable);
    EXPECT_DOUBLE_EQ(dt_ratio_lower(o, stable), f < 1.0 ? 0.5 * u : o.dt_ratio_min);
    EXPECT_LE(dt_ratio_lower(o, stable), dt_ratio_max(o, stable));
  }
}

TEST(Records, SearchStartIsThePapersRecipeWithASizeBasedNstep) {
  const AlgorithmSpec base = sample_params();
  const AlgorithmSpec s = search_start(base, 100, 0.5);
  EXPECT_EQ(s.dt_ratio, 0.2);
  EXPECT_EQ(s.steps, kStartStepsPerParticle * 100);
  EXPECT_EQ(s.damping_ratio_translation, 1.0);
  EXPECT_EQ(s.damping_ratio_rotation, 1.0);
  EXPECT_EQ(s.mass_scaling, base.mass_scaling);
  EXPECT_EQ(search_start(base, 100, 0.13).dt_ratio, 0.13);  // capped by the stable bound
  EXPECT_EQ(round_steps(6172500.0), 6173000);
  EXPECT_EQ(round_steps(3.0), 10);
}

TEST(Records, ParamsFileCarriesTheCalibratedBlocks) {
  SceneConfig config = default_config();
  config.assembly.columns = config.assembly.rows = 5;
  const ConsolidatedState state = consolidate(config, make_assembly(config));
  CalibrationOptions options = CalibrationOptions::from(config.calibration);
  CalibrationSummary summary;
  summary.success = true;
  summary.message = "calibrated";
  summary.best = sample_params();
  summary.best.lock_rotation = false;
  summary.best_trial = sample_trial();
  summary.trials = {summary.best_trial, summary.best_trial};
  summary.certificate.steps = summary.best.steps;
  summary.certificate.richardson_error = 0.004;
  summary.certificate.passed = true;
  summary.strategy = Strategy::model;
  const json p = params_file(config, state, options, summary);
  EXPECT_EQ(p.at("schema"), "demcal.params/1");
  EXPECT_EQ(p.at("rev").at("dt_ratio"), summary.best.dt_ratio);
  EXPECT_EQ(p.at("rev").at("steps"), summary.best.steps);
  EXPECT_EQ(p.at("rev").at("particles"), state.world.size());
  EXPECT_FALSE(p.at("rev").contains("lock_rotation"));
  EXPECT_EQ(p.at("criteria"), to_json(summary.best_trial.score.criteria));
  EXPECT_EQ(p.at("certificate"), to_json(summary.certificate));
  EXPECT_EQ(p.at("strategy"), "model");
  EXPECT_EQ(p.at("trials"), 2);
  EXPECT_DOUBLE_EQ(p.at("particle_steps_run").get<double>(),
                   2.0 * 12345 * static_cast<double>(state.world.size()));
  EXPECT_TRUE(p.contains("analytical_peak_stress_yy"));  // a hexagonal scene
}

// A prototype from a particle file: the upscaling block counts the file's
// particles, as the prototype block does (it counted config.prototype.
// particles, 0 for a file, so the REV's: particles_prototype 25 and factor 1
// beside a prototype of 100 disks whose Nstep was scaled ×4).
TEST(Records, ParamsFileUpscalesToTheParticlesOfAPrototypeFile) {
  test::TempDir dir("records_proto_file");
  SceneConfig config = default_config();
  config.assembly.columns = config.assembly.rows = 5;
  config.prototype.particles = 0;  // a config names a file or a count
  config.prototype.file = test::write_text(
      dir / "proto.csv", particle_csv(hexagonal_packing(10, 10, config.assembly.radius)));
  const ConsolidatedState state = consolidate(config, make_assembly(config));
  CalibrationSummary summary;
  summary.success = true;
  summary.best = sample_params();
  summary.best_trial = sample_trial();
  const json p = params_file(config, state, CalibrationOptions::from(config.calibration), summary);
  EXPECT_EQ(p.at("prototype").at("particles"), 100);
  EXPECT_EQ(p.at("upscaling").at("particles_prototype"), 100);
  EXPECT_EQ(p.at("upscaling").at("particles_rev"), 25);
}

TEST(Records, EvidenceBlockMeasuresPeakErrorsAgainstTheReference) {
  CalibrationEvidence e;
  e.reference.coarse = e.reference.fine = sample_trial();
  e.reference.peak = -6.0e5;
  TrialRecord best = sample_trial();
  best.score.criteria.peak_stress_yy = -6.3e5;  // 5 % stronger: a positive error
  const json b = evidence_block(e, best);
  EXPECT_NEAR(b.at("reference").at("calibrated_peak_error").get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(*peak_error(best, e.reference.peak), 0.05, 1e-12);
  best.score.diverged = true;
  EXPECT_TRUE(peak_error_json(best, e.reference.peak).is_null());
  best.score.diverged = false;
  best.score.complete = false;  // stopped early: its peak is not the run's
  EXPECT_FALSE(peak_error(best, e.reference.peak));
  const std::string lines = evidence_lines(e);  // the two reference runs, no baseline
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 2);
}

TEST(ScalingStudy, SizesParseSortedAndBadPlansAreBadInput) {
  EXPECT_EQ(parse_sizes("400,25,100"), (std::vector<int64_t>{25, 100, 400}));
  // A size twice is a typo, not a plan.
  EXPECT_NE(input_error_of([] { parse_sizes("400,25,100,25"); }).find("25 given twice"),
            std::string::npos);
  EXPECT_THROW(parse_sizes("25"), InputError);
  EXPECT_THROW(parse_sizes("25,x"), InputError);
  EXPECT_THROW(parse_sizes("2,25"), InputError);
  ScalingStudyOptions o;
  o.sizes = {25, 100, 1600};
  o.calibrate_max = 400;
  EXPECT_NO_THROW(check_scaling_sizes(o));
  o.calibrate_max = 50;  // one calibrated size only
  EXPECT_NE(input_error_of([&] { check_scaling_sizes(o); }).find("--sizes"), std::string::npos);
  // Every size calibrated: no forward check, which is the study's proof.
  o.sizes = {25, 100};
  o.calibrate_max = 400;
  EXPECT_NE(input_error_of([&] {
              check_scaling_sizes(o);
            }).find("the forward check needs a size above --calibrate-max (400)"),
            std::string::npos);
  o.calibrate_max = 100;
  EXPECT_NE(input_error_of([&] { check_scaling_sizes(o); }).find("--calibrate-max (100)"),
            std::string::npos);
  o.calibrate_max = 99;  // 100 is then the forward size, and 25 alone is calibrated
  EXPECT_NE(input_error_of([&] { check_scaling_sizes(o); }).find("two sizes <= --calibrate-max"),
            std::string::npos);
}

// The counts the sizes make on the config's family, checked before any
// consolidation: hexagonal 10x10 resized makes 25 for 25 and for 26.
TEST(ScalingStudy, SizesThatMakeOneCountAreBadInput) {
  const SceneConfig hex = default_config();
  ScalingStudyOptions o;
  o.sizes = {16, 24, 36};  // 16, 25 and 36 particles
  o.calibrate_max = 24;
  EXPECT_NO_THROW(check_scaling_sizes(hex, o));
  o.sizes = {25, 26, 100};
  o.calibrate_max = 26;
  EXPECT_EQ(input_error_of([&] { check_scaling_sizes(hex, o); }),
            "--sizes: 25 and 26 both make 25 particles (a hexagonal lattice of whole columns and "
            "rows): each size must make a count of its own");
  // The plan is checked first, as before.
  o.calibrate_max = 25;
  EXPECT_NE(input_error_of([&] { check_scaling_sizes(hex, o); }).find("two sizes"),
            std::string::npos);
}

// run_scaling_study on a config alone checks it as `demcal scaling` does
// (check_scaling_sizes) before it writes anything; a checked study (whose
// assemblies were made and checked once, by the check) runs only the sizes
// it was checked with.
TEST(ScalingStudy, ARunChecksItsSizesFirstAndRunsOnlyTheCheckedOnes) {
  test::TempDir dir("scaling_run_checks");
  SceneConfig hex = default_config();
  hex.test.lateral_stress = 4e-3;  // unresolvable at 3600 particles
  ScalingStudyOptions o;
  o.sizes = {400, 900, 3600};
  o.calibrate_max = 900;
  o.work_dir = (dir / "work").string();
  EXPECT_NE(input_error_of([&] { run_scaling_study(hex, o); }).find("size 3600's assembly"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(o.work_dir));
  hex = default_config();
  CheckedScalingStudy checked = check_scaling_sizes(hex, o);
  ScalingStudyOptions other = o;
  other.sizes = {400, 900, 1600};
  EXPECT_THROW(run_scaling_study(std::move(checked), other), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(o.work_dir));
}

TEST(ScalingStudy, SpreadIsRangeOverMean) {
  const Spread s = spread_of({0.1, 0.2, 0.3});
  EXPECT_DOUBLE_EQ(s.mean, 0.2);
  EXPECT_DOUBLE_EQ(s.relative, 1.0);
  EXPECT_EQ(spread_of({}).relative, 0.0);
}

TEST(ScalingStudy, ASizeRoundTripsThroughItsJson) {
  ScalingSize r;
  r.requested = 100;
  r.particles = 100;
  r.calibrated = true;
  r.success = true;
  r.best = sample_params();
  r.richardson = 0.01;
  r.peak = -6e5;
  r.trials = 30;
  r.fixed.found = true;
  r.fixed.steps = 12345;
  r.fixed.best = sample_trial();
  r.fixed.trials = {sample_trial(), sample_trial()};
  const json j = to_json(r);
  EXPECT_EQ(to_json(scaling_size_from_json(j, "result.json")), j);
  EXPECT_THROW(scaling_size_from_json(json{{"particles", 3}}, "result.json"), InputError);
}

// A resumed study reads its sizes back from result.json and fixed.json:
// a count there that is no whole number in range is the file's error,
// naming the key (never a float-to-int cast of 5.9e110).
TEST(ScalingStudy, ACountInAStoredSizeThatIsNoCountIsNamed) {
  ScalingSize r;
  r.requested = r.particles = 100;
  r.calibrated = true;
  r.best = sample_params();
  r.trials = 30;
  r.consolidation.steps = 4000;
  r.fixed.found = true;
  r.fixed.steps = 12345;
  r.fixed.best = sample_trial();
  r.fixed.trials = {sample_trial()};
  r.consolidation.wall_time_s = 0.5;
  r.consolidation.from_cache = true;
  const json good = to_json(r);
  ASSERT_NO_THROW(scaling_size_from_json(good, "result.json"));
  // The consolidation's record reads back whole (a resumed study's sizes).
  const ScalingSize back = scaling_size_from_json(good, "result.json");
  EXPECT_EQ(back.consolidation.steps, 4000);
  EXPECT_EQ(back.consolidation.wall_time_s, 0.5);
  EXPECT_TRUE(back.consolidation.from_cache);
  const std::vector<std::pair<std::string, std::string>> counts = {
      {"/requested", "requested"},
      {"/particles", "particles"},
      {"/trials", "trials"},
      {"/consolidation_steps", "consolidation_steps"},
      {"/fixed_multipliers/steps", "fixed_multipliers.steps"}};
  for (const auto& [pointer, field] : counts)
    for (const json& v : {json(5.9e110), json(-1), json(2.5), json("7")}) {
      json bad = good;
      bad[json::json_pointer(pointer)] = v;
      SCOPED_TRACE(::testing::Message() << pointer << " = " << v.dump());
      const auto e = test::input_error([&] { scaling_size_from_json(bad, "result.json"); });
      ASSERT_TRUE(e);
      EXPECT_EQ(e->file(), "result.json");
      EXPECT_EQ(e->field(), field) << e->what();
    }
  // The consolidation's time and label of the wrong type are named too
  // (were "not a demcal scaling result: [json.exception.type_error.302]").
  for (const auto& [field, v] :
       std::vector<std::pair<std::string, json>>{{"consolidation_wall_time_s", json("0.5")},
                                                 {"consolidation_from_cache", json(1)},
                                                 {"consolidation_from_cache", json("true")}}) {
    json bad = good;
    bad[field] = v;
    SCOPED_TRACE(::testing::Message() << field << " = " << v.dump());
    const auto e = test::input_error([&] { scaling_size_from_json(bad, "result.json"); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), "result.json");
    EXPECT_EQ(e->field(), field) << e->what();
  }
  // A size of an older demcal (no consolidation keys) still reads.
  json older = good;
  for (const char* k :
       {"consolidation_steps", "consolidation_wall_time_s", "consolidation_from_cache"})
    older.erase(k);
  const ScalingSize old_size = scaling_size_from_json(older, "result.json");
  EXPECT_EQ(old_size.consolidation.steps, 0);
  EXPECT_FALSE(old_size.consolidation.from_cache);
  json whole = good;
  whole["particles"] = 100.0;  // a whole number written as a float reads
  EXPECT_EQ(scaling_size_from_json(whole, "result.json").particles, 100);
}

TEST(ScalingStudy, ReportStatesTheVerdictAndTheLaw) {
  // A synthetic study: two calibrated sizes and a forward size where
  // Nstep grows exactly linearly.
  ScalingStudy st;
  st.scene = "hex";
  st.sizes = {25, 100, 400};
  st.sizes_text = "25,100,400";
  st.calibrated_sizes = {25, 100};
  st.calibrate_max = 100;
  st.ref_size = 100;
  st.forward_size = 400;
  for (int64_t n : st.sizes) {
    ScalingSize& r = st.results[n];
    r.requested = r.particles = n;
    r.calibrated = n <= 100;
    r.success = r.calibrated;
    r.best = sample_params();
    r.best.steps = 500 * n;
    r.fixed.found = true;
    r.fixed.steps = 500 * n;
  }
  st.have_forward = st.forward_ok = true;
  st.law_run = st.reference = sample_trial();
  st.law_peak_error = 0.004;
  st.measured.exponent = 1.0;
  st.linear_holds = true;
  st.accuracy = 0.02;
  const SceneConfig config = default_config();
  const std::string md = scaling_markdown(st, config);
  EXPECT_NE(md.find("Forward check of the linear law (Tu & Andrade) at 400 particles: **passed**"),
            std::string::npos);
  EXPECT_NE(md.find("the linear law holds"), std::string::npos);
  EXPECT_NE(md.find("peak 0.4 % from the reference, target ±2 %"), std::string::npos);
  // The law's Nstep, and the run's where round_steps moved it (it printed
  // the run's as the product: "92870 × 1600/400 = 371500").
  st.law_run.params.steps = 200000;
  EXPECT_NE(scaling_markdown(st, config).find("Nstep = 50000 × 400/100 = 200000; scored"),
            std::string::npos);
  st.results[100].best.steps = 46435;
  st.law_run.params.steps = round_steps(4.0 * 46435);
  EXPECT_NE(scaling_markdown(st, config)
                .find("Nstep = 46435 × 400/100 = 185740, run as 185700 (four significant "
                      "digits); scored"),
            std::string::npos);
  const json j = to_json(st, config);
  EXPECT_EQ(j.at("law").at("law"), "linear");
  EXPECT_EQ(j.at("forward").at("passed"), true);
  EXPECT_EQ(j.at("results").size(), 3u);
}
