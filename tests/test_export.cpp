// Export (issue #6 §4): radius classes, the content of the LAMMPS and
// LIGGGHTS decks, and — when LAMMPS is installed — a short run of the
// exported deck: it starts, its timestep is ours, and the consolidated
// state it reads carries σ3 on its walls from the first step.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "consolidate_in.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scoring/external_series.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/rev.hpp"
#include "support/deck_text.hpp"
#include "support/files.hpp"
#include "support/liggghts_servo.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"

namespace demcal {

using test::deck_variable;
namespace {

namespace fs = std::filesystem;

AlgorithmSpec params() {
  AlgorithmSpec p;
  p.dt_ratio = 0.22;
  p.steps = 44390;
  p.damping_ratio_translation = 0.7;
  p.damping_ratio_rotation = 1.0;
  return p;
}

TEST(RadiusClasses, MonodisperseFewAndMany) {
  int types = 0;
  auto t = radius_classes(std::vector<double>(50, 1.0), 8, &types);
  EXPECT_EQ(types, 1);
  t = radius_classes({3.0, 1.0, 2.0, 1.0, 3.0}, 8, &types);
  EXPECT_EQ(types, 3);
  EXPECT_EQ(t, (std::vector<int>{3, 1, 2, 1, 3}));
  std::vector<double> r;
  for (int i = 0; i < 1000; ++i) r.push_back(1.0 + 0.001 * ((i * 37) % 1000));
  t = radius_classes(r, 8, &types);
  EXPECT_EQ(types, 8);
  // Ordered by radius: a larger type never holds a smaller radius.
  for (int i = 0; i < 1000; ++i)
    for (int j = 0; j < 1000; j += 17)
      if (t[i] < t[j]) {
        EXPECT_LE(r[i], r[j]);
      }
}

TEST(Export, EveryFileOfADeckIsNamedAfterIt) {
  // The files a deck reads and writes: its whole file name and a suffix, so
  // that decks in one folder share none (README, "Export").
  const DeckFiles f = deck_files("h5.lammps");
  EXPECT_EQ(f.deck, "h5.lammps");
  EXPECT_EQ(f.data, "h5.lammps.data");
  EXPECT_EQ(f.series, "h5.lammps.series.csv");
  EXPECT_EQ(f.restart, "h5.lammps.restart");
  EXPECT_EQ(f.restart_args, "h5.lammps.restart.args");
  EXPECT_EQ(f.mesh("top"), "h5.lammps-top.stl");
  // The decks write there: the series (each format), the restart and its
  // args (LAMMPS), and the args continue the same series.
  const SceneConfig c = default_config();
  const Assembly a = hexagonal_packing(5, 5, 5e-4);
  ExportOptions o;
  o.deck_name = "h5.lammps";
  const std::string lammps = export_deck(c, params(), a, o).deck;
  for (const char* needle : {"variable series    index h5.lammps.series.csv ",
                             "variable restart_from index h5.lammps.restart\n",
                             "variable restart_out index h5.lammps.restart\n",
                             "lmp $(cat h5.lammps.restart.args) -in THIS_DECK\n",
                             "-var series ${series} ", "\" file ${restart_out}.args screen no\n"})
    EXPECT_NE(lammps.find(needle), std::string::npos) << needle;
  EXPECT_EQ(lammps.find("series.csv\n"), std::string::npos);
  EXPECT_EQ(lammps.find("final.restart"), std::string::npos);
  o.deck_name = "h5.liggghts";
  o.format = "liggghts";
  const ExportResult liggghts = export_deck(c, params(), a, o);
  EXPECT_NE(liggghts.deck.find("variable series    index h5.liggghts.series.csv "),
            std::string::npos);
  EXPECT_EQ(liggghts.files.count("h5.liggghts.data"), 1u);
  EXPECT_EQ(liggghts.files.count("h5.liggghts-top.stl"), 1u);
}

TEST(Export, LammpsDeckMapsEveryParameter) {
  const SceneConfig c = default_config();
  const Assembly a = hexagonal_packing(5, 5, 5e-4);
  ExportOptions o;
  o.deck_name = "proto";
  const ExportResult r = export_deck(c, params(), a, o);
  const ParticleScales s = particle_scales(a.r, c.material);
  // The engine's explicit fix viscous: alpha*f, Nstep/f, f(0.7) = 0.520656.
  const double f = dashpot_step_factor(0.7);
  EXPECT_NEAR(f, std::sqrt(1.49) - 0.7, 1e-15);
  EXPECT_EQ(r.step_factor, f);
  EXPECT_NEAR(r.dt, 0.22 * f * s.dt_crit, 1e-18);
  EXPECT_EQ(r.steps, std::llround(44390 / f));
  // The loading time, hence the rate and the strain, is demcal's.
  EXPECT_NEAR(r.steps * r.dt / (44390 * 0.22 * s.dt_crit), 1.0, 0.5 / r.steps);
  EXPECT_EQ(r.types, 1);
  for (const char* needle :
       {"units           si", "dimension       2", "density/disc 2650", "nve/sphere disc",
        "pair_style      gran/hooke/history ${kn} ${kt} 0 0.0 ${mu} 0",
        "fix             twod all enforce2d", "wall/gran/region hooke/history",
        "fix             dampt all viscous", "#fix            dampr all viscous/sphere",
        "variable nstep     equal 85258", "variable run_steps index ${nstep}",
        "f = sqrt(1 + zeta_t^2) - zeta_t = 0.5206555616 (zeta_t = 0.7)",
        "variable        fc1_a atom fx+v_gam_a*(vx-v_hdt*fx/mass)",
        "fix             wbottom gbottom wall/gran", "yplane ${yb0} NULL\n",
        "fix             series all print ${monitor_every}",
        "variable vtop      equal $(v_strain*v_H0/(v_nstep*v_dt))", "then \"read_data proto.data\"",
        "variable kn        equal 100000000",
        // the lateral servo: both walls in one vector formula, summed after
        // the series is printed; the continuation's walls to the last bit
        "variable        rawv vector ${gain_kn}*(f_servo_sign*f_servo_load-c_cf)/",
        "fix             servol all ave/time 1 1 1 v_movev[1] ave running",
        "fix             servor all ave/time 1 1 1 v_movev[2] ave running",
        "-var xl_now $(v_xl_now+f_servo_end[1])"})
    EXPECT_NE(r.deck.find(needle), std::string::npos) << needle;
  // fix servol sums this step's moves after fix series printed the row, so a
  // row gives the walls where this step's forces had them
  EXPECT_LT(r.deck.find("fix             series all print"),
            r.deck.find("fix             servol all ave/time"));
  // ζ_t·2·sqrt(kn·m) for the one class.
  const double gamma = 0.7 * s.damping_translation_crit;
  char buf[64];
  std::snprintf(buf, sizeof buf, "viscous %.10g", gamma);
  EXPECT_NE(r.deck.find(buf), std::string::npos) << buf;
  ASSERT_EQ(r.files.count("proto.data"), 1u);
  EXPECT_NE(r.files.at("proto.data").find("25 atoms"), std::string::npos);
  EXPECT_FALSE(r.notes.empty());  // rotational damping is not applied
  EXPECT_THROW(
      [&] {
        ExportOptions bad;
        bad.format = "yade";
        export_deck(c, params(), a, bad);
      }(),
      InputError);
}

TEST(Export, OnlyFrictionalTopAndBottomWallsKeepTheirContactArrays) {
  // Frictionless (demcal's default) walls: the top and bottom wall forces
  // come from the overlaps at monitoring steps, no per-step contact arrays
  // or force store; the deck refuses an edited mu_wall. With wall friction
  // the tangential force must be read back: `contacts` on all four walls.
  SceneConfig c = default_config();
  const Assembly a = hexagonal_packing(5, 5, 5e-4);
  ExportOptions o;
  o.deck_name = "proto";
  const std::string plain = export_deck(c, params(), a, o).deck;
  c.material.wall.friction = 0.2;
  const std::string rough = export_deck(c, params(), a, o).deck;
  auto has = [](const std::string& deck, const std::string& s) {
    return deck.find(s) != std::string::npos;
  };
  for (const std::string& deck : {plain, rough}) {
    EXPECT_FALSE(has(deck, "store/force"));
    EXPECT_TRUE(has(deck, "region rleft contacts\n"));
    EXPECT_TRUE(has(deck, "region rright contacts\n"));
    EXPECT_TRUE(has(deck, "fix             wbottom gbottom wall/gran"));
  }
  EXPECT_TRUE(has(plain, "yplane ${yb0} NULL\n"));
  EXPECT_TRUE(has(plain, "region rtop\n"));
  EXPECT_TRUE(has(plain, "compute         ct gtop reduce sum v_fyt_a\n"));
  EXPECT_TRUE(has(plain, "\"${mu_wall} != 0 && ${kt_wall} != 0\""));
  EXPECT_TRUE(has(rough, "yplane ${yb0} NULL contacts\n"));
  EXPECT_TRUE(has(rough, "region rtop contacts\n"));
  EXPECT_TRUE(has(rough, "f_wtop[5]*f_wtop[3]"));
  EXPECT_FALSE(has(rough, "v_fyt_a"));
  EXPECT_FALSE(has(rough, "${mu_wall} != 0"));
}

TEST(Export, ExplicitDampingStepFactorIsTheDampedOscillatorsStabilityLimit) {
  // A mass on a spring integrated as LAMMPS does with fix viscous
  // (velocity Verlet, the drag -gamma*v from the half-step velocity): the
  // step Omega = omega*dt at which it turns unstable is 2f, f =
  // sqrt(1 + zeta^2) - zeta. 1 % below, the motion decays; 1 % above,
  // it grows (the root z = -1 of the characteristic equation).
  auto amplitude = [](double zeta, double omega_dt) {
    const double w = 1.0, dt = omega_dt / w, c = 2.0 * zeta * w;  // k/m = w^2, gamma/m = c
    double x = 1.0, v = 0.0, a = -w * w * x;
    double peak = 0.0;
    for (int n = 0; n < 2000; ++n) {
      const double vh = v + 0.5 * dt * a;  // first half kick
      x += dt * vh;
      a = -w * w * x - c * vh;  // forces, then the post-force drag on vh
      v = vh + 0.5 * dt * a;
      if (n >= 1900) peak = std::max(peak, std::abs(x));
    }
    return peak;
  };
  for (const double zeta : {0.0, 0.2, 0.7, 1.107, 3.0}) {
    const double f = dashpot_step_factor(zeta);
    EXPECT_NEAR(f, std::sqrt(1.0 + zeta * zeta) - zeta, 1e-14);
    EXPECT_LT(amplitude(zeta, 2.0 * f * (1.0 - 1e-2)), 1.0 + 1e-9) << "zeta " << zeta;
    EXPECT_GT(amplitude(zeta, 2.0 * f * (1.0 + 1e-2)), 1e3) << "zeta " << zeta;
  }
  EXPECT_EQ(dashpot_step_factor(0.0), 1.0);
}

TEST(Export, PolydisperseDampingPerClass) {
  SceneConfig c = default_config();
  c.assembly.type = "random";
  c.assembly.count = 300;
  const Assembly a = make_assembly(c);
  const ExportResult r = export_deck(c, params(), a, {});
  EXPECT_EQ(r.types, 8);
  // One "scale type ratio" per type after the first (LAMMPS's syntax).
  EXPECT_NE(r.deck.find(" scale 2 "), std::string::npos);
  EXPECT_NE(r.deck.find(" scale 8 "), std::string::npos);
  EXPECT_EQ(r.deck.find(" scale 1 "), std::string::npos);
  // Radii from 0.375 to 0.625 mm in 8 classes: each class spans ~1/8 of it.
  EXPECT_GT(r.damping_class_error, 0.0);
  EXPECT_LT(r.damping_class_error, 0.05);
}

TEST(Export, LiggghtsDeckHasMeshesAndServo) {
  const SceneConfig c = default_config();
  const Assembly a = hexagonal_packing(5, 5, 5e-4);
  ExportOptions o;
  o.format = "liggghts";
  o.deck_name = "proto";
  const ExportResult r = export_deck(c, params(), a, o);
  for (const char* needle :
       {"pair_style gran model hooke/stiffness tangential history", "mesh/surface/stress/servo",
        "move/mesh", "fix twod all enforce2d", "Checked with LIGGGHTS 3.8",
        "primitive type 2 yplane",
        // the series demcal score reads: per-atom wall forces, the
        // servo on the current height, LIGGGHTS' lever arm
        "store_force yes", "target_val v_ftl", "target_val v_ftr", "demcal.series/1: LIGGGHTS deck",
        "moment_lever_arm = radius - overlap/2", "title \"step,strain_yy,b_xx"})
    EXPECT_NE(r.deck.find(needle), std::string::npos) << needle;
  // 2D masses: LIGGGHTS takes pi r^2 * density, so the density column is
  // the areal density f_ms*rho*t.
  EXPECT_NE(r.files.at("proto.data").find(" 0.001 2650 "), std::string::npos);
  EXPECT_EQ(r.files.count("proto-top.stl"), 1u);
  EXPECT_EQ(r.files.count("proto-left.stl"), 1u);
}

/// demcal's servo move per unit of force error, gain/(R·max(1, n)) [m/N]
/// per demcal step, on a wall without contacts (n = 1): from
/// servo_velocity itself, at a target small enough not to be clamped.
double demcal_move_per_force(const SceneConfig& c, const AlgorithmSpec& p, const Assembly& a) {
  World w(c.material, a.x, a.y, a.r, a.left, a.right, a.bottom, a.top);
  w.set_integration(integration_for(w, p));
  w.update_forces();
  EXPECT_EQ(w.wall(kLeft).contacts, 0);
  const double target = 1e-3;  // Pa: a move ~1e-16 m, far from the cap
  const double force = target * w.height() * c.material.thickness;
  return servo_velocity(w, kLeft, target, c.test.servo_gain) * w.integration().dt / force;
}

/// demcal's servo carry (servo_carry of its R, 0 without contact damping):
/// from servo_velocity itself, on a wall without contacts at the target 0
/// (no error: only the carried share of the wall's velocity remains).
double demcal_servo_carry(const SceneConfig& c, const AlgorithmSpec& p, const Assembly& a) {
  World w(c.material, a.x, a.y, a.r, a.left, a.right, a.bottom, a.top);
  w.set_integration(integration_for(w, p));
  w.update_forces();
  EXPECT_EQ(w.wall(kLeft).contacts, 0);
  const double velocity = 1e-6;  // m/s toward the sample: far from the cap
  w.wall(kLeft).velocity = velocity;
  return servo_velocity(w, kLeft, 0.0, c.test.servo_gain) / velocity;
}

TEST(Export, TheLoadingServosGainIsDemcalsWithTheWallDashpots) {
  // demcal's 2D servo divides by R = kn_wall + c/Δt with contact damping
  // (c = 2ζ_c·sqrt(kn_wall·m_max), the heaviest disc's; servo_resistance):
  // the LAMMPS deck's gain_kn, per step of dt, is demcal's per-step law
  // times dt/servo_dt, and the LIGGGHTS deck's kp·vel_max is demcal's wall
  // velocity per unit of force. Polydisperse (m_max > m_min) and with
  // mass scaling; without contact damping R = kn_wall. (Before 2026-12-02
  // both decks divided by kn_wall only: with ζ_c 0.25 here a servo
  // 1 + c/(Δt·kn_wall) = 2.9 times as stiff as demcal's.)
  SceneConfig c = default_config();
  c.assembly.type = "random";
  c.assembly.count = 40;
  const Assembly a = make_assembly(c);
  AlgorithmSpec p = params();
  p.mass_scaling = 4.0;
  for (const double zeta_c : {0.0, 0.25}) {
    c.material.contact_damping_ratio = zeta_c;
    const double demcal = demcal_move_per_force(c, p, a);
    ExportOptions o;
    o.deck_name = "proto";
    const ExportResult r = export_deck(c, p, a, o);
    const std::string& d = r.deck;
    const double servo_dt = deck_variable(d, "servo_dt");
    const double dt = deck_variable(d, "dt");
    EXPECT_NEAR(dt / servo_dt, r.step_factor, 1e-9);
    const std::string gain_kn_line = d.substr(d.find("variable gain_kn"), 60);
    double resist = deck_variable(d, "kn_wall");
    if (zeta_c > 0.0) {
      EXPECT_NE(gain_kn_line.find("$(v_gain*v_servo_f/v_resist)"), std::string::npos)
          << gain_kn_line;
      EXPECT_NE(d.find("variable resist    equal $(v_kn_wall+v_c_wall/v_servo_dt)"),
                std::string::npos);
      resist += deck_variable(d, "c_wall") / servo_dt;
      EXPECT_GT(resist / c.material.wall.kn, 2.0);  // the stiffness it had before
    } else {
      EXPECT_NE(gain_kn_line.find("$(v_gain*v_servo_f/v_kn_wall)"), std::string::npos)
          << gain_kn_line;
      EXPECT_EQ(d.find("variable c_wall"), std::string::npos);
    }
    const double gain_kn = deck_variable(d, "gain") * (dt / servo_dt) / resist;
    // the deck's numbers are written with 10 digits
    EXPECT_NEAR(gain_kn / (demcal * r.step_factor), 1.0, 1e-9) << "zeta_c " << zeta_c;

    o.format = "liggghts";
    const ExportResult g = export_deck(c, p, a, o);
    const double h = a.top - a.bottom;
    const double force = c.test.lateral_stress * h * c.material.thickness;
    const double dt_demcal = g.dt / g.step_factor;
    if (zeta_c > 0.0) {
      // demcal's servo carries a share of the last move, LIGGGHTS' mesh
      // servo cannot: the deck moves the walls by demcal's law itself
      // (per demcal step, gain/R per unit of force on a wall without
      // contacts, the carry, at u/dt_demcal)
      EXPECT_EQ(g.deck.find("mesh/surface/stress/servo"), std::string::npos);
      const double carry = demcal_servo_carry(c, p, a);
      EXPECT_GT(carry, 0.5);
      for (const auto& [fix, k, target] :
           {std::tuple{"mleft", 1, "ftl"}, std::tuple{"mright", 2, "ftr"}}) {
        const test::LiggghtsCarriedLaw law = test::liggghts_carried_law(g.deck, fix, k, target, 0);
        if (std::string(fix) == "mleft") {  // without contacts in this packing: n = 1
          EXPECT_NEAR(law.gain / law.resist / demcal, 1.0, 1e-9);
        }
        EXPECT_NEAR(law.carry / carry, 1.0, 1e-9) << fix;
        EXPECT_NEAR(law.dt_demcal / dt_demcal, 1.0, 1e-9) << fix;
        EXPECT_NEAR(law.cap / servo_move_cap(*std::min_element(a.r.begin(), a.r.end())), 1.0, 1e-9)
            << fix;
        EXPECT_NE(g.deck.find(std::string("fix smove_") + fix + " all move/mesh mesh " + fix +
                              " linear/variable v_sv_" + fix + " v_servo_zero v_servo_zero\n"),
                  std::string::npos)
            << fix;
      }
      // the contacts n are counted over the walls' bands, the LAMMPS decks'
      // (2*strain*width + 6*r_max from the wall's start), with the series'
      // overlap flags; a particle outside a band at its wall stops the run
      const double band = 2.0 * c.test.vertical_strain * (a.right - a.left) +
                          6.0 * *std::max_element(a.r.begin(), a.r.end());
      const test::LiggghtsBand left = test::liggghts_band(g.deck, "mleft", 0, false);
      const test::LiggghtsBand right = test::liggghts_band(g.deck, "mright", 0, true);
      EXPECT_NEAR(left.bound, a.left + band, 1e-9 * band);
      EXPECT_NEAR(right.bound, a.right - band, 1e-9 * band);
      EXPECT_EQ(left.touch, "ll_a");
      EXPECT_EQ(right.touch, "lr_a");
      for (const char* needle :
           {"\nvariable gap_mleft atom x-c_pa[1]-v_xl\n",
            "\nvariable gap_mright atom v_xr-x-c_pa[1]\n",
            "\ncompute clear_mleft out_mleft reduce min v_gap_mleft\n",
            "\ngroup out_mleft subtract all band_mleft\n",
            "\nvariable band_out equal (c_clear_mleft<0)+(c_clear_mright<0)\n",
            "\nrun ${run_steps} pre no post no every ${band_check} 'if \"${band_out} > 0\" then "
            "\"print ${band_msg}\" quit'\n"})
        EXPECT_NE(g.deck.find(needle), std::string::npos) << needle;
      continue;
    }
    EXPECT_EQ(demcal_servo_carry(c, p, a), 0.0);
    // the left wall starts without contacts in this packing (n = 1 as demcal's)
    const std::string fix = g.deck.substr(g.deck.find("fix mleft "));
    auto number_after = [&](const std::string& key) {
      return std::stod(fix.substr(fix.find(" " + key + " ") + key.size() + 2));
    };
    const double velocity_per_force = number_after("vel_max") * number_after("kp") / force;
    EXPECT_NEAR(velocity_per_force * dt_demcal / demcal, 1.0, 1e-9) << "zeta_c " << zeta_c;
  }
}

TEST(Export, AConsolidatedStateReadBackGivesTheSameDeck) {
  // `demcal verify` writes the consolidated prototype (particle_csv); read
  // back (`export --prototype FILE --no-consolidate`) it carries its walls,
  // so the deck starts at sigma3 as the one exported from the state does.
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  const Assembly a = assembly_of(state.world);
  std::istringstream csv(particle_csv(a));
  const Assembly b = read_particles(csv, "prototype.csv");
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(b.left, a.left);
  EXPECT_EQ(b.right, a.right);
  EXPECT_EQ(b.bottom, a.bottom);
  EXPECT_EQ(b.top, a.top);
  // The walls press into the particles (sigma3 on them): not the bounding box.
  double extent_left = a.x[0] - a.r[0];
  for (int i = 0; i < a.size(); ++i) extent_left = std::min(extent_left, a.x[i] - a.r[i]);
  EXPECT_GT(b.left, extent_left);
  ExportOptions o;
  o.deck_name = "p";
  const ExportResult from_state = export_deck(c, params(), a, o);
  const ExportResult read_back = export_deck(c, params(), b, o);
  EXPECT_EQ(read_back.deck, from_state.deck);
  EXPECT_EQ(read_back.files, from_state.files);
  // A walls line that presses further than a contact can is an error naming
  // the file and the line.
  std::istringstream bad(
      std::string(kParticleFileWalls) +
      " 0.0002 0.01 0 0.01\nx,y,r\n0.0005,0.0005,0.0005\n0.0015,0.0005,0.0005\n");
  try {
    read_particles(bad, "bad.csv");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv: line 1"), std::string::npos) << e.what();
  }
}

class LammpsRun : public ::testing::TestWithParam<const char*> {};

TEST_P(LammpsRun, TheDeckStartsWithOurTimestepAndSigma3OnTheWalls) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the exported deck is not run");
  SceneConfig c = default_config();
  if (std::string(GetParam()) == "hexagonal") {
    c.assembly.columns = c.assembly.rows = 5;
  } else {  // polydisperse: 8 radius classes, per-type damping
    c.assembly.type = "random";
    c.assembly.count = 100;
  }
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  const Assembly a = assembly_of(state.world);
  ExportOptions o;
  o.deck_name = "hex5";
  const ExportResult r = export_deck(c, params(), a, o);

