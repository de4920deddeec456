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

/// The band over which a LIGGGHTS deck with contact damping counts the
/// contacts of its wall `fix` (compute nservo_FIX over group band_FIX, the
/// region rband_FIX: `touch` the per-atom flag it sums, `bound` the band's
/// inner bound along the wall's axis `axis`); NaN and a failure if the deck
/// does not write it in that form.
struct LiggghtsBand {
  std::string touch;
  double bound = std::nan("");
};

inline LiggghtsBand liggghts_band(const std::string& deck, const std::string& fix, int axis,
                                  bool upper) {
  const std::string number = "([-+0-9.e]+)";
  std::string limits;
  for (int a = 0; a < 3; ++a)
    limits += a != axis ? " INF INF" : upper ? " " + number + " INF" : " INF " + number;
  const std::regex region("\nregion rband_" + fix + " block" + limits + " units box\n");
  const std::regex group("\ngroup band_" + fix + " region rband_" + fix + "\n");
  const std::regex count("\ncompute nservo_" + fix + " band_" + fix + " reduce sum v_(\\w+)\n");
  LiggghtsBand out;
  std::smatch m;
  if (std::regex_search(deck, m, region))
    out.bound = std::stod(m[1].str());
  else
    ADD_FAILURE() << "no band region for " << fix;
  if (!std::regex_search(deck, group)) ADD_FAILURE() << "no band group for " << fix;
  if (std::regex_search(deck, m, count))
    out.touch = m[1].str();
  else
    ADD_FAILURE() << "no band count for " << fix;
  return out;
}

/// The law of the deck's wall `fix` (e.g. "mleft"), its count compute
/// nservo_FIX, its k-th (1-based) in fix servo_u, target variable `target`, force
/// component `axis` + 1 of its mesh; NaN members (and a failure) if the
/// deck does not write it in that form.
inline LiggghtsCarriedLaw liggghts_carried_law(const std::string& deck, const std::string& fix,
                                               int k, const std::string& target, int axis) {
  const std::string n = "c_nservo_" + fix;
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
