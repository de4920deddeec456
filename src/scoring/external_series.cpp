#include "demcal/scoring/external_series.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"

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

/// A count of the file (a step, the particles): a whole number from 0 to
/// `max`, never a cast of 1e300 to an integer (undefined behaviour).
int64_t count(double v, const std::string& source, const std::string& where,
              int64_t max = std::numeric_limits<int64_t>::max()) {
  try {
    return whole_number(v, 0, max, nlohmann::json(v).dump());
  } catch (const std::out_of_range& e) {
    throw InputError(source, where, e.what());
  }
}

/// The file as read: its columns by name and its rows up to the first
/// non-finite one (a diverged engine run: what came before is scored).
struct Table {
  std::vector<std::string> columns;
  std::map<std::string, size_t> col;
  std::vector<std::vector<double>> rows;
  bool diverged = false;
  int64_t diverged_step = -1;
  std::map<std::string, int> meta_line;  ///< the line of each "# key = value"
  std::optional<int64_t> steps;          ///< "# steps": the steps planned
  int header_line = 0;                   ///< the line of the column header

  bool has(const char* name) const { return col.count(name) > 0; }
  double value(const std::vector<double>& row, const std::string& name, double fallback) const {
    const auto it = col.find(name);
    return it == col.end() ? fallback : row[it->second];
  }
};

/// A count of the metadata (steps, particles, a step), from `min` to `max`,
/// shown as written.
int64_t meta_count(const std::string& value, const std::string& source, const std::string& where,
                   int64_t min, int64_t max) {
  try {
    return whole_number(parse_number(value, source, where), min, max, value);
  } catch (const std::out_of_range& e) {
    throw InputError(source, where, e.what());
  }
}

/// The run's parameters with a range: each checked against it.
struct Ranged {
  const char* key;
  RealRange range;
  const char* as;  ///< where the same range holds
};
const Ranged kRanged[] = {
    // sigma3 as a config holds it: positive, with no fixed cap (the
    // config bounds it by its contact stiffness, which the series does
    // not carry): a run of demcal's at 2e12 Pa writes its own series.
    {"lateral_stress", kPositive, "sigma3 [Pa], as a config's test.lateral_stress"},
    {"dt", kPositive, "the time step [s]"},
    {"dt_crit", kPositive, "the critical time step [s]"},
    {"damping_ratio_translation", kDampingRatio,
     "as a config's algorithm.damping_ratio_translation"},
    {"damping_ratio_rotation", kDampingRatio, "as a config's algorithm.damping_ratio_rotation"},
    {"mass_scaling", kMassScaling, "as a config's algorithm.mass_scaling"},
};

/// A metadata value checked where it is read, with its line (`where`):
/// the run's parameters in the ranges a config and the command line hold
/// them to (config.hpp), the counts whole numbers. `t.steps` takes
/// "# steps". Keys demcal does not read are kept as written.
void check_metadata(const std::string& key, const std::string& value, const std::string& source,
                    const std::string& where, Table& t) {
  for (const Ranged& r : kRanged)
    if (key == r.key) {
      const double v = parse_number(value, source, where);
      if (!r.range.contains(v))
        throw InputError(
            source, where,
            "must be " + r.range.text() + " (" + r.as + "), got " + quoted_value(value));
      return;
    }
  if (key == "reference_peak") {
    // A compressive peak whichever sign the file gives it: its magnitude,
    // positive and finite (demcal writes its ratio times sigma3, uncapped
    // as sigma3 is).
    const double v = parse_number(value, source, where);
    if (!kPositive.contains(std::abs(v)))
      throw InputError(source, where,
                       "must be " + kPositive.text() +
                           " in magnitude (Pa; either sign: a compressive peak), got " +
                           quoted_value(value));
  } else if (key == "steps") {
    t.steps = meta_count(value, source, where, 1, kMaxSteps);
  } else if (key == "particles") {
    meta_count(value, source, where, 0, kMaxParticles);
  } else if (key == "divergence_step") {
    meta_count(value, source, where, 0, std::numeric_limits<int64_t>::max());
  }
}

