// The 3D (triaxial) criteria and run summary, built on the 2D criteria of
// scoring.hpp: each vertical plane of the triaxial series is measured
// exactly as the biaxial test is.
#include "demcal/scoring/triaxial_scoring.hpp"

#include <algorithm>

#include "demcal/scoring/trial.hpp"

namespace demcal {

namespace {

/// A triaxial point seen in one vertical plane (lateral axis `a`, 0 = x or
/// 1 = y, and the axial z) as a biaxial point: index 0 the lateral axis,
/// index 1 the axial one, the servo error that of the two walls normal to
/// `a`. compute_criteria() then measures in that plane exactly what it
/// measures in 2D.
MonitorPoint vertical_plane_point(const TriaxialPoint& t, int a) {
  MonitorPoint p;
  const int idx[2] = {a, 2};
  p.step = t.step;
  p.strain_yy = t.strain_zz;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      p.b(i, j) = t.b(idx[i], idx[j]);
      p.sigma(i, j) = t.sigma(idx[i], idx[j]);
    }
  p.kinetic_energy = t.kinetic_energy;
  p.kinetic_energy_rotation = t.kinetic_energy_rotation;
  p.elastic_energy = t.elastic_energy;
  p.unbalanced_force_ratio = t.unbalanced_force_ratio;
  p.inertial_number = t.inertial_number;
  p.coordination_number = t.coordination_number;
  p.lateral_stress_error = 0.5 * (t.servo_error[2 * a] + t.servo_error[2 * a + 1]);
  p.left = t.walls[2 * a];
  p.right = t.walls[2 * a + 1];
  p.bottom = t.walls[kZMin];
  p.top = t.walls[kZMax];
  return p;
}

/// The horizontal pair through the same function: the off-diagonal slots
/// hold xy and yx (the shear and moment terms read only those), the
/// diagonal x and the axial z, so that the peak that ends the gaps' range
/// is the axial one, as in the vertical planes. Its xx and yy terms repeat
/// the xz plane's; its servo error is the four lateral walls' mean.
MonitorPoint horizontal_plane_point(const TriaxialPoint& t) {
  MonitorPoint p = vertical_plane_point(t, 0);
  p.b(0, 1) = t.b(0, 1);
  p.b(1, 0) = t.b(1, 0);
  p.sigma(0, 1) = t.sigma(0, 1);
  p.sigma(1, 0) = t.sigma(1, 0);
  p.lateral_stress_error = t.lateral_stress_error;
  return p;
}

/// burst_ratio() of a plane's asymmetry a = moment_term(), over the points
/// compute_criteria() scores (the consolidated start left out).
double moment_burst_of(const std::vector<MonitorPoint>& plane, double s3) {
  std::vector<double> a;
  for (size_t k = 1; k < plane.size(); ++k) a.push_back(moment_term(plane[k], s3));
  return burst_ratio(a);
}

}  // namespace

double rotational_drag_share(const TriaxialPoint& p) {
  return p.axial_power > 0.0 ? p.damping_power_rotation / p.axial_power : 0.0;
}

