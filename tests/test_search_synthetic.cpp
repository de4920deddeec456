// The search and its certificate on a scene whose answers are known in
// closed form: a TrialRunner that runs nothing and scores each trial from
// formulas, so that what the calibration decides can be derived by hand.
//
// The scene (SyntheticRunner): the rate-driven criteria (force balance,
// servo, moment balance) are c_k·q(α, ζ_t, ζ_r)/N — exactly the 1/Nstep
// law the model strategy assumes (calibration.cpp; two tests bend it) — so
// the smallest passing Nstep at the multipliers is N₀·q with N₀ =
// max_k c_k/tolerance_k; the oscillation is a constant below its tolerance
// (or a ramp in α); the peak is P(N) = P∞·(1 + a/N + b/N² + c/√N). Every
// test derives its expectation from these and from the search's documented
// constants, written here once: the model aims kMargin inside the
// tolerances (and a tightened round inside the accuracy), its probes run at
// 1/kFidelity of the Nstep they aim at.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "demcal/search/calibration.hpp"
#include "demcal/search/evidence.hpp"
#include "demcal/search/trial_runner.hpp"

using namespace demcal;

namespace {

constexpr double kMargin = 1.1;    // calibration.cpp: kModelMargin, kAccuracyMargin
constexpr double kFidelity = 8.0;  // calibration.cpp: kFidelity

struct SyntheticScene {
  int dimension = 2;
  int64_t particles = 100;
  double stable_dt_ratio = 0.5;
  /// Smallest passing Nstep at the optimum multipliers (q = 1).
  double n0 = 123456.0;
  /// Each rate criterion's share of its tolerance at N₀ (the largest is 1:
  /// force balance sets N₀).
  double servo_share = 0.5, moment_share = 0.25;
  /// The rate criteria go as (N₀·q/N)^rate_exponent: 1 is the model's law.
  double rate_exponent = 1.0;
  /// Oscillation / its tolerance, whatever Nstep (more steps do not cure
  /// it): oscillation_share, plus oscillation_slope·(α − oscillation_from)
  /// above that α.
  double oscillation_share = 0.1, oscillation_slope = 0.0, oscillation_from = 0.35;
  /// q = 1 + curvature·((α − α*)² + (ζ_t − ζ_t*)² + (ζ_r − ζ_r*)²); with
  /// second_q > 0, a second basin: q is the smaller of that and second_q +
  /// curvature·|(α, ζ_t, ζ_r) − second|².
  double curvature = 0.0, alpha_best = 0.3, zeta_t_best = 0.7, zeta_r_best = 0.4;
  double second_q = 0.0, second_alpha = 0.0, second_zeta_t = 0.0, second_zeta_r = 0.0;
  /// Runs longer than this diverge (0: none does), as a long run may meet
  /// an instability a shorter one did not.
  int64_t diverges_beyond = 0;
  /// The peak law P(N) = peak_limit·(1 + a/N + b/N² + c/√N).
  double peak_limit = -1e5, a = 1000.0, b = 0.0, c = 0.0;

  double q(const AlgorithmSpec& p) const {
    const auto d2 = [&](double alpha, double zeta_t, double zeta_r) {
      const double da = p.dt_ratio - alpha, dt = p.damping_ratio_translation - zeta_t,
                   dr = p.damping_ratio_rotation - zeta_r;
      return da * da + dt * dt + dr * dr;
    };
    const double first = 1.0 + curvature * d2(alpha_best, zeta_t_best, zeta_r_best);
    if (second_q <= 0.0) return first;
    return std::min(first, second_q + curvature * d2(second_alpha, second_zeta_t, second_zeta_r));
  }
  double oscillation(const AlgorithmSpec& p) const {
    return oscillation_share + oscillation_slope * std::max(0.0, p.dt_ratio - oscillation_from);
  }
  double peak(double n) const {
    return peak_limit * (1.0 + a / n + b / (n * n) + c / std::sqrt(n));
  }
  /// The certificate's change from Nstep n to n2, |P(n) − P(n2)|/|P(n2)|.
  double change(double n, double n2) const {
    return std::abs(peak(n) - peak(n2)) / std::abs(peak(n2));
  }
};

class SyntheticRunner final : public TrialRunner {
 public:
  explicit SyntheticRunner(SyntheticScene scene) : s_(scene) {}
  int dimension() const override { return s_.dimension; }
  int64_t particles() const override { return s_.particles; }
  double stable_dt_ratio(const AlgorithmSpec&) const override { return s_.stable_dt_ratio; }
  TrialRun run(const AlgorithmSpec& params, const Tolerances& tolerances, bool, double,
               const std::atomic<bool>*) const override {
    // The criteria are fixed fractions of the default tolerances: the
    // scene is fixed, the tolerances a run is judged by are not (tightened
    // after a failed certificate).
    const Tolerances t0;
    const double n = static_cast<double>(params.steps),
                 rate = std::pow(s_.n0 * s_.q(params) / n, s_.rate_exponent);
    Criteria c;
    c.force_balance = t0.force_balance * rate;
    c.servo = t0.servo * s_.servo_share * rate;
    c.moment_balance = t0.moment_balance * s_.moment_share * rate;
    c.oscillation = t0.oscillation * s_.oscillation(params);
    c.peak_stress_yy = s_.peak(n);
    c.points = 100;
    RunOutcome outcome;
    outcome.diverged = s_.diverges_beyond > 0 && params.steps > s_.diverges_beyond;
    outcome.steps_planned = params.steps;
    outcome.steps_run = outcome.diverged ? s_.diverges_beyond : params.steps;
    outcome.particles = s_.particles;
    outcome.parameters = params;
    TrialRun r;
    r.score = score_of(c, outcome, tolerances);
    r.steps_run = outcome.steps_run;
    return r;
  }

