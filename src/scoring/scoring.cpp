#include "demcal/scoring/scoring.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "demcal/io/format.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/kernel/sphere_world.hpp"

namespace demcal {

namespace {

double rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

double ratio(double num, double den) { return den > 0.0 ? num / den : 0.0; }

// The zigzag ignores the largest 5 % of the high-passed values: a single
// failure drop or the kink at the peak is an event, not a zigzag.
constexpr double kZigzagTrim = 0.05;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The largest |trend| beyond what noise alone would give: white noise of
// standard deviation n averaged over 2h+1 points has standard deviation
// n/sqrt(2h+1); three of those are taken off (a gap is what the noise
// cannot explain).
// `upto` limits the maximum to the points [0, upto] (the trend and the
// noise still use the whole series).
double max_abs_trend(const std::vector<double>& v, size_t upto = SIZE_MAX) {
  const double floor = 3.0 * robust_noise(v) / std::sqrt(2.0 * kTrendHalfWidth + 1.0);
  std::vector<double> t = moving_trend(v, kTrendHalfWidth);
  if (upto < t.size()) t.resize(upto + 1);
  return std::max(0.0, max_abs(t) - floor);
}

// Fourth differences x_{k−2} − 4x_{k−1} + 6x_k − 4x_{k+1} + x_{k+2}: zero
// for any cubic, so a smoothly curving response does not read as noise.
std::vector<double> fourth_differences(const std::vector<double>& x) {
  std::vector<double> hp;
  if (x.size() < 5) return hp;
  hp.reserve(x.size() - 4);
  for (size_t k = 2; k + 2 < x.size(); ++k)
    hp.push_back(x[k - 2] - 4.0 * x[k - 1] + 6.0 * x[k] - 4.0 * x[k + 1] + x[k + 2]);
  return hp;
}

// The fourth difference of white noise of variance s² has variance 70 s².
constexpr double kHighPassGain = 8.366600265340756;  // sqrt(70)

}  // namespace

Excesses excesses(const Criteria& c, const Tolerances& t) {
  auto excess = [&](const char* key, double value, double tolerance) {
    return c.available(key) ? value / tolerance : 0.0;
  };
  return {excess("force_balance", c.force_balance, t.force_balance),
          excess("moment_balance", c.moment_balance, t.moment_balance),
          excess("servo", c.servo, t.servo), excess("oscillation", c.oscillation, t.oscillation)};
}

double Excesses::worst() const {
  return std::max({force_balance, moment_balance, servo, oscillation});
}

std::string Excesses::worst_name() const {
  const double w = worst();
  if (w == force_balance) return "force balance";
  if (w == moment_balance) return "moment balance";
  if (w == servo) return "servo";
  return "oscillation";
}

std::optional<double> peak_error_of(double peak, std::optional<double> reference) {
  if (!reference || *reference == 0.0) return std::nullopt;
  return (*reference - peak) / std::abs(*reference);
}

double robust_noise(const std::vector<double>& x) {
  std::vector<double> hp = fourth_differences(x);
  if (hp.empty()) return 0.0;
  for (double& v : hp) v = std::abs(v);
  std::nth_element(hp.begin(), hp.begin() + static_cast<std::ptrdiff_t>(hp.size() / 2), hp.end());
  const double median = hp[hp.size() / 2];
  // |N(0, 70 s²)| has median 0.6745·sqrt(70)·s.
  return median / (0.6744897501960817 * kHighPassGain);
}

double burst_ratio(const std::vector<double>& x) {
  std::vector<double> magnitude(x.size());
  for (size_t k = 0; k < x.size(); ++k) magnitude[k] = std::abs(x[k]);
  // Zero at most points and not everywhere: bursts above a zero floor (a
  // symmetric lattice's asymmetry, or a series read back at CSV
  // precision), the clearest case there is, not the absence of one.
  const double floor = median(magnitude), size = rms(x);
  if (floor > 0.0) return size / floor;
  return size > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
}

double rms_noise(const std::vector<double>& x, double trim) {
  std::vector<double> hp = fourth_differences(x);
  if (hp.empty()) return 0.0;
  for (double& v : hp) v = v * v;
  std::sort(hp.begin(), hp.end());
  const size_t keep = std::max<size_t>(
      1, hp.size() - static_cast<size_t>(std::floor(trim * static_cast<double>(hp.size()))));
  double sum = 0.0;
  for (size_t k = 0; k < keep; ++k) sum += hp[k];
  // E[z² | z² below its (1 − trim) quantile] for standard normal z: the
  // trimmed mean of a Gaussian's squares, so white noise still reads s.
  double gaussian = 1.0;
  if (keep < hp.size()) {
    const double q = static_cast<double>(keep) / static_cast<double>(hp.size());
    // Two-sided quantile z_q of |z| and E[z²; |z| < z_q]/q = 1 − 2 z_q φ(z_q)/q.
    double lo = 0.0, hi = 10.0;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      (std::erf(mid / std::sqrt(2.0)) < q ? lo : hi) = mid;
    }
    const double z = 0.5 * (lo + hi);
    const double phi = std::exp(-0.5 * z * z) / std::sqrt(2.0 * 3.141592653589793);
    gaussian = 1.0 - 2.0 * z * phi / q;
  }
  return std::sqrt(sum / static_cast<double>(keep) / gaussian) / kHighPassGain;
}