  const test::TempDir dir("lammps");
  const test::DeckRun lammps = test::run_deck(lmp, dir.path(), r.deck, r.files,
                                              {"-var", "run_steps", "300", "-screen", "none"});
  ASSERT_EQ(lammps.status, 0) << lammps.log;
  const std::string& text = lammps.log;
  ASSERT_NE(text.find("Loop time"), std::string::npos) << text;
  // Thermo rows: step dt time epsyy p_top p_left p_right W H ke.
  std::stringstream lines(text.substr(text.find("Step Dt Time")));
  std::string header, line;
  std::getline(lines, header);
  std::vector<std::vector<double>> rows;
  while (std::getline(lines, line) && line.find("Loop time") == std::string::npos) {
    std::stringstream f(line);
    std::vector<double> v;
    for (double x; f >> x;) v.push_back(x);
    if (v.size() == 10) rows.push_back(v);
  }
  ASSERT_GE(rows.size(), 2u) << text;
  EXPECT_EQ(rows.front()[0], 0);
  EXPECT_EQ(rows.back()[0], 300);
  for (const auto& row : rows) EXPECT_NEAR(row[1] / r.dt, 1.0, 1e-6);  // our timestep
  // demcal's consolidated state holds σ3 on every wall in LAMMPS too.
  const double s3 = c.test.lateral_stress;
  EXPECT_NEAR(rows.front()[4] / s3, 1.0, 0.01);
  EXPECT_NEAR(rows.front()[5] / s3, 1.0, 0.01);
  EXPECT_NEAR(rows.front()[6] / s3, 1.0, 0.01);
  // The top wall loads the sample; the servo keeps the lateral walls at σ3.
  EXPECT_GT(rows.back()[4], rows.front()[4]);
  EXPECT_NEAR(rows.back()[5] / s3, 1.0, 0.01);
  EXPECT_NEAR(rows.back()[6] / s3, 1.0, 0.01);
}

INSTANTIATE_TEST_SUITE_P(Export, LammpsRun, ::testing::Values("hexagonal", "random"));

/// Thermo rows (step dt time epsyy p_top p_left p_right W H ke) of a log.
std::vector<std::vector<double>> thermo_rows(const std::string& text) {
  std::vector<std::vector<double>> rows;
  const auto at = text.find("Step Dt Time");
  if (at == std::string::npos) return rows;
  std::stringstream lines(text.substr(at));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line) && line.find("Loop time") == std::string::npos) {
    std::stringstream f(line);
    std::vector<double> v;
    for (double x; f >> x;) v.push_back(x);
    if (v.size() == 10) rows.push_back(v);
  }
  return rows;
}