/// The run's parameters the reader takes from the metadata (checked by
/// check_metadata): before the column header only, since they hold for
/// every row.
bool is_run_parameter(const std::string& key) {
  return key == "steps" || key == "particles" ||
         std::find_if(std::begin(kRanged), std::end(kRanged),
                      [&](const Ranged& r) { return key == r.key; }) != std::end(kRanged);
}

/// "peak_stress_yy, ..., divergence": the keys that may follow the rows.
std::string result_keys() {
  std::string out;
  for (const char* key : kSeriesResultKeys) out += (out.empty() ? "" : ", ") + std::string(key);
  return out;
}

/// Whether `s` is one word of a metadata key: letters, digits, '_'.
bool is_one_word(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_';
  });
}

/// The key and value of a metadata line "# key = value" (`line` trimmed,
/// starting with '#'), or nothing for a comment. A one-word key may leave
/// out the spaces ("#lateral_stress=1e5", as a hand-written print in an
/// engine's script gives it): read as the spaced form, never as a comment,
/// which would make a given sigma3 "missing". A key of several words is
/// read only with " = " ("# restarted with run_steps = 2000").
std::optional<std::pair<std::string, std::string>> metadata_line(const std::string& line) {
  const auto eq = line.find('=');
  if (eq == std::string::npos) return std::nullopt;
  if (std::string key = trim(line.substr(1, eq - 1)); is_one_word(key))
    return std::make_pair(std::move(key), trim(line.substr(eq + 1)));
  const auto spaced = line.find(" = ");
  if (spaced == std::string::npos) return std::nullopt;
  return std::make_pair(trim(line.substr(1, spaced - 1)), trim(line.substr(spaced + 3)));
}

Table read_table(const std::string& text, ExternalSeries& out) {
  const std::string& source = out.source;
  Table t;
  std::stringstream lines(text);
  int line_no = 0;
  for (std::string raw; std::getline(lines, raw);) {
    ++line_no;
    if (line_no == 1) drop_utf8_bom(raw);  // an editor's, as particle files
    const std::string line = trim(raw);
    if (line.empty()) continue;
    const std::string where = "line " + std::to_string(line_no);
    if (line[0] == '#') {
      const auto meta = metadata_line(line);
      if (!meta) continue;  // a comment
      // (no structured binding: the lambda below captures the key, which
      // clang before 16 refuses for a binding)
      const std::string& key = meta->first;
      const std::string& value = meta->second;
      const std::string field = where + ": # " + key;
      // After the header only what a run found, which an exported deck
      // appends once its run is over (series_result_lines); a parameter of
      // the run there would hold for the rows above it too. Any other
      // "# text = text" there is a comment ("# restarted with run_steps =
      // 2000"), neither read nor kept.
      const bool result =
          std::find_if(kSeriesResultKeys.begin(), kSeriesResultKeys.end(),
                       [&](const char* k) { return key == k; }) != kSeriesResultKeys.end();
      if (!t.columns.empty() && !result && !is_run_parameter(key)) continue;
      if (!t.columns.empty() && !result)
        throw InputError(source, field,
                         "after the column header (line " + std::to_string(t.header_line) +
                             "): the run's parameters come before the header; after it only "
                             "what the run found (" +
                             result_keys() + ")");
      if (const auto first = t.meta_line.find(key); first != t.meta_line.end())
        throw InputError(
            source, field,
            "given twice (first on line " + std::to_string(first->second) + "): keep one");
      check_metadata(key, value, source, field, t);
      t.meta_line[key] = line_no;
      out.meta[key] = value;
      continue;
    }
    if (t.columns.empty()) {
      t.header_line = line_no;
      t.columns = split_commas(line);
      for (size_t k = 0; k < t.columns.size(); ++k) {
        if (t.columns[k].empty()) throw InputError(source, where, "an empty column name");
        if (!t.col.emplace(t.columns[k], k).second)
          throw InputError(source, where, "column \"" + t.columns[k] + "\" appears twice");
      }
      continue;
    }
    // The continuation of a split run repeats the header (skipped here) and
    // the row of the step it restarted from (below).
    const auto fields = split_commas(line);
    if (fields == t.columns) continue;
    if (fields.size() != t.columns.size())
      throw InputError(source, where,
                       std::to_string(fields.size()) + " values for " +
                           std::to_string(t.columns.size()) + " columns");
    std::vector<double> row;
    for (const auto& f : fields) row.push_back(parse_number(f, source, where));
    // The step, from its column by name (columns may come in any order;
    // without one the file is refused for want of it, after the table).
    const auto step_column = t.col.find("step");
    const bool stepped = step_column != t.col.end() && std::isfinite(row[step_column->second]);
    const double step = stepped ? row[step_column->second] : 0.0;
    const bool after_rows = stepped && !t.diverged && !t.rows.empty();
    const double last = after_rows ? t.rows.back()[step_column->second] : 0.0;
    // A step is a count: refused here, with its line, before it is compared.
    const int64_t step_count = stepped && !t.diverged ? count(step, source, where + ": step") : -1;
    // A row beyond the loading the file plans: the run went on past it (an
    // exported deck run with a run_steps larger than its nstep, the walls
    // still moving). Neither complete nor incomplete: refused.
    if (t.steps && step_count > *t.steps)
      throw InputError(source, where,
                       "step " + std::to_string(step_count) + " is beyond the " +
                           std::to_string(*t.steps) + " steps planned (# steps, line " +
                           std::to_string(t.meta_line.at("steps")) +
                           "): keep the rows up to step " + std::to_string(*t.steps) +
                           " (an exported deck: run it without a run_steps larger than its "
                           "nstep)");
    // Steps that go back: the rows of two runs in one file (e.g. a split
    // run continued a second time, from a restart older than the rows the
    // file holds). Scored in file order they would give a verdict on
    // neither.
    if (after_rows && step < last)
      throw InputError(source, where,
                       "step " + num(step, 17) + " after step " + num(last, 17) +
                           ": the steps go back (the rows of two runs in one file? as a split "
                           "run continued a second time from an older restart leaves it); keep "
                           "one run's rows, in the order of their steps");
    if (!t.diverged &&
        std::any_of(row.begin(), row.end(), [](double v) { return !std::isfinite(v); })) {
      t.diverged = true;  // the engine's run blew up here: score what came before
      t.diverged_step = step_count;
    }
    // The continuation of a split run repeats the row of the step it
    // restarted from: skipped.
    if (after_rows && !t.diverged && step == last) continue;
    if (!t.diverged) t.rows.push_back(std::move(row));
  }
  if (t.columns.empty()) throw InputError(source, "", "no column header (and no data)");
  return t;
}