std::vector<double> moving_trend(const std::vector<double>& x, int h) {
  const int n = static_cast<int>(x.size());
  std::vector<double> out(x.size());
  for (int k = 0; k < n; ++k) {
    const int w = std::min({h, k, n - 1 - k});
    double s = 0.0;
    for (int j = k - w; j <= k + w; ++j) s += x[j];
    out[k] = s / (2 * w + 1);
  }
  return out;
}

Eigen::Matrix2d force_balance_gap(const World& world) { return world.net_force_moment(); }

namespace {
template <class W>
double identity_residual(const W& world) {
  const auto m = world.measure();
  const auto gap = (m.boundary_stress - m.homogenized_stress).eval();
  const double scale = std::max(m.boundary_stress.norm(), 1e-300);
  return (gap - world.net_force_moment()).norm() / scale;
}
}  // namespace

double gap_identity_residual(const World& world) { return identity_residual(world); }
double gap_identity_residual(const SphereWorld& world) { return identity_residual(world); }

Criteria compute_criteria(const LoadingResult& run, double s3,
                          std::optional<double> reference_peak) {
  Criteria c = compute_criteria(run.series, s3, reference_peak);
  // The step-level peak when the run tracked one (it cannot be missed
  // between monitoring points), else the monitored one.
  if (run.peak_stress_yy < 0.0) {
    c.peak_stress_yy = run.peak_stress_yy;
    c.peak_strain_yy = run.peak_strain_yy;
    c.peak_error = peak_error_of(c.peak_stress_yy, reference_peak);
  }
  return c;
}

std::array<double, 3> force_balance_terms(const MonitorPoint& p, double s3) {
  const double syy = std::max(std::abs(p.b(1, 1)), s3);
  return {(p.b(0, 0) - p.sigma(0, 0)) / s3, (p.b(1, 1) - p.sigma(1, 1)) / syy,
          (0.5 * (p.b(0, 1) + p.b(1, 0)) - 0.5 * (p.sigma(0, 1) + p.sigma(1, 0))) / s3};
}

double moment_term(const MonitorPoint& p, double s3) {
  return (p.sigma(0, 1) - p.sigma(1, 0)) / s3;
}

EarlyFailure::EarlyFailure(const Tolerances& tolerances, double factor, int monitor_points,
                           double s3)
    : tolerances_(tolerances), factor_(factor), s3_(s3), monitor_points_(monitor_points) {}

bool EarlyFailure::add(const MonitorPoint& p) {
  if (failed_) return true;
  const int index = points_++;
  // find_peak(): the first most compressive b_yy.
  if (peak_index_ < 0 || p.b(1, 1) < peak_) {
    peak_ = p.b(1, 1);
    peak_index_ = index;
  }
  if (index == 0 || s3_ <= 0.0) return false;  // the start is not scored
  const auto g = force_balance_terms(p, s3_);
  for (int c = 0; c < 3; ++c) g_[c].push_back(g[c]);
  const double a = moment_term(p, s3_);
  moment_sum_ += a * a;
  if (std::sqrt(moment_sum_ / monitor_points_) > factor_ * tolerances_.moment_balance)
    return failed_ = true;
  // g index k is series index k + 1; compute_criteria takes force balance
  // up to g index peak − 1, and the final peak is at or after peak_index_.
  const size_t n = g_[0].size();
  const int h = kTrendHalfWidth;
  const double bound = factor_ * tolerances_.force_balance + tolerances_.oscillation;
  while (peak_index_ >= 1 && next_trend_ + h < n &&
         next_trend_ <= static_cast<size_t>(peak_index_ - 1)) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (size_t j = next_trend_ - h; j <= next_trend_ + h; ++j) sum += g_[c][j];
      if (std::abs(sum / (2 * h + 1)) > bound) return failed_ = true;
    }
    ++next_trend_;
  }
  return false;
}

