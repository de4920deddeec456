// The 3D scene layer: "dimension": 3 configs (parsing, defaults, mismatches
// as bad input) and the triaxial protocol of triaxial.hpp (consolidation to
// σ3 on all six walls; Thornton's FCC peak with rotation locked).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "demcal/scene/biaxial.hpp"  // consolidation_dashpot_factor
#include "demcal/scene/config.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "support/input_errors.hpp"
#include "support/scenes.hpp"

namespace demcal {
namespace {

using test::input_error;

SceneConfig parse(const std::string& text) {
  return parse_config_text(test::with_required_material(text), "scene3d.json");
}

// A small FCC config; `extra` is spliced into the test block.
std::string fcc_text(int n, double sigma3, double strain, int64_t steps, bool lock,
                     const std::string& extra = "") {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                R"({"name": "fcc", "dimension": 3,
      "assembly": {"type": "fcc", "cells_x": %d, "cells_y": %d, "cells_z": %d, "radius": 5e-4},
      "test": {"type": "triaxial", "lateral_stress": %g, "vertical_strain": %g,
               "monitor_points": 50%s},
      "algorithm": {"steps": %lld, "lock_rotation": %s}})",
                n, n, n, sigma3, strain, extra.c_str(), static_cast<long long>(steps),
                lock ? "true" : "false");
  return buf;
}

TEST(Config3D, ReadsTheTriaxialKeys) {
  const SceneConfig c = parse(fcc_text(3, 2e5, 0.002, 20000, true));
  EXPECT_EQ(c.dimension, 3);
  EXPECT_EQ(c.assembly.type, "fcc");
  EXPECT_EQ(c.assembly.cells_x, 3);
  EXPECT_EQ(c.assembly.cells_z, 3);
  EXPECT_EQ(c.test.type, "triaxial");
  EXPECT_EQ(c.test.lateral_stress, 2e5);
  EXPECT_EQ(c.test.vertical_strain, 0.002);
  EXPECT_TRUE(c.algorithm.lock_rotation);
  // Written back: the dimension and the FCC keys, no disk thickness.
  const nlohmann::json j = to_json(c);
  EXPECT_EQ(j.at("dimension"), 3);
  EXPECT_EQ(j.at("assembly").at("cells_y"), 3);
  EXPECT_FALSE(j.at("material").contains("thickness"));
  EXPECT_EQ(parse(j.dump()).assembly.cells_y, 3);
}

TEST(Config3D, DefaultsAreThe3DOnes) {
  const SceneConfig c = parse(R"({"dimension": 3})");
  EXPECT_EQ(c.assembly.type, kDefaultAssembly3D);
  EXPECT_EQ(c.test.type, kDefaultTest3D);
  EXPECT_EQ(c.assembly.cells_x, AssemblySpec{}.cells_x);
  // Random and file assemblies keep their 2D keys and meaning.
  const SceneConfig r = parse(
      R"({"dimension": 3, "assembly": {"type": "random", "count": 50, "distribution": "lognormal",
          "radius_mean": 5e-4, "radius_std": 1e-4, "seed": 3}})");
  EXPECT_EQ(r.assembly.count, 50);
  EXPECT_EQ(r.assembly.distribution, "lognormal");
}

TEST(Config3D, TwoDConfigsAreUnchanged) {
  const SceneConfig c = parse(R"({"assembly": {"type": "hexagonal", "columns": 4, "rows": 4}})");
  EXPECT_EQ(c.dimension, 2);
  EXPECT_EQ(c.test.type, "biaxial");
  const nlohmann::json j = to_json(c);
  EXPECT_FALSE(j.contains("dimension"));
  EXPECT_TRUE(j.at("material").contains("thickness"));
}

