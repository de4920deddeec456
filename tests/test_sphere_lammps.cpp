// Cross-implementation check of the sphere kernel against LAMMPS 3D, on the
// library's own deck (export_3d_decks, lateral servo off: one home for the
// 3D mapping; its header gives every line of it). Skipped with a message
// when `lmp` is not on PATH.
//
// The mapping in short: masses ρ·f_ms·(4/3)πr³ and I = (2/5)·m·r² (atom_style
// sphere, as the kernel); gran/hooke/history kn kt 0 0 μ 0 (no contact
// damping); D_t = ζ_t·2·sqrt(kn·m_i) as fix viscous with one atom type per
// distinct radius (max_types = N), so each sphere gets its own γ; ζ_r = 0
// (LAMMPS 29 Sep 2021 has no rotational viscous fix); the deck runs at
// α·f·Δt_crit for Nstep/f steps (f = dashpot_step_factor(ζ_t): its damping is
// explicit), and the kernel here at the same Δt and top-wall speed.
// Known differences, all small in a slow run: LAMMPS integrates velocity
// Verlet with the damping explicit (demcal: leapfrog, damping
// semi-implicit); its tangential history is projected without rescaling
// and not twisted, and its lever arms are the radii (demcal: r − δ/2).
//
// Protocol, no servo: walls fixed except the top one, which moves down at
// constant speed. Compared at the deck's monitoring rows: the number of
// particle contacts at the end, the diagonal of the boundary stress b over
// the run (the deck's b from the walls' contact arrays, demcal's
// SphereMeasures::boundary_stress) and its peak ratio b_zz/b_xx.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "demcal/scene/sphere_packing.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "support/files.hpp"
#include "support/process.hpp"
#include "support/programs.hpp"
#include "test_sphere_helpers.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;
using sphere_test::kR;

/// One sample of a run: step, particle contacts, diagonal of b.
struct Sample {
  int64_t step = 0;
  int contacts = 0;
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
};

/// The run both codes make: the library's deck (export_3d_decks, lateral
/// servo off) of the world for `params` and the config's material and
/// strain, and demcal's kernel at the deck's timestep and top-wall speed.
struct Protocol {
  SceneConfig config;
  AlgorithmSpec params;
};

Protocol protocol(const SphereMaterial& m, double strain, double zeta_t, int64_t steps) {
  Protocol p;
  p.config.name = "sphere_lammps";
  p.config.dimension = 3;
  p.config.material.density = m.density;
  p.config.material.particle = m.particle;
  p.config.material.wall = m.wall;
  p.config.material.contact_damping_ratio = m.contact_damping_ratio;
  p.config.test.vertical_strain = strain;
  p.config.test.monitor_points = 20;
  p.params.dt_ratio = 0.2;
  p.params.steps = steps;
  p.params.damping_ratio_translation = zeta_t;
  p.params.damping_ratio_rotation = 0.0;  // LAMMPS 29 Sep 2021 has none
  return p;
}

/// demcal's kernel at the deck's Δt, sampled at `steps`.
std::vector<Sample> run_demcal(SphereWorld w, const Protocol& p, const ExportResult& deck,
                               const std::vector<int64_t>& steps) {
  Integration in = w.integration();
  in.dt = deck.dt;
  in.damping_ratio_translation = p.params.damping_ratio_translation;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);
  w.wall(kZMax).velocity =
      -p.config.test.vertical_strain * w.extent(2) / (static_cast<double>(deck.steps) * deck.dt);
  std::vector<Sample> out;
  int64_t done = 0;
  for (int64_t s : steps) {
    EXPECT_TRUE(w.step(s - done)) << to_string(w.divergence());
    done = s;
    const SphereMeasures m = w.measure();
    out.push_back({s, m.particle_contacts, m.boundary_stress.diagonal()});
  }
  return out;
}

