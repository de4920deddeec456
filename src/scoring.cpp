#include "demcal/scoring.hpp"

#include <algorithm>
#include <cmath>

namespace demcal {

namespace {

double rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

double ratio(double num, double den) { return den > 0.0 ? num / den : 0.0; }

}  // namespace

double robust_noise(const std::vector<double>& x) {
  if (x.size() < 3) return 0.0;
  std::vector<double> hp;
  hp.reserve(x.size() - 2);
  for (size_t k = 1; k + 1 < x.size(); ++k)
    hp.push_back(std::abs(x[k] - 0.5 * (x[k - 1] + x[k + 1])));
  std::nth_element(hp.begin(), hp.begin() + static_cast<std::ptrdiff_t>(hp.size() / 2), hp.end());
  const double median = hp[hp.size() / 2];
  // |N(0, 1.5 s²)| has median 0.6745·sqrt(1.5)·s.
  return median / (0.6744897501960817 * std::sqrt(1.5));
}

Criteria compute_criteria(const LoadingResult& run, double s3,
                          std::optional<double> reference_peak) {
  Criteria c;
  const auto& series = run.series;
  // Skip the consolidated start point: it is static by construction.
  std::vector<double> gxx, gyy, gxy, gyx, byy, asym, servo, shared_yy;
  for (size_t k = 1; k < series.size(); ++k) {
    const auto& p = series[k];
    gxx.push_back(p.b(0, 0) - p.sigma(0, 0));
    gyy.push_back(p.b(1, 1) - p.sigma(1, 1));
    gxy.push_back(p.b(0, 1) - p.sigma(0, 1));
    gyx.push_back(p.b(1, 0) - p.sigma(1, 0));
    byy.push_back(p.b(1, 1));
    asym.push_back(p.sigma(0, 1) - p.sigma(1, 0));
    servo.push_back(p.lateral_stress_error);
    shared_yy.push_back(0.5 * (p.b(1, 1) + p.sigma(1, 1)));
    const double ke_ratio = ratio(p.kinetic_energy, p.elastic_energy);
    c.kinetic_energy_ratio_max = std::max(c.kinetic_energy_ratio_max, ke_ratio);
    c.unbalanced_force_ratio_mean += p.unbalanced_force_ratio;
    c.unbalanced_force_ratio_max = std::max(c.unbalanced_force_ratio_max, p.unbalanced_force_ratio);
    c.inertial_number_max = std::max(c.inertial_number_max, p.inertial_number);
  }
  if (!gxx.empty()) c.unbalanced_force_ratio_mean /= static_cast<double>(gxx.size());
  const double byy_rms = rms(byy);
  c.force_balance_paper = ratio(rms(gyy), byy_rms);
  c.force_balance_xx = ratio(rms(gxx), s3);
  c.force_balance_yy = c.force_balance_paper;
  c.force_balance_xy = ratio(rms(gxy), s3);
  c.force_balance_yx = ratio(rms(gyx), s3);
  c.force_balance =
      std::max({c.force_balance_xx, c.force_balance_yy, c.force_balance_xy, c.force_balance_yx});
  c.moment_balance = ratio(rms(asym), s3);
  c.servo = rms(servo);
  c.oscillation = std::max({ratio(robust_noise(gxx), s3), ratio(robust_noise(gyy), byy_rms),
                            ratio(robust_noise(gxy), s3), ratio(robust_noise(gyx), s3)});
  c.zigzag = ratio(robust_noise(shared_yy), byy_rms);

  const Peak peak = find_peak(series);
  if (peak.index >= 0) {
    // The step-level peak when the run tracked one (it cannot be missed
    // between monitoring points), else the monitored one.
    const bool tracked = run.peak_stress_yy < 0.0;
    c.peak_stress_yy = tracked ? run.peak_stress_yy : peak.stress_yy;
    c.peak_strain_yy = tracked ? run.peak_strain_yy : peak.strain_yy;
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
    if (reference_peak && *reference_peak != 0.0)
      c.peak_error = (c.peak_stress_yy - *reference_peak) / std::abs(*reference_peak);
  }
  return c;
}

Diagnosis diagnose(const Criteria& c, const Tolerances& t, bool diverged) {
  Diagnosis d;
  if (diverged) {
    return {"dt", "decrease", 0.95,
            "the run diverged: the time step is beyond the stable limit; decrease dt_ratio"};
  }
  const double fb = c.force_balance / t.force_balance;
  const double mb = c.moment_balance / t.moment_balance;
  const double osc = c.oscillation / t.oscillation;
  const double sv = c.servo / t.servo;
  const double worst = std::max({fb, mb, osc, sv});
  if (worst <= 1.0) return {"none", "", 0.9, "quasi-static: every criterion is within tolerance"};
  // Moment imbalance with step-to-step noise: the rotational mode of the
  // explicit scheme is near its stability limit.
  if (mb >= worst * 0.999 && osc > 1.0)
    return {"dt", "decrease", std::min(0.9, 0.5 + 0.1 * osc),
            "sigma_xy and sigma_yx are large and noisy: the time step is near the rotational "
            "stability limit; decrease dt_ratio"};
  if (mb >= worst * 0.999)
    return {"damping_rotation", "decrease", 0.6,
            "sigma is not symmetric without noise: rotational damping holds the particles' "
            "moments; decrease damping_ratio_rotation"};
  if (osc >= worst * 0.999)
    return {"damping_translation", "increase", 0.6,
            "b and sigma disagree by step-to-step noise: the run is under-damped; increase "
            "damping_ratio_translation"};
  if (sv >= worst * 0.999)
    return {"steps", "increase", 0.6,
            "the lateral walls cannot hold sigma3: loading too fast for the servo; increase steps"};
  if (c.plateau_spread < 1e-3 && c.post_peak_softening < 1e-3)
    return {"damping_translation", "decrease", 0.5,
            "b and sigma disagree and the post-peak plateau is perfectly plastic: damping drags "
            "the particles; decrease damping_ratio_translation or increase steps"};
  return {"steps", "increase", std::min(0.9, 0.5 + 0.1 * fb),
          "b and sigma disagree smoothly: loading too fast for this damping; increase steps"};
}

Score score_run(const LoadingResult& run, double s3, const Tolerances& t,
                std::optional<double> reference_peak) {
  Score s;
  s.criteria = compute_criteria(run, s3, reference_peak);
  s.diverged = run.diverged;
  s.complete = !run.diverged && !run.stopped_early && run.steps_run == run.steps_planned;
  s.force_balance_excess = s.criteria.force_balance / t.force_balance;
  s.moment_balance_excess = s.criteria.moment_balance / t.moment_balance;
  s.servo_excess = s.criteria.servo / t.servo;
  s.oscillation_excess = s.criteria.oscillation / t.oscillation;
  s.worst_excess = std::max(
      {s.force_balance_excess, s.moment_balance_excess, s.servo_excess, s.oscillation_excess});
  s.passed = !s.diverged && s.complete && s.worst_excess <= 1.0;
  s.diagnosis = diagnose(s.criteria, t, s.diverged);
  return s;
}

nlohmann::json to_json(const Criteria& c) {
  nlohmann::json j{{"force_balance", c.force_balance},
                   {"force_balance_paper", c.force_balance_paper},
                   {"force_balance_xx", c.force_balance_xx},
                   {"force_balance_yy", c.force_balance_yy},
                   {"force_balance_xy", c.force_balance_xy},
                   {"force_balance_yx", c.force_balance_yx},
                   {"moment_balance", c.moment_balance},
                   {"servo", c.servo},
                   {"oscillation", c.oscillation},
                   {"zigzag", c.zigzag},
                   {"post_peak_softening", c.post_peak_softening},
                   {"plateau_spread", c.plateau_spread},
                   {"kinetic_energy_ratio_max", c.kinetic_energy_ratio_max},
                   {"unbalanced_force_ratio_mean", c.unbalanced_force_ratio_mean},
                   {"unbalanced_force_ratio_max", c.unbalanced_force_ratio_max},
                   {"inertial_number_max", c.inertial_number_max}};
  if (c.peak_error) j["peak_error"] = *c.peak_error;
  return j;
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
          {"message", d.message}};
}

}  // namespace demcal
