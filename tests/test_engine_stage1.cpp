// Stage 1 of the LAMMPS decks that consolidate themselves (--consolidate-in
// deck): every wall's servo move in one vector-style formula is the per-wall
// formula, bit for bit (reports/engines.md §17); with contact dashpots the
// critical-damping fallback comes at demcal's check (§21) and the servo
// carries its last move as demcal's consolidation servo (§23).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "support/deck_text.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"
#include "support/trace_rows.hpp"

namespace demcal {

using test::replaced;
namespace {

namespace fs = std::filesystem;

/// The whole line of `deck` that starts with `head`.
std::string line_of(const std::string& deck, const std::string& head) {
  const auto at = deck.find(head);
  EXPECT_NE(at, std::string::npos) << head;
  if (at == std::string::npos) return {};
  return deck.substr(at, deck.find('\n', at) + 1 - at);
}

/// What stage 1 decided, from a log: the step count it printed and the
/// start walls it left to the loading (the echoed lines with the values).
std::string stage1_outcome(const std::string& log) {
  static const std::regex line(
      "(demcal deck: consolidated in [0-9][^\n]*|variable +[xyz][a-z]*0 (index|equal) "
      "[-+0-9.e]+)\n");
  std::string out;
  for (std::sregex_iterator it(log.begin(), log.end(), line), end; it != end; ++it)
    out += (*it)[0].str();
  return out;
}

/// The exported deck (stage 1's servo a vector formula) against the same deck
/// with the servo per wall and inline: each wall's scalar formula
/// clamp(gain*(sigma3*A*tail ∓ F)/(R*(1+n+abs(1-n))/2)), the clamp of the
/// unclamped formula itself, max(1, n) as (1+n+abs(1-n))/2, a max wall's force
/// and move with their own signs (the form before engines.md §17). `area[k]`
/// is wall k's area variable (walls min, max, axis by axis). Both run stage 1
/// to its end and `loading` steps of the loading; a trace of every stage-1
/// step's moves and running means (%.20g), the printed step count, the end
/// walls and the series compare character for character. Both decks' cap is
/// `cap` times r_min (the export's 0.02: the clamp would rarely bind), and
/// over a hundred moves must bind and as many not. `series`: the deck's
/// series file (deck_files).
void expect_per_wall_bit_for_bit(const std::string& lmp, const ExportResult& r,
                                 const std::vector<std::string>& area, const std::string& tail,
                                 const std::string& tag, int loading, const std::string& cap,
                                 const std::string& series) {
  const size_t walls = area.size();
  const std::string rawv = line_of(r.deck, "variable        cons_rawv vector ");
  const std::string head =
      "variable        cons_rawv vector ${gain}*(f_cons_sign*${sigma3}*f_cons_len" + tail +
      "-c_cons_wf)/(";
  // with contact dashpots the carry of the last moves (f_cons_prev) follows
  const std::string carry_tail = "+v_cons_carry*f_cons_prev\n";
  const bool carried = rawv.ends_with(carry_tail);
  const std::string foot = "*(c_cons_wn+!c_cons_wn))" + (carried ? carry_tail : "\n");
  ASSERT_EQ(rawv.rfind(head, 0), 0u) << rawv;
  ASSERT_GT(rawv.size(), head.size() + foot.size()) << rawv;
  ASSERT_EQ(rawv.substr(rawv.size() - foot.size()), foot) << rawv;
  // R: kn_wall, plus the wall dashpots' c/dt with contact damping
  const std::string resist = rawv.substr(head.size(), rawv.size() - head.size() - foot.size());
  auto clamp = [](const std::string& x) {
    return "(abs(" + x + "+${cap})-abs(" + x + "-${cap}))/2";
  };
  EXPECT_EQ(line_of(r.deck, "variable        cons_movev vector "),
            "variable        cons_movev vector " + clamp("v_cons_rawv") + "\n");
  const std::string servo =
      "fix             cons_servo all ave/time 1 1 1 v_cons_movev mode "
      "vector ave running\n";
  ASSERT_NE(r.deck.find(servo), std::string::npos);

  std::string per_wall_moves, names, vector_moves, means;
  for (size_t k = 0; k < walls; ++k) {
    const std::string i = std::to_string(k + 1), n = "c_cons_wn[" + i + "]";
    const bool min = k % 2 == 0;
    // (a max wall's inward move: its last move along +axis negated)
    const std::string raw = "${gain}*(${sigma3}*v_" + area[k] + tail + (min ? "-" : "+") +
                            "c_cons_wf[" + i + "])/(" + resist + "*(1+" + n + "+abs(1-" + n +
                            "))/2)" +
                            (carried ? "+v_cons_carry*" + std::string(min ? "" : "(-") +
                                           "f_cons_prev[" + i + "]" + (min ? "" : ")")
                                     : "");
    per_wall_moves +=
        "variable        cons_m" + i + " equal " + (min ? "" : "-") + clamp(raw) + "\n";
    names += " v_cons_m" + i;
    vector_moves += " $(v_cons_movev[" + i + "])";
    means += " $(f_cons_servo[" + i + "])";
  }
  // the moves every step (the per-wall ones read from a fix: a `v_`
  // reference would go through text), after the line `after`; unfixed
  // before stage 1's fixes go
  auto traced = [&](const std::string& deck, const std::string& after, const std::string& moves) {
    return replaced(replaced(deck, after,
                             after + "fix             trace all print 1 \"" + means.substr(1) +
                                 moves + "\" file trace.txt screen no\n"),
                    "unfix           cons_servo\n",
                    "unfix           trace\nunfix           cons_servo\n");
  };
  const std::string vector_deck = traced(r.deck, servo, vector_moves);
  // (fix moves before fix cons_servo: both read the walls before this step's move)
  const std::string per_wall_fixes = "fix             moves all ave/time 1 1 1" + names +
                                     "\nfix             cons_servo all ave/time 1 1 1" + names +
                                     " ave running\n";
  std::string per_wall_deck = replaced(r.deck, servo, per_wall_moves + per_wall_fixes);
  if (carried) {
    // the last moves: the per-wall ones (fix cons_prev after cons_servo)
    std::string prev_fix = "fix             cons_prev all ave/time 1 1 1", last;
    for (size_t k = 0; k < walls; ++k) {
      prev_fix += " v_cons_movev[" + std::to_string(k + 1) + "]";
      last += " f_moves[" + std::to_string(k + 1) + "]";
    }
    per_wall_deck = replaced(per_wall_deck, prev_fix + "\n",
                             "fix             cons_prev all ave/time 1 1 1" + last + "\n");
  }
  per_wall_deck = replaced(per_wall_deck, "unfix           cons_servo\n",
                           "unfix           cons_servo\nunfix           moves\n");
  std::string fix_moves;
  for (size_t k = 0; k < walls; ++k) fix_moves += " $(f_moves[" + std::to_string(k + 1) + "])";
  per_wall_deck = traced(per_wall_deck, per_wall_fixes, fix_moves);

  // the cap (2 % of r_min) lowered in both decks so that the clamp binds at
  // some steps and not at others: both branches of the clamp are compared
  auto capped = [&](const std::string& deck) {
    return replaced(deck, "variable        cap equal $(0.02*v_r_min)",
                    "variable        cap equal $(" + cap + "*v_r_min)");
  };
  per_wall_deck = capped(per_wall_deck);

  const test::TempDir dir(tag);
  const std::vector<std::string> args{"-var", "run_steps", std::to_string(loading), "-screen",
                                      "none"};
  const test::DeckRun vector =
      test::run_deck(lmp, dir / "vector", capped(vector_deck), r.files, args);
  ASSERT_EQ(vector.status, 0) << vector.log;
  const test::DeckRun scalar = test::run_deck(lmp, dir / "per_wall", per_wall_deck, r.files, args);
  ASSERT_EQ(scalar.status, 0) << scalar.log;
  const std::string outcome = stage1_outcome(vector.log);
  EXPECT_NE(outcome.find("demcal deck: consolidated in"), std::string::npos) << vector.log;
  EXPECT_EQ(std::count(outcome.begin(), outcome.end(), '\n'), 1 + static_cast<long>(walls))
      << outcome;
  EXPECT_EQ(outcome, stage1_outcome(scalar.log));
  const std::string ta = test::read_text(dir / "vector" / "trace.txt"),
                    tb = test::read_text(dir / "per_wall" / "trace.txt");
  EXPECT_GE(std::count(ta.begin(), ta.end(), '\n'), 500);
  EXPECT_EQ(ta, tb);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(vector.log, m, std::regex("\nvariable +cap equal ([-+0-9.e]+)\n")));
  const double cap_value = std::stod(m[1].str());
  int clamped = 0, free = 0;
  std::stringstream rows(ta);
  for (std::string row; std::getline(rows, row);) {
    if (row.empty() || row[0] == '#') continue;
    std::stringstream fields(row);
    std::vector<double> v;
    for (double x; fields >> x;) v.push_back(x);
    ASSERT_EQ(v.size(), 2 * walls) << row;
    // a bound move is the cap to rounding ((x+cap)-(x-cap) is 2 cap to an ulp of x)
    for (size_t k = walls; k < 2 * walls; ++k)
      ++(std::abs(v[k]) > (1 - 1e-9) * cap_value ? clamped : free);
  }
  EXPECT_GT(clamped, 100) << "the clamp never bound";
  EXPECT_GT(free, 100) << "the clamp always bound";
  const std::string sa = test::read_text(dir / "vector" / series),
                    sb = test::read_text(dir / "per_wall" / series);
  EXPECT_GE(std::count(sa.begin(), sa.end(), '\n'), 10);
  EXPECT_EQ(sa, sb);
}

/// The loading every stage-1 test exports after the consolidation it
/// checks: short, no rotational damping (this LAMMPS has none).
AlgorithmSpec stage1_loading() {
  AlgorithmSpec p;
  p.steps = 8000;
  p.damping_ratio_rotation = 0.0;
  return p;
}

/// Export options of a deck that consolidates itself (stage 1).
template <class Options>
Options stage1_options(const char* deck_name) {
  Options o;
  o.deck_name = deck_name;
  o.consolidate_in_deck = true;
  return o;
}

TEST(EngineLammpsStage1, TheVectorServoIsThePerWallFormulaBitForBit2D) {
  // Hex 5x5 as generated, with contact damping: the servo's R carries the
  // wall dashpots' c/dt, so that part of the formula is checked too. The
  // cap at 1e-5 r_min: about half the moves bound.
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  c.material.contact_damping_ratio = 0.1;
  const AlgorithmSpec p = stage1_loading();
  const ExportOptions o = stage1_options<ExportOptions>("hex5");
  const ExportResult r = export_deck(c, p, make_assembly(c), o);
  EXPECT_NE(line_of(r.deck, "variable        cons_rawv vector ").find("/dt)"), std::string::npos);
  expect_per_wall_bit_for_bit(lmp, r, {"cons_H", "cons_H", "cons_W", "cons_W"}, "*${thick}",
                              "engine_stage1_2d", 1000, "0.00001", deck_files(o.deck_name).series);
}

TEST(EngineLammpsStage1, TheVectorServoIsThePerWallFormulaBitForBit3D) {
  // The fcc_4x4x4 lattice as generated (256 spheres); its moves are mostly
  // 1e-16 .. 1e-11 m, hence the cap at 1e-8 r_min (half the moves bound).
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  const SceneConfig c = load_config(test::shipped_config("fcc_4x4x4"));
  AlgorithmSpec p = stage1_loading();
  p.damping_ratio_translation = 0.4;
  const Export3dOptions o = stage1_options<Export3dOptions>("r");
  const ExportResult r = export_3d_decks(c, p, make_sphere_assembly(c), o);
  expect_per_wall_bit_for_bit(
      lmp, r, {"cons_Ax", "cons_Ax", "cons_Ay", "cons_Ay", "cons_Az", "cons_Az"}, "",
      "engine_stage1_3d", 500, "0.00000001", deck_files(o.deck_name).series);
}

/// A number the deck defines: the value LAMMPS echoed in `log` for
/// `variable NAME equal VALUE` (its immediate $(...) evaluated), -1 if absent.
double echoed(const std::string& log, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(log, m, std::regex("\nvariable +" + name + " equal ([-+0-9.e]+)\n")))
    return -1;
  return std::stod(m[1].str());
}