Criteria compute_criteria(const std::vector<MonitorPoint>& series, double s3,
                          std::optional<double> reference_peak) {
  Criteria c;
  // Skip the consolidated start point: it is static by construction.
  std::vector<double> gxx, gyy, gs, gxy, gyx, asym, servo, interior, syy_raw;
  std::vector<double> gyy_raw, byy_raw, rot_share, ke_ratio;
  for (size_t k = 1; k < series.size(); ++k) {
    const auto& p = series[k];
    const auto g = force_balance_terms(p, s3);
    gxx.push_back(g[0]);
    gyy.push_back(g[1]);
    gs.push_back(g[2]);
    gxy.push_back((p.b(0, 1) - p.sigma(0, 1)) / s3);
    gyx.push_back((p.b(1, 0) - p.sigma(1, 0)) / s3);
    asym.push_back(moment_term(p, s3));
    servo.push_back(p.lateral_stress_error);
    interior.push_back((-p.sigma(0, 0) - s3) / s3);
    syy_raw.push_back(p.sigma(1, 1));
    gyy_raw.push_back(p.b(1, 1) - p.sigma(1, 1));
    byy_raw.push_back(p.b(1, 1));
    ke_ratio.push_back(ratio(p.kinetic_energy, p.elastic_energy));
    rot_share.push_back(ratio(p.kinetic_energy_rotation, p.kinetic_energy));
    c.kinetic_energy_ratio_max = std::max(c.kinetic_energy_ratio_max, ke_ratio.back());
    c.unbalanced_force_ratio_mean += p.unbalanced_force_ratio;
    c.unbalanced_force_ratio_max = std::max(c.unbalanced_force_ratio_max, p.unbalanced_force_ratio);
    c.inertial_number_max = std::max(c.inertial_number_max, p.inertial_number);
  }
  c.points = static_cast<int>(gxx.size());
  if (!gxx.empty()) c.unbalanced_force_ratio_mean /= static_cast<double>(gxx.size());
  if (s3 <= 0.0) return c;

  c.force_balance_paper = ratio(rms(gyy_raw), rms(byy_raw));
  // Up to the peak: after it, the failure mechanism (sliding blocks of a
  // crystal) moves fast against the global damping and the gap grows with
  // the sample's width squared, although the converged softening branch is
  // reached as fast as the peak (reports/signature-atlas.md §6.5).
  const Peak monitored_peak = find_peak(series);
  const size_t upto =
      monitored_peak.index >= 1 ? static_cast<size_t>(monitored_peak.index - 1) : SIZE_MAX;
  c.force_balance_xx = max_abs_trend(gxx, upto);
  c.force_balance_yy = max_abs_trend(gyy, upto);
  c.force_balance_shear = max_abs_trend(gs, upto);
  c.force_balance_whole = std::max({max_abs_trend(gxx), max_abs_trend(gyy), max_abs_trend(gs)});
  c.force_balance_xy = max_abs_trend(gxy);
  c.force_balance_yx = max_abs_trend(gyx);
  c.force_balance = std::max({c.force_balance_xx, c.force_balance_yy, c.force_balance_shear});
  c.force_balance_xx_rms = rms(gxx);

  c.moment_balance = rms(asym);
  c.moment_balance_trend = max_abs_trend(asym);
  c.moment_noise = robust_noise(asym);

  c.servo = max_abs_trend(servo);
  c.servo_rms = rms(servo);
  c.servo_noise = robust_noise(servo);
  c.interior_lateral = max_abs_trend(interior);

  c.oscillation_xx = robust_noise(gxx);
  c.oscillation_yy = robust_noise(gyy);
  c.oscillation_shear = robust_noise(gs);
  c.oscillation = std::max({c.oscillation_xx, c.oscillation_yy, c.oscillation_shear});

  {
    // Against RMS(b_yy), a fixed scale: a pointwise one would divide the
    // shared serration out of b_yy.
    const double scale = rms(byy_raw);
    std::vector<double> sum(byy_raw.size()), diff(byy_raw.size());
    for (size_t k = 0; k < byy_raw.size(); ++k) {
      sum[k] = ratio(byy_raw[k] + syy_raw[k], scale);
      diff[k] = ratio(byy_raw[k] - syy_raw[k], scale);
    }
    const double ns = rms_noise(sum, kZigzagTrim), nd = rms_noise(diff, kZigzagTrim);
    c.zigzag = std::sqrt(std::max(0.0, ns * ns - nd * nd) / 4.0);
  }
  c.rotational_energy_share = median(rot_share);
  c.kinetic_energy_ratio_median = median(ke_ratio);

  const Peak peak = find_peak(series);
  if (peak.index >= 0) {
    c.peak_stress_yy = peak.stress_yy;
    c.peak_strain_yy = peak.strain_yy;
    const double mag = std::abs(c.peak_stress_yy);
    const size_t after = static_cast<size_t>(peak.index);
    if (mag > 0.0 && after + 1 < series.size()) {
      c.post_peak_softening = (series.back().b(1, 1) - c.peak_stress_yy) / mag;
      std::vector<double> post;
      for (size_t k = after; k < series.size(); ++k) post.push_back(series[k].b(1, 1));
      double mean = 0.0;
      for (double v : post) mean += v;
      mean /= static_cast<double>(post.size());
      double var = 0.0;
      for (double v : post) var += (v - mean) * (v - mean);
      c.plateau_spread = std::sqrt(var / static_cast<double>(post.size())) / mag;
    }
    c.peak_error = peak_error_of(c.peak_stress_yy, reference_peak);
  }
  return c;
}

AlgorithmSpec run_parameters(const Integration& integration, double dt_crit,
                             int64_t steps_planned) {
  AlgorithmSpec a;
  a.dt_ratio = dt_crit > 0.0 ? integration.dt / dt_crit : 0.0;
  a.steps = steps_planned;
  a.damping_ratio_translation = integration.damping_ratio_translation;
  a.damping_ratio_rotation = integration.damping_ratio_rotation;
  a.mass_scaling = integration.mass_scaling;
  a.lock_rotation = integration.lock_rotation;
  return a;
}

