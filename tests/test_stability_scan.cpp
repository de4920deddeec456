// The stability scan (issue #9 §3): the measured divergence α against the
// estimate from the stiffnesses, and every diverged trial reported as such
// with its step.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "demcal/scene/packing.hpp"
#include "demcal/search/stability_scan.hpp"

namespace demcal {
namespace {

// The options of scan() below.
StabilityScanOptions scan_options() {
  StabilityScanOptions options;
  options.steps = 20000;
  return options;
}

StabilityScanResult scan(const std::string& scene, double zeta_t, double zeta_r) {
  SceneConfig config = load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/" + scene + ".json");
  config.algorithm.damping_ratio_translation = zeta_t;
  config.algorithm.damping_ratio_rotation = zeta_r;
  const ConsolidatedState state = consolidate(config, make_assembly(config));
  return stability_scan(config, state, scan_options());
}

// The ladder: options.points rungs evenly spaced from `from` to `to` × the
// estimate, both ends included (the bisections come on top).
void expect_ladder(const StabilityScanResult& r, const StabilityScanOptions& o) {
  std::vector<double> rungs;
  for (const auto& t : r.trials)
    if (!t.bisection) rungs.push_back(t.dt_ratio);
  ASSERT_EQ(rungs.size(), static_cast<size_t>(o.points));
  for (int k = 0; k < o.points; ++k)
    EXPECT_NEAR(rungs[k], (o.from + (o.to - o.from) * k / (o.points - 1)) * r.dt_ratio_estimate,
                1e-12 * r.dt_ratio_estimate)
        << k;
}

void expect_sharp_limit(const StabilityScanResult& r) {
  ASSERT_GT(r.dt_ratio_first_diverged, 0.0);
  EXPECT_EQ(r.stable_above_limit, 0);
  for (const auto& t : r.trials) {
    if (t.dt_ratio <= r.dt_ratio_last_stable) {
      EXPECT_FALSE(t.diverged) << t.dt_ratio;
      EXPECT_EQ(t.steps_run, r.steps);
    } else {
      // Every trial past the limit is reported diverged, with its step.
      EXPECT_TRUE(t.diverged) << t.dt_ratio;
      EXPECT_NE(t.divergence, Divergence::kNone);
      EXPECT_GT(t.divergence_step, 0);
      EXPECT_LE(t.divergence_step, r.steps);
      EXPECT_LT(t.steps_run, r.steps);
    }
  }
}

// With the calibrated kind of damping the explicit scheme's limit ω_max·Δt
// = 2 is where the runs diverge: the Lanczos estimate and the measured limit
// agree to the bisection's resolution (measured: 1.001 on hex_10x10, 1.004
// on random_400). The bracket is 2^-6 of a rung (0.1 × estimate) wide, the
// Lanczos estimate good to about 1 %: 3 % covers both.
TEST(StabilityScan, MeasuredLimitMatchesTheEstimateWhenDamped) {
  for (const char* scene : {"hex_10x10", "random_400"}) {
    const StabilityScanResult r = scan(scene, 1.0, 1.0);
    SCOPED_TRACE(scene);
    expect_ladder(r, scan_options());
    expect_sharp_limit(r);
    EXPECT_NEAR(r.ratio(), 1.0, 0.03);
    EXPECT_LT(r.dt_ratio_first_diverged - r.dt_ratio_last_stable, 0.01 * r.dt_ratio_estimate);
  }
}

// Undamped, the hexagonal REV's rattle still shows in the energy ledger.
// (On random_400 with ζ_r = 0 friction alone absorbs it up to 1.14 × the
// estimate: sliding contacts bound the rattle; moment balance catches
// those runs in scoring. Not asserted here; see the polydisperse test.)
TEST(StabilityScan, UndampedHexagonalLimitIsFound) {
  const StabilityScanResult r = scan("hex_10x10", 0.0, 0.0);
  expect_sharp_limit(r);
  EXPECT_NEAR(r.ratio(), 1.0, 0.03);
}

// On a polydisperse sample the scan's "limit" lies above the estimate
// (1.09 × on these 200 disks), yet the estimate is the scheme's limit:
// with friction 10, so that no contact can slide, the runs diverge there.
// In between, the unstable modes stay bounded by sliding contacts, a local
// rattle the global checks miss (reports/robustness.md §3); the report
// says so rather than offering the higher figure as the limit.
TEST(StabilityScan, OnAPolydisperseSampleTheEstimateIsTheLimitWhenNoContactCanSlide) {
  SceneConfig config =
      load_config(std::string(DEMCAL_SOURCE_DIR) + "/configs/poly_lognormal_500.json");
  config.assembly.count = 200;
  StabilityScanOptions options;
  options.steps = 20000;
  options.from = 0.9;
  options.to = 1.2;
  options.points = 7;

  SceneConfig sticking = config;
  sticking.material.particle.friction = 10.0;
  const StabilityScanResult s =
      stability_scan(sticking, consolidate(sticking, make_assembly(sticking)), options);
  expect_sharp_limit(s);
  EXPECT_NEAR(s.ratio(), 1.0, 0.03);
  EXPECT_EQ(beyond_estimate_caveat(s), "");

  const StabilityScanResult r =
      stability_scan(config, consolidate(config, make_assembly(config)), options);
  ASSERT_GT(r.ratio(), 1.03);  // the rattle the checks miss (measured 1.093)
  EXPECT_NE(stability_markdown(r, "poly200").find(beyond_estimate_caveat(r)), std::string::npos);
  EXPECT_NE(beyond_estimate_caveat(r), "");
}

// The measured limit is the middle of the bracket [last stable, first
// diverged] over the estimate; 0 without a bracket.
TEST(StabilityScan, RatioIsTheBracketsMiddleOverTheEstimate) {
  StabilityScanResult r;
  r.dt_ratio_estimate = 0.5;
  EXPECT_EQ(r.ratio(), 0.0);
  r.dt_ratio_last_stable = 0.45;
  EXPECT_EQ(r.ratio(), 0.0);  // no diverged end
  r.dt_ratio_first_diverged = 0.65;
  EXPECT_DOUBLE_EQ(r.ratio(), 1.1);
}

}  // namespace
}  // namespace demcal
