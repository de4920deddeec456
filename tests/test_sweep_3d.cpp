// The signature atlas and the stability scan on a triaxial (sphere) REV
// (issue #18): the same sweep as in 2D (search/sweep.hpp), scored by the 3D
// criteria, with the per-plane columns; one of the paper's signatures with
// its physical direction; the measured stable step against the estimate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/stability_scan.hpp"
#include "demcal/search/sweep.hpp"
#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

// FCC 3×3×3 (108 spheres), the material, test and benchmark of
// configs/fcc_4x4x4.json.
std::string fcc_config(int cells) {
  const std::string n = std::to_string(cells);
  return R"({
  "name": "fcc_)" +
         n + "x" + n + "x" + n + R"(", "dimension": 3,
  "material": {"density": 2650, "kn": 1e8, "kt": 5e7, "friction": 0.3,
               "wall": {"kn": 1e8, "kt": 5e7, "friction": 0.0}},
  "assembly": {"type": "fcc", "cells_x": )" +
         n + R"(, "cells_y": )" + n + R"(, "cells_z": )" + n + R"(, "radius": 5e-4},
  "test": {"type": "triaxial", "lateral_stress": 1e5, "vertical_strain": 1e-5,
           "monitor_points": 200},
  "algorithm": {"dt_ratio": 0.2, "steps": 40000, "damping_ratio_translation": 1.0,
                "damping_ratio_rotation": 1.0},
  "calibration": {"accuracy": 0.02, "seed": 1}})";
}

struct Fcc {
  SceneConfig config;
  std::unique_ptr<TriaxialState> state;
};
const Fcc& fcc3() {
  static const Fcc f = [] {
    Fcc x;
    x.config = parse_config_text(fcc_config(3), "fcc_3x3x3");
    x.state = std::make_unique<TriaxialState>(
        consolidate_triaxial(x.config, make_sphere_assembly(x.config)));
    return x;
  }();
  return f;
}

const SweepCaseResult& find(const SweepResult& r, const std::string& name) {
  for (const auto& c : r.cases)
    if (c.spec.name == name) return c;
  ADD_FAILURE() << "missing " << name;
  return r.cases.front();
}

// The paper's first signature, Nstep (or Δt at fixed Nstep) too small: b and
// σ part, and the peak is over-predicted. With viscous damping and the walls'
// constant speed, the gap b − σ is the particles' viscous drag, proportional
// to the loading rate (their inertia is second order in it): a loading 4×
// faster (Nstep/4) and one 10× faster (Δt/10 at the same Nstep) make gaps
// 4× and 10× the benchmark's (measured 4.00× and 10.00×; the axial one
// 9.6×). Asserted to 10 %, room for the rate's higher-order terms and the
// noise floor subtracted from each trend; and the faster the loading, the
// more the peak is over-predicted
// (measured +1.7 %, +6.9 %, +15 %).
TEST(Sweep3D, FasterLoadingOpensTheForceBalanceGapAndOverPredictsThePeak) {
  const Fcc& f = fcc3();
  AlgorithmSpec b = f.config.algorithm;
  b.steps = 20000;  // half the config's: the ladder to 4x in a few seconds
  std::vector<SweepCase> cases;
  cases.push_back({"benchmark", "benchmark", "none", "", b});
  for (int k : {2, 4}) {
    AlgorithmSpec a = b;
    a.steps = b.steps * k;
    cases.push_back({"steps_x" + std::to_string(k), "convergence", "", "", a});
  }
  AlgorithmSpec quarter = b;
  quarter.steps = b.steps / 4;
  cases.push_back({"steps_x1_4", "atlas", "Nstep x1/4", "gap", quarter});
  AlgorithmSpec small_dt = b;
  small_dt.dt_ratio = b.dt_ratio * 0.1;
  cases.push_back({"dt_x0.1", "atlas", "dt x0.1", "gap", small_dt});
  SweepSettings settings;
  settings.jobs = 2;
  const SweepResult r = run_sweep(f.config, *f.state, cases, settings);
  EXPECT_EQ(r.dimension, 3);
  EXPECT_EQ(r.particles, 108);
  ASSERT_EQ(r.reference.ladder.size(), 3u);
  const double ref = r.reference.peak_stress_yy;
  EXPECT_LT(ref, -f.config.test.lateral_stress);  // compressive, above σ3

  const Criteria& c1 = find(r, "benchmark").score.criteria;
  const Criteria& c4 = find(r, "steps_x1_4").score.criteria;
  const Criteria& c10 = find(r, "dt_x0.1").score.criteria;
  ASSERT_GT(c1.force_balance, 0.0);
  EXPECT_NEAR(c4.force_balance / c1.force_balance, 4.0, 0.4);
  EXPECT_NEAR(c10.force_balance / c1.force_balance, 10.0, 1.0);
  // Lateral and axial components alike (the axial on |b_zz|'s scale).
  EXPECT_NEAR(c10.force_balance_yy / c1.force_balance_yy, 10.0, 1.0);
  ASSERT_TRUE(c1.peak_error && c4.peak_error && c10.peak_error);
  EXPECT_GT(*c4.peak_error, *c1.peak_error);
  EXPECT_GT(*c10.peak_error, *c4.peak_error);
  EXPECT_GT(*c1.peak_error, 0.0);
  // Every trial's final state satisfies V·(b − σ) = Σ x ⊗ F (spheres).
  for (const auto& c : r.cases) {
    EXPECT_FALSE(c.run.diverged) << c.spec.name;
    EXPECT_LT(c.identity_residual, 1e-9) << c.spec.name;
    ASSERT_TRUE(c.planes.has_value()) << c.spec.name;
    // The combined criteria are the planes' largest, with the rotational
    // drag folded into moment balance (scored_criteria).
    const double planes_max = std::max(
        {c.planes->xz.moment_balance, c.planes->yz.moment_balance, c.planes->xy.moment_balance});
    EXPECT_GE(c.score.criteria.moment_balance, planes_max);
    EXPECT_EQ(c.score.criteria.moment_balance,
              scored_criteria(*c.planes, r.tolerances).moment_balance);
  }
}