/// The budget's last check in demcal's consolidation (every cons_check =
/// 200 steps from 0): the first at or after the budget.
int64_t demcal_last_check(int64_t budget) { return (budget + 199) / 200 * 200; }

/// Where demcal's consolidation switches to critical damping, as a check of
/// stage 1: the first check at or after critical_damping_after, never
/// beyond the budget's last check (a switch there has no step left).
int64_t demcal_switch_check(int64_t budget, double shrink) {
  const int64_t after = critical_damping_after(budget, shrink);
  return std::min((after + 199) / 200 * 200, demcal_last_check(budget));
}

/// The step at which stage 1's phase 0 ended in `log` (the marker
/// with_phase0_marker prints), -1 if it did not.
int64_t phase0_end(const std::string& log) {
  std::smatch m;
  if (!std::regex_search(log, m, std::regex("\nPHASE0_END ([0-9]+)\n"))) return -1;
  return std::stoll(m[1].str());
}

/// `deck` printing the step at which phase 0 ended ("PHASE0_END step").
std::string with_phase0_marker(const std::string& deck) {
  return replaced(deck, "# phase 1: friction on",
                  "print           \"PHASE0_END $(step)\"\n# phase 1: friction on");
}

// Phase 0 may end at the budget's last check or at the one before (static,
// at the light damping, when the cut is the budget's end); phase 1's first
// check interval then reaches or passes cons_last. demcal's consolidation
// stops there, not static (it runs phase 1's first check interval, then
// its budget is spent); the deck must too: quit 2 with its message. The
// deck before ran phase 1 on `run ${cons_last} upto` when its contacts had
// no dashpots: 0 steps at the last check, after which LAMMPS stopped with
// "Compute used in variable between runs is not current", and an error
// ("Invalid run command upto value") past it. A sample of 30 disks, no
// contact damping: its phase 0 ends at light damping (step S0, 2 600 here)
// and phase 1 needs more than one check interval, static at step E; the
// same deck with a budget whose last check is S0 + 200 or S0 takes the same
// path to S0 once its cut and quarter are the budget's last check (without
// that edit phase 0 would be cut at half the budget, before S0; a budget of
// a few hundred steps puts the cut there by itself, frictionless_phase_cut
// rounded up to a check). The budget's last check is demcal's, the first at
// or after it (its loop ends at the first check with steps >= the
// budget): a budget of E − 1 steps consolidates in E steps, as demcal's
// does. The deck before ended at the last check at or before it (E − 200:
// quit 2), and a budget of S0 + 199 there at S0.
TEST(EngineLammpsStage1, WhenPhase0EndsAtTheBudgetsLastChecksPhase1StopsThereWithQuit2) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("random_400"));
  c.assembly.count = 30;
  const AlgorithmSpec p = stage1_loading();
  const ExportOptions o = stage1_options<ExportOptions>("r");
  const ExportResult r = export_deck(c, p, make_assembly(c), o);
  ASSERT_EQ(r.deck.find("/dt)"), std::string::npos) << "the sample has contact dashpots";
  const std::string deck = with_phase0_marker(r.deck);
  const std::vector<std::string> args{"-var", "run_steps", "0", "-screen", "none"};
  const test::TempDir dir("engine_stage1_end");
  const test::DeckRun full = test::run_deck(lmp, dir / "full", deck, r.files, args);
  ASSERT_EQ(full.status, 0) << full.log;
  const int64_t s0 = phase0_end(full.log);
  const std::regex done("\ndemcal deck: consolidated in ([0-9]+) steps");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(full.log, m, done)) << full.log;
  const int64_t steps = std::stoll(m[1].str());
  ASSERT_GT(s0, 0) << full.log;
  ASSERT_EQ(s0 % 200, 0);
  // the premise: phase 1 needs more than one check interval
  ASSERT_GT(steps - s0, 200) << "phase 1 was static at its first check: nothing to test";
  const std::string budget_line = line_of(deck, "variable cons_max_steps equal ");
  const std::string quarter_line = line_of(deck, "variable        cons_quarter equal ");
  const std::string cut_line = line_of(deck, "variable        cons_cut equal ");
  for (int64_t budget : {s0 + 200, s0 + 199, s0, s0 - 1, steps - 1}) {
    SCOPED_TRACE("cons_max_steps " + std::to_string(budget));
    std::string edited = replaced(deck, budget_line,
                                  "variable cons_max_steps equal " + std::to_string(budget) + "\n");
    for (const std::string* line : {&quarter_line, &cut_line})
      edited = replaced(edited, *line,
                        line->substr(0, line->find(" equal ")) + " equal $(v_cons_last)\n");
    const test::DeckRun run =
        test::run_deck(lmp, dir / std::to_string(budget), edited, r.files, args);
    EXPECT_EQ(echoed(run.log, "cons_last"), static_cast<double>(demcal_last_check(budget)));
    EXPECT_EQ(phase0_end(run.log), s0) << run.log;
    if (steps <= demcal_last_check(budget)) {  // the same path to a static state
      EXPECT_EQ(run.status, 0) << run.log;
      ASSERT_TRUE(std::regex_search(run.log, m, done)) << run.log;
      EXPECT_EQ(std::stoll(m[1].str()), steps);
    } else {
      EXPECT_EQ(run.status, 2) << run.log;
      EXPECT_NE(run.log.find("\ndemcal deck: consolidation did not reach a static state in " +
                             std::to_string(budget) + " steps"),
                std::string::npos)
          << run.log;
    }
    EXPECT_EQ(run.log.find("ERROR"), std::string::npos) << run.log;
  }
}

