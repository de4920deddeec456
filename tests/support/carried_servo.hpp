// Test support: demcal's carried servo law as the decks' trace tests check
// it (LAMMPS: test_engine_loading_servo.cpp; LIGGGHTS:
// test_engine_score.cpp), one oracle for both: each traced move must be
// clamp(law + carry·u_prev, ±cap), law the per-step move over R =
// servo_resistance, carry = servo_carry(kn_wall, R), u_prev the wall's move
// of the step before (scene/biaxial.hpp, servo_velocity); and over the
// trace the clamp must bind at some moves and not at others, and the carry
// must weigh in many free moves, or the trace proved nothing about them.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace demcal::test {

class CarriedServoTally {
 public:
  CarriedServoTally(double carry, double cap) : carry_(carry), cap_(cap) {}

  /// demcal's move: the per-step `law` plus the carry of `prev`, clamped.
  double expected(double law, double prev) const {
    return std::clamp(law + carry_ * prev, -cap_, cap_);
  }

  /// Counts a traced move: clamped, or free (and carried when the carry
  /// term is 10 % of the law or more).
  void count(double move, double law, double prev) {
    if (std::abs(move) > (1 - 1e-9) * cap_) {
      ++clamped_;
    } else {
      ++free_;
      if (carry_ * std::abs(prev) >= 0.1 * std::abs(law)) ++carried_;
    }
  }

  /// Prints the tally and expects over a hundred moves of each kind.
  void expect_every_regime(const std::string& tag) const {
    std::printf("%s: carry %.6f, cap %.3g, %d moves clamped, %d free, %d of them carried\n",
                tag.c_str(), carry_, cap_, clamped_, free_, carried_);
    EXPECT_GT(clamped_, 100) << "the clamp never bound";
    EXPECT_GT(free_, 100) << "the clamp always bound";
    EXPECT_GT(carried_, 100) << "the carry never weighed";
  }

 private:
  double carry_, cap_;
  int clamped_ = 0, free_ = 0, carried_ = 0;
};

}  // namespace demcal::test