TEST(Config3D, MismatchesAreInputErrorsNamingFileAndKey) {
  struct Case {
    const char* text;
    const char* field;
  };
  const Case cases[] = {
      {R"({"test": {"type": "triaxial"}})", "test.type"},
      {R"({"dimension": 2, "assembly": {"type": "fcc"}})", "assembly.type"},
      {R"({"dimension": 3, "assembly": {"type": "hexagonal"}})", "assembly.type"},
      {R"({"dimension": 3, "assembly": {"type": "square"}})", "assembly.type"},
      {R"({"dimension": 3, "test": {"type": "biaxial"}})", "test.type"},
      {R"({"dimension": 3, "material": {"thickness": 1.0}})", "material.thickness"},
      {R"({"dimension": 4})", "dimension"},
      {R"({"dimension": "3"})", "dimension"},
      {R"({"dimension": 3, "assembly": {"type": "fcc", "cells_x": 0}})", "assembly.cells_x"},
      {R"({"dimension": 3, "assembly": {"type": "fcc", "columns": 3}})", "assembly.columns"},
      {R"({"dimension": 3, "assembly": {"type": "fcc", "radius": -1}})", "assembly.radius"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.text);
    const auto e = input_error([&] { parse(k.text); });
    ASSERT_TRUE(e);
    EXPECT_EQ(e->file(), "scene3d.json");
    EXPECT_EQ(e->field(), k.field) << e->what();
  }
}

TEST(Config3D, OverlapAtSigma3IsCheckedWithTheRadii) {
  // δ/r = 4·σ3·r/kn: 0.05 at σ3 = 2.5e9 Pa for r = 5e-4 m, kn = 1e8 N/m.
  const SceneConfig ok = parse(fcc_text(2, 2.4e9, 0.001, 1000, true));
  EXPECT_NO_THROW(make_sphere_assembly(ok));
  const SceneConfig bad = parse(fcc_text(2, 2.6e9, 0.001, 1000, true));
  const auto e = input_error([&] { make_sphere_assembly(bad); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->field(), "test.lateral_stress");
}

double max_wall_error(const SphereWorld& w, double sigma3) {
  double err = 0.0;
  for (int s = 0; s < 6; ++s)
    err =
        std::max(err, std::abs(wall_pressure(w, static_cast<SphereWallSide>(s)) - sigma3) / sigma3);
  return err;
}

// A loose random gas is compressed until every one of the six walls carries
// σ3 within the consolidation tolerance and the sample is static. σ3 = 1e7
// Pa: kn/(σ3·d) = 1e4, the stiffness level of configs/random_500_3d.json (kn 1e6 at 100 kPa there).
// A box about 1.6 times as wide as high (assembly.aspect), so that each
// wall's pressure must be its force over its own face: the boundary stress
// b, from the contact points, reads σ3 on all three axes. (Its x and y
// extents are equal, so this tells the z walls' face from the lateral
// ones', not x's from y's.)
TEST(TriaxialScene, ConsolidationReachesSigma3OnAllSixWalls) {
  const SceneConfig c = parse(
      R"({"dimension": 3, "assembly": {"type": "random", "count": 60, "radius_min": 4e-4,
          "radius_max": 6e-4, "aspect": 1.6, "seed": 2}, "test": {"lateral_stress": 1e7}})");
  const SphereAssembly a = make_sphere_assembly(c);
  int calls = 0;
  const TriaxialState s =
      consolidate_triaxial(c, a, [&](const ConsolidationProgress&) { ++calls; });
  std::printf("60 spheres consolidated in %lld steps, wall error %.2e, unbalanced %.2e\n",
              static_cast<long long>(s.steps), s.stress_error, s.unbalanced_ratio);
  EXPECT_TRUE(s.converged);
  EXPECT_GT(calls, 0);
  EXPECT_LT(max_wall_error(s.world, c.test.lateral_stress), c.test.consolidation_tolerance);
  const SphereMeasures m = s.world.measure();
  EXPECT_LT(m.unbalanced_force_ratio, c.test.consolidation_unbalanced);
  EXPECT_GT(s.world.extent(0), 1.3 * s.world.extent(2));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(s.extent0[axis], s.world.extent(axis));
    EXPECT_NEAR(-m.boundary_stress(axis, axis), c.test.lateral_stress,
                c.test.consolidation_tolerance * c.test.lateral_stress);
  }
  // Friction is on for the loading.
  EXPECT_EQ(s.world.material().particle.friction, c.material.particle.friction);
}