// Stage 1's critical-damping fallback comes where demcal's does: after a
// quarter of the budget in the simulated time of the undamped step, i.e.
// (cons_max_steps/4)/S steps, at a check (the first at or after it), never
// beyond the budget; with contact dashpots the step is demcal's shrunk one
// (alpha 0.2·S, consolidation_dashpot_factor), without them S = 1. The deck
// computes it from cons_max_steps, so a budget edited in its parameters
// block moves it as it moves demcal's. Each deck is run up to the
// definition of cons_quarter (then quit) with the exported budget and
// edited ones (123 457 and 1 000 are no multiples of 4·cons_check = 800);
// LAMMPS' value must be demcal_switch_check's, to the step. (The deck
// before put it at a quarter of cons_max_steps in steps with dashpots:
// 500 000 of 2·10⁶ where demcal's came after 3 299 212 steps, i.e. never,
// on random_500_3d at ζ_c 0.3; and without them at the check at or BEFORE
// a quarter: 30 800 and 200 where demcal switches at 31 000 and 400.)
TEST(EngineLammpsStage1, TheCriticalFallbackComesAtDemcalsCheck) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  const AlgorithmSpec p = stage1_loading();
  struct Case {
    std::string name;
    ExportResult deck;
  };
  std::vector<Case> cases;
  for (double zeta_c : {0.0, 0.02}) {
    SceneConfig c = load_config(test::shipped_config("random_400"));
    c.assembly.count = 100;
    c.material.contact_damping_ratio = zeta_c;
    const ExportOptions o = stage1_options<ExportOptions>("r");
    cases.push_back(
        {zeta_c > 0.0 ? "2D zeta_c 0.02" : "2D zeta_c 0", export_deck(c, p, make_assembly(c), o)});
  }
  {
    SceneConfig c = load_config(test::shipped_config("random_500_3d"));
    c.assembly.count = 60;
    c.material.contact_damping_ratio = 0.7;
    const Export3dOptions o = stage1_options<Export3dOptions>("r");
    cases.push_back({"3D zeta_c 0.7", export_3d_decks(c, p, make_sphere_assembly(c), o)});
    c.material.contact_damping_ratio = 0.0;
    cases.push_back({"3D zeta_c 0", export_3d_decks(c, p, make_sphere_assembly(c), o)});
  }
  const test::TempDir dir("engine_stage1_fallback");
  int switching = 0, never = 0;
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    // S as the deck holds it (17 digits) and stage 1's alpha (10 digits)
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        k.deck.deck, m,
        std::regex("\\(floor\\(v_cons_max_steps/4\\)/([0-9.e+-]+)\\)/v_cons_check\\)\\)\n")))
        << "no quarter (cons_max_steps/4)/S in the deck";
    const double shrink = std::stod(m[1].str());
    ASSERT_TRUE(std::regex_search(
        k.deck.deck, m, std::regex("# alpha\\*f\\(zeta\\)\\*dt_crit, alpha ([0-9.e+-]+)\n")));
    EXPECT_NEAR(shrink, std::stod(m[1].str()) / AlgorithmSpec{}.dt_ratio, 1e-9 * shrink);
    if (k.name.ends_with("zeta_c 0"))
      EXPECT_EQ(shrink, 1.0);
    else
      EXPECT_LT(shrink, 1.0);
    const std::string budget_line = line_of(k.deck.deck, "variable cons_max_steps equal ");
    const std::string quarter_line = line_of(k.deck.deck, "variable        cons_quarter equal ");
    for (int64_t budget : {int64_t{2000000}, int64_t{123457}, int64_t{1000}}) {
      SCOPED_TRACE("cons_max_steps " + std::to_string(budget));
      std::string deck = replaced(k.deck.deck, budget_line,
                                  "variable cons_max_steps equal " + std::to_string(budget) + "\n");
      deck = replaced(deck, quarter_line, quarter_line + "quit 0\n");
      const test::DeckRun run = test::run_deck(
          lmp, dir / (std::to_string(&k - cases.data()) + "_" + std::to_string(budget)), deck,
          k.deck.files);
      ASSERT_EQ(run.status, 0) << run.log;
      const int64_t expected = demcal_switch_check(budget, shrink);
      EXPECT_EQ(echoed(run.log, "cons_quarter"), static_cast<double>(expected)) << run.log;
      ++(expected < demcal_last_check(budget) ? switching : never);
    }
  }
  // both branches: a switch within the budget and none
  EXPECT_GT(switching, 0);
  EXPECT_GT(never, 0);
}