TEST(Export, LammpsReproducesDemcalsPeak) {
  // The whole loading of the 25-particle sample in both codes (ζ_r = 0:
  // this LAMMPS has no rotational damping, so both run the same model):
  // the axial peak agrees within 1 %. ~1·10⁶ particle-steps each.
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the exported deck is not run");
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  const ConsolidatedState state = consolidate(c, make_assembly(c));
  AlgorithmSpec p = params();
  p.damping_ratio_rotation = 0.0;
  const LoadingResult run = run_loading(state, c.test, p);
  ASSERT_FALSE(run.diverged);
  ExportOptions o;
  o.deck_name = "hex5";
  const ExportResult r = export_deck(c, p, assembly_of(state.world), o);
  const test::TempDir dir("lammps_peak");
  const test::DeckRun lammps = test::run_deck(lmp, dir.path(), r.deck, r.files);
  ASSERT_EQ(lammps.status, 0) << lammps.log;
  const auto rows = thermo_rows(lammps.log);
  ASSERT_GT(rows.size(), 100u);
  EXPECT_EQ(rows.back()[0], r.steps);
  double lammps_peak = 0.0;
  for (const auto& row : rows) lammps_peak = std::max(lammps_peak, row[4]);
  const double demcal_peak = -run.peak_stress_yy;
  EXPECT_NEAR(lammps_peak / demcal_peak, 1.0, 0.01)
      << "LAMMPS " << lammps_peak << " Pa, demcal " << demcal_peak << " Pa";
  // The servo held σ3 in LAMMPS too.
  EXPECT_NEAR(rows.back()[5] / c.test.lateral_stress, 1.0, 0.01);
}