// Contact dashpots at ζ_c = 0.3 shrink the consolidation's step (α 0.2 →
// 0.074 here, consolidation_dashpot_factor; 0.035 before 2026-12-03), so
// the light damping needs more steps to the same simulated time: 149 400
// for this sample (configs/random_500_3d.json's material and σ3, 60
// spheres; 164 800 at α 0.035), 59 800 since the consolidation's servo
// carries its dashpots' share (servo_velocity). The
// critical-damping fallback used to come after a quarter of the step budget
// whatever the step, here at 75 000 steps, before the packing was static,
// and critical damping then did not bring it there within 300 000 steps
// (wall stress error 4 %, unbalanced-force ratio 0.088; random_500_3d at
// ζ_c 0.2 and 0.3 stalled the same way in 2·10⁶). It now comes after the
// same simulated time as undamped.
TEST(TriaxialScene, ContactDampingConsolidatesARandomSampleWithinAModestBudget) {
  SceneConfig c = parse(
      R"({"dimension": 3, "material": {"density": 2650, "kn": 1e6, "kt": 5e5, "friction": 0.3,
          "wall": {"kn": 1e6, "kt": 5e5, "friction": 0.0}, "contact_damping_ratio": 0.3},
          "assembly": {"type": "random", "count": 60, "radius_min": 4e-4, "radius_max": 6e-4,
          "seed": 2}, "test": {"lateral_stress": 1e5, "consolidation_max_steps": 300000},
          "algorithm": {"dt_ratio": 0.05}})");
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c), std::string());
  std::printf("60 spheres, contact damping 0.3: consolidated in %lld steps\n",
              static_cast<long long>(s.steps));
  // Static by the consolidation's own readings at its last check. (Not by
  // a measure of the state handed over: its velocities are then set to 0,
  // which with dashpots removes their share c·v_n of each contact force, so
  // the unbalanced-force ratio moves; built with clang it read 1.008e-4
  // there against the 1e-4 certified.)
  EXPECT_TRUE(s.converged);
  EXPECT_LT(s.stress_error, c.test.consolidation_tolerance);
  EXPECT_LT(s.unbalanced_ratio, c.test.consolidation_unbalanced);
}

// The servo (consolidation and loading) carries servo_carry = (c/Δt)/R of
// its last move into the next (servo_velocity): a steady error then drives
// the wall at the undamped law's velocity gain·error·A/(n·kn_wall·Δt), the
// fixed point of the law, where the per-step law alone (the wall at rest,
// R = kn_wall + c/Δt) reaches kn_wall/R of it. Without contact damping
// nothing is carried, bit for bit, whatever the wall's velocity.
TEST(TriaxialScene, ConsolidationServoDrivesASteadyErrorAtTheUndampedVelocity) {
  for (const double zeta_c : {0.0, 0.7}) {
    SceneConfig c = parse(
        R"({"dimension": 3, "material": {"density": 2650, "kn": 1e6, "kt": 5e5, "friction": 0.3,
            "wall": {"kn": 1e6, "kt": 5e5, "friction": 0.0}},
            "assembly": {"type": "random", "count": 60, "radius_min": 4e-4, "radius_max": 6e-4,
            "seed": 2}, "test": {"lateral_stress": 1e5}})");
    c.material.contact_damping_ratio = zeta_c;
    const SphereAssembly a = make_sphere_assembly(c);
    SphereWorld w(sphere_material(c.material), a.x, a.y, a.z, a.r, a.lo, a.hi);
    AlgorithmSpec settle;
    settle.dt_ratio = 0.05;
    w.set_integration(integration_for(w, settle));
    w.update_forces();
    const double dt = w.integration().dt, kn_wall = c.material.wall.kn;
    const double gain = c.test.servo_gain;
    const double target = 1.0;  // [Pa]: far below the move cap
    for (int s = 0; s < 6; ++s) {
      const auto side = static_cast<SphereWallSide>(s);
      const int axis = s / 2;
      const double area = w.extent((axis + 1) % 3) * w.extent((axis + 2) % 3);
      const double inward = s % 2 == 0 ? 1.0 : -1.0;
      const double error = target - wall_pressure(w, side);
      const double undamped =
          inward * gain * error * area / (std::max(1, w.wall(side).contacts) * kn_wall * dt);
      // At rest the law is the per-step one (nothing to carry).
      w.wall(side).velocity = 0.0;
      const double per_step = servo_velocity(w, side, target, gain);
      if (zeta_c == 0.0) {
        w.wall(side).velocity = 0.3 * undamped;  // any velocity: no carry
        EXPECT_EQ(servo_velocity(w, side, target, gain), per_step) << s;
        EXPECT_NEAR(per_step, undamped, 1e-12 * std::abs(undamped)) << s;
        continue;
      }
      // Moving at the undamped velocity, it stays there.
      w.wall(side).velocity = undamped;
      EXPECT_NEAR(servo_velocity(w, side, target, gain), undamped, 1e-12 * std::abs(undamped)) << s;
      // The per-step law alone is kn_wall/R of it (R/kn_wall ≈ 27 here).
      EXPECT_LT(std::abs(per_step), 0.05 * std::abs(undamped)) << s;
    }
  }
}