// The deck's own consolidation with contact dashpots (ζ_c 0.3 shrinks stage
// 1's step, alpha 0.2 → 0.094 on this material: consolidation_dashpot_factor)
// certifies within a modest budget, as demcal's does: 200 disks of
// random_400, budget 120 000 steps. Its fallback comes at demcal's check,
// (30 000/S) steps (63 800), and the packing is static before it, at light
// damping throughout (the deck 17 400 steps, demcal 39 400, both servoes
// carrying their last moves; 37 000 without the deck's carry, §23). The deck before
// switched to critical damping at a quarter of the budget in steps (30 000),
// before the packing was static (with the older, smaller step it then crept
// to the end of the budget: quit 2, engines.md §21).
TEST(EngineLammpsStage1, WithContactDashpotsTheDeckConsolidatesARandomSampleWithinAModestBudget) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("random_400"));
  c.assembly.count = 200;
  c.material.contact_damping_ratio = 0.3;
  c.test.consolidation_max_steps = 120000;
  const AlgorithmSpec p = stage1_loading();
  const ExportOptions o = stage1_options<ExportOptions>("r");
  const Assembly a = make_assembly(c);
  const ExportResult r = export_deck(c, p, a, o);
  const test::TempDir dir("engine_stage1_damped");
  const test::DeckRun run = test::run_deck(lmp, dir.path(), r.deck, r.files,
                                           {"-var", "run_steps", "0", "-screen", "none"});
  const std::regex done(
      "\ndemcal deck: consolidated in ([0-9]+) steps \\(wall stress error ([-+0-9.eE]+), "
      "unbalanced-force ratio ([-+0-9.eE]+)\\)");
  std::smatch m;
  ASSERT_EQ(run.status, 0) << run.log.substr(run.log.size() > 3000 ? run.log.size() - 3000 : 0);
  ASSERT_TRUE(std::regex_search(run.log, m, done)) << run.log;
  const long long deck_steps = std::stoll(m[1].str());
  EXPECT_LT(std::stod(m[2].str()), c.test.consolidation_tolerance);
  EXPECT_LT(std::stod(m[3].str()), c.test.consolidation_unbalanced);
  EXPECT_LE(deck_steps, c.test.consolidation_max_steps);
  // at light damping throughout, the fallback at demcal's check, after the
  // packing was static
  std::smatch q;
  ASSERT_TRUE(std::regex_search(
      r.deck, q,
      std::regex("\\(floor\\(v_cons_max_steps/4\\)/([0-9.e+-]+)\\)/v_cons_check\\)\\)\n")))
      << "no shrunk quarter in the deck";
  const int64_t switch_at =
      demcal_switch_check(c.test.consolidation_max_steps, std::stod(q[1].str()));
  EXPECT_EQ(echoed(run.log, "cons_quarter"), static_cast<double>(switch_at));
  EXPECT_LT(deck_steps, switch_at);
  EXPECT_EQ(run.log.find("\nvariable cons_critical equal 1\n"), std::string::npos);
  const ConsolidatedState d = consolidate(c, a, std::string());
  EXPECT_TRUE(d.converged);
  std::printf(
      "200 disks, contact damping 0.3, budget %lld: the deck consolidated in %lld steps, demcal "
      "in %lld\n",
      static_cast<long long>(c.test.consolidation_max_steps), deck_steps,
      static_cast<long long>(d.steps));
}

