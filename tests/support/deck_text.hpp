// Test support: a deck's text edited and read (the engine and export tests
// of both dimensions).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

namespace demcal::test {

/// `what` replaced by `with` in `text`, which must hold it once (a test
/// fails otherwise).
inline std::string replaced(std::string text, const std::string& what, const std::string& with) {
  const auto at = text.find(what);
  EXPECT_NE(at, std::string::npos) << what;
  EXPECT_EQ(text.find(what, at + 1), std::string::npos) << what;
  if (at != std::string::npos) text.replace(at, what.size(), with);
  return text;
}

/// The number of `variable NAME equal NUMBER` in a deck (NaN if absent).
inline double deck_variable(const std::string& deck, const std::string& name) {
  std::istringstream lines(deck);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream in(line);
    std::string word, var, style;
    double v = 0.0;
    if (in >> word >> var >> style && word == "variable" && var == name && style == "equal" &&
        in >> v)
      return v;
  }
  return std::nan("");
}

}  // namespace demcal::test