void require_columns(const Table& t, const std::string& source,
                     std::initializer_list<std::string> names) {
  for (const std::string& need : names)
    if (!t.col.count(need)) throw InputError(source, "columns", "no column \"" + need + "\"");
}

const char* const kAxis = "xyz";

std::string component(const char* prefix, int i, int j) {
  return std::string(prefix) + kAxis[i] + kAxis[j];
}

/// The measures of Criteria (to_json keys) that a column the series does
/// not have leaves unknown, with the column: ExternalSeries::not_available.
/// Their points hold 0 (read_measures), which nothing then reads.
void note_missing_measures(const Table& t, std::map<std::string, std::string>& missing) {
  auto need = [&](std::initializer_list<const char*> keys,
                  std::initializer_list<const char*> columns) {
    for (const char* column : columns)
      if (!t.has(column)) {
        for (const char* key : keys) missing.emplace(key, std::string("no column ") + column);
        return;
      }
  };
  need({"kinetic_energy_ratio_median", "kinetic_energy_ratio_max"},
       {"kinetic_energy", "elastic_energy"});
  need({"rotational_energy_share"}, {"kinetic_energy", "kinetic_energy_rotation"});
  need({"unbalanced_force_ratio_mean", "unbalanced_force_ratio_max"}, {"unbalanced_force_ratio"});
  need({"inertial_number_max"}, {"inertial_number"});
}

/// The servo measures of Criteria, unknown for want of `why`.
void note_missing_servo(std::map<std::string, std::string>& missing, const std::string& why) {
  for (const char* key : {"servo", "servo_rms", "servo_noise"}) missing.emplace(key, why);
}

