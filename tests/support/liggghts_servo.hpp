// Test support: the numbers of the carried servo a LIGGGHTS deck writes with
// contact damping (deck::liggghts_carried_servo_run), read from the deck's
// text, for the no-engine checks of the 2D and 3D decks (test_export.cpp,
// test_export_3d.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

namespace demcal::test {

/// A lateral wall's servo law in a LIGGGHTS deck: u = clamp(gain*(F_target
/// + F)/(resist*max(1, n)) + carry*u', +-cap) per demcal step (the move
/// before the clamp stored by fix servo_w, u by fix servo_u), moved at
/// u/dt_demcal.
struct LiggghtsCarriedLaw {
  double gain = std::nan(""), resist = std::nan(""), carry = std::nan("");
  double cap = std::nan(""), dt_demcal = std::nan("");
};

/// The law of the deck's wall `fix` (e.g. "mleft"), its k-th (1-based) in
/// compute nservo and fix servo_u, target variable `target`, force
/// component `axis` + 1 of its mesh; NaN members (and a failure) if the
/// deck does not write it in that form.
inline LiggghtsCarriedLaw liggghts_carried_law(const std::string& deck, const std::string& fix,
                                               int k, const std::string& target, int axis) {
  const std::string n = "c_nservo\\[" + std::to_string(k) + "\\]";
  const std::string u = "f_servo_u\\[" + std::to_string(k) + "\\]";
  const std::string number = "([-+0-9.e]+)";
  const std::regex law("\nvariable sw_" + fix + " equal \\(step>0\\)\\*\\(" + number + "\\*\\(v_" +
                       target + "\\+f_" + fix + "\\[" + std::to_string(axis + 1) + "\\]\\)/\\(" +
                       number + "\\*\\(" + n + "\\+\\(" + n + "<1\\)\\)\\)\\+" + number + "\\*" +
                       u + "\\)\n");
  // the clamp of the stored move before it (fix servo_w, before fix servo_u)
  const std::string w = "f_servo_w\\[" + std::to_string(k) + "\\]";
  const std::regex clamp("\nvariable su_" + fix + " equal " + w + "\\*\\(abs\\(" + w + "\\)<=" +
                         number + "\\)\\+\\1\\*\\(" + w + ">\\1\\)-\\1\\*\\(" + w + "<-\\1\\)\n");
  const auto raw_fix = deck.find("\nfix servo_w all ave/time 1 1 1 ");
  const auto move_fix = deck.find("\nfix servo_u all ave/time 1 1 1 ");
  if (raw_fix == std::string::npos || move_fix == std::string::npos || move_fix < raw_fix)
    ADD_FAILURE() << "fix servo_w must store the moves before the clamp, before fix servo_u";
  const std::regex velocity("\nvariable sv_" + fix + " equal " + u + "/" + number + "\n");
  LiggghtsCarriedLaw out;
  std::smatch m;
  if (std::regex_search(deck, m, law)) {
    out.gain = std::stod(m[1].str());
    out.resist = std::stod(m[2].str());
    out.carry = std::stod(m[3].str());
  } else {
    ADD_FAILURE() << "no carried servo law for " << fix;
  }
  if (std::regex_search(deck, m, clamp))
    out.cap = std::stod(m[1].str());
  else
    ADD_FAILURE() << "no clamp for " << fix;
  if (std::regex_search(deck, m, velocity))
    out.dt_demcal = std::stod(m[1].str());
  else
    ADD_FAILURE() << "no velocity for " << fix;
  return out;
}

}  // namespace demcal::test