AlgorithmSpec run_parameters(const LoadingResult& run) {
  return run_parameters(run.integration, run.scales.dt_crit, run.steps_planned);
}

namespace {

// Thresholds of the signatures (reports/signature-atlas.md). A rotational
// chatter puts most of the kinetic energy into rotation and an asymmetry of
// the order of σ3 (the monitoring interval aliases the step-to-step sign
// flips, so the asymmetry need not look noisy); rotational drag leaves a
// small, steady asymmetry and little rotational energy.
constexpr double kChatterEnergyShare = 0.3;
constexpr double kChatterAsymmetry = 1e-2;
constexpr double kDragAsymmetryMax = 1e-3;
// In 3D none of these holds (reports/signature-atlas-3d.md, 2026-12-04):
// random_500_3d's rotational energy share is 0.34 at the benchmark, 0.72
// with ζ_r = 0, and its drag alone lifts the asymmetry to 1e-3 (ζ_r = 3,
// Nstep/4). Its chatter, at 0.98-1.01 × the estimated stable α, comes in
// bursts over part of the loading: the asymmetry's RMS is 9-1400 × its
// median (FCC: 2e9) where every run without chatter reads 1.2-1.3 (a steady
// drag) and at most 4 (ζ_r = 0, within tolerance). Beyond this factor the
// 3D diagnosis names the chatter, when the asymmetry's trend also reaches
// the moment tolerance (a burst of a 1e-10 asymmetry on FCC is round-off).
constexpr double kChatterBurst = 5.0;
// A dynamic run: kinetic energy above this fraction of the elastic energy
// at most monitoring points (quasi-static runs sit at 1e-7–1e-4).
constexpr double kDynamicEnergyRatio = 1e-3;
// The paper's start point: α = 0.2, ζ_t = ζ_r = 1. A parameter is "clearly
// off" beyond these factors of it.
constexpr double kHighDamping = 2.0;
constexpr double kLowDampingRatio = 0.3;
constexpr double kSmallDtRatio = 0.1;
// b − σ noise (relative to its tolerance) above which a steady asymmetry is
// read as undamped ringing rather than rotational drag (pattern only).
constexpr double kRingingNoise = 0.1;

double confidence_from(double excess, double base, double top) {
  // base at excess 1, rising by 0.1 per factor 4, capped at top.
  if (!(excess > 1.0)) return base;
  return std::min(top, base + 0.1 * std::log(excess) / std::log(4.0));
}

/// Two significant digits: "140 %", "3.5 %".
std::string percent(double v) { return num(100.0 * v, 2) + " %"; }

/// "servo (no column lateral_stress_error ...), rotational_drag (...)".
std::string not_checked_list(const std::map<std::string, std::string>& not_checked) {
  std::string out;
  for (const auto& [name, why] : not_checked)
    out += (out.empty() ? "" : ", ") + name + " (" + why + ")";
  return out;
}

/// The criteria among `c.not_available`: what a verdict did not check.
std::map<std::string, std::string> criteria_not_checked(const Criteria& c) {
  std::map<std::string, std::string> out;
  for (const char* key :
       {"force_balance", "moment_balance", "servo", "oscillation", "rotational_drag"})
    if (!c.available(key)) out.emplace(key, c.not_available.at(key));
  return out;
}

// A parameter is "known and ..." only when the run says it.
template <class Test>
bool known(const std::optional<double>& v, Test test) {
  return v && test(*v);
}

/// A diverged run: cut mass_scaling when heavy masses ran with a tiny step,
/// else the time step.
Diagnosis diagnose_divergence(const RunParameters& p) {
  if (known(p.mass_scaling, [](double f) { return f > 1.0; }) &&
      known(p.dt_ratio, [](double a) { return a < 0.05; }))
    return {"mass_scaling", "decrease", 0.6,
            "the run diverged with heavily scaled masses and no stable dynamics; reduce "
            "mass_scaling",
            "divergence"};
  return {"dt", "decrease", 0.95,
          "the run diverged: the time step is beyond the stable limit; decrease dt_ratio",
          "divergence"};
}

/// Every criterion within tolerance: quasi-static (fewer steps would do
/// when b and sigma share a zigzag or the worst criterion is far within).
Diagnosis diagnose_within_tolerance(const Criteria& c, const Tolerances& t, double worst,
                                    const std::map<std::string, std::string>& not_checked) {
  if (c.zigzag > t.oscillation && c.zigzag > 3.0 * c.oscillation)
    return {"steps", "decrease", 0.5,
            "quasi-static, but b and sigma share a zigzag (stick-slip): the loading is slower "
            "than it needs to be; fewer steps would do",
            "shared zigzag"};
  std::string msg = not_checked.empty()
                        ? "quasi-static: every criterion is within tolerance (worst at " +
                              percent(worst) + " of its tolerance)"
                        : "quasi-static on the criteria checked: each is within tolerance "
                          "(worst at " +
                              percent(worst) + " of its tolerance)";
  if (worst < 0.1) msg += "; far within: fewer steps would do";
  if (!not_checked.empty()) msg += "; not checked: " + not_checked_list(not_checked);
  return {"none", "", not_checked.empty() ? 0.9 : 0.6, msg, "none"};
}

/// What the causes of a run out of tolerance read: the criteria's excesses,
/// the energies, and how moment balance is named (3D: the rotational drag
/// folded into it; 2D: the pair of measures that differ).
struct Symptoms {
  const Criteria& c;
  const Tolerances& t;
  const RunParameters& p;
  double fb, mb, osc, sv, worst;
  double ke_ratio;   ///< kinetic over elastic energy; 0 when not available
  double rot_share;  ///< the rotational share of the kinetic energy; 0 when not available
  bool drag;         ///< 3D: the rotational drag set moment balance
  double asymmetry;  ///< moment balance, 0 for a drag (the asymmetry thresholds do not apply)
  const std::string& pair;
  bool dynamic;   ///< force balance out and the kinetic energy a dynamic run's
  bool large_zr;  ///< ζ_r known and large
};

/// The symptoms of a run out of tolerance (`e` its excesses).
Symptoms symptoms_of(const Criteria& c, const Tolerances& t, const RunParameters& p,
                     const Excesses& e) {
  // A measure not available reads as nothing: its excess 0 (excesses()),
  // the energies' patterns not seen.
  const double ke_ratio =
      c.available("kinetic_energy_ratio_median") ? c.kinetic_energy_ratio_median : 0.0;
  const double rot_share = c.available("rotational_energy_share") ? c.rotational_energy_share : 0.0;
  // 3D: the rotational drag folded into moment balance set it; the words
  // name the drag, and the asymmetry thresholds below do not apply to it.
  const bool drag = c.moment_from_drag.has_value();
  return {.c = c,
          .t = t,
          .p = p,
          .fb = e.force_balance,
          .mb = e.moment_balance,
          .osc = e.oscillation,
          .sv = e.servo,
          .worst = e.worst(),
          .ke_ratio = ke_ratio,
          .rot_share = rot_share,
          .drag = drag,
          .asymmetry = drag ? 0.0 : c.moment_balance,
          .pair = c.moment_pair,
          .dynamic = e.force_balance > 1.0 && ke_ratio > kDynamicEnergyRatio,
          .large_zr = known(p.damping_ratio_rotation, [](double z) { return z >= kHighDamping; })};
}

/// "the rotational damping takes 12 % of the axial wall's power": the 3D
/// words for a moment balance the drag set.
std::string drag_power(const Criteria& c) {
  return "the rotational damping takes " + percent(*c.moment_from_drag) +
         " of the axial wall's power";
}

/// Cause 2, rotational chatter (Δt beyond the rotational stability limit),
/// when moment balance fails.
std::optional<Diagnosis> diagnose_chatter(const Symptoms& s) {
  const std::string words =
      " the time step is beyond the rotational stability limit; decrease dt_ratio";
  const std::string imbalance = s.drag ? drag_power(s.c) : s.pair + " are far apart";
  // 3D: the asymmetry comes in bursts (kChatterBurst).
  if (s.c.moment_burst) {
    const double burst = *s.c.moment_burst;
    if (!(burst > kChatterBurst && s.c.moment_balance_trend > s.t.moment_balance))
      return std::nullopt;
    const double clarity = std::min(1.0, std::log(burst / kChatterBurst) / std::log(100.0));
    return Diagnosis{
        "dt", "decrease", 0.6 + 0.3 * clarity,
        imbalance + " and the particles' rotations chatter in bursts (" +
            (std::isinf(burst) ? std::string("the asymmetry is zero at most points")
                               : "the asymmetry's RMS " + num(burst, 2) + " times its median") +
            "):" + words,
        "moment imbalance with rotational chatter"};
  }
  // 2D. Rotational drag never reached kDragAsymmetryMax in the atlas (ζ_r
  // up to 20 on hex_10x10): beyond it, unless ζ_r is large, it is the onset
  // of the chatter (at 1.05 α_stable on random_400 the rotational energy
  // share is still low on most monitoring points).
  if (!(s.rot_share > kChatterEnergyShare || s.asymmetry > kChatterAsymmetry ||
        (s.asymmetry > kDragAsymmetryMax && !s.large_zr)))
    return std::nullopt;
  const double clarity =
      std::max(std::min(1.0, s.rot_share / 0.6), std::min(1.0, s.asymmetry / 0.1));
  return Diagnosis{"dt", "decrease", std::min(0.95, 0.6 + 0.3 * clarity),
                   imbalance + " and the particles' rotations chatter:" + words,
                   "moment imbalance with rotational chatter"};
}

/// Causes 1-3, a dynamic run or rotational chatter: whether the scaled
/// masses, the time step or too few steps are to blame.
std::optional<Diagnosis> diagnose_dynamics(const Symptoms& s) {
  // 1. A dynamic run with scaled masses: inertia, not the contacts, carries
  //    the load.
  if (s.dynamic && known(s.p.mass_scaling, [](double f) { return f > 1.0; }))
    return Diagnosis{"mass_scaling", "decrease", 0.8,
                     "the run is dynamic (kinetic energy " + percent(s.ke_ratio) +
                         " of the elastic energy) and b and sigma follow different trends: the "
                         "scaled masses are too heavy for this loading; decrease mass_scaling",
                     "dynamic run, b and sigma follow different trends"};
  // 2. Rotational chatter: Δt beyond the rotational stability limit.
  if (s.mb > 1.0) {
    if (auto d = diagnose_chatter(s)) return d;
  }
  // 3. A dynamic run without scaled masses: loading too fast for inertia.
  if (s.dynamic)
    return Diagnosis{"steps", "increase", 0.7,
                     "the run is dynamic (kinetic energy " + percent(s.ke_ratio) +
                         " of the elastic energy): the loading is too fast for the particles' "
                         "inertia; increase steps",
                     "dynamic run, b and sigma follow different trends"};
  return std::nullopt;
}

/// Cause 4, noise where b and sigma disagree: a time step near its limit
/// (the run is damped) or too little translational damping.
std::optional<Diagnosis> diagnose_noise(const Symptoms& s) {
  if (!(s.osc > 1.0 && s.osc >= 0.5 * s.worst)) return std::nullopt;
  if (known(s.p.damping_ratio_translation, [](double z) { return z >= kLowDampingRatio; }) &&
      known(s.p.dt_ratio, [](double a) { return a > 0.25; }))
    return Diagnosis{"dt", "decrease", 0.5,
                     "b and sigma disagree by step-to-step noise although the run is damped: the "
                     "time step is near its stability limit; decrease dt_ratio",
                     "oscillation"};
  return Diagnosis{"damping_translation", "increase", confidence_from(s.osc, 0.6, 0.85),
                   "b and sigma disagree by step-to-step noise: the run is under-damped; "
                   "increase damping_ratio_translation",
                   "oscillation, b != sigma"};
}

/// Cause 5, a steady moment imbalance out of proportion with the
/// rate-driven measures: undamped rotations ringing, or rotational drag.
std::optional<Diagnosis> diagnose_moment_imbalance(const Symptoms& s) {
  // The rate-driven measures all scale with the loading rate; a rotational
  // damping far too large lifts the asymmetry alone.
  const double rate_excess = std::max(s.fb, s.sv);
  // Without damping the particles' spins ring (σ's antisymmetric part is
  // Σ I·dω/dt): noisy b − σ, and no rotational damping to blame. Known
  // damping ratios decide; without them (a series that does not give
  // them) the pattern does, and the words say it is a guess. A drag is
  // damping's own: never ringing.
  const RunParameters& p = s.p;
  const bool damping_known = p.damping_ratio_translation && p.damping_ratio_rotation;
  const bool ringing =
      !s.drag && (damping_known ? *p.damping_ratio_translation < kLowDampingRatio &&
                                      *p.damping_ratio_rotation < kLowDampingRatio
                                : s.c.oscillation > kRingingNoise * s.t.oscillation);
  if (s.mb > 1.0 && ringing && (rate_excess <= 1.0 || s.mb >= rate_excess)) {
    if (damping_known)
      return Diagnosis{"damping_translation", "increase", 0.6,
                       s.pair +
                           " differ while the run is (almost) undamped: the particles' rotations "
                           "ring; add damping (damping_ratio_translation 0.1 or more)",
                       "moment imbalance without damping"};
    return Diagnosis{"damping_translation", "increase", 0.4,
                     s.pair +
                         " differ and b - sigma is noisy, the pattern of a run whose rotations "
                         "ring without damping; its damping ratios are not known (the series "
                         "does not give them): if it has none, add damping "
                         "(damping_ratio_translation 0.1 or more)",
                     "moment imbalance without damping"};
  }
  const bool rot_drag = s.mb > 1.0 && (rate_excess <= 1.0 || s.mb >= 5.0 * rate_excess ||
                                       (s.large_zr && s.mb >= rate_excess));
  if (!rot_drag) return std::nullopt;
  return Diagnosis{
      "damping_rotation", "decrease",
      s.large_zr ? 0.85 : confidence_from(s.mb / std::max(1.0, rate_excess), 0.55, 0.8),
      (s.drag ? drag_power(s.c) +
                    " (rotational drag) without chatter: it holds the particles' rotations and "
                    "stiffens the response"
              : s.pair + " differ steadily without chatter: rotational damping holds the "
                         "particles' rotations and stiffens the response") +
          "; decrease damping_ratio_rotation",
      "moment imbalance, peak over-predicted"};
}

/// Causes 6-7 and the rest, a gap between b and sigma: the walls' lag or
/// translational drag, cured by more steps, a larger time step or less
/// damping.
Diagnosis diagnose_gap(const Symptoms& s) {
  const Criteria& c = s.c;
  const bool small_dt = known(s.p.dt_ratio, [](double a) { return a <= kSmallDtRatio; });
  // 6. The servo walls lag behind σ3: only Nstep sets how fast they must move.
  if (s.sv > 1.0) {
    if (small_dt && s.fb > s.sv)
      return {"dt", "increase", 0.7,
              "b and sigma disagree (gap " + percent(c.force_balance) +
                  ") and the walls lag: the time step is small, so the same steps load the "
                  "sample fast; increase dt_ratio",
              "gap without oscillation, peak over-predicted"};
    return {"steps", "increase", confidence_from(s.sv, 0.6, 0.9),
            "the lateral walls cannot hold sigma3 (error " + percent(c.servo) +
                ") and b and sigma drift apart: the loading is too fast; increase steps",
            "gap b != sigma, servo lag, peak over-predicted"};
  }
  // 7. Translational drag: damping acts as extra confinement (smooth gap).
  if (s.fb > 1.0 || s.mb > 1.0) {
    const std::string gap =
        "b and sigma disagree smoothly (gap " + percent(c.force_balance) + ", mostly " +
        (c.force_balance_xx >= c.force_balance_yy ? "lateral" : "vertical") + ")";
    if (known(s.p.damping_ratio_translation, [](double z) { return z >= kHighDamping; }))
      return {"damping_translation", "decrease", 0.8,
              gap +
                  ": global damping drags against the lateral expansion like extra "
                  "confinement; decrease damping_ratio_translation",
              "gap without oscillation, peak over-predicted"};
    if (small_dt)
      return {"dt", "increase", 0.75,
              gap +
                  ": the time step is small, so the same steps load the sample fast; "
                  "increase dt_ratio",
              "gap without oscillation, peak over-predicted"};
    return {"steps", "increase", confidence_from(s.fb, 0.55, 0.85),
            gap +
                ": the loading is too fast for this damping; increase steps (or decrease "
                "damping_ratio_translation)",
            "gap b != sigma, peak over-predicted"};
  }
  return {"steps", "increase", 0.5, "a criterion is out of tolerance; increase steps", "other"};
}

}  // namespace