TriaxialCriteria compute_triaxial_criteria(const std::vector<TriaxialPoint>& series, double s3) {
  TriaxialCriteria c;
  std::vector<MonitorPoint> xz, yz, xy;
  xz.reserve(series.size());
  yz.reserve(series.size());
  xy.reserve(series.size());
  for (const auto& t : series) {
    xz.push_back(vertical_plane_point(t, 0));
    yz.push_back(vertical_plane_point(t, 1));
    xy.push_back(horizontal_plane_point(t));
  }
  c.xz = compute_criteria(xz, s3);
  c.yz = compute_criteria(yz, s3);
  c.xy = compute_criteria(xy, s3);
  if (s3 > 0.0) {
    c.xz.moment_burst = moment_burst_of(xz, s3);
    c.yz.moment_burst = moment_burst_of(yz, s3);
    c.xy.moment_burst = moment_burst_of(xy, s3);
  }
  // Each lateral wall on its own: the plane series with that wall's error
  // (compute_criteria's servo measure, nothing else of it is used).
  for (int w = 0; w < 4; ++w) {
    std::vector<MonitorPoint>& plane = w < 2 ? xz : yz;
    for (size_t k = 0; k < series.size(); ++k)
      plane[k].lateral_stress_error = series[k].servo_error[w];
    c.servo_walls[w] = compute_criteria(plane, s3).servo;
  }

  // Rotational and translational drag: the damping's share of the axial
  // power, trend (as every gap) up to the monitored peak.
  size_t peak = 0;
  for (size_t k = 0; k < series.size(); ++k)
    if (series[k].b(2, 2) < series[peak].b(2, 2)) peak = k;
  std::vector<double> rot, tr;
  for (size_t k = 1; k < series.size(); ++k) {
    const double pz = series[k].axial_power;
    rot.push_back(rotational_drag_share(series[k]));
    tr.push_back(pz > 0.0 ? series[k].damping_power_translation / pz : 0.0);
  }
  if (!rot.empty()) {
    const std::vector<double> rt = moving_trend(rot, kTrendHalfWidth);
    const std::vector<double> tt = moving_trend(tr, kTrendHalfWidth);
    const size_t end = std::max<size_t>(peak, 1);  // rot[k-1] is point k
    for (size_t k = 0; k < end && k < rt.size(); ++k) {
      c.rotational_drag = std::max(c.rotational_drag, rt[k]);
      c.translational_drag = std::max(c.translational_drag, tt[k]);
    }
  }

  Criteria& m = c.combined;
  m = c.xz;  // peak, energies and the other codes' measures: the same series
  // Every measure a plane gives is combined over the planes that have it,
  // in the 2D names (xx lateral, yy axial, shear the plane's off-diagonal):
  // a plane's value alone under the combined record's name read as the
  // whole sample's (oscillation_xx was the x walls' only). The off-diagonal
  // gaps themselves (a plane's force_balance_xy/_yx: b_xz − σ_xz and b_zx −
  // σ_zx in the xz plane) have no combined meaning under those names: they
  // are the planes' own (criteria_planes).
  m.force_balance_xx = std::max(c.xz.force_balance_xx, c.yz.force_balance_xx);
  m.force_balance_yy = std::max(c.xz.force_balance_yy, c.yz.force_balance_yy);
  m.force_balance_xx_rms = std::max(c.xz.force_balance_xx_rms, c.yz.force_balance_xx_rms);
  for (const char* key : {"force_balance_xy", "force_balance_yx"})
    m.not_available.emplace(key, "3D: each plane's off-diagonal gaps, in criteria_planes");
  m.oscillation_xx = std::max(c.xz.oscillation_xx, c.yz.oscillation_xx);
  m.oscillation_yy = std::max(c.xz.oscillation_yy, c.yz.oscillation_yy);
  m.oscillation_shear =
      std::max({c.xz.oscillation_shear, c.yz.oscillation_shear, c.xy.oscillation_shear});
  m.servo_rms = std::max(c.xz.servo_rms, c.yz.servo_rms);
  m.servo_noise = std::max(c.xz.servo_noise, c.yz.servo_noise);
  m.moment_balance_trend =
      std::max({c.xz.moment_balance_trend, c.yz.moment_balance_trend, c.xy.moment_balance_trend});
  m.force_balance_shear =
      std::max({c.xz.force_balance_shear, c.yz.force_balance_shear, c.xy.force_balance_shear});
  m.force_balance = std::max({m.force_balance_xx, m.force_balance_yy, m.force_balance_shear});
  m.force_balance_whole =
      std::max({c.xz.force_balance_whole, c.yz.force_balance_whole, c.xy.force_balance_whole});
  // The pair the diagnosis names: the plane whose asymmetry is largest.
  c.xz.moment_pair = "sigma_xz and sigma_zx";
  c.yz.moment_pair = "sigma_yz and sigma_zy";
  c.xy.moment_pair = "sigma_xy and sigma_yx";
  const Criteria* most = &c.xz;
  for (const Criteria* k : {&c.yz, &c.xy})
    if (k->moment_balance > most->moment_balance) most = k;
  m.moment_pair = most->moment_pair;
  m.moment_balance = most->moment_balance;
  m.moment_burst = most->moment_burst;
  m.moment_noise = std::max({c.xz.moment_noise, c.yz.moment_noise, c.xy.moment_noise});
  m.servo = std::max({c.xz.servo, c.yz.servo, c.servo_walls[0], c.servo_walls[1], c.servo_walls[2],
                      c.servo_walls[3]});
  m.oscillation = std::max({c.xz.oscillation, c.yz.oscillation, c.xy.oscillation});
  m.interior_lateral = std::max(c.xz.interior_lateral, c.yz.interior_lateral);
  c.monitored_peak_stress_zz = m.peak_stress_yy;
  c.monitored_peak_strain_zz = m.peak_strain_yy;
  return c;
}

