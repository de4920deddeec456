// Test support: reading the series.csv `demcal run` writes, in the CLI tests
// of both dimensions.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace demcal::test {

/// The lines of a series.csv after its metadata (the lines starting with
/// '#', which come first): the column header, then the rows.
inline std::vector<std::string> series_table(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  bool table = false;
  for (std::string line; std::getline(s, line);) {
    table = table || line.empty() || line[0] != '#';
    if (table) out.push_back(line);
  }
  return out;
}

/// The "# key = value" lines of a series.csv's metadata, by key.
inline std::map<std::string, std::string> series_metadata(const std::string& text) {
  std::map<std::string, std::string> out;
  std::stringstream s(text);
  for (std::string line; std::getline(s, line) && !line.empty() && line[0] == '#';) {
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) out[line.substr(2, eq - 2)] = line.substr(eq + 3);
  }
  return out;
}

/// The fields of `line` between the separators `sep`.
inline std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, sep);) out.push_back(f);
  return out;
}

/// Every row after the header (rows[0]) has the header's number of
/// comma-separated fields, each a number.
inline void expect_numeric_rows(const std::vector<std::string>& rows) {
  const size_t columns = split(rows.at(0), ',').size();
  for (size_t k = 1; k < rows.size(); ++k) {
    const auto fields = split(rows[k], ',');
    ASSERT_EQ(fields.size(), columns) << "row " << k;
    for (const auto& f : fields) {
      char* end = nullptr;
      std::strtod(f.c_str(), &end);
      ASSERT_TRUE(end != f.c_str() && *end == '\0') << "row " << k << ": " << f;
    }
  }
}

/// The criteria `demcal score` computed from a run's series.csv
/// (`scored`) are the run's own (`run`, its summary.json's): the same keys,
/// the same whole numbers, and every measure within what the file's 10
/// significant digits leave: a criterion is a mean, an RMS or a high-pass
/// of stresses over σ3 (up to ~10 σ3 at the peak, each rounded by 5e-10
/// of itself; the fourth difference sums 16 such errors, over its gain
/// sqrt(70)), so 1e-8 absolute, and 1e-9 of a value carried as such (a
/// peak in Pa, a ratio). Objects (the 3D planes') are compared key by key,
/// arrays (per wall) element by element.
inline void expect_same_criteria(const nlohmann::json& run, const nlohmann::json& scored) {
  ASSERT_TRUE(run.is_object()) << run;
  std::set<std::string> run_keys, scored_keys;
  for (const auto& [k, v] : run.items()) run_keys.insert(k);
  for (const auto& [k, v] : scored.items()) scored_keys.insert(k);
  EXPECT_EQ(run_keys, scored_keys);
  for (const auto& [key, v] : run.items()) {
    if (!scored.contains(key)) continue;
    const auto& w = scored.at(key);
    if (v.is_object()) {  // the 3D planes' criteria
      SCOPED_TRACE(key);
      expect_same_criteria(v, w);
      continue;
    }
    if (v.is_array()) {  // per wall
      ASSERT_TRUE(w.is_array() && w.size() == v.size()) << key << ": " << w;
      for (size_t i = 0; i < v.size(); ++i)
        EXPECT_NEAR(w[i].get<double>(), v[i].get<double>(),
                    1e-8 + 1e-9 * std::abs(v[i].get<double>()))
            << key << "[" << i << "]";
      continue;
    }
    if (v.is_number_integer() || !v.is_number()) {
      EXPECT_EQ(w, v) << key;
      continue;
    }
    const double a = v.get<double>(), b = w.get<double>();
    EXPECT_NEAR(b, a, 1e-8 + 1e-9 * std::abs(a)) << key;
  }
}

}  // namespace demcal::test