Diagnosis diagnose(const Criteria& c, const Tolerances& t, bool diverged, const RunParameters& p) {
  if (diverged) return diagnose_divergence(p);
  const Excesses e = excesses(c, t);
  if (e.worst() <= 1.0) return diagnose_within_tolerance(c, t, e.worst(), criteria_not_checked(c));
  // The causes in order, the first that fits.
  const Symptoms s = symptoms_of(c, t, p, e);
  if (auto d = diagnose_dynamics(s)) return *d;
  if (auto d = diagnose_noise(s)) return *d;
  if (auto d = diagnose_moment_imbalance(s)) return *d;
  return diagnose_gap(s);
}

Score score_of(const Criteria& criteria, const RunOutcome& run, const Tolerances& t) {
  Score s;
  s.criteria = criteria;
  s.diverged = run.diverged;
  s.complete = !run.diverged && !run.stopped_early && run.steps_run == run.steps_planned;
  s.completed_fraction = run.steps_planned > 0 ? static_cast<double>(run.steps_run) /
                                                     static_cast<double>(run.steps_planned)
                                               : 0.0;
  s.particle_steps = static_cast<double>(run.particles) * static_cast<double>(run.steps_planned);
  s.worst_excess = excesses(s.criteria, t).worst();
  s.not_checked = criteria_not_checked(s.criteria);
  s.passed = !s.diverged && s.complete && s.worst_excess <= 1.0;
  s.diagnosis = diagnose(s.criteria, t, s.diverged, run.parameters);
  return s;
}