/// The measures MonitorPoint and TriaxialPoint share (MonitorMeasures), by
/// the same names: the step, b and σ (b_ij, s_ij, 2×2 or 3×3), the energies
/// and ratios (0 where the column is missing: note_missing_measures() marks
/// them).
template <class Point>
void read_measures(const Table& t, const std::vector<double>& row, const std::string& source,
                   Point& p) {
  p.step = count(t.value(row, "step", 0), source, "step");
  for (int i = 0; i < p.b.rows(); ++i)
    for (int j = 0; j < p.b.cols(); ++j) {
      p.b(i, j) = t.value(row, component("b_", i, j), 0);
      p.sigma(i, j) = t.value(row, component("s_", i, j), 0);
    }
  p.kinetic_energy = t.value(row, "kinetic_energy", 0);
  p.kinetic_energy_rotation = t.value(row, "kinetic_energy_rotation", 0);
  p.elastic_energy = t.value(row, "elastic_energy", 0);
  p.unbalanced_force_ratio = t.value(row, "unbalanced_force_ratio", 0);
  p.inertial_number = t.value(row, "inertial_number", 0);
  p.coordination_number = t.value(row, "coordination_number", 0);
}

/// The biaxial rows (2D): disks, b and σ 2×2.
void read_biaxial_rows(const Table& t, ExternalSeries& out) {
  const double s3 = out.lateral_stress;
  const bool has_error = t.has("lateral_stress_error");
  const bool has_pressures = t.has("p_left") && t.has("p_right");
  out.torque_column = t.has("torque_stress");
  note_missing_measures(t, out.not_available);
  if (!has_error && !has_pressures)
    note_missing_servo(out.not_available, "no column lateral_stress_error, nor p_left and p_right");
  for (const auto& row : t.rows) {
    MonitorPoint p;
    read_measures(t, row, out.source, p);
    p.strain_yy = t.value(row, "strain_yy", 0);
    if (out.torque_column) {
      // Moment balance on the engine's own rotational disequilibrium (see the
      // header); the symmetric part, all force balance uses, is unchanged.
      const double tau = t.value(row, "torque_stress", 0);
      const double asym = p.sigma(0, 1) - p.sigma(1, 0);
      out.lever_arm_floor.push_back((asym - tau) / s3);
      const double sym = 0.5 * (p.sigma(0, 1) + p.sigma(1, 0));
      p.sigma(0, 1) = sym + 0.5 * tau;
      p.sigma(1, 0) = sym - 0.5 * tau;
    }
    if (has_error)
      p.lateral_stress_error = t.value(row, "lateral_stress_error", 0);
    else if (has_pressures)
      p.lateral_stress_error =
          (0.5 * (t.value(row, "p_left", 0) + t.value(row, "p_right", 0)) - s3) / s3;
    p.left = t.value(row, "wall_left", 0);
    p.right = t.value(row, "wall_right", 0);
    p.bottom = t.value(row, "wall_bottom", 0);
    p.top = t.value(row, "wall_top", 0);
    out.run.series.push_back(p);
  }
}

