// Test support: a deck's per-step trace (fix print to a file, one row of
// numbers per step, the step first), read into rows by step.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace demcal::test {

/// The rows of `text` by step (their first number), each with `columns`
/// numbers; comment and empty lines skipped. A run's setup prints its first
/// step again: the first row of a step is kept (that of the step's end). A
/// row of another width fails the test and ends the reading (fewer rows).
inline std::map<int64_t, std::vector<double>> trace_rows(const std::string& text, size_t columns) {
  std::map<int64_t, std::vector<double>> rows;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream fields(line);
    std::vector<double> v;
    for (double x; fields >> x;) v.push_back(x);
    if (v.size() != columns) {
      ADD_FAILURE() << "a trace row of " << v.size() << " numbers, not " << columns << ": " << line;
      break;
    }
    rows.emplace(static_cast<int64_t>(v[0]), v);
  }
  return rows;
}

}  // namespace demcal::test