Score score_run(const LoadingResult& run, double s3, const Tolerances& t,
                std::optional<double> reference_peak) {
  return score_of(compute_criteria(run, s3, reference_peak),
                  {run.diverged, run.stopped_early, run.steps_run, run.steps_planned, run.particles,
                   run_parameters(run)},
                  t);
}

std::array<double, 4> constraint_values(const Score& s, const Tolerances& t) {
  if (s.diverged) return {3.0, 3.0, 3.0, 3.0};
  auto g = [](double v, double tol) { return std::log(std::max(v, 1e-12) / tol); };
  std::array<double, 4> out{g(s.criteria.force_balance, t.force_balance),
                            g(s.criteria.moment_balance, t.moment_balance),
                            g(s.criteria.servo, t.servo), g(s.criteria.oscillation, t.oscillation)};
  if (!s.complete)
    for (double& v : out) v = std::max(v, 0.1);
  return out;
}

double rate_excess(const Criteria& c, const Tolerances& t) {
  return std::max(
      {c.force_balance / t.force_balance, c.servo / t.servo, c.moment_balance / t.moment_balance});
}

double search_objective(int64_t steps, const Score& score, const Tolerances& tolerances,
                        bool penalised) {
  double f = std::log10(static_cast<double>(steps));
  if (penalised)
    for (double g : constraint_values(score, tolerances)) f += 10.0 * std::max(0.0, g);
  return f;
}