// The loading's lateral servo carries its last move too (servo_velocity):
// with contact dashpots it holds σ3 as closely as without them. 100 spheres
// of configs/random_500_3d.json (its material, radii and σ3), 50 000 steps
// at α 0.05: servo criterion 0.0077 at ζ_c 0, 0.0068 at 0.3; with the
// per-step law alone 0.090 at 0.3 (11.6×), the walls moving at kn_wall/R of
// the speed a steady error asks for (reports/robustness.md, "The loading's
// servo carries too").
TEST(TriaxialScene, WithContactDashpotsTheLoadingServoHoldsSigma3AsWithout) {
  double servo[2];
  for (const int k : {0, 1}) {
    SceneConfig c = parse(
        R"({"dimension": 3, "material": {"density": 2650, "kn": 1e6, "kt": 5e5, "friction": 0.3,
            "wall": {"kn": 1e6, "kt": 5e5, "friction": 0.0}},
            "assembly": {"type": "random", "count": 100, "radius_min": 3.75e-4,
            "radius_max": 6.25e-4, "seed": 1},
            "test": {"lateral_stress": 1e5}, "algorithm": {"dt_ratio": 0.05, "steps": 50000}})");
    c.material.contact_damping_ratio = k == 0 ? 0.0 : 0.3;
    const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c), std::string());
    ASSERT_TRUE(s.converged);
    const TriaxialResult run = run_triaxial_loading(s, c.test, c.algorithm);
    ASSERT_FALSE(run.diverged);
    servo[k] = score_triaxial_run(run, c.test.lateral_stress, triaxial_tolerances()).criteria.servo;
  }
  std::printf("100 spheres, loading servo criterion: %.5g undamped, %.5g at contact damping 0.3\n",
              servo[0], servo[1]);
  EXPECT_LT(servo[1], 1.5 * servo[0]);
}

// Contact damping ζ_c 0.7 on 100 spheres of configs/random_500_3d.json
// (its material, radii and σ3, seed 1). With the per-step servo law alone
// the consolidation's walls moved at kn_wall/R = 1/44 of the undamped law's
// velocity for a steady error: a deviatoric wall error (one axis pair above
// σ3, another below) fell by an e-fold in ~50 000 steps, slower than the
// frictionless packing rearranges, and the servo chased it: not static in
// 300 000 steps (wall stress error 12 %, unbalanced-force ratio 0.0052),
// nor in 600 000 (random_500_3d itself: 1–5 % to the end of 2·10⁶). With
// the carry (servo_velocity): static in 97 800 steps.
// (reports/robustness.md, "The 3D consolidation at contact damping 0.7".)
TEST(TriaxialScene, HeavilyDampedRandomSampleConsolidatesWithinAModestBudget) {
  SceneConfig c = parse(
      R"({"dimension": 3, "material": {"density": 2650, "kn": 1e6, "kt": 5e5, "friction": 0.3,
          "wall": {"kn": 1e6, "kt": 5e5, "friction": 0.0}, "contact_damping_ratio": 0.7},
          "assembly": {"type": "random", "count": 100, "radius_min": 3.75e-4,
          "radius_max": 6.25e-4, "seed": 1},
          "test": {"lateral_stress": 1e5, "consolidation_max_steps": 300000},
          "algorithm": {"dt_ratio": 0.02}})");
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c), std::string());
  std::printf("100 spheres, contact damping 0.7: consolidated in %lld steps\n",
              static_cast<long long>(s.steps));
  EXPECT_TRUE(s.converged);
  EXPECT_LT(s.stress_error, c.test.consolidation_tolerance);
  EXPECT_LT(s.unbalanced_ratio, c.test.consolidation_unbalanced);
}