 private:
  SyntheticScene s_;
};

CalibrationOptions one_job() {
  CalibrationOptions o;
  o.jobs = 1;
  return o;
}

/// A calibration of the scene with the default options, on one job.
CalibrationSummary calibrate_on(const SyntheticScene& scene) {
  return calibrate(SyntheticRunner(scene), AlgorithmSpec{}, one_job());
}

/// The trials of one phase.
std::vector<TrialRecord> of_phase(const CalibrationSummary& s, TrialPhase phase) {
  std::vector<TrialRecord> out;
  for (const auto& t : s.trials)
    if (t.phase == phase) out.push_back(t);
  return out;
}

/// Their Nsteps, in increasing order.
std::vector<int64_t> steps_of(const std::vector<TrialRecord>& trials) {
  std::vector<int64_t> out;
  for (const auto& t : trials) out.push_back(t.params.steps);
  std::sort(out.begin(), out.end());
  return out;
}

/// What a probe predicts under the default tolerances: its Nstep times its
/// worst rate criterion over its tolerance, with the margin (the 1/N law's
/// smallest passing Nstep, the model's objective).
double prediction(const TrialRecord& probe) {
  return static_cast<double>(probe.params.steps) * rate_excess(probe.score.criteria, Tolerances{}) *
         kMargin;
}

}  // namespace

// With every probe exactly on the 1/Nstep law, each predicts the smallest
// passing Nstep N₀ exactly; the model aims kModelMargin = 1.1 above it, and
// the verification at that Nstep passes with excess 1/1.1 > 0.9, close
// enough to stop: the result is 1.1·N₀ as the search rounds it. The
// certificate runs it and 2N: P(N), P(2N), the change |P(N) − P(2N)|/|P(2N)|
// and the Richardson estimate 2·change.
TEST(SearchSynthetic, FlatSceneCalibratesAtTheModelsMarginAboveTheSmallestPassingNstep) {
  const SyntheticScene scene;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  const int64_t n = round_steps(kMargin * scene.n0);
  EXPECT_EQ(s.best.steps, n);
  // Where the multipliers do not matter, the first probe's stay: the
  // paper's α = 0.2, ζ_t = ζ_r = 1 (search_start()).
  EXPECT_EQ(s.best.dt_ratio, 0.2);
  EXPECT_EQ(s.best.damping_ratio_translation, 1.0);
  EXPECT_EQ(s.best.damping_ratio_rotation, 1.0);
  const Certificate& c = s.certificate;
  EXPECT_EQ(c.steps, n);
  EXPECT_DOUBLE_EQ(c.peak, scene.peak(n));
  EXPECT_DOUBLE_EQ(c.peak_doubled, scene.peak(2 * n));
  const double change = scene.change(n, 2 * n);
  EXPECT_DOUBLE_EQ(c.steps_doubled_peak_change, change);
  EXPECT_DOUBLE_EQ(c.richardson_error, 2.0 * change);
  EXPECT_FALSE(c.peak_halved.has_value());
  EXPECT_TRUE(c.passed);
  // The certificate's first run is the verified trial itself (the same
  // parameters: the cache's); it adds the run at 2N alone.
  EXPECT_EQ(steps_of(of_phase(s, TrialPhase::certificate)), (std::vector<int64_t>{2 * n}));
  const std::vector<TrialRecord> verified = of_phase(s, TrialPhase::verify);
  ASSERT_EQ(verified.size(), 1u);
  EXPECT_EQ(verified[0].params.steps, n);
}