/// The peak σ_yy of the series file `series` a deck wrote in `dir` (tension
/// positive: the most negative).
double series_peak(const fs::path& dir, const std::string& series, const SceneConfig& c) {
  const ExternalSeries s =
      parse_external_series(test::read_text(dir / series), series, c.test.lateral_stress);
  double peak = 0.0;
  for (const auto& p : s.run.series) peak = std::min(peak, p.sigma(1, 1));
  return peak;
}

TEST(Export, LammpsDeckConsolidatesItselfToDemcalsPeak) {
  // --consolidate-in deck: the deck takes the generated hex 5x5 lattice to
  // isotropic sigma3 itself (stage 1), then loads it. A hexagonal lattice
  // has one consolidated packing (the lattice compressed isotropically) and
  // its peak is proportional to sigma3 (failure at a fixed sigma1/sigma3),
  // and each consolidation leaves every wall within consolidation_tolerance
  // of sigma3: the peak after the deck's consolidation is that after
  // demcal's within 2 * consolidation_tolerance (both loaded in LAMMPS, so
  // the engines' differences cancel). Under mpirun -np 2 the same run: the
  // peak within 1e-9 (the order of the MPI sums).
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the exported deck is not run");
  SceneConfig c = default_config();
  c.assembly.columns = c.assembly.rows = 5;
  AlgorithmSpec p = params();
  p.damping_ratio_rotation = 0.0;
  p.steps = 8000;  // a faster loading, the same in both decks: seconds per run
  const Assembly generated = make_assembly(c);
  ExportOptions o;
  o.deck_name = "hex5";
  const ExportResult by_demcal =
      export_deck(c, p, assembly_of(consolidate(c, generated, "").world), o);
  o.consolidate_in_deck = true;
  const ExportResult in_deck = export_deck(c, p, generated, o);
  EXPECT_NE(in_deck.deck.find("stage 1: consolidation"), std::string::npos);
  EXPECT_EQ(by_demcal.deck.find("stage 1: consolidation"), std::string::npos);

  const test::TempDir d1("lammps_cons_demcal"), d2("lammps_cons_deck"), d3("lammps_cons_np2");
  const test::DeckRun r1 = test::run_deck(lmp, d1.path(), by_demcal.deck, by_demcal.files);
  ASSERT_EQ(r1.status, 0) << r1.log;
  const test::DeckRun r2 = test::run_deck(lmp, d2.path(), in_deck.deck, in_deck.files);
  ASSERT_EQ(r2.status, 0) << r2.log;
  ASSERT_NE(r2.log.find("demcal deck: consolidated in"), std::string::npos) << r2.log;
  // The loading starts at sigma3 on all four walls (series row 0).
  const std::string series = deck_files(o.deck_name).series;
  const ExternalSeries s2 =
      parse_external_series(test::read_text(d2.path() / series), series, c.test.lateral_stress);
  ASSERT_FALSE(s2.run.series.empty());
  const double tol = c.test.consolidation_tolerance;
  const auto& first = s2.run.series.front();
  EXPECT_NEAR(-first.sigma(0, 0) / c.test.lateral_stress, 1.0, 2 * tol);
  EXPECT_NEAR(-first.sigma(1, 1) / c.test.lateral_stress, 1.0, 2 * tol);
  const double peak_demcal = series_peak(d1.path(), series, c),
               peak_deck = series_peak(d2.path(), series, c);
  EXPECT_NEAR(peak_deck / peak_demcal, 1.0, 2 * tol)
      << "deck-consolidated " << peak_deck << " Pa, demcal-consolidated " << peak_demcal << " Pa";

  // A split run: the continuation skips stage 1 and takes its start walls
  // and the lateral walls' last positions from the restart args; the same
  // peak but for what a LAMMPS restart changes (its setup's forces, the atom
  // sort): measured 2.6e-13 (1e-7 before the args carried the walls exactly).
  const test::TempDir d4("lammps_cons_split");
  const int half = static_cast<int>(in_deck.steps / 2);
  const test::DeckRun first_part =
      test::run_deck(lmp, d4.path(), in_deck.deck, in_deck.files,
                     {"-var", "run_steps", std::to_string(half), "-screen", "none"});
  ASSERT_EQ(first_part.status, 0) << first_part.log;
  std::vector<std::string> args;
  std::stringstream words(test::read_text(d4.path() / deck_files(o.deck_name).restart_args));
  for (std::string w; words >> w;) args.push_back(w);
  ASSERT_NE(std::find(args.begin(), args.end(), "yt0"), args.end());
  args.insert(args.end(), {"-screen", "none"});
  const test::DeckRun second_part = test::run_deck(lmp, d4.path(), in_deck.deck, {}, args);
  ASSERT_EQ(second_part.status, 0) << second_part.log;
  EXPECT_EQ(second_part.log.find("demcal deck: consolidated in"), std::string::npos);
  EXPECT_NEAR(series_peak(d4.path(), series, c) / peak_deck, 1.0, 1e-10);

  DEMCAL_FIND_PROGRAM(mpirun, "mpirun", "openmpi-bin", "the deck is not run under MPI");
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  const test::DeckRun r3 = test::run_deck(mpirun, d3.path(), in_deck.deck, in_deck.files,
                                          {"-np", "2", lmp, "-screen", "none"});
  ASSERT_EQ(r3.status, 0) << r3.log;
  EXPECT_NEAR(series_peak(d3.path(), series, c) / peak_deck, 1.0, 1e-9);
}