/// The deck run by LAMMPS: the rows of its series file `series` after step 0
/// (step, b_xx b_yy b_zz, contacts); empty when it failed (the log goes to
/// `log`).
std::vector<Sample> run_lammps(const std::string& lmp, const ExportResult& deck,
                               const std::string& series, std::string& log) {
  const test::TempDir tmp("sphere_lammps");
  const test::DeckRun run = test::run_deck(lmp, tmp.path(), deck.deck, deck.files);
  log = run.log;
  std::vector<Sample> out;
  if (run.status != 0 || !fs::exists(tmp.path() / series)) return out;
  std::stringstream lines(test::read_text(tmp.path() / series));
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 's') continue;
    std::vector<double> v;
    std::stringstream f(line);
    for (std::string cell; std::getline(f, cell, ',');) v.push_back(std::stod(cell));
    if (v.size() < 12 || v[0] == 0) continue;
    // step, strain_zz, b row by row (b_xx at 2, b_yy at 6, b_zz at 10), ..., contacts last
    out.push_back({static_cast<int64_t>(v[0]), static_cast<int>(std::lround(v.back())),
                   Eigen::Vector3d(v[2], v[6], v[10])});
  }
  return out;
}

/// Largest relative difference of b over the samples (each component
/// relative to the largest |b| of that sample), and the peak ratios.
struct Comparison {
  double b_error = 0.0, peak_demcal = 0.0, peak_lammps = 0.0;
};

Comparison compare(const std::vector<Sample>& d, const std::vector<Sample>& l) {
  Comparison c;
  for (size_t k = 0; k < d.size() && k < l.size(); ++k) {
    EXPECT_EQ(d[k].step, l[k].step);
    const double scale = d[k].b.cwiseAbs().maxCoeff();
    if (scale > 0.0)
      c.b_error = std::max(c.b_error, (d[k].b - l[k].b).cwiseAbs().maxCoeff() / scale);
    if (d[k].b.x() < 0.0) c.peak_demcal = std::max(c.peak_demcal, d[k].b.z() / d[k].b.x());
    if (l[k].b.x() < 0.0) c.peak_lammps = std::max(c.peak_lammps, l[k].b.z() / l[k].b.x());
  }
  return c;
}

// tol: the largest relative difference of b and of the peak b_zz/b_xx
// allowed (the 1 % for a random packing, whose contacts form and
// break chaotically; tighter for a lattice, see its test).
void check_against_lammps(const char* name, const SphereWorld& w, const Protocol& p, double tol) {
  DEMCAL_FIND_PROGRAM(lmp, "lmp", "lammps", "the cross-check is not run");
  Export3dOptions o;
  o.lateral_servo = false;
  o.max_types = w.size();  // one class per distinct radius: each sphere its own γ
  o.deck_name = "spheres";
  const ExportResult deck = export_3d_decks(p.config, p.params, w, o);
  std::string log;
  const std::vector<Sample> l = run_lammps(lmp, deck, deck_files(o.deck_name).series, log);
  ASSERT_GE(l.size(), 10u) << log;
  std::vector<int64_t> steps;
  for (const Sample& s : l) steps.push_back(s.step);
  const std::vector<Sample> d = run_demcal(w, p, deck, steps);
  const Comparison c = compare(d, l);
  std::printf(
      "%s vs LAMMPS after %lld steps: contacts %d / %d, b_zz %.5g / %.5g Pa, b_xx %.5g / %.5g "
      "Pa, largest b difference %.2e of |b|, peak b_zz/b_xx %.4f / %.4f\n",
      name, static_cast<long long>(deck.steps), d.back().contacts, l.back().contacts,
      d.back().b.z(), l.back().b.z(), d.back().b.x(), l.back().b.x(), c.b_error, c.peak_demcal,
      c.peak_lammps);
  EXPECT_NEAR(l.back().contacts, d.back().contacts, 0.01 * d.back().contacts);
  EXPECT_LT(c.b_error, tol);
  EXPECT_NEAR(c.peak_lammps, c.peak_demcal, tol * c.peak_demcal);
}