// In 3D the certificate runs N/2 as well (beside 2N), judged by its peak
// alone, and the estimate is the larger of 2·|P(N) − P(2N)|/|P(2N)| and
// |P(N/2) − P(N)|/|P(N)| (calibration.hpp, Certificate). A peak that does
// not yet follow the 1/N law, P = P∞(1 + b/N²), makes the halved change the
// larger: 3b/N²/(1 + b/N²) against 1.5b/N²/(1 + b/(4N²)).
TEST(SearchSynthetic, ThreeDimensionalCertificateTakesTheLargerOfTheDoubledAndHalvedChanges) {
  SyntheticScene scene;
  scene.dimension = 3;
  scene.a = 0.0;
  scene.b = 5e7;  // b/N² ≈ 0.0027 at N = 135 800: the halved change 0.8 %, within 2 %
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  const int64_t n = round_steps(kMargin * scene.n0);
  ASSERT_EQ(s.best.steps, n);
  const Certificate& c = s.certificate;
  ASSERT_TRUE(c.peak_halved.has_value());
  EXPECT_DOUBLE_EQ(*c.peak_halved, scene.peak(n / 2));
  const double halved = scene.change(n / 2, n), doubled = scene.change(n, 2 * n);
  EXPECT_DOUBLE_EQ(*c.steps_halved_peak_change, halved);
  EXPECT_DOUBLE_EQ(c.steps_doubled_peak_change, doubled);
  ASSERT_GT(halved, 2.0 * doubled);
  EXPECT_DOUBLE_EQ(c.richardson_error, halved);
  EXPECT_TRUE(c.passed);
  EXPECT_EQ(steps_of(of_phase(s, TrialPhase::certificate)), (std::vector<int64_t>{n / 2, 2 * n}));
}

// Where the multipliers matter (q = 1 + 4·|(α, ζ_t, ζ_r) − (0.3, 0.7, 0.4)|²),
// each probe at Nstep N predicts N·max_k(criterion_k/tolerance_k)·1.1, and
// the search verifies the smallest prediction any probe made. The probes
// run at 1/8 of the Nstep they aim at: the first round at the lower
// start's (500 per particle, and 10^-0.3 of it), the second at the first
// round's prediction. BOBYQA's quadratic model finds the optimum of a
// quadratic q: the result is within 0.5 % of 1.1·N₀ (its stopping test is
// 0.5 % of Nstep). (That the smallest prediction of all probes is the one
// verified holds because the law is exact: each start verifies its second
// round's best, and a first round's probes predict no less.)
TEST(SearchSynthetic, ModelSearchVerifiesTheSmallestPredictionAtTheOptimumMultipliers) {
  SyntheticScene scene;
  scene.curvature = 4.0;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  const std::vector<TrialRecord> probes = of_phase(s, TrialPhase::search);
  ASSERT_FALSE(probes.empty());
  double smallest = HUGE_VAL;
  for (const auto& p : probes) smallest = std::min(smallest, prediction(p));
  EXPECT_EQ(s.best.steps, round_steps(smallest));
  EXPECT_LT(scene.q(s.best), 1.005);
  EXPECT_NEAR(static_cast<double>(s.best.steps), kMargin * scene.n0, 0.005 * kMargin * scene.n0);
  // Each start's first round probes at round_steps(500·n·10^-0.3/8), the
  // lower start's fidelity; its second round at 1/8 of the first round's
  // smallest prediction. With one job the trials come in the order asked:
  // a start's rounds one after the other, then the other start's.
  const int64_t first_round =
      round_steps(kStartStepsPerParticle * scene.particles * std::pow(10.0, -0.3) / kFidelity);
  int rounds = 0;
  for (size_t k = 0; k < probes.size();) {
    ASSERT_EQ(probes[k].params.steps, first_round) << "probe " << probes[k].id;
    double first = HUGE_VAL;
    for (; k < probes.size() && probes[k].params.steps == first_round; ++k)
      first = std::min(first, prediction(probes[k]));
    const int64_t second_round = round_steps(first / kFidelity);
    ASSERT_LT(k, probes.size()) << "no second round";
    for (; k < probes.size() && probes[k].params.steps != first_round; ++k)
      EXPECT_EQ(probes[k].params.steps, second_round) << "probe " << probes[k].id;
    ++rounds;
  }
  EXPECT_EQ(rounds, 2);  // the two starts
}