/// The triaxial rows (3D): spheres, b and σ 3×3, the four lateral walls'
/// servo errors (from servo_error_* or else from the pressures p_*).
void read_triaxial_rows(const Table& t, ExternalSeries& out) {
  static const char* const kWall[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  const double s3 = out.lateral_stress;
  note_missing_measures(t, out.not_available);
  // Each lateral wall's servo error: its column, else its pressure, else
  // unknown ("servo_xmin" .. "servo_ymax"); the mean of the four
  // (lateral_stress_error, the xy pair's servo) needs the four.
  bool all_walls = true;
  for (int w = 0; w < 4; ++w)
    if (!t.has(("servo_error_" + std::string(kWall[w])).c_str()) &&
        !t.has(("p_" + std::string(kWall[w])).c_str())) {
      all_walls = false;
      out.not_available.emplace(
          std::string("servo_") + kWall[w],
          std::string("no column servo_error_") + kWall[w] + ", nor p_" + kWall[w]);
    }
  if (!t.has("lateral_stress_error") && !all_walls)
    out.not_available.emplace("lateral_stress_error",
                              "no column lateral_stress_error, nor the four lateral walls' "
                              "servo_error_* or p_*");
  // The drags are shares of the axial wall's power.
  for (const char* column : {"axial_power", "damping_power_rotation"})
    if (!t.has(column)) {
      out.not_available.emplace("rotational_drag", std::string("no column ") + column);
      break;
    }
  for (const char* column : {"axial_power", "damping_power_translation"})
    if (!t.has(column)) {
      out.not_available.emplace("translational_drag", std::string("no column ") + column);
      break;
    }
  for (const auto& row : t.rows) {
    TriaxialPoint p;
    read_measures(t, row, out.source, p);
    p.strain_zz = t.value(row, "strain_zz", 0);
    double mean_error = 0.0;
    for (int w = 0; w < 4; ++w) {
      const std::string pressure = std::string("p_") + kWall[w];
      const double from_pressure =
          t.has(pressure.c_str()) ? (t.value(row, pressure, 0) - s3) / s3 : 0.0;
      p.servo_error[w] = t.value(row, std::string("servo_error_") + kWall[w], from_pressure);
      mean_error += 0.25 * p.servo_error[w];
    }
    p.lateral_stress_error = t.value(row, "lateral_stress_error", mean_error);
    for (int w = 0; w < 6; ++w) p.walls[w] = t.value(row, std::string("wall_") + kWall[w], 0);
    p.damping_power_translation = t.value(row, "damping_power_translation", 0);
    p.damping_power_rotation = t.value(row, "damping_power_rotation", 0);
    p.axial_power = t.value(row, "axial_power", 0);
    out.triaxial.series.push_back(p);
  }
}

/// The reason of "# divergence = REASON" (to_string(Divergence)); a
/// missing or unknown one reads as values that are not finite (the
/// reason's words are kept apart: ExternalSeries::divergence_reason).
Divergence divergence_named(const ExternalSeries& s) {
  const auto it = s.meta.find("divergence");
  for (Divergence d : {Divergence::kOverlap, Divergence::kEnergy, Divergence::kEnergyCreated})
    if (it != s.meta.end() && it->second == to_string(d)) return d;
  return Divergence::kNotFinite;
}

/// What the series says of the parameters the diagnosis reads: only what
/// its metadata give (α needs both dt and dt_crit).
RunParameters known_parameters(const ExternalSeries& s) {
  RunParameters p;
  const auto dt = meta_number(s, "dt"), dt_crit = meta_number(s, "dt_crit");
  if (dt && dt_crit && *dt_crit > 0.0) p.dt_ratio = *dt / *dt_crit;
  p.damping_ratio_translation = meta_number(s, "damping_ratio_translation");
  p.damping_ratio_rotation = meta_number(s, "damping_ratio_rotation");
  p.mass_scaling = meta_number(s, "mass_scaling");
  return p;
}

/// What the metadata and the rows say of the run (LoadingResult and
/// TriaxialResult name these fields alike). Its last monitoring point may
/// fall short of the last step by less than one interval (Nstep not a
/// multiple of M).
template <class Run>
void read_run_facts(const Table& t, ExternalSeries& out, Run& run) {
  const auto& series = run.series;
  const int64_t last = series.empty() ? 0 : series.back().step;
  const int64_t interval = series.size() >= 2 ? last - series[series.size() - 2].step : 0;
  run.diverged = t.diverged;
  if (t.diverged) {
    run.divergence = Divergence::kNotFinite;
    run.divergence_step = t.diverged_step;
    out.divergence_reason =
        t.diverged_step >= 0
            ? "non-finite values in the series' row of step " + std::to_string(t.diverged_step)
            : "non-finite values in the series after step " + std::to_string(last);
  } else if (const auto step = meta_number(out, "divergence_step")) {
    // A run whose own checks stopped it (demcal's): its rows are finite.
    run.diverged = true;
    run.divergence_step = count(*step, out.source, "# divergence_step");
    run.divergence = divergence_named(out);
    const auto why = out.meta.find("divergence");
    out.divergence_reason =
        why != out.meta.end() ? why->second : "its reason not given (no # divergence)";
  }
  const auto steps = meta_number(out, "steps");
  run.steps_planned = steps ? count(*steps, out.source, "# steps") : last;
  run.steps_run =
      (!run.diverged && steps && last < run.steps_planned && run.steps_planned - last < interval)
          ? run.steps_planned
          : last;
  run.particles = static_cast<int>(
      count(meta_number(out, "particles").value_or(0), out.source, "# particles", kMaxParticles));
  run.integration.dt = meta_number(out, "dt").value_or(0);
  run.scales.dt_crit = meta_number(out, "dt_crit").value_or(0);
  run.integration.damping_ratio_translation =
      meta_number(out, "damping_ratio_translation").value_or(0);
  run.integration.damping_ratio_rotation = meta_number(out, "damping_ratio_rotation").value_or(0);
  run.integration.mass_scaling = meta_number(out, "mass_scaling").value_or(1);
  // The integration above fills the run's fields; the diagnosis reads only
  // what the metadata gave.
  out.parameters = known_parameters(out);
}

/// How the run ended, and the parameters the series gives.
template <class Run>
RunOutcome outcome(const Run& run, const RunParameters& parameters) {
  return {run.diverged,      run.stopped_early, run.steps_run,
          run.steps_planned, run.particles,     parameters};
}

/// The 3D measures the series cannot give, on the criteria that hold them:
/// each plane's servo (its two walls; the xy pair's is the four walls'
/// mean), the walls', the drags, and the combined ones (servo: any wall).
void mark_not_available(TriaxialCriteria& c, const std::map<std::string, std::string>& missing) {
  static const char* const kWall[4] = {"servo_xmin", "servo_xmax", "servo_ymin", "servo_ymax"};
  auto servo_of = [&](Criteria& plane, std::initializer_list<int> walls) {
    for (int w : walls)
      if (missing.count(kWall[w])) {
        note_missing_servo(plane.not_available, missing.at(kWall[w]));
        return;
      }
  };
  // The energies' and the other codes' measures: every plane's (the same
  // series); the drags are TriaxialCriteria's, the rotational one also
  // judged (folded into the combined moment balance).
  for (Criteria* k : {&c.xz, &c.yz, &c.xy, &c.combined})
    for (const auto& [key, why] : missing)
      if (key.rfind("servo_", 0) != 0 && key != "lateral_stress_error" &&
          key.find("_drag") == std::string::npos)
        k->not_available[key] = why;
  if (missing.count("rotational_drag"))
    c.combined.not_available["rotational_drag"] = missing.at("rotational_drag");
  servo_of(c.xz, {0, 1});
  servo_of(c.yz, {2, 3});
  if (missing.count("lateral_stress_error"))
    note_missing_servo(c.xy.not_available, missing.at("lateral_stress_error"));
  servo_of(c.combined, {0, 1, 2, 3});
  for (int w = 0; w < 4; ++w)
    if (missing.count(kWall[w])) c.not_available.emplace(kWall[w], missing.at(kWall[w]));
  for (const char* key : {"rotational_drag", "translational_drag"})
    if (missing.count(key)) c.not_available.emplace(key, missing.at(key));
}

}  // namespace

