// Scoring and diagnosis on short real runs of hex_10x10, and the sweep
// (issue #4 §3–§4). The clear-cut cases our kernel shows: Δt beyond the
// rotational stability limit (α = 0.32: rotational chatter, σxy ≠ σyx),
// Nstep far too small, D_r far too large. The identity V·(b − σ) =
// Σ_p x^p ⊗ F^p (World::net_force_moment()) is used by the scoring's
// consistency check, and checked here on the final states.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/sweep.hpp"
#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

// hex_10x10, consolidated once for the whole file (a few ms).
struct Hex {
  SceneConfig config;
  std::unique_ptr<ConsolidatedState> state;
};
const Hex& hex() {
  static const Hex h = [] {
    Hex x;
    x.config = load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/hex_10x10.json");
    x.state = std::make_unique<ConsolidatedState>(consolidate(x.config, make_assembly(x.config)));
    return x;
  }();
  return h;
}

struct Trial {
  LoadingResult run;
  Score score;
  World final_state;
};
Trial trial(const AlgorithmSpec& a) {
  const Hex& h = hex();
  World final_state = h.state->world;
  LoadingResult run = run_loading(*h.state, h.config.test, a, {}, &final_state);
  Score score = score_run(run, h.config.test.lateral_stress, Tolerances{});
  return {std::move(run), score, std::move(final_state)};
}

// Beyond the rotational stable step the rotational mode does not blow up
// here: sliding contacts and damping bound it to a rattle. The kernel's
// energy ledger flags it as diverged within a few hundred steps.
TEST(ScoringRealRuns, DtBeyondRotationalLimitIsDivergedByTheEnergyLedger) {
  AlgorithmSpec a;
  a.dt_ratio = 0.32;  // stable limit of the rotational mode ≈ 0.29 here
  a.steps = 20000;
  const Trial t = trial(a);
  ASSERT_TRUE(t.run.diverged);
  EXPECT_EQ(t.run.divergence, Divergence::kEnergyCreated);
  EXPECT_LT(t.run.divergence_step, 1000);
  EXPECT_FALSE(t.score.passed);
  EXPECT_EQ(t.score.diagnosis.parameter, "dt");
  EXPECT_EQ(t.score.diagnosis.direction, "decrease");
}

// The same run without the ledger: the scoring alone still sees the rattle
// (moment imbalance of the order of σ3, rotational kinetic energy) and
// blames Δt.
TEST(ScoringRealRuns, DtBeyondRotationalLimitIsDiagnosedAsDtWithoutTheLedger) {
  const Hex& h = hex();
  ConsolidatedState state = *h.state;
  KernelOptions options = state.world.options();
  options.max_energy_created = std::numeric_limits<double>::infinity();
  state.world.set_options(options);
  AlgorithmSpec a;
  a.dt_ratio = 0.32;
  a.steps = 20000;
  const LoadingResult run = run_loading(state, h.config.test, a);
  const Score score = score_run(run, h.config.test.lateral_stress, Tolerances{});
  ASSERT_FALSE(run.diverged);
  const Criteria& c = score.criteria;
  EXPECT_GT(c.moment_balance, 0.01);  // σxy ≠ σyx, of the order of σ3
  EXPECT_GT(c.rotational_energy_share, 0.3);
  EXPECT_FALSE(score.passed);
  EXPECT_EQ(score.diagnosis.parameter, "dt");
  EXPECT_EQ(score.diagnosis.direction, "decrease");
  EXPECT_GE(score.diagnosis.confidence, 0.7);
}

TEST(ScoringRealRuns, NstepFarTooSmallIsDiagnosedAsSteps) {
  AlgorithmSpec a;
  a.steps = 5000;  // 1/20 of the default
  const Trial t = trial(a);
  const Criteria& c = t.score.criteria;
  EXPECT_GT(c.force_balance, 10 * Tolerances{}.force_balance);
  EXPECT_GT(c.servo, Tolerances{}.servo);
  EXPECT_LT(c.rotational_energy_share, 0.3);
  EXPECT_EQ(t.score.diagnosis.parameter, "steps");
  EXPECT_EQ(t.score.diagnosis.direction, "increase");
  // The paper's form still reads about 1 %: it cannot see this.
  EXPECT_LT(c.force_balance_paper, 0.02);
}