// FCC 3×3×3 (108 spheres), pre-compressed, μ = 0.3: the top wall
// compresses the lattice by 0.2 % over 20 000 steps at α = 0.2, ζ_t = 0.3.
// The two codes differ by known small terms only: LAMMPS takes torques at
// r_i, demcal at r_i − δ/2 (δ/2r ≈ 1e-4 here), its history is projected
// without demcal's rescale and twist (O(θ²) per step, θ the contacts'
// turn), and its velocity-Verlet with fix viscous against demcal's
// semi-implicit damping (same continuous equation, O(Δt²)): 1e-3 bounds
// them with a margin (measured 1.3e-5 for b, 3e-5 for the peak).
TEST(SphereLammps, FccCompressionMatchesLammps) {
  const SphereAssembly a = fcc_packing(3, 3, 3, kR, 2e-4);
  SphereWorld w(sphere_test::test_material(0.3), a.x, a.y, a.z, a.r, a.lo, a.hi);
  check_against_lammps("FCC 3x3x3", w, protocol(w.material(), 2e-3, 0.3, 20000), 1e-3);
}

// A random polydisperse sample: 300 spheres, radii uniform in [0.8, 1.2]·r,
// consolidated frictionless by demcal (all six walls inward in steps, each
// followed by a relaxation, to about 20 MPa), velocities zeroed, friction on (μ = 0.3, histories
// empty in both codes); then the same compression as the FCC run, 1 % in 20 000 steps. A dense
// random packing makes and breaks contacts as it deforms: the contact count is a real check here.
TEST(SphereLammps, RandomSampleCompressionMatchesLammps) {
  // Before the consolidation (seconds): nothing to compare without LAMMPS.
  if (test::find_on_path("lmp").empty())
    DEMCAL_SKIP_MISSING("lmp", "lammps", "the cross-check is not run");
  AssemblySpec spec;
  spec.count = 300;
  spec.radius_min = 0.8 * kR;
  spec.radius_max = 1.2 * kR;
  spec.seed = 5;
  const SphereAssembly a = random_sphere_gas(spec);
  SphereWorld w(sphere_test::test_material(0.0), a.x, a.y, a.z, a.r, a.lo, a.hi);
  Integration in;
  in.damping_ratio_translation = 0.5;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);
  in.dt = 0.2 * w.reference_scales().dt_crit;
  w.set_integration(in);
  // Cycles of a short inward move of all six walls and a relaxation with the
  // walls held, until the relaxed packing holds 20 MPa (unbalanced force
  // below 10 %); the moves shrink from 0.1·r to 0.02·r once contacts form
  // and to 0.005·r near jamming (where the pressure rises steeply with the
  // strain).
  SphereMeasures m = w.measure();
  for (int cycle = 0; cycle < 400 && !(m.mean_pressure > 2e7 && m.unbalanced_force_ratio < 0.1);
       ++cycle) {
    const double z = m.coordination_number;
    const double move = (z < 1.0 ? 0.1 : z < 3.0 ? 0.02 : 0.005) * kR;
    for (int s = 0; s < 6; ++s)
      w.wall(static_cast<SphereWallSide>(s)).velocity =
          (s % 2 == 0 ? 1.0 : -1.0) * move / (500 * in.dt);
    ASSERT_TRUE(w.step(500)) << to_string(w.divergence());
    for (int s = 0; s < 6; ++s) w.wall(static_cast<SphereWallSide>(s)).velocity = 0.0;
    ASSERT_TRUE(w.step(1500)) << to_string(w.divergence());
    m = w.measure();
  }
  ASSERT_GT(m.mean_pressure, 2e7);
  for (int i = 0; i < w.size(); ++i)
    w.set_velocity(i, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  w.set_particle_friction(0.3);
  m = w.measure();
  std::printf("random 300: consolidated to %.3g Pa, %d contacts, coordination %.2f\n",
              m.mean_pressure, m.particle_contacts, m.coordination_number);
  check_against_lammps("random 300", w, protocol(w.material(), 1e-2, 0.3, 20000), 1e-2);
}

}  // namespace
}  // namespace demcal
