#include "demcal/scoring/external_series.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "demcal/io/input_error.hpp"

namespace demcal {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string field; std::getline(s, field, ',');) out.push_back(trim(field));
  return out;
}

/// A number of the file: the whole field, finite or not (nan/inf mark a
/// diverged engine run); anything else is bad input.
double parse_number(const std::string& field, const std::string& source, const std::string& where) {
  const char* begin = field.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (field.empty() || end != begin + field.size())
    throw InputError(source, where, "not a number: \"" + field + "\"");
  return v;
}

std::optional<double> meta_number(const ExternalSeries& s, const std::string& key) {
  const auto it = s.meta.find(key);
  if (it == s.meta.end()) return std::nullopt;
  return parse_number(it->second, s.source, "# " + key);
}

}  // namespace

ExternalSeries parse_external_series(const std::string& text, const std::string& source,
                                     std::optional<double> lateral_stress) {
  ExternalSeries out;
  out.source = source;
  std::vector<std::string> columns;
  std::map<std::string, size_t> col;
  std::vector<std::vector<double>> rows;
  std::stringstream lines(text);
  int line_no = 0;
  bool diverged = false;
  int64_t diverged_step = -1;
  for (std::string raw; std::getline(lines, raw);) {
    ++line_no;
    const std::string line = trim(raw);
    if (line.empty()) continue;
    if (line[0] == '#') {
      const auto eq = line.find(" = ");
      if (eq != std::string::npos)
        out.meta[trim(line.substr(1, eq - 1))] = trim(line.substr(eq + 3));
      continue;
    }
    const std::string where = "line " + std::to_string(line_no);
    if (columns.empty()) {
      columns = split_commas(line);
      for (size_t k = 0; k < columns.size(); ++k) {
        if (columns[k].empty()) throw InputError(source, where, "an empty column name");
        if (!col.emplace(columns[k], k).second)
          throw InputError(source, where, "column \"" + columns[k] + "\" appears twice");
      }
      continue;
    }
    // The continuation of a split run repeats the header and the row of the
    // step it restarted from: both are skipped.
    if (split_commas(line) == columns) continue;
    const auto fields = split_commas(line);
    if (fields.size() != columns.size())
      throw InputError(source, where,
                       std::to_string(fields.size()) + " values for " +
                           std::to_string(columns.size()) + " columns");
    std::vector<double> row;
    for (const auto& f : fields) row.push_back(parse_number(f, source, where));
    if (!diverged &&
        std::any_of(row.begin(), row.end(), [](double v) { return !std::isfinite(v); })) {
      diverged = true;  // the engine's run blew up here: score what came before
      diverged_step = static_cast<int64_t>(std::isfinite(row[0]) ? row[0] : -1);
    }
    if (!diverged && !rows.empty() && row[0] == rows.back()[0]) continue;
    if (!diverged) rows.push_back(std::move(row));
  }
  if (columns.empty()) throw InputError(source, "", "no column header (and no data)");
  for (const char* need :
       {"step", "strain_yy", "b_xx", "b_xy", "b_yx", "b_yy", "s_xx", "s_xy", "s_yx", "s_yy"})
    if (!col.count(need))
      throw InputError(source, "columns", std::string("no column \"") + need + "\"");
  if (rows.size() < 2 && !diverged)
    throw InputError(source, "", "fewer than two monitoring points");

  if (lateral_stress) {
    out.lateral_stress = *lateral_stress;
  } else if (auto v = meta_number(out, "lateral_stress")) {
    out.lateral_stress = *v;
  } else {
    throw InputError(source, "# lateral_stress",
                     "missing: give it in the file (# lateral_stress = PA) or --lateral-stress");
  }
  if (!(out.lateral_stress > 0.0))
    throw InputError(source, "lateral_stress", "must be positive (sigma3, Pa)");

  auto value = [&](const std::vector<double>& row, const char* name, double fallback) {
    const auto it = col.find(name);
    return it == col.end() ? fallback : row[it->second];
  };
  const double s3 = out.lateral_stress;
  const bool has_error = col.count("lateral_stress_error") > 0;
  const bool has_pressures = col.count("p_left") && col.count("p_right");
  out.torque_column = col.count("torque_stress") > 0;
  LoadingResult& run = out.run;
  for (const auto& row : rows) {
    MonitorPoint p;
    p.step = static_cast<int64_t>(value(row, "step", 0));
    p.strain_yy = value(row, "strain_yy", 0);
    p.b << value(row, "b_xx", 0), value(row, "b_xy", 0), value(row, "b_yx", 0),
        value(row, "b_yy", 0);
    p.sigma << value(row, "s_xx", 0), value(row, "s_xy", 0), value(row, "s_yx", 0),
        value(row, "s_yy", 0);
    if (out.torque_column) {
      // Moment balance on the engine's own rotational disequilibrium (see the
      // header); the symmetric part, all force balance uses, is unchanged.
      const double tau = value(row, "torque_stress", 0);
      const double asym = p.sigma(0, 1) - p.sigma(1, 0);
      out.lever_arm_floor.push_back((asym - tau) / s3);
      const double sym = 0.5 * (p.sigma(0, 1) + p.sigma(1, 0));
      p.sigma(0, 1) = sym + 0.5 * tau;
      p.sigma(1, 0) = sym - 0.5 * tau;
    }
    p.kinetic_energy = value(row, "kinetic_energy", 0);
    p.kinetic_energy_rotation = value(row, "kinetic_energy_rotation", 0);
    p.elastic_energy = value(row, "elastic_energy", 0);
    p.unbalanced_force_ratio = value(row, "unbalanced_force_ratio", 0);
    p.inertial_number = value(row, "inertial_number", 0);
    p.coordination_number = value(row, "coordination_number", 0);
    if (has_error)
      p.lateral_stress_error = value(row, "lateral_stress_error", 0);
    else if (has_pressures)
      p.lateral_stress_error =
          (0.5 * (value(row, "p_left", 0) + value(row, "p_right", 0)) - s3) / s3;
    p.left = value(row, "wall_left", 0);
    p.right = value(row, "wall_right", 0);
    p.bottom = value(row, "wall_bottom", 0);
    p.top = value(row, "wall_top", 0);
    run.series.push_back(p);
  }

  // What is known of the run. Its last monitoring point may fall short of
  // the last step by less than one interval (Nstep not a multiple of M).
  const int64_t last = run.series.empty() ? 0 : run.series.back().step;
  const int64_t interval =
      run.series.size() >= 2 ? last - run.series[run.series.size() - 2].step : 0;
  const auto steps = meta_number(out, "steps");
  run.steps_planned = steps ? static_cast<int64_t>(*steps) : last;
  run.steps_run =
      (!diverged && steps && last < run.steps_planned && run.steps_planned - last < interval)
          ? run.steps_planned
          : last;
  run.diverged = diverged;
  if (diverged) {
    run.divergence = Divergence::kNotFinite;
    run.divergence_step = diverged_step;
  }
  run.particles = static_cast<int>(meta_number(out, "particles").value_or(0));
  run.integration.dt = meta_number(out, "dt").value_or(0);
  run.scales.dt_crit = meta_number(out, "dt_crit").value_or(0);
  run.integration.damping_ratio_translation =
      meta_number(out, "damping_ratio_translation").value_or(0);
  run.integration.damping_ratio_rotation = meta_number(out, "damping_ratio_rotation").value_or(0);
  run.integration.mass_scaling = meta_number(out, "mass_scaling").value_or(1);
  return out;
}