// Nstep stays within its bounds, 50 to 20 000 per particle by default: a
// scene that passes from N₀ = 1 000 steps, with 100 particles, calibrates at
// the floor, 5 000 (a model probe at 16 per particle, 1 600 steps, passes
// too, and is no result).
TEST(SearchSynthetic, ASceneThatPassesBelowTheFloorCalibratesAtFiftyStepsPerParticle) {
  SyntheticScene scene;
  scene.n0 = 1000.0;
  scene.a = 10.0;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  EXPECT_EQ(s.best.steps, 50 * scene.particles);
}

// A first certificate that fails: P = P∞(1 + a/N) with a = 8 000, whose
// estimate err(N) = 2·|P(N) − P(2N)|/|P(2N)| = (a/N)/(1 + a/(2N)) is 5.7 % at
// the first result N₁ = 1.1·N₀ = 135 800. The smallest Nstep it certifies
// (err ≤ 2 %) is N_c = a·(1 − acc/2)/acc = 396 000. The tightened search
// scales the tolerances by f = acc/(margin·err(N₁)), so its prediction
// N₁/f lands the margin (1.1) inside the accuracy: err ≈ acc/1.1. Without
// the margin it lands on the boundary itself, err(N₁/f) = acc·(1 +
// a/(2N₁))/(1 + a/(2N₁/f)) > acc, and a second round (f clamped to 0.8)
// ended at 485 700 = 1.23·N_c.
TEST(SearchSynthetic, AFailedCertificateTightensOnceAndLandsWithinTheMarginOfTheCertifiableNstep) {
  SyntheticScene scene;
  scene.a = 8000.0;
  const CalibrationOptions options = one_job();
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  const double acc = options.accuracy;
  const double n_c = scene.a * (1.0 - 0.5 * acc) / acc;
  const auto err = [&](double n) { return (scene.a / n) / (1.0 + scene.a / (2.0 * n)); };
  const int64_t n1 = round_steps(kMargin * scene.n0);
  ASSERT_GT(err(static_cast<double>(n1)), acc);
  // The first result and its failed certificate, then one tightened round.
  const std::vector<TrialRecord> verified = of_phase(s, TrialPhase::verify);
  ASSERT_EQ(verified.size(), 2u);
  EXPECT_EQ(verified[0].params.steps, n1);
  const double f = acc / (kMargin * err(static_cast<double>(n1)));
  EXPECT_NEAR(static_cast<double>(verified[1].params.steps), n1 / f, 1e-3 * n1 / f);
  EXPECT_EQ(s.best.steps, verified[1].params.steps);
  EXPECT_GE(static_cast<double>(s.best.steps), n_c);
  EXPECT_LE(static_cast<double>(s.best.steps), kMargin * n_c);
  EXPECT_NEAR(s.certificate.richardson_error, err(static_cast<double>(s.best.steps)), 1e-15);
  EXPECT_LT(s.certificate.richardson_error, acc / 1.05);
  // The tightened search's probes ran at 1/kFidelity of the Nstep it aimed
  // at, the rounding of the search aside.
  const std::vector<TrialRecord> tightened = of_phase(s, TrialPhase::search_tightened);
  ASSERT_FALSE(tightened.empty());
  for (const auto& t : tightened)
    EXPECT_NEAR(static_cast<double>(t.params.steps), s.best.steps / kFidelity,
                2e-3 * s.best.steps / kFidelity);
}