ExternalSeries parse_external_series(const std::string& text, const std::string& source,
                                     std::optional<double> lateral_stress) {
  ExternalSeries out;
  out.source = source;
  const Table t = read_table(text, out);
  // A triaxial series names the axial strain strain_zz (and has b_zz).
  out.dimension = t.has("strain_zz") || t.has("b_zz") ? 3 : 2;
  if (out.dimension == 2) {
    require_columns(
        t, source,
        {"step", "strain_yy", "b_xx", "b_xy", "b_yx", "b_yy", "s_xx", "s_xy", "s_yx", "s_yy"});
  } else {
    require_columns(t, source, {"step", "strain_zz"});
    for (const char* prefix : {"b_", "s_"})
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) require_columns(t, source, {component(prefix, i, j)});
  }
  // A diverged run may have fewer (its engine's or demcal's own checks).
  if (t.rows.size() < 2 && !t.diverged && !out.meta.count("divergence_step"))
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

  // A compressive peak, whichever sign the file gives it (as --reference-peak).
  if (const auto ref = meta_number(out, "reference_peak")) out.reference_peak = -std::abs(*ref);
  if (out.dimension == 2) {
    read_biaxial_rows(t, out);
    read_run_facts(t, out, out.run);
    // The peak tracked at every step, when the writer tracked one (demcal):
    // score_run() takes it over the monitored one, as for demcal's runs.
    if (const auto peak = meta_number(out, "peak_stress_yy")) {
      out.run.peak_stress_yy = *peak;
      out.run.peak_strain_yy = meta_number(out, "peak_strain_yy").value_or(0.0);
    }
  } else {
    read_triaxial_rows(t, out);
    read_run_facts(t, out, out.triaxial);
    if (const auto peak = meta_number(out, "peak_stress_zz")) {  // as in 2D
      out.triaxial.peak_stress_zz = *peak;
      out.triaxial.peak_strain_zz = meta_number(out, "peak_strain_zz").value_or(0.0);
    }
  }
  return out;
}