ExternalScore score_external(const ExternalSeries& series, const Tolerances& tolerances,
                             std::optional<double> reference_peak) {
  ExternalScore out;
  out.score = score_run(series.run, series.lateral_stress, tolerances, reference_peak);
  // As the criteria, the start point (static by construction) is left out.
  double sum = 0.0;
  int n = 0;
  for (size_t k = 1; k < series.lever_arm_floor.size(); ++k, ++n) {
    const double v = series.lever_arm_floor[k];
    sum += v * v;
    out.lever_arm_floor_max = std::max(out.lever_arm_floor_max, std::abs(v));
  }
  out.lever_arm_floor_rms = n ? std::sqrt(sum / n) : 0.0;
  return out;
}

nlohmann::json external_summary(const ExternalSeries& series, const ExternalScore& score,
                                const Tolerances& tolerances) {
  const Score& s = score.score;
  const LoadingResult& run = series.run;
  nlohmann::json j{{"schema", "demcal.score/1"},
                   {"source", series.source},
                   {"metadata", series.meta},
                   {"points", run.series.size()},
                   {"steps_planned", run.steps_planned},
                   {"steps_run", run.steps_run},
                   {"lateral_stress", series.lateral_stress},
                   {"criteria", to_json(s.criteria)},
                   {"tolerances", to_json(tolerances)},
                   {"passed", s.passed},
                   {"complete", s.complete},
                   {"diagnosis", to_json(s.diagnosis)},
                   {"peak",
                    {{"stress_yy", s.criteria.peak_stress_yy},
                     {"strain_yy", s.criteria.peak_strain_yy},
                     {"ratio", -s.criteria.peak_stress_yy / series.lateral_stress}}},
                   {"diverged", run.diverged}};
  j["moment_balance_source"] = series.torque_column
                                   ? "torque_stress (the engine's net contact torques / V)"
                                   : "s_xy - s_yx as written";
  if (series.torque_column)
    j["lever_arm_floor"] = {
        {"rms", score.lever_arm_floor_rms},
        {"max", score.lever_arm_floor_max},
        {"note",
         "((s_xy - s_yx) - torque_stress)/sigma3: the static moment term of an engine that "
         "applies tangential forces at r_i instead of r_i - delta/2; not counted in moment "
         "balance"}};
  if (run.diverged) j["divergence"] = {{"step", run.divergence_step}};
  return j;
}

}  // namespace demcal