// Stage 1 cuts a frictionless phase not static by cons_cut there, as
// demcal's run_consolidation does, and goes on with friction at the light
// damping, critical damping only from cons_capped (twice the quarter): the
// gases of the demcal tests (ConsolidationProgress.AFrictionless*), 400
// disks with a 40 000-step budget and 500 spheres with 100 000, whose
// phase 0 is not static at the quarter in demcal; and the same gases with
// contact dashpots strong enough that the quarter lies past the budget
// (ConsolidationProgress.WithStrongContactDashpots*: ζ_c 1 and 0.5), whose
// cut is half the budget (frictionless_phase_cut). The deck before ran
// phase 0 on at critical damping to the budget's end (quit 2); then, with
// such dashpots, at the light damping (quit 2 too: the 3D deck after
// 100 000 steps, wall stress error 0.4 %).
TEST(EngineLammpsStage1, AFrictionlessPhaseNotStaticByTheQuarterEndsThereAsDemcals) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  const AlgorithmSpec p = stage1_loading();
  struct Case {
    std::string name;
    int64_t budget;
    int64_t cut;  ///< where phase 0 must end
    bool light;   ///< static before critical damping's switch (within 2·cut)
    ExportResult deck;
  };
  std::vector<Case> cases;
  for (const double zeta_c : {0.0, 1.0}) {
    SceneConfig c = load_config(test::shipped_config("random_400"));
    c.material.contact_damping_ratio = zeta_c;
    c.test.consolidation_max_steps = zeta_c > 0.0 ? 60000 : 40000;
    const int64_t budget = c.test.consolidation_max_steps;
    cases.push_back({zeta_c > 0.0 ? "2D zeta_c 1" : "2D zeta_c 0", budget,
                     zeta_c > 0.0 ? budget / 2 : budget / 4, zeta_c == 0.0,
                     export_deck(c, p, make_assembly(c), stage1_options<ExportOptions>("r"))});
  }
  for (const double zeta_c : {0.0, 0.5}) {
    SceneConfig c = load_config(test::shipped_config("random_500_3d"));
    c.material.contact_damping_ratio = zeta_c;
    c.test.consolidation_max_steps = 100000;
    const int64_t budget = c.test.consolidation_max_steps;
    cases.push_back(
        {zeta_c > 0.0 ? "3D zeta_c 0.5" : "3D zeta_c 0", budget,
         zeta_c > 0.0 ? budget / 2 : budget / 4, zeta_c == 0.0,
         export_3d_decks(c, p, make_sphere_assembly(c), stage1_options<Export3dOptions>("r"))});
  }
  const test::TempDir dir("engine_stage1_cut");
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const test::DeckRun run = test::run_deck(lmp, dir / std::to_string(&k - cases.data()),
                                             with_phase0_marker(k.deck.deck), k.deck.files,
                                             {"-var", "run_steps", "0", "-screen", "none"});
    ASSERT_EQ(run.status, 0) << run.log.substr(run.log.size() > 3000 ? run.log.size() - 3000 : 0);
    EXPECT_EQ(echoed(run.log, "cons_cut"), static_cast<double>(k.cut));
    if (k.light) {  // undamped contacts: the quarter is the cut, capped twice it
      EXPECT_EQ(echoed(run.log, "cons_quarter"), static_cast<double>(k.cut));
      EXPECT_EQ(echoed(run.log, "cons_capped"), static_cast<double>(2 * k.cut));
    }
    EXPECT_EQ(phase0_end(run.log), k.cut) << "phase 0 did not end at the cut";
    std::smatch m;
    ASSERT_TRUE(
        std::regex_search(run.log, m, std::regex("\ndemcal deck: consolidated in ([0-9]+) steps")))
        << run.log;
    const int64_t steps = std::stoll(m[1].str());
    EXPECT_GT(steps, k.cut);
    EXPECT_LE(steps, k.light ? 2 * k.cut : k.budget);
    EXPECT_EQ(run.log.find("\nvariable cons_critical equal 1\n"), std::string::npos);
    std::printf("%s, budget %lld: the deck's frictionless phase until %lld, static at %lld\n",
                k.name.c_str(), static_cast<long long>(k.budget), static_cast<long long>(k.cut),
                static_cast<long long>(steps));
  }
}