// A peak that falls slower than 1/N, P = P∞(1 + c/√N): err(N) =
// 2·|P(N) − P(2N)|/|P(2N)| falls like 1/√N only, so the two tightened
// rounds (each aimed by the 1/N law) fall short and the certificate's
// fallback doubles Nstep until it holds, each doubled run judged by the
// user's tolerances and the next round starting above it. It ends
// certified, and no more than twice the smallest certifiable Nstep.
TEST(SearchSynthetic, APeakSlowerThanOneOverNFallsBackToDoublingAndEndsCertified) {
  SyntheticScene scene;
  scene.a = 0.0;
  scene.c = 60.0;  // err(135 800) = 0.586·(c/√N)/(1 + c/√(2N)) ≈ 8.6 %
  const CalibrationOptions options = one_job();
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  // The estimate as the certificate makes it (2N rounded by the search),
  // and its continuous form for the smallest certifiable Nstep N_c.
  const auto err_at = [&](double n, double n2) { return 2.0 * scene.change(n, n2); };
  const auto err = [&](double n) { return err_at(n, 2.0 * n); };
  double lo = 1e3, hi = 1e9;  // err(lo) > acc ≥ err(hi): bisect for N_c
  for (int k = 0; k < 200; ++k) {
    const double mid = std::sqrt(lo * hi);
    (err(mid) > options.accuracy ? lo : hi) = mid;
  }
  const double n = static_cast<double>(s.best.steps);
  EXPECT_DOUBLE_EQ(s.certificate.richardson_error,
                   err_at(n, static_cast<double>(round_steps(2.0 * n))));
  EXPECT_LE(s.certificate.richardson_error, options.accuracy);
  EXPECT_GE(static_cast<double>(s.best.steps), hi);
  EXPECT_LE(static_cast<double>(s.best.steps), 2.0 * hi);
  // The two tightened rounds' probes are search-tightened trials (the
  // first search's alone are search trials).
  EXPECT_FALSE(of_phase(s, TrialPhase::search_tightened).empty());
  // Reached by the fallback: the result is a doubled run.
  bool doubled = false;
  for (const auto& t : of_phase(s, TrialPhase::certificate))
    doubled = doubled || t.params.steps == s.best.steps;
  EXPECT_TRUE(doubled);
}

// A doubled run that diverges certifies nothing, however close its peak:
// runs beyond 200 000 steps diverge here, so every certificate from the
// first result (135 800, its 2N 271 600) on fails, and the calibration
// ends with its best passing parameters, uncertified.
TEST(SearchSynthetic, ACertificateWhoseDoubledRunDivergesCertifiesNothing) {
  SyntheticScene scene;
  scene.diverges_beyond = 200000;
  const CalibrationSummary s = calibrate_on(scene);
  EXPECT_FALSE(s.certificate.passed);
  EXPECT_FALSE(s.success);
  ASSERT_TRUE(s.has_best());
  EXPECT_LE(s.best.steps, scene.diverges_beyond);
  EXPECT_NE(s.message.find("did not pass the convergence certificate"), std::string::npos)
      << s.message;
}

// Two basins, steep (curvature 40): q = 1 at (0.2, 1, 1), the first start,
// and 1.03 at (0.4, 0.5, 0.5), near the second. Each start's model search
// stays in its own basin, and the cheaper prediction is the one verified:
// 1.1·N₀, not 1.1·1.03·N₀.
TEST(SearchSynthetic, OfTwoStartsPredictionsTheCheaperIsVerified) {
  SyntheticScene scene;
  scene.curvature = 40.0;
  scene.alpha_best = 0.2;
  scene.zeta_t_best = scene.zeta_r_best = 1.0;
  scene.second_q = 1.03;
  scene.second_alpha = 0.4;
  scene.second_zeta_t = scene.second_zeta_r = 0.5;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  // Each start's smallest prediction: with one job the first start's
  // rounds come first (its first round's probes, then its second's), then
  // the second start's, whose first round runs at the first's Nstep again.
  const std::vector<TrialRecord> probes = of_phase(s, TrialPhase::search);
  ASSERT_FALSE(probes.empty());
  const int64_t first_round = probes.front().params.steps;
  std::vector<double> by_start;
  for (size_t k = 0; k < probes.size(); ++k) {
    if (k == 0 ||
        (probes[k].params.steps == first_round && probes[k - 1].params.steps != first_round))
      by_start.push_back(HUGE_VAL);
    by_start.back() = std::min(by_start.back(), prediction(probes[k]));
  }
  ASSERT_EQ(by_start.size(), 2u);
  ASSERT_GT(by_start[1], 1.02 * by_start[0]) << "the second start left its basin";
  EXPECT_EQ(s.best.steps, round_steps(by_start[0]));
  EXPECT_NEAR(scene.q(s.best), 1.0, 1e-3);
}