TEST(ScoringRealRuns, RotationalDampingFarTooLargeIsDiagnosedAsDr) {
  AlgorithmSpec a;
  a.damping_ratio_rotation = 20.0;
  const Trial t = trial(a);
  const Criteria& c = t.score.criteria;
  EXPECT_GT(c.moment_balance, 10 * Tolerances{}.moment_balance);
  EXPECT_LT(c.moment_balance, 0.01);  // steady and small: no chatter
  EXPECT_LT(c.rotational_energy_share, 0.3);
  EXPECT_EQ(t.score.diagnosis.parameter, "damping_rotation");
  EXPECT_EQ(t.score.diagnosis.direction, "decrease");
}

TEST(ScoringRealRuns, SlowLightlyDampedRunPasses) {
  AlgorithmSpec a;
  a.steps = 200000;
  a.damping_ratio_translation = 0.3;
  a.damping_ratio_rotation = 0.0;
  const Trial t = trial(a);
  EXPECT_TRUE(t.score.passed) << to_json(t.score.criteria).dump();
  EXPECT_EQ(t.score.diagnosis.parameter, "none");
  EXPECT_GT(objective(t.score, Tolerances{}), 0.0);
  EXPECT_LT(objective(t.score, Tolerances{}), 1.0);
}

TEST(ScoringRealRuns, GapIdentityHoldsOnFinalStates) {
  // force_balance_gap() is net_force_moment(); it equals b − σ of measure().
  AlgorithmSpec a;
  a.steps = 5000;
  const Trial t = trial(a);
  EXPECT_LT(gap_identity_residual(t.final_state), 1e-9);
  const Measures m = t.final_state.measure();
  const Eigen::Matrix2d gap = force_balance_gap(t.final_state);
  EXPECT_LT((gap - (m.boundary_stress - m.homogenized_stress)).norm(),
            1e-9 * m.boundary_stress.norm());
  // And the last monitoring point's lateral gap is that of the final state.
  const auto& last = t.run.series.back();
  EXPECT_NEAR(last.b(0, 0) - last.sigma(0, 0), gap(0, 0), 1e-6 * std::abs(last.b(0, 0)));
}

// --- the sweep -----------------------------------------------------------

TEST(Sweep, CasesChangeOneParameterAtATime) {
  AlgorithmSpec b;
  b.steps = 120000;
  const auto cases = atlas_cases(b, 0.29, false);
  std::set<std::string> names;
  for (const auto& c : cases) EXPECT_TRUE(names.insert(c.name).second) << c.name;
  auto find = [&](const std::string& n) -> const SweepCase& {
    for (const auto& c : cases)
      if (c.name == n) return c;
    ADD_FAILURE() << "missing " << n;
    return cases.front();
  };
  EXPECT_EQ(find("steps_x1_6").algorithm.steps, 20000);
  EXPECT_EQ(find("steps_x33").algorithm.steps, 120000 * 33);
  EXPECT_DOUBLE_EQ(find("dt_x0.1").algorithm.dt_ratio, 0.02);
  EXPECT_DOUBLE_EQ(find("dt_x1.5").algorithm.dt_ratio, 0.3);
  EXPECT_DOUBLE_EQ(find("zeta_t_x0.7").algorithm.damping_ratio_translation, 0.7);
  EXPECT_DOUBLE_EQ(find("zeta_t_x4.3").algorithm.damping_ratio_translation, 4.3);
  EXPECT_DOUBLE_EQ(find("zeta_r_x0").algorithm.damping_ratio_rotation, 0.0);
  EXPECT_DOUBLE_EQ(find("zeta_r_x2").algorithm.damping_ratio_rotation, 2.0);
  const auto& m4 = find("mass_1e4_undamped").algorithm;
  EXPECT_DOUBLE_EQ(m4.mass_scaling, 1e4);
  EXPECT_DOUBLE_EQ(m4.damping_ratio_translation, 0.0);
  EXPECT_DOUBLE_EQ(m4.damping_ratio_rotation, 0.0);
  EXPECT_NEAR(m4.dt_ratio * std::sqrt(m4.mass_scaling), b.dt_ratio, 1e-12);  // same Δt
  EXPECT_DOUBLE_EQ(find("mass_1e8_undamped").algorithm.mass_scaling, 1e8);
  for (int f : {2, 4, 8, 16})
    EXPECT_EQ(find("steps_x" + std::to_string(f)).algorithm.steps, 120000 * f);
  // α scan: same loading time, up to beyond the stable limit.
  double alpha_max = 0.0;
  for (const auto& c : cases) {
    if (c.group != "alpha_scan") continue;
    alpha_max = std::max(alpha_max, c.algorithm.dt_ratio);
    EXPECT_NEAR(c.algorithm.dt_ratio * static_cast<double>(c.algorithm.steps),
                b.dt_ratio * static_cast<double>(b.steps), 2.0 * c.algorithm.dt_ratio);
  }
  EXPECT_GT(alpha_max, 1.3 * 0.29);
  // Everything else equal to the benchmark in the one-at-a-time cases.
  const auto& z = find("zeta_t_x4.3").algorithm;
  EXPECT_EQ(z.steps, b.steps);
  EXPECT_DOUBLE_EQ(z.dt_ratio, b.dt_ratio);
  EXPECT_DOUBLE_EQ(z.damping_ratio_rotation, b.damping_ratio_rotation);
  EXPECT_GT(atlas_cases(b, 0.29, true).size(), cases.size());
}