// The consolidation's step with contact dashpots (consolidation_dashpot_factor,
// ζ_c·sqrt(Λ) the damping ratio a mode can carry, biaxial.cpp) stays below
// the kernel's dashpot-aware estimate of the stable step on the packing it
// consolidated (Lanczos ω_max with the contacts' own γ_max, stability.cpp):
// it is 1.54× below at ζ_c 0.3 and 1.74× at 0.7 (1.66× and 1.71× on the
// packings of the per-step servo law, before servo_velocity),
// so a factor that much bolder fails. The step before 2026-12-03 (0.035 and 0.015) was 3.5× and
// 3.9× below.
TEST(TriaxialScene, DampedConsolidationStepIsBelowTheStableStepOfItsPacking) {
  for (const double zeta_c : {0.3, 0.7}) {
    SceneConfig c = parse(
        R"({"dimension": 3, "material": {"density": 2650, "kn": 1e6, "kt": 5e5, "friction": 0.3,
            "wall": {"kn": 1e6, "kt": 5e5, "friction": 0.0}},
            "assembly": {"type": "random", "count": 60, "radius_min": 4e-4, "radius_max": 6e-4,
            "seed": 2}, "test": {"lateral_stress": 1e5}, "algorithm": {"dt_ratio": 0.02}})");
    c.material.contact_damping_ratio = zeta_c;
    const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c), std::string());
    ASSERT_TRUE(s.converged) << zeta_c;
    const double alpha =
        AlgorithmSpec{}.dt_ratio *
        consolidation_dashpot_factor(zeta_c, 3, s.world.min_radius(), s.world.max_radius());
    const double stable = estimated_stable_dt_ratio(s, c.algorithm);
    std::printf(
        "60 spheres, contact damping %.1f: consolidation alpha %.4f, %lld steps; stable "
        "alpha of the packing %.4f (%.2fx)\n",
        zeta_c, alpha, static_cast<long long>(s.steps), stable, stable / alpha);
    EXPECT_LT(alpha, stable) << zeta_c;
  }
}

TEST(TriaxialScene, ConsolidationThatCannotFinishSaysWhatItReached) {
  SceneConfig c = parse(fcc_text(2, 1e7, 5e-4, 1000, true));
  c.test.consolidation_max_steps = 1000;
  c.test.consolidation_unbalanced = 1e-30;  // unreachable
  try {
    consolidate_triaxial(c, make_sphere_assembly(c));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("did not reach a static state in 1000 steps"), std::string::npos) << what;
    EXPECT_NE(what.find("unbalanced-force ratio"), std::string::npos) << what;
    EXPECT_EQ(what.find("empty slab"), std::string::npos) << what;  // a lattice has none
  }
}

// A stray sphere (a wrong row of a particle file): a 5x5x5 block of
// touching spheres, 5 mm wide, and one sphere 25 mm above it. The top wall
// meets the stray alone and pushes it against the global damping's drag
// alone, which its servo reads as stress: the wall stalls at 28.6 % short
// of σ3 (2·10⁶ steps measured), and the error said only that. It now names
// the empty slab and the sphere beyond it.
TEST(TriaxialScene, ConsolidationThatFailsNamesAStraySphere) {
  SceneConfig c = parse(fcc_text(2, 1e5, 5e-4, 1000, false));
  c.test.consolidation_max_steps = 100000;
  const double r = 5e-4;
  SphereAssembly a;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) {
        a.x.push_back((2 * i + 1) * r);
        a.y.push_back((2 * j + 1) * r);
        a.z.push_back((2 * k + 1) * r);
        a.r.push_back(r);
      }
  a.x.push_back(0.0045), a.y.push_back(0.0045), a.z.push_back(0.03), a.r.push_back(r);
  a.lo = {0.0, 0.0, 0.0};
  a.hi = {0.005, 0.005, 0.03 + r};
  try {
    consolidate_triaxial(c, a);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("did not reach a static state"), std::string::npos) << what;
    EXPECT_NE(what.find("empty slab 0.0245 m wide across the box along z (from 0.005 to 0.0295 m)"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("1 particle lies beyond it (the nearest at (0.0045, 0.0045, 0.03) m)"),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find("raise test.consolidation_max_steps"), std::string::npos) << what;
  }
}