// The model's penalty on oscillation, which more steps do not cure: the
// rate criteria are least at α = 0.47, but above α = 0.35 the oscillation
// rises by 10 × its tolerance per unit α, past its tolerance at α = 0.44.
// The result keeps to α ≤ 0.44. The model is no constrained optimiser (a
// steep penalty beyond the edge, ftol 0.5 %): its cost is within 10 % of
// the edge's 1.1·N₀·q(0.44) (4.5 % above it, measured).
TEST(SearchSynthetic, TheModelKeepsOutOfTheOscillatingRange) {
  SyntheticScene scene;
  scene.curvature = 4.0;
  scene.alpha_best = 0.47;
  scene.oscillation_slope = 10.0;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  EXPECT_LE(scene.oscillation(s.best), 1.0);
  AlgorithmSpec edge = s.best;
  edge.dt_ratio = 0.44;
  edge.damping_ratio_translation = scene.zeta_t_best;
  edge.damping_ratio_rotation = scene.zeta_r_best;
  const double at_edge = kMargin * scene.n0 * scene.q(edge);
  EXPECT_GE(static_cast<double>(s.best.steps), at_edge * (1.0 - 1e-3));
  EXPECT_LE(static_cast<double>(s.best.steps), 1.1 * at_edge);
}

// Criteria that fall faster than the model's 1/N, as (N₀/N)^1.2: the
// probes at 1/8 of the target over-predict (by 8^0.2), the first
// verification passes far from the boundary, and the walk comes down to
// it. Every verification that passed is a candidate, and the result is the
// cheapest of them; it is at most 1.1·N₀ (the walk stops at excess > 0.9,
// N ≤ N₀·0.9^(-1/1.2)).
TEST(SearchSynthetic, TheVerificationWalksDownAndTheCheapestPassingTrialIsTheResult) {
  SyntheticScene scene;
  scene.rate_exponent = 1.2;
  const CalibrationSummary s = calibrate_on(scene);
  ASSERT_TRUE(s.success) << s.message;
  std::vector<int64_t> passed;
  for (const auto& t : s.trials)
    if (t.score.passed) passed.push_back(t.params.steps);
  std::vector<int64_t> verified_passing;
  for (const auto& t : of_phase(s, TrialPhase::verify))
    if (t.score.passed) verified_passing.push_back(t.params.steps);
  ASSERT_GE(verified_passing.size(), 2u) << "the walk did not come down";
  EXPECT_EQ(s.best.steps, *std::min_element(passed.begin(), passed.end()));
  EXPECT_GE(static_cast<double>(s.best.steps), scene.n0);
  EXPECT_LE(static_cast<double>(s.best.steps), scene.n0 * std::pow(0.9, -1.0 / 1.2));
}

// The --evidence reference: the result's multipliers at 8N and 16N, and
// the Richardson limit 2·P(16N) − P(8N), which for P = P∞(1 + a/N) is P∞
// itself (the 1/N terms cancel), up to rounding.
TEST(SearchSynthetic, TheEvidenceReferenceIsTheRichardsonLimitOfEightAndSixteenTimesNstep) {
  SyntheticScene scene;
  scene.a = 5000.0;
  AlgorithmSpec best;
  best.steps = 135800;
  const ReferenceEvidence r =
      run_refined_reference(SyntheticRunner(scene), best, Tolerances{}, /*jobs=*/1);
  EXPECT_EQ(r.coarse.params.steps, 8 * best.steps);
  EXPECT_EQ(r.fine.params.steps, 16 * best.steps);
  EXPECT_DOUBLE_EQ(r.coarse.score.criteria.peak_stress_yy, scene.peak(8.0 * best.steps));
  EXPECT_DOUBLE_EQ(r.fine.score.criteria.peak_stress_yy, scene.peak(16.0 * best.steps));
  EXPECT_NEAR(r.peak, scene.peak_limit, 1e-12 * std::abs(scene.peak_limit));
}

// A tightened round judges its verifications by its own tolerances: with
// criteria falling slower than the model's 1/N, as (N₀/N)^0.8, the
// tightened prediction comes out short, and its first verification passes
// the user's tolerances but not the tightened ones. The walk must go on up
// to a trial that meets the tightened tolerances, which the certificate
// then takes; stopping there left nothing for the certificate's round, and
// the calibration ended uncertified.
TEST(SearchSynthetic, ATightenedVerificationWalksOnUntilItMeetsTheTightenedTolerances) {
  SyntheticScene scene;
  scene.rate_exponent = 0.8;
  scene.a = 8000.0;
  const CalibrationSummary s = calibrate_on(scene);
  EXPECT_TRUE(s.success) << s.message;
  EXPECT_LE(s.certificate.richardson_error, CalibrationOptions{}.accuracy);
}