TEST(ConsolidateIn, AutoIsDemcalsKernelAtEverySizeDeckOnlyWhenAsked) {
  // The rule (consolidate_in.hpp): the deck's stage 1 costs 19x demcal's CPU
  // at 2 500 disks and more at 10 000 (reports/engines.md §27), so `auto` is
  // demcal's consolidation for both formats, and the deck consolidates only
  // with `deck`. Before, auto gave LAMMPS prototypes above 2 000 particles
  // to the deck (this test's auto rows failed).
  using demcal::cli::consolidate_in_deck;
  for (const char* format : {"lammps", "liggghts"})
    for (const int n : {25, 2000, 2500, 10000, 40000, 1000000}) {
      EXPECT_FALSE(consolidate_in_deck("auto", format, false, n)) << format << " " << n;
      EXPECT_FALSE(consolidate_in_deck("demcal", format, false, n)) << format << " " << n;
      EXPECT_FALSE(consolidate_in_deck("auto", format, true, n)) << format << " " << n;
    }
  EXPECT_TRUE(consolidate_in_deck("deck", "lammps", false, 25));
  EXPECT_TRUE(consolidate_in_deck("deck", "lammps", false, 40000));
  EXPECT_THROW(consolidate_in_deck("gpu", "lammps", false, 25), demcal::InputError);
  EXPECT_THROW(consolidate_in_deck("deck", "liggghts", false, 25), demcal::InputError);
  EXPECT_THROW(consolidate_in_deck("deck", "lammps", true, 25), demcal::InputError);
  EXPECT_THROW(consolidate_in_deck("demcal", "lammps", true, 25), demcal::InputError);
}