TriaxialCriteria compute_triaxial_criteria(const TriaxialResult& run, double s3,
                                           std::optional<double> reference_peak) {
  TriaxialCriteria c = compute_triaxial_criteria(run.series, s3);
  // The step-level peak when the run tracked one (it cannot be missed
  // between monitoring points), else the monitored one.
  if (run.peak_stress_zz < 0.0) {
    for (Criteria* k : {&c.xz, &c.yz, &c.xy, &c.combined}) {
      k->peak_stress_yy = run.peak_stress_zz;
      k->peak_strain_yy = run.peak_strain_zz;
    }
  }
  c.combined.peak_error = peak_error_of(c.combined.peak_stress_yy, reference_peak);
  return c;
}

nlohmann::json to_json(const TriaxialCriteria& c) {
  // A wall's servo error not available is null (an array keeps its four
  // places), a drag not available is left out, as to_json(Criteria) leaves
  // out its measures.
  static const char* const kWall[4] = {"servo_xmin", "servo_xmax", "servo_ymin", "servo_ymax"};
  nlohmann::json walls = nlohmann::json::array();
  for (int w = 0; w < 4; ++w)
    walls.push_back(c.not_available.count(kWall[w]) ? nlohmann::json(nullptr)
                                                    : nlohmann::json(c.servo_walls[w]));
  nlohmann::json j{{"xz", to_json(c.xz)},
                   {"yz", to_json(c.yz)},
                   {"xy",
                    {{"force_balance_shear", c.xy.force_balance_shear},
                     {"oscillation_shear", c.xy.oscillation_shear},
                     {"moment_balance", c.xy.moment_balance},
                     {"moment_noise", c.xy.moment_noise}}},
                   {"servo_walls", walls},
                   {"combined_without_drag", to_json(c.combined)}};
  if (!c.not_available.count("rotational_drag")) j["rotational_drag"] = c.rotational_drag;
  if (!c.not_available.count("translational_drag")) j["translational_drag"] = c.translational_drag;
  if (!c.not_available.empty()) j["not_available"] = c.not_available;
  return j;
}

AlgorithmSpec run_parameters(const TriaxialResult& run) {
  return run_parameters(run.integration, run.scales.dt_crit, run.steps_planned);
}

Tolerances triaxial_tolerances() {
  Tolerances t;
  t.force_balance = 0.0064;
  t.servo = 0.0020;
  return t;
}

Tolerances default_tolerances(const SceneConfig& config) {
  return config.dimension == 3 ? triaxial_tolerances() : Tolerances{};
}

Criteria scored_criteria(const TriaxialCriteria& c, const Tolerances& t) {
  Criteria m = c.combined;
  if (!m.available("rotational_drag")) return m;
  const double from_drag = t.moment_balance * c.rotational_drag / kRotationalDragTolerance;
  if (from_drag > m.moment_balance) {
    m.moment_balance = from_drag;
    m.moment_from_drag = c.rotational_drag;
  }
  return m;
}

Score score_triaxial_run(const TriaxialResult& run, double s3, const Tolerances& t) {
  return score_triaxial_run(run, compute_triaxial_criteria(run, s3), t);
}

Score score_triaxial_run(const TriaxialResult& run, const TriaxialCriteria& c,
                         const Tolerances& t) {
  return score_of(scored_criteria(c, t),
                  {run.diverged, run.stopped_early, run.steps_run, run.steps_planned, run.particles,
                   run_parameters(run)},
                  t);
}

TriaxialEarlyFailure::TriaxialEarlyFailure(const Tolerances& tolerances, double factor,
                                           int monitor_points, double s3)
    : planes_{EarlyFailure(tolerances, factor, monitor_points, s3),
              EarlyFailure(tolerances, factor, monitor_points, s3),
              EarlyFailure(tolerances, factor, monitor_points, s3)},
      drag_limit_(factor * kRotationalDragTolerance) {}