ExternalScore score_external(const ExternalSeries& series, const Tolerances& tolerances,
                             std::optional<double> reference_peak) {
  ExternalScore out;
  if (series.dimension == 3) {
    // The criteria of the three planes, as `demcal run` and the calibration
    // score demcal's 3D runs (the rotational drag folded into moment
    // balance; 0 without the power columns); the peak tracked at every step
    // where the file gives one (demcal's own), else the monitored one.
    const TriaxialResult& run = series.triaxial;
    TriaxialCriteria c = compute_triaxial_criteria(run, series.lateral_stress, reference_peak);
    mark_not_available(c, series.not_available);
    out.score =
        score_of(scored_criteria(c, tolerances), outcome(run, series.parameters), tolerances);
    out.planes = c;
    return out;
  }
  Criteria c = compute_criteria(series.run, series.lateral_stress, reference_peak);
  c.not_available = series.not_available;
  out.score = score_of(c, outcome(series.run, series.parameters), tolerances);
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

std::string score_verdict(const ExternalSeries& series, const ExternalScore& score) {
  const Score& s = score.score;
  const bool is_3d = series.dimension == 3;
  if (!s.diverged && !s.complete) {
    const int64_t run = is_3d ? series.triaxial.steps_run : series.run.steps_run;
    const int64_t planned = is_3d ? series.triaxial.steps_planned : series.run.steps_planned;
    return "FAIL: incomplete: the series ran " + std::to_string(run) + " of the " +
           std::to_string(planned) + " steps planned";
  }
  return std::string(s.passed ? "PASS: " : "FAIL: ") + s.diagnosis.message;
}

nlohmann::json external_summary(const ExternalSeries& series, const ExternalScore& score,
                                const Tolerances& tolerances) {
  const Score& s = score.score;
  const bool is_3d = series.dimension == 3;
  const size_t points = is_3d ? series.triaxial.series.size() : series.run.series.size();
  const bool diverged = is_3d ? series.triaxial.diverged : series.run.diverged;
  const int64_t divergence_step =
      is_3d ? series.triaxial.divergence_step : series.run.divergence_step;
  const std::string axial = is_3d ? "zz" : "yy";  // the loaded axis
  nlohmann::json j{
      {"schema", "demcal.score/1"},
      {"source", series.source},
      {"dimension", series.dimension},
      {"metadata", series.meta},
      {"points", points},
      {"steps_planned", is_3d ? series.triaxial.steps_planned : series.run.steps_planned},
      {"steps_run", is_3d ? series.triaxial.steps_run : series.run.steps_run},
      {"lateral_stress", series.lateral_stress},
      {"criteria", to_json(s.criteria)},
      {"tolerances", to_json(tolerances)},
      {"passed", s.passed},
      {"complete", s.complete},
      {"diagnosis", to_json(s.diagnosis)},
      {"peak",
       {{"stress_" + axial, s.criteria.peak_stress_yy},
        {"strain_" + axial, s.criteria.peak_strain_yy},
        {"ratio", -s.criteria.peak_stress_yy / series.lateral_stress}}},
      {"diverged", diverged},
      {"verdict_line", score_verdict(series, score)}};
  if (!s.not_checked.empty()) j["not_checked"] = s.not_checked;
  if (score.planes) {
    j["criteria_planes"] = to_json(*score.planes);
    j["axial_component"] = kTriaxialCriteriaNames;
  }
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
  if (diverged) j["divergence"] = {{"step", divergence_step}, {"reason", series.divergence_reason}};
  return j;
}

}  // namespace demcal