TEST(Sweep, RichardsonReferenceIsExactForOneOverNErrors) {
  // p(N) = p∞ + c/N.
  const double p_inf = -6.2e5, c = 2e9;
  std::vector<std::pair<int64_t, double>> peaks;
  for (int64_t n : {400000, 100000, 200000, 3300000, 800000, 1600000})
    peaks.emplace_back(n, p_inf + c / static_cast<double>(n));
  const ConvergedReference r = converged_reference(peaks, 0.005);
  ASSERT_EQ(r.ladder.size(), 6u);
  EXPECT_EQ(r.ladder.front().steps, 100000);  // sorted
  EXPECT_NEAR(r.peak_stress_yy, p_inf, 1e-6 * std::abs(p_inf));
  for (size_t i = 1; i < r.ladder.size(); ++i)
    EXPECT_NEAR(r.ladder[i].richardson, p_inf, 1e-6 * std::abs(p_inf));
  EXPECT_TRUE(r.converged);
  // Far from converged: the last doubling still moves the peak by 10 %.
  const ConvergedReference far = converged_reference({{1000, -1.2e5}, {2000, -1.1e5}}, 0.005);
  EXPECT_FALSE(far.converged);
}

TEST(Sweep, RunsInParallelAndScoresAgainstTheLadder) {
  const Hex& h = hex();
  SceneConfig config = h.config;
  config.algorithm.steps = 10000;
  AlgorithmSpec b = config.algorithm;
  std::vector<SweepCase> cases;
  cases.push_back({"benchmark", "benchmark", "none", "", b});
  for (int f : {2, 4}) {
    AlgorithmSpec a = b;
    a.steps = b.steps * f;
    cases.push_back({"steps_x" + std::to_string(f), "convergence", "", "", a});
  }
  AlgorithmSpec chatter = b;
  chatter.dt_ratio = 0.33;
  cases.push_back({"dt_x1.65", "atlas", "dt x1.65", "chatter", chatter});
  AlgorithmSpec diverge = b;
  diverge.dt_ratio = 0.9;
  diverge.damping_ratio_translation = 0.0;
  diverge.damping_ratio_rotation = 0.0;
  cases.push_back({"dt_x4.5", "atlas", "dt x4.5", "divergence", diverge});

  SweepSettings settings;
  settings.jobs = 2;
  int calls = 0;
  settings.progress = [&](int k, int n, const std::string&, double) {
    ++calls;
    EXPECT_LE(k, n);
  };
  const SweepResult r = run_sweep(config, *h.state, cases, settings);
  EXPECT_EQ(calls, 5);
  ASSERT_EQ(r.cases.size(), cases.size());
  for (size_t i = 0; i < cases.size(); ++i) EXPECT_EQ(r.cases[i].spec.name, cases[i].name);
  ASSERT_EQ(r.reference.ladder.size(), 3u);
  EXPECT_LT(r.reference.peak_stress_yy, 0.0);
  // Faster loading, higher peak: the benchmark over-predicts.
  ASSERT_TRUE(r.cases[0].score.criteria.peak_error.has_value());
  EXPECT_GT(*r.cases[0].score.criteria.peak_error, 0.0);
  EXPECT_EQ(r.cases[3].score.diagnosis.parameter, "dt");
  EXPECT_TRUE(r.cases[4].run.diverged);
  EXPECT_EQ(r.cases[4].score.diagnosis.parameter, "dt");
  EXPECT_GT(objective(r.cases[4].score, r.tolerances), 2.0);
  for (const auto& c : r.cases)
    if (!c.run.diverged) {
      EXPECT_LT(c.identity_residual, 1e-9) << c.spec.name;
    }
  EXPECT_EQ(r.evidence.size(), 15u);

  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["schema"], "demcal.sweep/1");
  EXPECT_EQ(j["cases"].size(), cases.size());
  const std::string md = atlas_markdown(r);
  EXPECT_NE(md.find("| benchmark |"), std::string::npos);
  EXPECT_NE(md.find("diverged"), std::string::npos);
  const std::string csv = evidence_csv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), static_cast<long>(cases.size()) + 1);
}