// The explicit scheme is stable for ω_max·Δt < 2 (6 DOF per sphere): with
// the damping of the benchmark, the runs diverge where the Lanczos estimate
// says, to the bisection's resolution and the estimate's ~1 % (as in 2D,
// test_stability_scan.cpp); the Gershgorin bound is below the limit.
TEST(Sweep3D, StabilityScanMeasuresTheEstimatedLimit) {
  const Fcc& f = fcc3();
  StabilityScanOptions options;
  options.from = 0.7;
  options.to = 1.6;
  options.points = 10;
  options.steps = 20000;
  options.jobs = 2;
  const StabilityScanResult r = stability_scan(f.config, *f.state, options);
  EXPECT_EQ(r.dimension, 3);
  ASSERT_GT(r.dt_ratio_first_diverged, 0.0);
  EXPECT_EQ(r.stable_above_limit, 0);
  EXPECT_NEAR(r.ratio(), 1.0, 0.03);
  EXPECT_LE(r.dt_ratio_gershgorin, r.dt_ratio_last_stable);
  for (const auto& t : r.trials) {
    EXPECT_EQ(t.diverged, t.dt_ratio > r.dt_ratio_last_stable) << t.dt_ratio;
    if (t.diverged) {
      EXPECT_GT(t.divergence_step, 0);
    }
  }
}

// `demcal sweep` and `demcal stability` on a 3D config: FCC 2×2×2 at a
// benchmark of 2000 steps, the whole atlas in about a second.
TEST(Sweep3D, CommandsWriteTheAtlasWithThe3DColumns) {
  const test::TempDir tmp("sweep3d");
  const fs::path config = tmp / "fcc2.json";
  test::write_text(config, fcc_config(2));
  const fs::path dir = tmp / "atlas";
  const test::RunResult r =
      test::run_demcal({"sweep", config.string(), "--set", "algorithm.steps=2000", "--jobs", "2",
                        "-o", dir.string()},
                       tmp.path());
  ASSERT_NE(r.status, -1);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"atlas.md", "atlas.json", "evidence.csv", "series/benchmark.csv",
                        "series/steps_x33.csv", "series/zeta_r_x2.csv"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  std::ifstream in(dir / "atlas.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["dimension"], 3);
  EXPECT_EQ(j["particles"], 32);
  EXPECT_GT(j["cases"].size(), 60u);
  EXPECT_TRUE(j["cases"][0]["planes"].contains("xy"));
  EXPECT_EQ(j["cases"][0]["planes"]["servo_walls"].size(), 4u);
  const std::string md = test::read_text(dir / "atlas.md");
  EXPECT_NE(md.find("32 spheres, triaxial test"), std::string::npos);
  EXPECT_NE(md.find("| FB x | FB y | FB z | FB sh | paper | MB | MB xz | MB yz | MB xy |"),
            std::string::npos);
  EXPECT_NE(md.find("Thornton"), std::string::npos);  // the FCC analytical peak
  const std::string csv = test::read_text(dir / "evidence.csv");
  EXPECT_NE(csv.find("moment_balance_xy,servo_xmin"), std::string::npos);
  EXPECT_NE(test::read_text(dir / "series/benchmark.csv").find("strain_zz"), std::string::npos);

  const fs::path sdir = tmp / "stability";
  const test::RunResult s = test::run_demcal(
      {"stability", config.string(), "--points", "4", "--steps", "3000", "-o", sdir.string()},
      tmp.path());
  ASSERT_EQ(s.status, 0) << s.err;
  std::ifstream sin(sdir / "stability.json");
  const nlohmann::json sj = nlohmann::json::parse(sin);
  EXPECT_EQ(sj["dimension"], 3);
  EXPECT_GT(sj["dt_ratio_estimate"].get<double>(), 0.0);
  EXPECT_NE(test::read_text(sdir / "stability.md").find("spheres, 6 DOF"), std::string::npos);
}

}  // namespace
}  // namespace demcal
