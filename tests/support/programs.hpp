// Test support: the other programs some tests run (LAMMPS, LIGGGHTS,
// mpirun, gnuplot), and what a test does when one is missing.
//
// On a user's machine a missing engine is no fault of demcal's: the test
// skips with a message that names the program and its Debian package. In
// CI it is a fault: the README's test command installs every one of them,
// and a test that skipped there (a renamed binary, a PATH the package did
// not reach) would leave CI green without having run the decks. `.ci/run`
// sets DEMCAL_REQUIRE_PROGRAMS=1, and then the same test fails instead.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "support/process.hpp"

namespace demcal::test {

/// "lmp is not installed (apt-get install lammps): the deck is not run".
std::string missing_program(const std::string& name, const std::string& package,
                            const std::string& consequence);

/// True when the environment variable DEMCAL_REQUIRE_PROGRAMS is set to
/// anything but "" or "0": a missing program fails the test.
bool programs_required();

}  // namespace demcal::test

/// Skip the current test (or fail it, under DEMCAL_REQUIRE_PROGRAMS)
/// because `name` is missing. Like GTEST_SKIP, it returns from the function
/// it is written in.
#define DEMCAL_SKIP_MISSING(name, package, consequence)                            \
  do {                                                                             \
    if (::demcal::test::programs_required()) {                                     \
      FAIL() << ::demcal::test::missing_program(name, package, consequence)        \
             << " (DEMCAL_REQUIRE_PROGRAMS is set: the test command installs it)"; \
    } else {                                                                       \
      GTEST_SKIP() << ::demcal::test::missing_program(name, package, consequence); \
    }                                                                              \
  } while (false)

/// `const std::string var` = the path of `name` on PATH; when there is none,
/// DEMCAL_SKIP_MISSING.
#define DEMCAL_FIND_PROGRAM(var, name, package, consequence)  \
  const std::string var = ::demcal::test::find_on_path(name); \
  if (var.empty()) DEMCAL_SKIP_MISSING(name, package, consequence)