TEST(Sweep, CommandWritesTheAtlas) {
  // hex_5x5 at a benchmark of 2000 steps: the whole atlas in about a second.
  const test::TempDir tmp("sweep");
  const fs::path dir = tmp / "atlas";
  // An earlier sweep's case that this one has not (its alpha scan was
  // another's): gone with the rest; the user's own files stay.
  fs::create_directories(dir / "series");
  std::ofstream(dir / "series" / "alpha_0.999.csv") << "an earlier sweep's\n";
  std::ofstream(dir / "series" / "notes.txt") << "mine\n";
  std::ofstream(dir / "series" / "my_probe.csv") << "mine too\n";
  const test::RunResult r =
      test::run_demcal({"sweep", test::shipped_config("hex_5x5"), "--set", "algorithm.steps=2000",
                        "--jobs", "2", "-o", dir.string()},
                       tmp.path());
  ASSERT_NE(r.status, -1);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "series" / "alpha_0.999.csv"));
  EXPECT_TRUE(fs::exists(dir / "series" / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "series" / "my_probe.csv"));
  for (const char* f : {"atlas.md", "atlas.json", "evidence.csv", "series/benchmark.csv",
                        "series/steps_x33.csv", "series/mass_1e8_undamped.csv"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  std::ifstream in(dir / "atlas.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["scene"], "hex_5x5");
  EXPECT_GT(j["cases"].size(), 60u);
  EXPECT_EQ(j["benchmark"]["steps"], 2000);
  // A case's series carries its run's metadata: `demcal score` on it, no
  // option, gives the case's peak (the step-level one) and verdict.
  const test::RunResult sc =
      test::run_demcal({"score", "benchmark.csv", "-o", "scored"}, dir / "series");
  ASSERT_TRUE(sc.status == 0 || sc.status == 1) << sc.err << sc.out;
  std::ifstream scored_in(dir / "series" / "scored" / "summary.json");
  const nlohmann::json scored = nlohmann::json::parse(scored_in);
  for (const auto& c : j["cases"])
    if (c["name"] == "benchmark") {
      EXPECT_EQ(scored["criteria"]["peak_stress_yy"], c["criteria"]["peak_stress_yy"]);
      EXPECT_EQ(scored["passed"], c["passed"]);
    }
}

// `demcal sweep` says how long its one consolidation took, as check, run,
// verify and export say it (print_consolidation_time): a fresh one's time,
// a cached one's "read from the cache in T s" (it said "(once)" and "(once,
// from the cache)", no time).
// A sweep of hex_5x5 into tmp/out with tmp/cache as the consolidation
// cache: the first consolidates, the next reads the state back.
test::RunResult sweep_with_cache(const test::TempDir& tmp, const char* out) {
  const test::RunResult r =
      test::run_program("/usr/bin/env",
                        {"DEMCAL_CACHE_DIR=" + (tmp / "cache").string(), test::kDemcalBinary,
                         "sweep", test::shipped_config("hex_5x5"), "--set", "algorithm.steps=2000",
                         "--jobs", "2", "-o", (tmp / out).string()},
                        tmp.path());
  EXPECT_EQ(r.status, 0) << r.err;
  return r;
}

TEST(Sweep, CommandSaysItsConsolidationTimeAsTheOtherCommands) {
  const test::TempDir tmp("sweepcache");
  auto sweep_line = [&](const char* out) {
    const test::RunResult r = sweep_with_cache(tmp, out);
    for (const std::string& line : test::lines_of(r.err))
      if (line.rfind("sweep hex_5x5: ", 0) == 0) return line;
    return "no sweep line in: " + r.err;
  };
  const std::string fresh = sweep_line("miss");
  const std::string read = sweep_line("hit");
  const size_t open = fresh.find(" steps (");
  ASSERT_NE(open, std::string::npos) << fresh;
  EXPECT_NE(fresh.find(" particles consolidated once, in "), std::string::npos) << fresh;
  // The same steps, then the fresh one's time, the cached one's reading.
  const std::string steps = fresh.substr(0, open + 8);
  EXPECT_EQ(fresh.find("cache"), std::string::npos) << fresh;
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(fresh[open + 8]))) << fresh;
  EXPECT_NE(fresh.find(" s); "), std::string::npos) << fresh;
  EXPECT_EQ(read.rfind(steps + "read from the cache in ", 0), 0u) << read;
  EXPECT_NE(read.find(" s); "), std::string::npos) << read;
}

