// Test support: a deck's text edited and read (the engine and export tests
// of both dimensions).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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

/// Every `what` in `text` replaced by `with`.
inline std::string replaced_all(std::string text, const std::string& what,
                                const std::string& with) {
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + with.size()))
    text.replace(at, what.size(), with);
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

/// The header a deck's series file opens with, as the engine writes it
/// (demcal score's metadata; upscaling/deck_sections.hpp,
/// lammps_series_header): the text of the print line that starts the file
/// (`print "..." file ${series} ...`) and of the `print "..." append
/// ${series}` lines right after it, each `${NAME}` in them replaced by the
/// deck's `variable NAME equal NUMBER` (%.17g; a test fails on one it
/// cannot resolve), one line each.
inline std::string deck_series_header(const std::string& deck) {
  std::istringstream lines(deck);
  std::string out;
  bool started = false;
  for (std::string line; std::getline(lines, line);) {
    const bool starts = line.find("\" file ${series} ") != std::string::npos;
    const bool appends = line.find("\" append ${series} ") != std::string::npos;
    if (line.rfind("print", 0) != 0 || !(started ? appends : starts)) {
      if (started) break;
      continue;
    }
    started = true;
    const auto open = line.find('"'), close = line.rfind('"');
    std::string text = line.substr(open + 1, close - open - 1);
    for (auto at = text.find("${"); at != std::string::npos; at = text.find("${", at)) {
      const auto end = text.find('}', at);
      const std::string name = text.substr(at + 2, end - at - 2);
      const double v = deck_variable(deck, name);
      EXPECT_FALSE(std::isnan(v)) << "${" << name << "} in " << line;
      char number[32];
      std::snprintf(number, sizeof number, "%.17g", v);
      text.replace(at, end + 1 - at, number);
    }
    out += text + "\n";
  }
  EXPECT_TRUE(started) << "no print line starts the series file";
  return out;
}

}  // namespace demcal::test