bool TriaxialEarlyFailure::add(const TriaxialPoint& point) {
  if (failed_) return true;
  // Every plane is fed every point (each keeps its own running bounds).
  const bool xz = planes_[0].add(vertical_plane_point(point, 0));
  const bool yz = planes_[1].add(vertical_plane_point(point, 1));
  const bool xy = planes_[2].add(horizontal_plane_point(point));
  if (xz || yz || xy) return failed_ = true;
  // Rotational drag, as compute_triaxial_criteria() takes it: the
  // moving_trend() of the shares, max over drag_ index k < max(peak, 1).
  const int index = points_++;
  if (peak_index_ < 0 || point.b(2, 2) < peak_) {
    peak_ = point.b(2, 2);
    peak_index_ = index;
  }
  if (index == 0) return false;  // the start is not scored
  drag_.push_back(rotational_drag_share(point));
  const int h = kTrendHalfWidth;
  const size_t n = drag_.size();
  const size_t counted = static_cast<size_t>(std::max(peak_index_, 1));  // k < counted
  // Trend k is final once its window no longer depends on the series'
  // length: n − 1 − k ≥ kTrendHalfWidth.
  while (next_trend_ < counted && next_trend_ + h < n) {
    const int k = static_cast<int>(next_trend_);
    const int w = std::min(h, k);
    double sum = 0.0;
    for (int j = k - w; j <= k + w; ++j) sum += drag_[j];
    drag_bound_ = std::max(drag_bound_, sum / (2 * w + 1));
    ++next_trend_;
  }
  return failed_ = drag_bound_ > drag_limit_;
}

const char* const kTriaxialVerdictNote =
    "3D criteria against the 3D default tolerances (triaxial_tolerances: force balance 0.0064, "
    "servo 0.0020 on each lateral wall, moment balance 1e-5 with the rotational drag folded in at "
    "0.003); on the shipped 3D scenes every run that passes them has its peak within 2 % of the "
    "converged one (reports/atlas-3d.md); `demcal calibrate` also certifies its answer with "
    "Nstep halved and doubled";

const char* const kTriaxialCriteriaNames =
    "criteria keep the 2D names: *_xx the lateral axes (the larger of x and y), *_yy the axial "
    "z (peak_stress_yy, and a certificate's peak_stress_yy*, hold the axial b_zz), *_shear the "
    "largest off-diagonal; each plane's own values are a run's criteria_planes (summary.json)";

nlohmann::json triaxial_run_summary(const SceneConfig& config, const TriaxialState& state,
                                    const TriaxialResult& run, const TriaxialCriteria& c,
                                    const Score& score, const Tolerances& t) {
  using nlohmann::json;
  const double s3 = config.test.lateral_stress;
  const Excesses e = excesses(score.criteria, t);
  json j{{"schema", "demcal.run/1"},
         {"scene", config.name},
         {"dimension", 3},
         {"test", "triaxial"},
         {"criteria", to_json(score.criteria)},
         {"criteria_planes", to_json(c)},
         {"axial_component", kTriaxialCriteriaNames},
         {"tolerances", to_json(t)},
         // The 2D summary's keys (and `demcal score`'s): a script reads a
         // run of either dimension the same way.
         {"passed", score.passed},
         {"diagnosis", to_json(score.diagnosis)},
         {"verdict",
          {{"within_tolerances", score.passed},
           {"worst", e.worst_name()},
           {"worst_excess", e.worst()},
           {"note", kTriaxialVerdictNote}}},
         {"peak",
          {{"stress_zz", run.peak_stress_zz},
           {"strain_zz", run.peak_strain_zz},
           {"ratio", -run.peak_stress_zz / s3},
           {"deviator", -run.peak_stress_zz - s3},
           {"ratio_wall_lateral", run.peak_ratio},
           {"ratio_wall_lateral_strain", run.peak_ratio_strain},
           {"monitored_stress_zz", c.monitored_peak_stress_zz},
           {"monitored_strain_zz", c.monitored_peak_strain_zz}}},
         {"consolidation", consolidation_json(state)},
         {"config_sha256", sha256_hex(config.text)},
         {"version", DEMCAL_VERSION}};
  j["consolidation"].update({{"stress_error", state.stress_error},
                             {"unbalanced_force_ratio", state.unbalanced_ratio},
                             {"box", state.extent0}});
  j.update(run_account_json(config.algorithm, run));
  if (auto a = analytical_peak_ratio_3d(config))
    j["analytical_peak"] = {{"ratio", *a},
                            {"ratio_periodic", fcc_peak_ratio(config.material.particle.friction)},
                            {"note",
                             "walled FCC, Thornton (1979) sliding mechanism, rotation absent "
                             "(derivation: fcc_peak_ratio_walled, src/scene/sphere_packing.cpp)"}};
  return j;
}

}  // namespace demcal