// atlas.json and atlas.md say where the sweep's consolidation came from:
// atlas.json's "consolidation" block is consolidation_json's record (steps,
// wall_time_s, from_cache; consolidation_time_s kept), atlas.md's last line
// "(consolidation read from the cache in T s, once)" for a cache read (both
// recorded the reading's time as the consolidation's, unlabelled).
TEST(Sweep, AtlasRecordsAConsolidationFromTheCache) {
  const test::TempDir tmp("sweepatlascache");
  sweep_with_cache(tmp, "miss");
  sweep_with_cache(tmp, "hit");
  const nlohmann::json fresh = test::read_json(tmp / "miss" / "atlas.json");
  const nlohmann::json read = test::read_json(tmp / "hit" / "atlas.json");
  ASSERT_TRUE(fresh.contains("consolidation")) << fresh.dump(1).substr(0, 2000);
  EXPECT_FALSE(fresh["consolidation"].at("from_cache").get<bool>());
  EXPECT_TRUE(read.at("consolidation").at("from_cache").get<bool>());
  EXPECT_GT(fresh["consolidation"].at("steps").get<int64_t>(), 0);
  EXPECT_EQ(read["consolidation"]["steps"], fresh["consolidation"]["steps"]);
  for (const nlohmann::json* j : {&fresh, &read})
    EXPECT_EQ(j->at("consolidation_time_s"), j->at("consolidation").at("wall_time_s"));
  auto last_line = [&](const char* out) {
    const std::vector<std::string> lines = test::lines_of(test::read_text(tmp / out / "atlas.md"));
    return lines.empty() ? std::string() : lines.back();
  };
  const std::string fresh_md = last_line("miss"), read_md = last_line("hit");
  EXPECT_NE(fresh_md.find(" threads (consolidation "), std::string::npos) << fresh_md;
  EXPECT_EQ(fresh_md.find("cache"), std::string::npos) << fresh_md;
  EXPECT_NE(read_md.find(" threads (consolidation read from the cache in "), std::string::npos)
      << read_md;
  EXPECT_NE(read_md.find(" s, once)."), std::string::npos) << read_md;
}

}  // namespace
}  // namespace demcal