double richardson_limit(double n_coarse, double p_coarse, double n_fine, double p_fine) {
  return n_fine > n_coarse ? (n_fine * p_fine - n_coarse * p_coarse) / (n_fine - n_coarse) : p_fine;
}

double richardson_error(double relative_change, double refinement) {
  return refinement / (refinement - 1.0) * relative_change;
}

double cost_term(double particle_steps) {
  return std::clamp(std::log10(std::max(particle_steps, 1.0)) / 20.0, 0.0, 1.0);
}

double objective(const Score& s, const Tolerances& t) {
  if (s.diverged) return 3.0 - std::clamp(s.completed_fraction, 0.0, 1.0);
  const double c = cost_term(s.particle_steps);
  if (s.passed) return c;
  double v = 0.0;
  for (double g : constraint_values(s, t)) v += std::max(0.0, g);
  if (!s.complete) v = std::max(v, 0.1);
  if (!std::isfinite(v)) v = 1e300;
  return 1.0 + 0.9 * v / (1.0 + v) + 0.1 * c;
}

namespace {

// Every field of Criteria with its JSON key, for to_json and its inverse.
struct CriteriaField {
  const char* key;
  double Criteria::*member;
};
constexpr CriteriaField kCriteriaFields[] = {
    {"force_balance", &Criteria::force_balance},
    {"force_balance_paper", &Criteria::force_balance_paper},
    {"force_balance_xx", &Criteria::force_balance_xx},
    {"force_balance_yy", &Criteria::force_balance_yy},
    {"force_balance_shear", &Criteria::force_balance_shear},
    {"force_balance_xy", &Criteria::force_balance_xy},
    {"force_balance_yx", &Criteria::force_balance_yx},
    {"force_balance_xx_rms", &Criteria::force_balance_xx_rms},
    {"force_balance_whole", &Criteria::force_balance_whole},
    {"moment_balance", &Criteria::moment_balance},
    {"moment_balance_trend", &Criteria::moment_balance_trend},
    {"moment_noise", &Criteria::moment_noise},
    {"servo", &Criteria::servo},
    {"servo_rms", &Criteria::servo_rms},
    {"servo_noise", &Criteria::servo_noise},
    {"interior_lateral", &Criteria::interior_lateral},
    {"oscillation", &Criteria::oscillation},
    {"oscillation_xx", &Criteria::oscillation_xx},
    {"oscillation_yy", &Criteria::oscillation_yy},
    {"oscillation_shear", &Criteria::oscillation_shear},
    {"zigzag", &Criteria::zigzag},
    {"post_peak_softening", &Criteria::post_peak_softening},
    {"plateau_spread", &Criteria::plateau_spread},
    {"rotational_energy_share", &Criteria::rotational_energy_share},
    {"kinetic_energy_ratio_median", &Criteria::kinetic_energy_ratio_median},
    {"kinetic_energy_ratio_max", &Criteria::kinetic_energy_ratio_max},
    {"unbalanced_force_ratio_mean", &Criteria::unbalanced_force_ratio_mean},
    {"unbalanced_force_ratio_max", &Criteria::unbalanced_force_ratio_max},
    {"inertial_number_max", &Criteria::inertial_number_max},
    {"peak_stress_yy", &Criteria::peak_stress_yy},
    {"peak_strain_yy", &Criteria::peak_strain_yy},
};

}  // namespace