/// A step for a message, 10 significant digits.
std::string deck_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

/// Stage 1 of a deck with contact dashpots (`r`, of scene `c`), traced at
/// every step: each wall's position, contact count n, force F on the
/// particles and the move the deck computed, with the step dt. Every move
/// must be demcal's consolidation servo (servo_velocity,
/// scene/biaxial.hpp), clamp(gain*(sigma3*A - F)/(R*max(1, n)) +
/// carry*u_prev, +-cap) along +axis (a max wall's load -sigma3*A), R =
/// servo_resistance(kn_wall, zeta_c, m_max, dt) at the row's dt, carry =
/// servo_carry(kn_wall, R), A from the traced positions (`area`), u_prev
/// the wall's move of the step before (0 at the first: the walls start at
/// rest); and each move must be the one applied: the wall's position one
/// step later is its position plus the move. Tolerance: 1e-9 of |law| +
/// |carry*u_prev| (the 2D deck writes the wall dashpot's c with 10
/// digits; the rest is rounding, 1e-15). The budget is edited to `budget`
/// so that the critical-damping switch (a smaller dt: R and the carry
/// change) comes within the trace, and the cap to `cap` r_min so that the
/// clamp binds at some steps and not at others. `positions`: the deck's
/// position variables, walls in cons_wn's order.
void expect_the_servo_carries_its_last_move(
    const std::string& lmp, const ExportResult& r, const SceneConfig& c, double m_max,
    const std::vector<std::string>& positions,
    const std::function<double(const std::vector<double>&, size_t)>& area, int64_t budget,
    const std::string& cap, const std::string& tag) {
  const size_t walls = positions.size();
  const std::string servo =
      "fix             cons_servo all ave/time 1 1 1 v_cons_movev mode "
      "vector ave running\n";
  ASSERT_NE(r.deck.find(servo), std::string::npos);
  // the trace before fix cons_servo: the positions where this step's forces
  // were computed (cons_servo's running sum then takes this step's move)
  std::string row = "$(step) $(dt:%.17g)";
  for (size_t k = 0; k < walls; ++k) {
    const std::string i = std::to_string(k + 1);
    row += " $(v_" + positions[k] + ":%.17g) $(c_cons_wn[" + i + "]:%.17g) $(c_cons_wf[" + i +
           "]:%.17g) $(v_cons_movev[" + i + "]:%.17g)";
  }
  std::string deck = replaced(
      r.deck, servo,
      "fix             trace all print 1 \"" + row + "\" file trace.txt screen no\n" + servo);
  deck = replaced(deck, "unfix           cons_servo\n",
                  "unfix           trace\nunfix           cons_servo\n");
  deck = replaced(deck, line_of(deck, "variable cons_max_steps equal "),
                  "variable cons_max_steps equal " + std::to_string(budget) + "\n");
  deck = replaced(deck, "variable        cap equal $(0.02*v_r_min)",
                  "variable        cap equal $(" + cap + "*v_r_min)");
  const test::TempDir dir(tag);
  const test::DeckRun run =
      test::run_deck(lmp, dir.path(), deck, r.files, {"-var", "run_steps", "0", "-screen", "none"});
  // static within the budget (0) or not (2: quit at the budget's end)
  ASSERT_TRUE(run.status == 0 || run.status == 2) << run.log;
  EXPECT_EQ(run.log.find("ERROR"), std::string::npos) << run.log;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(run.log, m, std::regex("\nvariable +cap equal ([-+0-9.e]+)\n")));
  const double cap_value = std::stod(m[1].str());
  // the rows by step: a run's setup prints its first step again (keep the
  // first row, that of the step's end)
  const std::map<int64_t, std::vector<double>> rows =
      test::trace_rows(test::read_text(dir / "trace.txt"), 2 + 4 * walls);
  ASSERT_GE(rows.size(), 1000u);
  ASSERT_EQ(rows.begin()->first, 0);
  ASSERT_EQ(rows.rbegin()->first, static_cast<int64_t>(rows.size()) - 1) << "a step is missing";
  const double kn_wall = c.material.wall.kn, zeta_c = c.material.contact_damping_ratio;
  const double sigma3 = c.test.lateral_stress, gain = c.test.servo_gain;
  std::vector<double> prev(walls, 0.0), last_position(walls, 0.0);
  std::map<double, int> carried;  // per dt: free moves whose carry term is >= 10 % of the law's
  int clamped = 0, free = 0;
  for (const auto& [step, v] : rows) {
    SCOPED_TRACE("step " + std::to_string(step));
    const double dt = v[1];
    const double resist = servo_resistance(kn_wall, zeta_c, m_max, dt);
    const double carry = servo_carry(kn_wall, resist);
    std::vector<double> position(walls);
    for (size_t k = 0; k < walls; ++k) position[k] = v[2 + 4 * k];
    for (size_t k = 0; k < walls; ++k) {
      const double n = v[3 + 4 * k], force = v[4 + 4 * k], move = v[5 + 4 * k];
      const double load = (k % 2 == 0 ? 1.0 : -1.0) * sigma3 * area(position, k);
      const double law = gain * (load - force) / (resist * std::max(1.0, n));
      const double expected = std::clamp(law + carry * prev[k], -cap_value, cap_value);
      const double scale = std::abs(law) + carry * std::abs(prev[k]);
      ASSERT_LE(std::abs(move - expected), 1e-9 * scale)
          << "wall " << k << ": move " << move << ", demcal's law " << expected << " (law " << law
          << ", carry " << carry << ", last move " << prev[k] << ")";
      if (step > 0) {
        // the move of the step before, applied: the position is x0 + the
        // running mean times the steps, rounded to 1e-16 of the box
        const double box = std::abs(position[k]) + std::abs(position[k ^ 1]);
        EXPECT_NEAR(position[k] - last_position[k], prev[k], 1e-13 * box + 1e-9 * std::abs(prev[k]))
            << "wall " << k;
      }
      if (std::abs(move) > (1 - 1e-9) * cap_value) {
        ++clamped;
      } else {
        ++free;
        if (carry * std::abs(prev[k]) >= 0.1 * std::abs(law)) ++carried[dt];
      }
      prev[k] = move;
    }
    last_position = position;
  }
  EXPECT_GT(clamped, 100) << "the clamp never bound";
  EXPECT_GT(free, 100) << "the clamp always bound";
  // both steps (light damping, then critical from the switch), and in each
  // the carry weighed in the free moves
  std::string counts;
  for (const auto& [dt, count] : carried)
    counts += ", at dt " + deck_number(dt) + " " + std::to_string(count) + " carried";
  int64_t switched = -1;  // the first step at the critical damping's dt
  for (const auto& [step, v] : rows)
    if (v[1] != rows.begin()->second[1]) {
      switched = step;
      break;
    }
  std::printf("%s: %zu steps, %d moves clamped, %d free%s; dt switched at step %lld\n", tag.c_str(),
              rows.size(), clamped, free, counts.c_str(), static_cast<long long>(switched));
  ASSERT_EQ(carried.size(), 2u) << "the trace does not cross the critical-damping switch";
  for (const auto& [dt, count] : carried) EXPECT_GT(count, 100) << "dt " << dt;
}

