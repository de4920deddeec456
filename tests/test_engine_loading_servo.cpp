// The LAMMPS decks' loading servo with contact damping, traced at every
// step: each move is demcal's servo_velocity per step of the deck's dt, the
// per-step law plus servo_carry of the wall's last move (reports/engines.md
// §24), in 2D and in 3D.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "demcal/upscaling/rev.hpp"
#include "support/carried_servo.hpp"
#include "support/deck_text.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"
#include "support/trace_rows.hpp"

namespace demcal {

using test::replaced;
namespace {

/// The number a deck line "variable NAME equal X" gives NAME.
double deck_value(const std::string& deck, const std::string& name) {
  std::smatch m;
  EXPECT_TRUE(
      std::regex_search(deck, m, std::regex("\nvariable " + name + " +equal ([-+0-9.eE]+)[ \n]")))
      << name;
  return m.empty() ? 0.0 : std::stod(m[1].str());
}

/// What the trace gives the law, and what demcal's law is made of.
struct LoadingServo {
  std::string fix_before;  ///< the trace goes just before this line (the fix summing the moves)
  std::vector<std::string> position, count, force, move;  ///< per wall, LAMMPS formulas
  std::vector<std::string> geometry;                      ///< formulas the area is made of
  /// wall k's area from the traced geometry
  std::function<double(const std::vector<double>&, size_t)> area;
  double m_max = 0.0;  ///< the heaviest particle's mass, with the mass scaling
  double r_min = 0.0;
};

/// The deck's loading (`r`, of scene `c`) with contact damping, traced at
/// every step for `steps` steps: each wall's position, contact count n,
/// force F on the particles (along +axis) and the move the deck computed,
/// with the step dt and the geometry. Every move must be demcal's servo
/// (servo_velocity, scene/biaxial.hpp and triaxial.cpp) per step of dt,
/// clamp(f*gain*(±sigma3*A - F)/(R*max(1, n)) + carry*u_prev, ±f*cap) along
/// +axis, f = dt/servo_dt (the deck's law per unit of time, engines.md §18),
/// R = servo_resistance(kn_wall, zeta_c, m_max, servo_dt), carry =
/// servo_carry(kn_wall, R), u_prev the wall's move of the step before (0 at
/// the first: the walls start the loading at rest); and each move must be
/// the one applied (the position one step later). Tolerance: 1e-9 of |law|
/// + carry*|u_prev| (the 2D deck writes numbers with 10 digits) and 1e-13
/// of the law's load and force terms (where they cancel). The cap is
/// edited to `cap` r_min so that the clamp binds at some steps and not at
/// others; the carry term must weigh 10 % of the law or more in over a
/// hundred free moves.
void expect_the_loading_servo_carries_its_last_move(const std::string& lmp, const ExportResult& r,
                                                    const SceneConfig& c, const LoadingServo& servo,
                                                    int steps, const std::string& cap,
                                                    const std::string& tag) {
  const size_t walls = servo.move.size();
  const size_t geometry = servo.geometry.size();
  std::string row = "$(step) $(dt:%.17g)";
  for (const std::string& g : servo.geometry) row += " $(" + g + ":%.17g)";
  for (size_t k = 0; k < walls; ++k)
    row += " $(" + servo.position[k] + ":%.17g) $(" + servo.count[k] + ":%.17g) $(" +
           servo.force[k] + ":%.17g) $(" + servo.move[k] + ":%.17g)";
  std::string deck = replaced(r.deck, servo.fix_before,
                              "fix             trace all print 1 \"" + row +
                                  "\" file trace.txt screen no\n" + servo.fix_before);
  deck = replaced(deck, "variable cap       equal $(0.02*v_r_min)",
                  "variable cap       equal $(" + cap + "*v_r_min)");
  const test::TempDir dir(tag);
  const test::DeckRun run =
      test::run_deck(lmp, dir.path(), deck, r.files,
                     {"-var", "run_steps", std::to_string(steps), "-screen", "none"});
  ASSERT_EQ(run.status, 0) << run.log;
  const double dt_deck = deck_value(r.deck, "dt"), servo_dt = deck_value(r.deck, "servo_dt");
  const double servo_f = dt_deck / servo_dt;
  const double cap_step = std::stod(cap) * servo.r_min * servo_f;
  const std::map<int64_t, std::vector<double>> rows =
      test::trace_rows(test::read_text(dir / "trace.txt"), 2 + geometry + 4 * walls);
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps) + 1);
  ASSERT_EQ(rows.begin()->first, 0);
  const double kn_wall = c.material.wall.kn, zeta_c = c.material.contact_damping_ratio;
  const double sigma3 = c.test.lateral_stress, gain = c.test.servo_gain;
  const double resist = servo_resistance(kn_wall, zeta_c, servo.m_max, servo_dt);
  const double carry = servo_carry(kn_wall, resist);
  ASSERT_GT(carry, 0.1);
  std::vector<double> prev(walls, 0.0), last_position(walls, 0.0);
  test::CarriedServoTally tally(carry, cap_step);
  std::vector<double> moves;  // |move|/cap_step
  for (const auto& [step, v] : rows) {
    SCOPED_TRACE("step " + std::to_string(step));
    EXPECT_NEAR(v[1], dt_deck, 1e-14 * dt_deck);  // timestep ${dt}: 15 digits
    const std::vector<double> g(v.begin() + 2, v.begin() + 2 + geometry);
    const size_t at = 2 + geometry;
    for (size_t k = 0; k < walls; ++k) {
      const double position = v[at + 4 * k], n = v[at + 1 + 4 * k], force = v[at + 2 + 4 * k],
                   move = v[at + 3 + 4 * k];
      const double load = (k % 2 == 0 ? 1.0 : -1.0) * sigma3 * servo.area(g, k);
      const double per_newton = servo_f * gain / (resist * std::max(1.0, n));
      const double law = per_newton * (load - force);
      const double expected = tally.expected(law, prev[k]);
      // and the rounding of the load (from the traced geometry, 15 digits;
      // the deck's own from load0 - load_step*step) where load - F cancels
      const double scale = std::abs(law) + carry * std::abs(prev[k]) +
                           1e-4 * per_newton * (std::abs(load) + std::abs(force));
      ASSERT_LE(std::abs(move - expected), 1e-9 * scale)
          << "wall " << k << ": move " << move << ", demcal's law " << expected << " (law " << law
          << ", carry " << carry << ", last move " << prev[k] << ")";
      if (step > 0) {
        EXPECT_NEAR(position - last_position[k], prev[k],
                    1e-13 * std::abs(position) + 1e-9 * std::abs(prev[k]))
            << "wall " << k;
      }
      moves.push_back(std::abs(move) / cap_step);
      tally.count(move, law, prev[k]);
      prev[k] = move;
      last_position[k] = position;
    }
  }
  std::sort(moves.begin(), moves.end());
  std::printf("%s: %zu steps; |move|/cap median %.3g, 90 %% %.3g\n", tag.c_str(), rows.size(),
              moves[moves.size() / 2], moves[moves.size() * 9 / 10]);
  tally.expect_every_regime(tag);
}