TEST(ExportCli, ConsolidateInChoosesWhereAndRejectsBadCombinations) {
  // auto: demcal's kernel (consolidate_in.hpp); deck: the deck's stage 1
  // (said on stderr); bad values and combinations exit 2 writing nothing.
  const test::TempDir dir("export_cli");
  const std::string params = test::example_params("hex_10x10");
  auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"export", params});
    return test::run_demcal(args, dir.path());
  };
  const auto automatic = run({"--particles", "25", "-o", "a/deck.lammps"});
  const auto deck = run({"--particles", "25", "--consolidate-in", "deck", "-o", "b/deck.lammps"});
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  ASSERT_EQ(deck.status, 0) << deck.err;
  EXPECT_NE(automatic.err.find("with demcal's kernel"), std::string::npos) << automatic.err;
  EXPECT_NE(deck.err.find("the deck consolidates the prototype"), std::string::npos) << deck.err;
  const std::string deck_a = test::read_text(dir.path() / "a" / "deck.lammps");
  const std::string deck_b = test::read_text(dir.path() / "b" / "deck.lammps");
  EXPECT_EQ(deck_a.find("stage 1: consolidation"), std::string::npos);
  EXPECT_NE(deck_b.find("stage 1: consolidation"), std::string::npos);
  EXPECT_EQ(run({"--particles", "25", "--consolidate-in", "gpu", "-o", "c/d.lammps"}).status, 2);
  EXPECT_EQ(run({"--particles", "25", "--consolidate-in", "deck", "--format", "liggghts", "-o",
                 "c/d.liggghts"})
                .status,
            2);
  EXPECT_EQ(
      run({"--particles", "25", "--consolidate-in", "deck", "--no-consolidate", "-o", "c/d.lammps"})
          .status,
      2);
  EXPECT_FALSE(fs::exists(dir.path() / "c"));
}