// demcal's consolidation servo with contact damping carries (R - kn_wall)/R
// of each wall's last move (servo_velocity: robustness.md, "The
// 3D consolidation at contact damping 0.7"); the decks' stage 1 must too, with
// R at its step, at light and at critical damping. 100 disks of random_400 and
// 60 spheres of random_500_3d at zeta_c 0.1, budget 4 000 steps: their
// frictionless phases are cut at demcal's check of (1 000/S) steps, and
// critical damping comes at the first check at or after twice that (2 800 and 3 000),
// within the budget for S >= 0.5 (zeta_c 0.3 has S < 0.5), the cap at 5e-4 r_min
// (the export's 0.02 does not bind on these samples). The deck before moved
// each wall by the per-step law alone: its moves miss the law by the carry
// term, 0.84 of the last move at light damping.
TEST(EngineLammpsStage1, WithContactDashpotsTheServoCarriesItsLastMoveAsDemcals2D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("random_400"));
  c.assembly.count = 100;
  c.material.contact_damping_ratio = 0.1;
  const AlgorithmSpec p = stage1_loading();
  const ExportOptions o = stage1_options<ExportOptions>("r");
  const Assembly a = make_assembly(c);
  const ExportResult r = export_deck(c, p, a, o);
  // the heaviest disc, with this run's mass scaling: the wall dashpot's
  const double m_max = disk_mass(disk_areal_density(c.material, p.mass_scaling),
                                 *std::max_element(a.r.begin(), a.r.end()));
  const double thick = c.material.thickness;
  expect_the_servo_carries_its_last_move(
      lmp, r, c, m_max, {"cons_xl", "cons_xr", "cons_yb", "cons_yt"},
      [thick](const std::vector<double>& x, size_t k) {
        return (k < 2 ? x[3] - x[2] : x[1] - x[0]) * thick;
      },
      4000, "0.002", "engine_stage1_carry_2d");
}

