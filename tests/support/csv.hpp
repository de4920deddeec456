// Test support: reading the series.csv `demcal run` writes, in the CLI tests
// of both dimensions.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace demcal::test {

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

}  // namespace demcal::test