// Criteria::moment_burst is not written: a ratio over the median of an
// asymmetry at round-off level (FCC, 1e-11) is not reproduced from a series'
// printed digits (`demcal score` must give a run's criteria); the diagnosis'
// words give it where it names the chatter.
nlohmann::json to_json(const Criteria& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& f : kCriteriaFields)
    if (c.available(f.key)) j[f.key] = c.*(f.member);
  j["points"] = c.points;
  if (c.peak_error) j["peak_error"] = *c.peak_error;
  if (!c.not_available.empty()) j["not_available"] = c.not_available;
  return j;
}

Criteria criteria_from_json(const nlohmann::json& j) {
  Criteria c;
  for (const auto& f : kCriteriaFields)
    if (j.contains(f.key)) c.*(f.member) = j.at(f.key).get<double>();
  if (j.contains("points"))
    c.points = static_cast<int>(json_integer(j.at("points"), 0, std::numeric_limits<int>::max()));
  if (j.contains("peak_error")) c.peak_error = j.at("peak_error").get<double>();
  if (j.contains("not_available"))
    c.not_available = j.at("not_available").get<std::map<std::string, std::string>>();
  return c;
}

nlohmann::json to_json(const Tolerances& t) {
  return {{"force_balance", t.force_balance},
          {"moment_balance", t.moment_balance},
          {"servo", t.servo},
          {"oscillation", t.oscillation}};
}

nlohmann::json to_json(const Diagnosis& d) {
  return {{"parameter", d.parameter},
          {"direction", d.direction},
          {"confidence", d.confidence},
          {"message", d.message},
          {"signature", d.signature}};
}

}  // namespace demcal