TEST(ExportCli, TwoDecksInOneFolderReadTheirOwnFiles) {
  // Both formats exported into one folder with their default names: each
  // deck reads files named after its whole file name, the same bytes as
  // when exported alone (before: both wrote demcal-NAME.data, and the
  // LAMMPS data file's one atom type broke the LIGGGHTS deck's walls).
  // An export that would overwrite a file another deck reads is refused.
  const test::TempDir dir("export_two_decks");
  const std::string params = test::example_params("hex_10x10");
  auto run = [&](std::vector<std::string> args, const fs::path& where) {
    args.insert(args.begin(), {"export", params, "--particles", "25"});
    return test::run_demcal(args, where);
  };
  const fs::path alone = dir / "alone", both = dir / "both";
  fs::create_directories(alone);
  fs::create_directories(both);
  ASSERT_EQ(run({"--format", "liggghts"}, alone).status, 0);
  const auto liggghts = run({"--format", "liggghts"}, both);
  ASSERT_EQ(liggghts.status, 0) << liggghts.err;
  const auto lammps = run({"--consolidate-in", "deck"}, both);
  ASSERT_EQ(lammps.status, 0) << lammps.err;
  const std::string l_deck = "demcal-hex_10x10.liggghts", m_deck = "demcal-hex_10x10.lammps";
  const std::string l_text = test::read_text(both / l_deck),
                    m_text = test::read_text(both / m_deck);
  // the files each deck reads: read_data FILE, mesh ... file FILE
  auto read_by = [](const std::string& deck) {
    std::vector<std::string> names;
    std::istringstream lines(deck);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind('#', 0) == 0) continue;
      std::istringstream words(line);
      for (std::string w, last; words >> w; last = w)
        if ((last == "read_data" || last == "\"read_data" || last == "file") && w[0] != '$')
          names.push_back(w.substr(0, w.find('"')));
    }
    return names;
  };
  const std::vector<std::string> l_files = read_by(l_text), m_files = read_by(m_text);
  ASSERT_EQ(l_files.size(), 4u) << l_text;  // the data file and three meshes
  ASSERT_FALSE(m_files.empty());
  for (const std::string& f : l_files) {
    EXPECT_EQ(f.rfind(l_deck, 0), 0u) << f;
    EXPECT_EQ(test::read_text(both / f), test::read_text(alone / f)) << f;
  }
  for (const std::string& f : m_files) {
    EXPECT_EQ(f.rfind(m_deck, 0), 0u) << f;
    EXPECT_TRUE(fs::exists(both / f)) << f;
  }
  EXPECT_EQ(test::read_text(both / l_deck), test::read_text(alone / l_deck));

  // A deck named as another deck's data file: refused, nothing written.
  const std::string m_data = m_deck + ".data";
  const std::string before = test::read_text(both / m_data);
  const auto clash = run({"--format", "liggghts", "-o", m_data}, both);
  EXPECT_EQ(clash.status, 2) << clash.err;
  EXPECT_NE(clash.err.find(m_deck), std::string::npos) << clash.err;
  EXPECT_EQ(test::read_text(both / m_data), before);
  EXPECT_FALSE(fs::exists(both / (m_data + ".data")));
  // A deck of an older demcal that names its data file after its stem
  // (old.lammps reads old.data): exporting `old` (data old.data) is refused.
  std::string old_deck = m_text;
  for (size_t at; (at = old_deck.find(m_data)) != std::string::npos;)
    old_deck.replace(at, m_data.size(), "old.data");
  test::write_text(both / "old.lammps", old_deck);
  test::write_text(both / "old.data", "the old deck's particles");
  EXPECT_EQ(run({"-o", "old"}, both).status, 2);
  EXPECT_EQ(test::read_text(both / "old.data"), "the old deck's particles");
  // Exporting a deck again replaces it and its own files.
  EXPECT_EQ(run({"--consolidate-in", "deck"}, both).status, 0);
  EXPECT_EQ(test::read_text(both / m_deck), m_text);

  // The LIGGGHTS deck runs beside the LAMMPS one (3.8 needs a screen).
  DEMCAL_FIND_PROGRAM(liggghts_program, "liggghts", "liggghts", "the deck is not run");
  const test::RunResult ran = test::run_program(
      liggghts_program, {"-var", "run_steps", "50", "-in", l_deck, "-log", "log.liggghts"}, both);
  EXPECT_EQ(ran.status, 0) << test::read_text(both / "log.liggghts");
  EXPECT_EQ(test::read_text(both / "log.liggghts").find("ERROR"), std::string::npos);
}

/// The data rows of a deck's series file (neither `#` lines nor the
/// column header).
size_t series_rows(const fs::path& file) {
  size_t rows = 0;
  for (const std::string& line : test::lines_of(test::read_text(file)))
    rows += !line.empty() && line[0] != '#' && line.rfind("step,", 0) != 0;
  return rows;
}