TEST(EngineLammpsStage1, WithContactDashpotsTheServoCarriesItsLastMoveAsDemcals3D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("random_500_3d"));
  c.assembly.count = 60;
  c.material.contact_damping_ratio = 0.1;
  const AlgorithmSpec p = stage1_loading();
  const Export3dOptions o = stage1_options<Export3dOptions>("r");
  const SphereAssembly a = make_sphere_assembly(c);
  const ExportResult r = export_3d_decks(c, p, a, o);
  const double m_max =
      sphere_mass(c.material.density * p.mass_scaling, *std::max_element(a.r.begin(), a.r.end()));
  // A of an x wall L_y*L_z, of a y wall L_z*L_x, of a z wall L_x*L_y
  expect_the_servo_carries_its_last_move(
      lmp, r, c, m_max,
      {"cons_xmin", "cons_xmax", "cons_ymin", "cons_ymax", "cons_zmin", "cons_zmax"},
      [](const std::vector<double>& x, size_t k) {
        const size_t a = k / 2, b = (a + 1) % 3, d = (a + 2) % 3;
        return (x[2 * b + 1] - x[2 * b]) * (x[2 * d + 1] - x[2 * d]);
      },
      4000, "0.0005", "engine_stage1_carry_3d");
}

/// Start `program ARGS` in `dir` in the background (stdout and stderr to
/// /dev/null); its pid.
pid_t spawn_in(const std::string& program, const std::vector<std::string>& args,
               const fs::path& dir) {
  // argv and the folder are built before the fork: the child of a threaded
  // process may call only async-signal-safe functions until exec
  std::vector<std::string> all{program};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string where = dir.string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) {
      ::dup2(null, STDOUT_FILENO);
      ::dup2(null, STDERR_FILENO);
    }
    if (::chdir(where.c_str()) == 0) ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

/// Stage 1 of `r` run by `lmp` until a fix print the test adds (which
/// flushes its file) says the run has passed step 4 000, then killed
/// (SIGKILL, as a batch job's time limit ends it): its log must hold
/// stage 1's progress rows of steps 0 and 2 000 (thermo every 10 checks),
/// whole, with the columns of its header. The run must still be in stage 1
/// when killed.
void expect_progress_rows_in_the_log_of_a_killed_run(const std::string& lmp, const ExportResult& r,
                                                     const std::string& tag) {
  const std::string phase0 = "# phase 0: frictionless\n";
  const std::string deck = replaced(r.deck, phase0,
                                    "variable        progress_step equal step\n"
                                    "fix             progress all print 2000 \"${progress_step}\" "
                                    "file progress.txt screen no\n" +
                                        phase0);
  const test::TempDir dir(tag);
  test::write_text(dir / "in.deck", deck);
  test::write_files(dir.path(), r.files);
  const pid_t pid = spawn_in(
      lmp, {"-in", "in.deck", "-log", "log.txt", "-screen", "none", "-var", "run_steps", "0"},
      dir.path());
  ASSERT_GT(pid, 0);
  bool passed = false, alive = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  while (!passed && alive && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const fs::path progress = dir / "progress.txt";
    passed =
        fs::exists(progress) && test::read_text(progress).find("\n4000\n") != std::string::npos;
    int status = 0;
    // alive after the read: the row was in the file while the run went on
    alive = ::waitpid(pid, &status, WNOHANG) == 0;
  }
  if (alive) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
  ASSERT_TRUE(passed) << "the run did not pass step 4000";
  ASSERT_TRUE(alive) << "the run ended before it was killed";
  const std::string log = test::read_text(dir / "log.txt");
  EXPECT_EQ(log.find("demcal deck: consolidated in"), std::string::npos) << "stage 1 ended";
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("\n *Step +Dt +v_cons_err[^\n]*\n")))
      << log.substr(log.size() > 2000 ? log.size() - 2000 : 0);
  const size_t header_end = static_cast<size_t>(m.position(0) + m.length(0));
  std::stringstream header(m[0].str());
  int columns = 0;
  for (std::string w; header >> w;) ++columns;
  for (const char* step : {"0", "2000"}) {
    std::smatch row;
    const std::string rest = log.substr(header_end - 1);
    ASSERT_TRUE(std::regex_search(
        rest, row, std::regex(std::string("\n *") + step + "(( +[-+0-9.eE]+)+) *\n")))
        << "no whole row of step " << step << " in the log:\n"
        << log.substr(header_end);
    std::stringstream fields(row[1].str());
    int count = 1;
    for (std::string w; fields >> w;) ++count;
    EXPECT_EQ(count, columns) << row[0].str();
  }
}

// Stage 1's progress rows (thermo_modify flush yes, deck::lammps_thermo_modify)
// reach the log as LAMMPS prints them, so a run that a signal stops (a batch
// job's time limit, Ctrl-C) shows in its log where it got. The deck before
// left them to the log's 4 KiB blocks: a 10 000-disk stage 1 stopped after
// 150 s showed step 6 000, cut mid-row, when it had passed some 50 000, and
// engines.md §27 read a cost per step 8x the real one from it (§28). Here
// neither row was in the old deck's log. Random disks and spheres as
// generated (a gas: stage 1 lasts far beyond step 4 000).
TEST(EngineLammpsStage1, AKilledRunsLogHoldsTheProgressRowsItPrinted2D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  const SceneConfig c = load_config(test::shipped_config("random_400"));
  const ExportOptions o = stage1_options<ExportOptions>("r");
  const ExportResult r = export_deck(c, stage1_loading(), make_assembly(c), o);
  expect_progress_rows_in_the_log_of_a_killed_run(lmp, r, "engine_stage1_killed_2d");
}

TEST(EngineLammpsStage1, AKilledRunsLogHoldsTheProgressRowsItPrinted3D) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  SceneConfig c = load_config(test::shipped_config("random_500_3d"));
  c.assembly.count = 300;
  const Export3dOptions o = stage1_options<Export3dOptions>("r");
  const ExportResult r = export_3d_decks(c, stage1_loading(), make_sphere_assembly(c), o);
  expect_progress_rows_in_the_log_of_a_killed_run(lmp, r, "engine_stage1_killed_3d");
}

}  // namespace
}  // namespace demcal