// The scene protocol on the walled FCC cube, rotation locked: the peak
// σ1/σ3 within 2 % of Thornton's value 2(1 + μ)/(1 − μ) for the walled
// sample (fcc_peak_ratio_walled; 3.714 at μ = 0.3). σ3 = 1e7 Pa keeps the
// overlaps near 2e-4·r (the elastic tilt of the inclined contacts is of
// that order); the peak comes near an axial strain of 2e-4.
TEST(TriaxialScene, FccPeakWithRotationLockedMatchesThornton) {
  const int n = 3;
  const SceneConfig c = parse(fcc_text(n, 1e7, 5e-4, 20000, true));
  const double analytical = fcc_peak_ratio_walled(0.3, n, n, n);
  ASSERT_EQ(analytical_peak_ratio_3d(c), analytical);
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c));
  ASSERT_TRUE(s.converged);
  const TriaxialResult r = run_triaxial_loading(s, c.test, c.algorithm);
  ASSERT_FALSE(r.diverged);
  EXPECT_EQ(r.steps_run, c.algorithm.steps);
  ASSERT_EQ(r.series.size(), static_cast<size_t>(c.test.monitor_points + 1));
  const double ratio = -r.peak_stress_zz / c.test.lateral_stress;
  std::printf(
      "FCC %dx%dx%d scene protocol, rotation locked: consolidated in %lld steps; peak "
      "sigma1/sigma3 %.4f (against the lateral walls %.4f), analytical %.4f (%+.2f %%) at strain "
      "%.2e\n",
      n, n, n, static_cast<long long>(s.steps), ratio, r.peak_ratio, analytical,
      100.0 * (ratio / analytical - 1.0), r.peak_strain_zz);
  EXPECT_NEAR(ratio, analytical, 0.02 * analytical);
  EXPECT_NEAR(r.peak_ratio, analytical, 0.02 * analytical);
  // Monitoring: the last point is the end of the loading; b is 3×3 with the
  // axial component the largest; the servo holds the four lateral walls.
  const TriaxialPoint& last = r.series.back();
  EXPECT_EQ(last.step, c.algorithm.steps);
  EXPECT_NEAR(last.strain_zz, -c.test.vertical_strain, 1e-3 * c.test.vertical_strain);
  EXPECT_LT(last.b(2, 2), last.b(0, 0));
  for (double e : last.servo_error) EXPECT_LT(std::abs(e), 0.05);
}