// demcal's servo with contact damping carries (R - kn_wall)/R of each
// wall's last move in the loading too (servo_velocity, since 483ff94); the
// decks' loading must, per step of their dt. hex_5x5 at zeta_c 0.25 (the
// WithContactDampingTheDecksServoIsDemcals case), 3 000 steps, the cap at
// 3.1e-7 r_min (the export's 0.02 is 7e4 times the moves here; this one is
// about their size, so the clamp binds at half of them: 2 977 clamped, 3 025
// free, 3 022 of which carry 10 % of the law or more). The deck before moved
// each wall by the per-step law alone: it fails at the second step (move
// -5.9509e-14 where demcal's law gives -5.9300e-14).
TEST(EngineLammpsLoading, WithContactDashpotsTheServoCarriesItsLastMoveAsDemcals2D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  c.material.contact_damping_ratio = 0.25;
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  ASSERT_TRUE(state.converged);
  AlgorithmSpec p;
  p.dt_ratio = 0.19341;
  p.steps = 20000;
  p.damping_ratio_translation = 0.370356;
  p.damping_ratio_rotation = 0.0;
  p.dt_ratio = std::min(p.dt_ratio, 0.9 * estimated_stable_dt_ratio(state, p));
  ExportOptions o;
  o.deck_name = "hex5";
  const Assembly a = assembly_of(state.world);
  const ExportResult r = export_deck(c, p, a, o);
  LoadingServo servo;
  servo.fix_before = "fix             servol all ave/time 1 1 1 v_movev[1] ave running\n";
  servo.position = {"v_xl", "v_xr"};
  servo.count = {"c_cn[1]", "c_cn[2]"};
  servo.force = {"c_cf[1]", "c_cf[2]"};
  servo.move = {"v_movev[1]", "v_movev[2]"};
  servo.geometry = {"v_H"};
  const double thick = c.material.thickness;
  servo.area = [thick](const std::vector<double>& g, size_t) { return g[0] * thick; };
  servo.r_min = *std::min_element(a.r.begin(), a.r.end());
  servo.m_max = disk_mass(disk_areal_density(c.material, p.mass_scaling),
                          *std::max_element(a.r.begin(), a.r.end()));
  expect_the_loading_servo_carries_its_last_move(lmp, r, c, servo, 3000, "3.1e-7",
                                                 "engine_loading_carry_2d");
}

