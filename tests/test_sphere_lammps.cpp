// Cross-implementation check of the sphere kernel against LAMMPS 3D
// (pair_style gran/hooke/history, fix nve/sphere, fix viscous, fix
// wall/gran/region planes). Skipped with a message when `lmp` is not on PATH.
//
// Mapping (one line each; the same as the 2D deck of src/upscaling/export.cpp):
//  - masses: per-atom density ρ·f_ms in the data file (atom_style sphere:
//    m = ρ·(4/3)πr³, I = (2/5)·m·r², as the kernel);
//  - contact: gran/hooke/history kn kt 0 0 μ 0 — linear normal spring kn·δ,
//    tangential spring kt on the accumulated shear displacement (force/
//    distance, the kernel's kt as it is), Coulomb cap μ·Fn, no contact
//    damping; walls: wall/gran/region hooke/history kn_w kt_w 0 0 μ_w 0;
//  - global damping: demcal's D_t = ζ_t·2·sqrt(kn·m_i) is fix viscous γ_i
//    (force −γ_i·v; one atom type per distinct mass so each sphere gets its
//    own γ through `scale`); ζ_r = 0, as LAMMPS 29 Sep 2021 has no
//    rotational viscous fix.
// Known differences, all small in a slow run: LAMMPS integrates velocity
// Verlet with the damping explicit (demcal: leapfrog, damping
// semi-implicit); its tangential history is projected without rescaling
// and not twisted, and its lever arms are the radii (demcal: r − δ/2).
//
// Protocol, no servo: walls fixed except the top one, which moves down at
// constant speed. Compared: the number of particle contacts at the end, and
// the diagonal of the boundary stress b over the run (b_aa =
// (L_a/2V)·(F_hi − F_lo), F the force of a wall on the spheres; walls
// frictionless so only these enter) and its peak ratio b_zz/b_xx.
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
#include "support/files.hpp"
#include "support/process.hpp"
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

struct Protocol {
  double dt = 0.0, zeta_t = 0.0, top_speed = 0.0;  // top_speed < 0: down
  int64_t steps = 0, every = 0;
};