// Contact damping ζ_c 0.3 (the wall contacts' dashpots too): the servo
// divides by R = kn_wall + c/Δt and the consolidation shrinks α for the
// dashpots, as in 2D (servo_resistance, consolidation_dashpot_factor).
// Before 2026-12-02 neither: this sample did not consolidate in the default
// 2·10⁶ steps (wall stress error 100 %, unbalanced-force ratio 3.5). The
// loading, at an α stable with the dashpots (0.1), then reaches Thornton's
// peak within the undamped test's 2 %: measured +1.08 %, 0.74 % above the
// undamped run (+0.34 % at α = 0.2). Both parts are rate effects, measured
// with this protocol (2026-12-03): the same 20 000 steps at half the Δt
// load twice as fast, and the global damping's drag grows with the rate
// (ζ_c = 0 at α = 0.1: +0.78 %); the contact dashpots add the remaining
// +0.30 %, a viscous stress: at half the rate (α = 0.1 over 40 000 steps)
// +0.44 % with them against +0.30 % without, +0.15 %.
TEST(TriaxialScene, WithContactDampingConsolidatesAndLoads) {
  const int n = 3;
  SceneConfig c = parse(fcc_text(n, 1e7, 5e-4, 20000, true));
  c.material.contact_damping_ratio = 0.3;
  c.algorithm.dt_ratio = 0.1;
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c));
  ASSERT_TRUE(s.converged);
  EXPECT_LT(s.stress_error, c.test.consolidation_tolerance);
  EXPECT_LT(s.unbalanced_ratio, c.test.consolidation_unbalanced);
  const TriaxialResult r = run_triaxial_loading(s, c.test, c.algorithm);
  ASSERT_FALSE(r.diverged);
  EXPECT_EQ(r.steps_run, c.algorithm.steps);
  const double analytical = fcc_peak_ratio_walled(0.3, n, n, n);
  const double ratio = -r.peak_stress_zz / c.test.lateral_stress;
  std::printf(
      "FCC 3x3x3, contact damping 0.3: consolidated in %lld steps; peak sigma1/sigma3 "
      "%.4f, analytical %.4f (%+.2f %%)\n",
      static_cast<long long>(s.steps), ratio, analytical, 100.0 * (ratio / analytical - 1.0));
  EXPECT_NEAR(ratio, analytical, 0.02 * analytical);
  for (double e : r.series.back().servo_error) EXPECT_LT(std::abs(e), 0.05);
}

// The monitor's powers: the global damping's D·|v|² summed over the
// spheres, with D_t = ζ_t·2·sqrt(kn·m) and D_r = ζ_r·2·sqrt(kt·r²·I) (the
// damping the kernel applies, sphere_world.cpp), and the axial power the
// top wall's push times its speed. The diagnosis reads their ratio as the
// rotational drag (rotational_drag_share). Checked at every monitoring
// point of a short loading with free rotation, against the world there.
TEST(TriaxialScene, MonitoredPowersAreTheGlobalDampingsAndTheTopWalls) {
  const int n = 3;
  SceneConfig c = parse(fcc_text(n, 1e7, 5e-4, 5000, false));
  const double zeta_t = 0.3, zeta_r = 0.5;
  c.algorithm.damping_ratio_translation = zeta_t;
  c.algorithm.damping_ratio_rotation = zeta_r;
  const TriaxialState s = consolidate_triaxial(c, make_sphere_assembly(c));
  ASSERT_TRUE(s.converged);
  int checked = 0, pushing = 0;
  auto observe = [&](const TriaxialPoint& p, const SphereWorld& w) {
    const double kn = w.material().particle.kn, kt = w.material().particle.kt;
    double pt = 0.0, pr = 0.0;
    for (int i = 0; i < w.size(); ++i) {
      const double m = w.mass()[i], inertia = w.inertia()[i], r = w.radius()[i];
      const Eigen::Vector3d v(w.vx()[i], w.vy()[i], w.vz()[i]);
      const Eigen::Vector3d om(w.omega_x()[i], w.omega_y()[i], w.omega_z()[i]);
      pt += zeta_t * 2.0 * std::sqrt(kn * m) * v.squaredNorm();
      pr += zeta_r * 2.0 * std::sqrt(kt * r * r * inertia) * om.squaredNorm();
    }
    EXPECT_NEAR(p.damping_power_translation, pt, 1e-12 * pt);
    EXPECT_NEAR(p.damping_power_rotation, pr, 1e-12 * pr);
    const SphereWall& top = w.wall(kZMax);  // moving down (v < 0), pushed up
    const double axial = -top.force[2] * top.velocity;
    EXPECT_NEAR(p.axial_power, axial, 1e-12 * std::abs(axial));
    pushing += axial > 0.0;
    ++checked;
  };
  const TriaxialResult r = run_triaxial_loading(s, c.test, c.algorithm, {}, nullptr, observe);
  ASSERT_FALSE(r.diverged);
  EXPECT_GT(checked, 40);
  EXPECT_GT(pushing, 40);
  EXPECT_GT(r.series.back().damping_power_rotation, 0.0);  // the spheres spin
}

}  // namespace
}  // namespace demcal