// The same in 3D: fcc_4x4x4 at zeta_c 0.3, alpha 0.1 (the
// Export3dLammps.WithContactDampingTheDecksServoIsDemcals case), 3 000
// steps, the four lateral walls, the cap at 8e-10 r_min (4 692 moves
// clamped, 7 312 free, 7 308 of which carried). The deck before fails at
// the second step (-3.1227e-18 where the law gives -2.5133e-18).
TEST(EngineLammpsLoading, WithContactDashpotsTheServoCarriesItsLastMoveAsDemcals3D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("fcc_4x4x4"));
  c.material.contact_damping_ratio = 0.3;
  const TriaxialState state = consolidate_triaxial(c, make_sphere_assembly(c));
  ASSERT_TRUE(state.converged);
  AlgorithmSpec p;
  p.dt_ratio = 0.1;
  p.steps = 10000;
  p.damping_ratio_translation = 0.4;
  p.damping_ratio_rotation = 0.0;
  Export3dOptions o;
  o.deck_name = "fcc";
  const ExportResult r = export_3d_decks(c, p, state, o);
  LoadingServo servo;
  servo.fix_before = "fix             servo all ave/time 1 1 1 v_movev mode vector ave running\n";
  for (int k = 1; k <= 4; ++k) {
    const std::string i = std::to_string(k);
    servo.position.push_back("f_servo[" + i + "]*step");
    servo.count.push_back("c_csn[" + i + "]");
    servo.force.push_back("c_csf[" + i + "]");
    servo.move.push_back("v_movev[" + i + "]");
  }
  servo.geometry = {"f_geom[1]", "f_geom[2]", "f_geom[3]"};  // Lx, Ly, H
  // A of an x wall Ly*H, of a y wall Lx*H
  servo.area = [](const std::vector<double>& g, size_t k) { return g[k < 2 ? 1 : 0] * g[2]; };
  servo.r_min = state.world.min_radius();
  servo.m_max = sphere_mass(c.material.density * p.mass_scaling, state.world.max_radius());
  expect_the_loading_servo_carries_its_last_move(lmp, r, c, servo, 3000, "8e-10",
                                                 "engine_loading_carry_3d");
}

}  // namespace
}  // namespace demcal