std::vector<Sample> run_demcal(SphereWorld w, const Protocol& p) {
  Integration in = w.integration();
  in.dt = p.dt;
  in.damping_ratio_translation = p.zeta_t;
  in.damping_ratio_rotation = 0.0;
  w.set_integration(in);
  w.wall(kZMax).velocity = p.top_speed;
  std::vector<Sample> out;
  for (int64_t s = 0; s < p.steps; s += p.every) {
    EXPECT_TRUE(w.step(p.every)) << to_string(w.divergence());
    const SphereMeasures m = w.measure();
    out.push_back({s + p.every, m.particle_contacts, m.boundary_stress.diagonal()});
  }
  return out;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// Run the same state and protocol in LAMMPS; empty when it failed (the
/// log goes to `log`).
std::vector<Sample> run_lammps(const std::string& lmp, const SphereWorld& w, const Protocol& p,
                               std::string& log) {
  const test::TempDir tmp("sphere_lammps");
  const fs::path& dir = tmp.path();
  const SphereMaterial& mat = w.material();
  // One atom type per distinct mass (a few for a polydisperse sample).
  std::map<double, int> type_of;
  for (int i = 0; i < w.size(); ++i) type_of.emplace(w.mass()[i], 0);
  int t = 0;
  for (auto& [m, k] : type_of) k = ++t;
  const double density = mat.density * w.integration().mass_scaling;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = w.wall(static_cast<SphereWallSide>(2 * a)).position;
    hi[a] = w.wall(static_cast<SphereWallSide>(2 * a + 1)).position;
  }
  {
    std::ofstream d(dir / "spheres.data");
    d << "demcal sphere state\n\n" << w.size() << " atoms\n" << type_of.size() << " atom types\n\n";
    const char* axis[3] = {"x", "y", "z"};
    const double pad = 4.0 * w.max_radius() + 0.1 * (hi[2] - lo[2]);
    for (int a = 0; a < 3; ++a)
      d << num(lo[a] - pad) << " " << num(hi[a] + pad) << " " << axis[a] << "lo " << axis[a]
        << "hi\n";
    d << "\nAtoms # sphere\n\n";
    for (int i = 0; i < w.size(); ++i)
      d << i + 1 << " " << type_of[w.mass()[i]] << " " << num(2.0 * w.radius()[i]) << " "
        << num(density) << " " << num(w.x()[i]) << " " << num(w.y()[i]) << " " << num(w.z()[i])
        << "\n";
  }
  const double kn = mat.particle.kn;
  std::ofstream in(dir / "in.spheres");
  in << "units si\ndimension 3\nboundary f f f\natom_style sphere\natom_modify map array\n"
     << "comm_modify vel yes\nnewton off\nread_data spheres.data\n"
     << "pair_style gran/hooke/history " << num(kn) << " " << num(mat.particle.kt) << " 0 0 "
     << num(mat.particle.friction) << " 0\npair_coeff * *\n"
     << "neighbor " << num(0.3 * w.min_radius()) << " bin\n"
     << "neigh_modify delay 0 every 1 check yes\ntimestep " << num(p.dt) << "\n"
     << "fix integ all nve/sphere\n";
  if (p.zeta_t > 0.0) {
    const double g0 = p.zeta_t * 2.0 * std::sqrt(kn * type_of.begin()->first);
    in << "fix damp all viscous " << num(g0);
    for (const auto& [m, k] : type_of)
      if (k > 1) in << " scale " << k << " " << num(p.zeta_t * 2.0 * std::sqrt(kn * m) / g0);
    in << "\n";
  }
  const char* names[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
  for (int s = 0; s < 6; ++s) {
    const int a = s / 2;
    double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
    point[a] = (s % 2 == 0) ? lo[a] : hi[a];
    normal[a] = (s % 2 == 0) ? 1.0 : -1.0;
    in << "region r" << names[s] << " plane " << num(point[0]) << " " << num(point[1]) << " "
       << num(point[2]) << " " << normal[0] << " " << normal[1] << " " << normal[2]
       << " side in units box";
    if (s == kZMax) in << " move NULL NULL v_dz";
    in << "\n";
    if (s == kZMax - 1) in << "variable dz equal " << num(p.top_speed) << "*step*dt\n";
  }
  for (int s = 0; s < 6; ++s)
    in << "fix w" << names[s] << " all wall/gran/region hooke/history " << num(mat.wall.kn) << " "
       << num(mat.wall.kt) << " 0 0 " << num(mat.wall.friction) << " 0 region r" << names[s]
       << " contacts\n";
  in << "compute cn all contact/atom\ncompute ncon all reduce sum c_cn\n"
     << "variable contacts equal c_ncon/2\n";
  for (int s = 0; s < 6; ++s)
    in << "compute f" << names[s] << " all reduce sum f_w" << names[s] << "[" << 2 + s / 2 << "]\n";
  in << "thermo_style custom step v_contacts c_fxlo c_fxhi c_fylo c_fyhi c_fzlo c_fzhi\n"
     << "thermo_modify norm no\nthermo " << p.every << "\nrun " << p.steps << "\n";
  in.close();
  const int status =
      test::run_program(lmp, {"-in", "in.spheres", "-log", "log.lammps", "-screen", "none"}, dir)
          .status;
  log = test::read_text(dir / "log.lammps");
  std::vector<Sample> out;
  if (status != 0) return out;
  const auto at = log.find("Step v_contacts");
  if (at == std::string::npos) return out;
  std::stringstream lines(log.substr(at));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line) && line.find("Loop time") == std::string::npos) {
    std::stringstream f(line);
    std::vector<double> v;
    for (double x; f >> x;) v.push_back(x);
    if (v.size() != 8 || v[0] == 0) continue;
    Sample s;
    s.step = static_cast<int64_t>(v[0]);
    s.contacts = static_cast<int>(std::lround(v[1]));
    const double top = hi[2] + p.top_speed * p.dt * static_cast<double>(s.step);
    const double len[3] = {hi[0] - lo[0], hi[1] - lo[1], top - lo[2]};
    const double vol = len[0] * len[1] * len[2];
    for (int a = 0; a < 3; ++a) s.b[a] = len[a] / (2.0 * vol) * (v[3 + 2 * a] - v[2 + 2 * a]);
    out.push_back(s);
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

void check_against_lammps(const char* name, const SphereWorld& w, const Protocol& p) {
  const std::string lmp = test::find_on_path("lmp");
  if (lmp.empty()) GTEST_SKIP() << "LAMMPS (lmp) is not installed: the cross-check is not run";
  const std::vector<Sample> d = run_demcal(w, p);
  std::string log;
  const std::vector<Sample> l = run_lammps(lmp, w, p, log);
  ASSERT_EQ(l.size(), d.size()) << log;
  const Comparison c = compare(d, l);
  std::printf(
      "%s vs LAMMPS after %lld steps: contacts %d / %d, b_zz %.5g / %.5g Pa, b_xx %.5g / %.5g "
      "Pa, largest b difference %.2e of |b|, peak b_zz/b_xx %.4f / %.4f\n",
      name, static_cast<long long>(p.steps), d.back().contacts, l.back().contacts, d.back().b.z(),
      l.back().b.z(), d.back().b.x(), l.back().b.x(), c.b_error, c.peak_demcal, c.peak_lammps);
  EXPECT_NEAR(l.back().contacts, d.back().contacts, 0.01 * d.back().contacts);
  EXPECT_LT(c.b_error, 0.01);
  EXPECT_NEAR(c.peak_lammps, c.peak_demcal, 0.01 * c.peak_demcal);
}

// FCC 3×3×3 (108 spheres), pre-compressed, μ = 0.3: the top wall
// compresses the lattice by 0.2 % over 20 000 steps at α = 0.2, ζ_t = 0.3.
TEST(SphereLammps, FccCompressionMatchesLammps) {
  const SphereAssembly a = fcc_packing(3, 3, 3, kR, 2e-4);
  SphereWorld w(sphere_test::test_material(0.3), a.x, a.y, a.z, a.r, a.lo, a.hi);
  Protocol p;
  p.dt = 0.2 * w.reference_scales().dt_crit;
  p.zeta_t = 0.3;
  p.steps = 20000;
  p.every = 1000;
  p.top_speed = -2e-3 * w.extent(2) / (p.steps * p.dt);
  check_against_lammps("FCC 3x3x3", w, p);
}

// A random polydisperse sample: 300 spheres, radii uniform in [0.8, 1.2]·r,
// consolidated frictionless by demcal (all six walls inward in steps, each
// followed by a relaxation, to about 20 MPa), velocities zeroed, friction on (μ = 0.3, histories
// empty in both codes); then the same compression as the FCC run, 1 % in 20 000 steps. A dense
// random packing makes and breaks contacts as it deforms: the contact count is a real check here.
TEST(SphereLammps, RandomSampleCompressionMatchesLammps) {
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
  Protocol p;
  p.dt = in.dt;
  p.zeta_t = 0.3;
  p.steps = 20000;
  p.every = 1000;
  p.top_speed = -1e-2 * w.extent(2) / (p.steps * p.dt);
  check_against_lammps("random 300", w, p);
}

}  // namespace
}  // namespace demcal