TEST(ExportCli, DecksInOneFolderWriteTheirOwnSeriesAndRestarts) {
  // A first-time user's walk (2026-12-04): h5.lammps and h5.liggghts run in
  // one folder both wrote series.csv (the second's replaced the first's),
  // and two LAMMPS decks both wrote series.csv and final.restart(.args).
  // A deck's outputs are named after its whole file name as its inputs are:
  // NAME.series.csv, NAME.restart, NAME.restart.args; README's continuation
  // `lmp $(cat NAME.restart.args) -in NAME` appends to its own series.
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the decks are not run");
  DEMCAL_FIND_PROGRAM(liggghts, "liggghts", "liggghts", "the decks are not run");
  const test::TempDir dir("export_deck_outputs");
  const fs::path d = dir.path();
  for (const std::string deck : {"a.lammps", "b.lammps", "a.liggghts"}) {
    const std::string format = deck.substr(deck.find('.') + 1);
    const test::RunResult r =
        test::run_demcal({"export", test::example_params("hex_10x10"), "--particles", "25",
                          "--format", format, "-o", deck},
                         d);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const std::string a_text = test::read_text(d / "a.lammps");
  const int every =
      static_cast<int>(deck_variable(a_text, "nstep") / deck_variable(a_text, "monitor_points"));
  ASSERT_GT(every, 1);
  // a to its first monitoring step after 0, b and the LIGGGHTS deck a few steps
  auto lammps = [&](std::vector<std::string> args, const std::string& log) {
    args.insert(args.end(), {"-log", log, "-screen", "none"});
    const int status = test::run_program(lmp, args, d).status;
    EXPECT_EQ(status, 0) << test::read_text(d / log);
  };
  lammps({"-var", "run_steps", std::to_string(every), "-in", "a.lammps"}, "log.a");
  lammps({"-var", "run_steps", "20", "-in", "b.lammps"}, "log.b");
  // (LIGGGHTS 3.8 needs a screen)
  const test::RunResult g = test::run_program(
      liggghts, {"-var", "run_steps", "20", "-in", "a.liggghts", "-log", "log.liggghts"}, d);
  ASSERT_EQ(g.status, 0) << test::read_text(d / "log.liggghts");
  for (const char* shared : {"series.csv", "final.restart", "final.restart.args"})
    EXPECT_FALSE(fs::exists(d / shared)) << shared;
  for (const char* own :
       {"a.lammps.restart", "a.lammps.restart.args", "b.lammps.restart", "b.lammps.restart.args"})
    EXPECT_TRUE(fs::exists(d / own)) << own;
  ASSERT_TRUE(fs::exists(d / "a.lammps.series.csv"));
  ASSERT_TRUE(fs::exists(d / "b.lammps.series.csv"));
  ASSERT_TRUE(fs::exists(d / "a.liggghts.series.csv"));
  EXPECT_NE(test::lines_of(test::read_text(d / "a.lammps.series.csv"))[0].find("LAMMPS deck"),
            std::string::npos);
  EXPECT_NE(test::lines_of(test::read_text(d / "a.liggghts.series.csv"))[0].find("LIGGGHTS deck"),
            std::string::npos);
  EXPECT_EQ(series_rows(d / "a.lammps.series.csv"), 2u);  // steps 0 and `every`
  EXPECT_EQ(series_rows(d / "b.lammps.series.csv"), 1u);  // step 0
  const std::string b_series = test::read_text(d / "b.lammps.series.csv");

  // The continuation of a, by README's command: its own restart and series.
  std::vector<std::string> args;
  std::stringstream words(test::read_text(d / "a.lammps.restart.args"));
  for (std::string w; words >> w;) args.push_back(w);
  const std::string joined = test::read_text(d / "a.lammps.restart.args");
  EXPECT_NE(joined.find("-var restart_from a.lammps.restart "), std::string::npos) << joined;
  args.insert(args.end(), {"-var", "run_steps", std::to_string(2 * every), "-in", "a.lammps"});
  lammps(args, "log.a2");
  EXPECT_EQ(series_rows(d / "a.lammps.series.csv"), 3u);
  EXPECT_EQ(test::read_text(d / "b.lammps.series.csv"), b_series);
  EXPECT_FALSE(fs::exists(d / "series.csv"));
  // The series scores as the deck's (demcal score reads it by its name).
  const test::RunResult scored = test::run_demcal({"score", "a.lammps.series.csv", "-o", "sc"}, d);
  EXPECT_TRUE(scored.status == 0 || scored.status == 1) << scored.err;
}

TEST(ExportCli, AnUncertifiedCalibrationsDeckSaysSoInItsHeader) {
  // `export --allow-failed` of a calibration whose parameters failed the
  // certificate: the warning went to stderr only, and the deck carried no
  // mark. Its header now says NOT CERTIFIED and why (params.json's
  // message), in comment lines a LAMMPS reader cannot leave (a newline, a
  // closing `&` or a `"` in the message would end the comment or join the
  // next line); a certified calibration's deck has no such line.
  const test::TempDir dir("export_uncertified");
  nlohmann::json params = test::read_json(test::example_params("hex_10x10"));
  ASSERT_EQ(params["success"], true);
  const std::string why =
      "the best passing parameters did not pass the convergence certificate\nrun 0 &";
  params["success"] = false;
  params["message"] = why;
  test::write_text(dir / "failed.json", params.dump(1));
  // the header's NOT CERTIFIED lines, up to the header's first "#" line
  auto uncertified_of = [](const std::string& deck) {
    const auto at = deck.find("# NOT CERTIFIED");
    return at == std::string::npos ? std::string() : deck.substr(at, deck.find("\n#\n", at) - at);
  };
  for (const std::string format : {"lammps", "liggghts"}) {
    SCOPED_TRACE(format);
    const std::string name = "u." + format, certified = "c." + format;
    const test::RunResult refused = test::run_demcal(
        {"export", "failed.json", "--particles", "25", "--format", format, "-o", name}, dir.path());
    EXPECT_EQ(refused.status, 2);
    const test::RunResult r = test::run_demcal({"export", "failed.json", "--particles", "25",
                                                "--format", format, "--allow-failed", "-o", name},
                                               dir.path());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string text = test::read_text(dir / name);
    const std::string header = uncertified_of(text);
    EXPECT_LT(text.find("# NOT CERTIFIED: the calibration of these parameters failed"),
              text.find("\n#\n"))
        << text.substr(0, 2000);
    EXPECT_NE(test::replaced_all(header, "\n# ", " ")
                  .find("(--allow-failed): the best passing parameters did not pass the "
                        "convergence certificate run 0 and"),
              std::string::npos)
        << header;
    for (const std::string& line : test::lines_of(header)) {
      EXPECT_EQ(line.rfind('#', 0), 0u) << line;
      EXPECT_NE(line.back(), '&') << line;
      EXPECT_LE(line.size(), 79u) << line;
    }
    const test::RunResult ok =
        test::run_demcal({"export", test::example_params("hex_10x10"), "--particles", "25",
                          "--format", format, "-o", certified},
                         dir.path());
    ASSERT_EQ(ok.status, 0) << ok.err;
    EXPECT_EQ(test::read_text(dir / certified).find("CERTIFIED"), std::string::npos);
  }
  // The LAMMPS deck runs (a short check): the header is comments only.
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the deck is not run");
  const test::RunResult ran = test::run_program(
      lmp, {"-var", "run_steps", "10", "-in", "u.lammps", "-log", "log.u", "-screen", "none"},
      dir.path());
  EXPECT_EQ(ran.status, 0) << test::read_text(dir / "log.u");
}

}  // namespace
}  // namespace demcal
