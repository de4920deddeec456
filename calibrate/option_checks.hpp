// Range checks for the numeric options of every subcommand, as CLI11
// validators: a value out of range (0, -5, nan, 1e999, a count that does
// not fit) fails the parse with one line naming the option, exit 2, before
// anything is read or written. An option left out keeps its default. Also
// the scene options (config, --set) every command on a config registers.
#pragma once

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace demcal::cli {

/// A whole number in [lo, hi] ("1e9" and "3.5" are not whole numbers here:
/// counts are read as integers, never through a double).
inline CLI::Validator whole_number(int64_t lo, int64_t hi, const std::string& why = "") {
  const std::string range =
      "a whole number from " + std::to_string(lo) + " to " + std::to_string(hi);
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        errno = 0;
        char* end = nullptr;
        const long long v = std::strtoll(s.c_str(), &end, 10);
        if (s.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
          return "must be " + range + (why.empty() ? "" : " (" + why + ")") + ", got " + s;
        return "";
      },
      range);
}

/// A finite real number (nan and inf refused: CLI::Range lets nan through)
/// for which `in_range` holds; else "must be RANGE, got S".
template <class InRange>
CLI::Validator finite_real(const std::string& range, InRange in_range) {
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (s.empty() || *end != '\0' || !std::isfinite(v) || !in_range(v))
          return "must be " + range + ", got " + s;
        return "";
      },
      range);
}

/// A finite real number in (lo, hi] (lo excluded: 0 is never a valid
/// accuracy, exponent or duration).
inline CLI::Validator real_above(double lo, double hi) {
  return finite_real(
      "a number > " + CLI::detail::to_string(lo) + " and <= " + CLI::detail::to_string(hi),
      [=](double v) { return v > lo && v <= hi; });
}

/// The same with hi excluded: a fraction in (0, 1).
inline CLI::Validator real_between(double lo, double hi) {
  return finite_real("a number strictly between " + CLI::detail::to_string(lo) + " and " +
                         CLI::detail::to_string(hi),
                     [=](double v) { return v > lo && v < hi; });
}

/// -o of every command: a path, not empty. `-o ''` (an unset variable in a
/// script) would otherwise mean the default, writing where the user did not
/// ask; leaving -o out is how to ask for the default.
inline CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        return s.empty() ? "must not be empty (leave the option out for the default)" : "";
      },
      "PATH");
}

/// --jobs: at least one; more threads than this is a typo, not a machine.
inline constexpr int64_t kMaxJobs = 1024;
/// --max-trials: a search of more trials than this is a typo (a REV trial
/// takes seconds; the default is 80).
inline constexpr int64_t kMaxTrials = 100'000;
/// --exponent of Nstep ~ N^exponent: measured laws lie near 1 (linear);
/// beyond 3 the upscaled step counts overflow for any real prototype.
inline constexpr double kMaxExponent = 3.0;
/// Durations in minutes: up to a year.
inline constexpr double kMaxMinutes = 525'600.0;

/// The scene every command on a config reads (check, run, sweep, calibrate,
/// stability, scaling, rev): a config file and its overrides.
inline void add_scene_options(CLI::App* command, std::string& config,
                              std::vector<std::string>& sets) {
  command->add_option("config", config, "scene config (JSON); default: the embedded one");
  command->add_option("--set", sets, "override a key: section.key=value (repeatable)");
}

/// --progress of every command that consolidates a sample (check, run,
/// sweep, calibrate, stability, rev, verify, scaling, export): seconds
/// between progress lines on stderr (default 2, kProgressEverySeconds; 0:
/// every check), a finite number from 0 to 1e9.
inline void add_progress_option(CLI::App* command, double& every_s) {
  command
      ->add_option("--progress", every_s,
                   "seconds between consolidation progress lines on stderr (default 2; 0: every "
                   "check)")
      ->check(finite_real("a number from 0 to 1e9", [](double v) { return v >= 0.0 && v <= 1e9; }));
}

}  // namespace demcal::cli
