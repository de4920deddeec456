// The 3D decks (export_3d.hpp). The mapping rules are the 2D decks'
// (export.cpp); the reasons given there (explicit damping and the step
// factor, the servo as a running sum, the fix order) hold here and are
// only recalled in the decks' headers.
#include "demcal/upscaling/export_3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "deck_sections.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"

namespace demcal {

namespace {

using deck::exact;
using deck::fmt3;
using deck::num;

constexpr const char* kAxis = "xyz";
constexpr const char* kWall[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

/// The 3D series file's columns (demcal.series/1 in 3D; `demcal score`
/// reads them by name): one home for both engines' decks.
std::string series_columns_3d() {
  std::string columns = "step,strain_zz";
  for (const char* t : {"b_", "s_"})
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) columns += std::string(",") + t + kAxis[i] + kAxis[j];
  columns += ",kinetic_energy,kinetic_energy_rotation,lateral_stress_error";
  for (int sd = 0; sd < 4; ++sd) columns += std::string(",servo_error_") + kWall[sd];
  for (int sd = 0; sd < 6; ++sd) columns += std::string(",wall_") + kWall[sd];
  for (int sd = 0; sd < 6; ++sd) columns += std::string(",p_") + kWall[sd];
  return columns + ",contacts";
}

/// b and sigma, component by component, from compute meas's sums about the
/// origin (both decks' layout: [2k+1] [2k+2] the walls' and the particles'
/// x (x) f of component k row by row, [19..21] the wall forces, [22..24] the
/// contact forces) moved to the box centre (v_cx, v_cy, v_cz) and divided by
/// v_V; `variable` is the command as the deck spaces it.
std::string b_and_sigma_3d(const std::string& variable) {
  std::ostringstream s;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int k = 2 * (3 * i + j) + 1;
      const std::string ij = std::string(1, kAxis[i]) + kAxis[j];
      s << variable << "b_" << ij << " equal (c_meas[" << k << "]-v_c" << kAxis[i] << "*c_meas["
        << 19 + j << "])/v_V\n"
        << variable << "s_" << ij << " equal v_b_" << ij << "-(c_meas[" << k + 1 << "]-v_c"
        << kAxis[i] << "*c_meas[" << 22 + j << "])/v_V\n";
    }
  return s.str();
}

/// A series row up to kinetic_energy, in series_columns_3d()'s order: step,
/// the strain variable `strain`, b and sigma row by row.
std::string series_row_head_3d(const std::string& strain) {
  std::string row = "${stepn},${" + strain + "}";
  for (const char* t : {"b_", "s_"})
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) row += std::string(",${") + t + kAxis[i] + kAxis[j] + "}";
  return row;
}

/// A series row from kinetic_energy on, in series_columns_3d()'s order: the
/// deck's variables ke, ke_rot, lat_err, err_WALL, wall_WALL,
/// p_WALL<p_suffix>, contacts.
std::string series_row_tail_3d(const std::string& p_suffix) {
  std::string row = ",${ke},${ke_rot},${lat_err}";
  for (int sd = 0; sd < 4; ++sd) row += std::string(",${err_") + kWall[sd] + "}";
  for (int sd = 0; sd < 6; ++sd) row += std::string(",${wall_") + kWall[sd] + "}";
  for (int sd = 0; sd < 6; ++sd) row += std::string(",${p_") + kWall[sd] + p_suffix + "}";
  return row + ",${contacts}";
}

/// Everything both decks need, computed once.
struct Plan3 : deck::PlanCommon {
  double density = 0.0;  // f_ms·ρ [kg/m³]
  double m_mean = 0.0;
  std::array<double, 3> lo{}, hi{};
  std::vector<double> gamma_critical;  // per class, zeta 1 [N·s/m]: stage 1's damping
  std::array<int, 6> wall_contacts{};  // at the start
};

Plan3 make_plan(const SceneConfig& c, const AlgorithmSpec& p, const SphereWorld& w, int max_types) {
  Plan3 plan;
  const std::vector<double> radii(w.radius().begin(), w.radius().end());
  deck::set_plan_classes(plan, radii, max_types);
  plan.density = c.material.density * p.mass_scaling;
  plan.r_min = w.min_radius();
  plan.r_max = w.max_radius();
  double m_sum = 0.0;
  for (double r : radii) m_sum += sphere_mass(plan.density, r);
  plan.m_mean = m_sum / plan.n;
  const double kn = c.material.particle.kn, kt = c.material.particle.kt;
  // Δt_crit of the lightest sphere, as integration_for (triaxial.cpp).
  plan.dt_crit = critical_time_step(sphere_mass(plan.density, plan.r_min), kn);
  // The engines' fix viscous is explicit: α·f for Nstep/f steps (export.hpp);
  // the servo's mass is the heaviest sphere's (as scene/triaxial.cpp).
  deck::set_plan_timing(plan, p, c.material, sphere_mass(plan.density, plan.r_max));
  for (int a = 0; a < 3; ++a) {
    plan.lo[a] = w.wall(static_cast<SphereWallSide>(2 * a)).position;
    plan.hi[a] = w.wall(static_cast<SphereWallSide>(2 * a + 1)).position;
  }
  plan.top_speed = c.test.vertical_strain * (plan.hi[2] - plan.lo[2]) /
                   (static_cast<double>(plan.steps) * plan.dt);
  // D_t = ζ_t·2·sqrt(kn·m) ∝ r^(3/2), D_r = ζ_r·2·sqrt(kt·r²·I) ∝ r^(7/2): each
  // class gets the value of its mid radius; the error bound is that of D_t.
  for (int k = 0; k < plan.types; ++k) {
    const double r = 0.5 * (plan.r_lo[k] + plan.r_hi[k]);
    const double m = sphere_mass(plan.density, r);
    plan.class_mass.push_back(m);
    plan.gamma_critical.push_back(critical_damping_translation(kn, m));
    plan.gamma_t.push_back(p.damping_ratio_translation * plan.gamma_critical.back());
    plan.gamma_r.push_back(p.damping_ratio_rotation *
                           critical_damping_rotation(kt, r, sphere_inertia(m, r)));
    const double lo = std::pow(plan.r_lo[k] / r, 1.5), hi = std::pow(plan.r_hi[k] / r, 1.5);
    plan.class_error = std::max({plan.class_error, 1.0 - lo, hi - 1.0});
  }
  for (int s = 0; s < 6; ++s)
    plan.wall_contacts[s] = w.wall(static_cast<SphereWallSide>(s)).contacts;
  return plan;
}

/// How the decks' comments name the servo's R (demcal's servo_resistance):
/// "kn_wall" without contact damping (R = kn_wall: the decks read as before
/// the wall dashpots), "R" with them (a comment then defines it).
std::string resist_name(const Plan3& plan) { return plan.wall_dashpot > 0.0 ? "R" : "kn_wall"; }

ExportResult result_of(const Plan3& plan) { return deck::plan_result(plan); }

std::string mapping_header(const SceneConfig& c, const AlgorithmSpec& p, const Plan3& plan,
                           const Export3dOptions& o, const std::string& code) {
  std::ostringstream s;
  const auto& m = c.material;
  const double h0 = plan.hi[2] - plan.lo[2];
  s << deck::header_opening(code, "3D triaxial test",
                            "scene " + c.name + "; " + std::to_string(plan.n) + " spheres (" +
                                deck_files(o.deck_name).data + ")",
                            o, p.dt_ratio, plan.step_factor, plan.dt_crit, plan.dt)
    << "#     dt_crit = 2 sqrt(m_min/kn) of the smallest sphere (r = " << num(plan.r_min)
    << " m, m = f_ms rho 4/3 pi r^3)\n"
    << deck::header_step_factor(code, plan.step_factor, p.damping_ratio_translation)
    << "#       (drag from the half-step velocity), which shrinks a damped oscillator's\n"
    << "#       stable step by f; demcal damps semi-implicitly (f = 1)\n"
    << "#   Nstep = " << p.steps << " / f = " << plan.steps
    << " loading steps (the same loading time Nstep*dt: the same rate\n"
    << "#     and strain); the top wall moves eps * H0 / (Nstep * dt) = "
    << num(c.test.vertical_strain) << " * " << num(h0) << " / (" << plan.steps << " * "
    << num(plan.dt) << ") = " << num(plan.top_speed) << " m/s\n"
    << deck::header_contact_law(m) << "\n"
    << "#   zeta_t = " << num(p.damping_ratio_translation)
    << ": D_t = zeta_t * 2 sqrt(kn m_i) per sphere -> fix viscous per radius class\n"
    << "#     (atom type): " << plan.types
    << " class(es), gamma of the class's mid radius, largest error against the\n"
    << "#     per-sphere value " << fmt3(100 * plan.class_error) << " %\n"
    << "#   zeta_r = " << num(p.damping_ratio_rotation)
    << ": D_r = zeta_r * 2 sqrt(kt r^2 I), I = 2/5 m r^2: NOT APPLIED (this release\n"
    << "#     has no rotational viscous fix); the run is demcal's with zeta_r = 0\n"
    << "#   mass scaling f_ms = " << num(p.mass_scaling)
    << " -> density f_ms*rho = " << num(plan.density) << " kg/m^3 in the data file\n"
    << deck::header_wall_law(m) << "; bottom (z min) fixed, top (z max) down\n"
    << "#     at constant speed, the four lateral walls "
    << (o.lateral_servo ? "servo-controlled to sigma3 = " + num(c.test.lateral_stress) +
                              " Pa (gain " + num(c.test.servo_gain) + ")"
                        : "held fixed (no servo)")
    << "\n"
    << "#   stresses: tension positive in b and s; wall pressures compressive positive\n"
    << (o.consolidate_in_deck
            ? "# The particle file holds the prototype as generated (walls at its box): stage 1\n"
              "# below consolidates it to isotropic sigma3 (demcal's consolidation), then the\n"
              "# run loads it from there.\n"
            : "# The particle file holds demcal's consolidated state (walls at its box); the\n"
              "# run starts loading from it. Not carried over: the tangential contact forces\n"
              "# (springs start at zero here), the velocities (zero).\n")
    << "# ===========================================================================\n";
  return s.str();
}

// ---------------------------------------------------------------------------
// LAMMPS (29 Sep 2021)

/// The particle file of either engine: rows "id type diameter density x y
/// z" (LAMMPS atom_style sphere, LIGGGHTS granular: m = density·(4/3)πr³);
/// `ntypes` the atom types (LIGGGHTS adds the walls'), `atoms` the section.
std::string data_file(const std::string& code, const SceneConfig& c, const Plan3& plan,
                      const SphereWorld& w, int ntypes, const std::string& atoms) {
  std::ostringstream d;
  d << code << " data file written by demcal " << DEMCAL_VERSION << " (scene " << c.name
    << ", 3D)\n\n"
    << plan.n << " atoms\n"
    << ntypes << " atom types\n\n";
  // Room around the walls: the top moves in, the lateral walls breathe.
  for (int a = 0; a < 3; ++a) {
    const double pad = 0.5 * (plan.hi[a] - plan.lo[a]) + 4.0 * plan.r_max;
    d << exact(plan.lo[a] - pad) << " " << exact(plan.hi[a] + pad) << " " << kAxis[a] << "lo "
      << kAxis[a] << "hi\n";
  }
  d << "\n" << atoms << "\n\n";
  char line[200];
  for (int i = 0; i < plan.n; ++i) {
    std::snprintf(line, sizeof line, "%d %d %.17g %.17g %.17g %.17g %.17g\n", i + 1, plan.type[i],
                  2.0 * w.radius()[i], plan.density, w.x()[i], w.y()[i], w.z()[i]);
    d << line;
  }
  return d.str();
}

/// Sum over the six walls of f_W[a] (times f_W[b] when b > 0).
std::string wall_sum(int a, int b) {
  return deck::lammps_wall_sum({"wxmin", "wxmax", "wymin", "wymax", "wzmin", "wzmax"}, a, b);
}

// The walls' geometry: wall k's position along its axis (the servo's
// running mean f_servo[k] times the step: its displacement), and the box's
// lengths and height as fix geom stores them once per step (fix geom, a
// double each: no text round trip, so that `f_geom[1]` is the double that the
// parenthesized formula of Lx_now gives inline).
std::string wall_pos(int sd) {
  return std::string("(${") + kWall[sd] + "0}+f_servo[" + std::to_string(sd + 1) + "]*step)";
}
const char* const kHeight = "${H0}-${vtop}*step*dt";
const char* const kLx = "f_geom[1]";
const char* const kLy = "f_geom[2]";
const char* const kH = "f_geom[3]";
// The areas as products of the stored lengths, in the order the inline
// formulas multiplied them: sigma3*Ly*H is (sigma3*Ly)*H either way.
std::string area_x() { return std::string(kLy) + "*" + kH; }
std::string area_y() { return std::string(kLx) + "*" + kH; }
std::string area_z() { return std::string(kLx) + "*" + kLy; }
// The four lateral walls' unclamped servo moves toward the sample, one
// vector-style formula (elements xmin xmax ymin ymax): gain_kn*(sigma3*A -
// F)/max(1, n) (gain_kn = gain*(dt/servo_dt)/R, R = kn_wall without contact
// damping: lammps_loading_derived) from each wall's area
// (fix servo_len: the box's length across the wall, times H), contacts
// (c_csn) and force on the spheres along +axis (c_csf), the max walls'
// elements with the opposite sign (f_servo_sign), so that the clamp of each
// element is the wall's move along +axis (deck::lammps_servo_raw_folded,
// lammps_servo_clamp, as in 2D). `carry` (contact damping): plus ${carry}
// times each wall's last move along +axis (fix servo_prev; a max wall's
// element -(law + carry*u) = (-law) + carry*(-u) bit for bit), demcal's
// servo_velocity.
std::string servo_raw_vector(bool carry) {
  return deck::lammps_servo_raw_folded("f_servo_sign*${sigma3}*f_servo_len*" + std::string(kH),
                                       "-c_csf", deck::lammps_count_max_one("c_csn")) +
         (carry ? deck::lammps_servo_carried("f_servo_prev") : "");
}

// Header: the mapping and what this LAMMPS cannot do as demcal does.
void lammps_3d_limitations(std::ostream& s, const SceneConfig& c, const AlgorithmSpec& p,
                           const Plan3& plan, const Export3dOptions& o, ExportResult& out) {
  s << mapping_header(c, p, plan, o, "LAMMPS");
  s << "#\n# What this LAMMPS cannot do as demcal does, and what the deck does instead:\n"
    << "#  - rotational damping: no rotational viscous fix in 29 Sep 2021 (zeta_r = 0\n"
    << "#    here); releases from 2022 on have fix viscous/sphere: the line is below,\n"
    << "#    commented out.\n"
    << "#  - damping explicit (fix viscous) vs demcal's semi-implicit: the factor f.\n"
    << "#  - servo walls are not native: each lateral wall is a wall/gran/region plane\n"
    << "#    whose displacement is the running sum of demcal's per-step servo move\n"
    << "#    gain*(sigma3*A - F)/(" << resist_name(plan) << "*max(1, n))"
    << (plan.servo_carry > 0.0 ? " + carry*u,\n#    capped at " : ", capped at ")
    << deck::servo_cap_text() << " (A the\n"
    << "#    wall's current area, F its force, n its contacts), kept by fix ave/time\n"
    << "#    (running mean times the step); one run command only (no restart split).\n";
  if (plan.wall_dashpot > 0.0)
    s << "#    R = kn_wall + c_wall/servo_dt: demcal's wall contacts resist a move\n"
      << "#    within its step by their dashpots too (contact damping; c_wall and\n"
      << "#    resist in the derived block); and a moving wall has their force in\n"
      << "#    its F, so a move carries carry = (R - kn_wall)/R of the wall's last, u.\n";
  s << "#  - LAMMPS takes a contact's torque at the lever arm r_i (demcal r_i - delta/2):\n"
    << "#    the antisymmetric part of s carries a small static term.\n"
    << "#  - a sphere's velocities and the tangential springs start at zero.\n"
    << "#  - each wall acts on the band of spheres near it (see the walls): fix halt\n"
    << "#    stops the run should a sphere outside it reach the wall.\n"
    << "# Outputs: ${series} (columns below) and, at the end, peak_axial_stress and\n"
    << "# peak_ratio over every step (print); ${series} ends with the axial peak\n"
    << "# and its strain (# peak_stress_zz, # peak_strain_zz: demcal's keys).\n";
  if (p.damping_ratio_rotation > 0.0)
    out.notes.push_back(deck::lammps_rotational_damping_note(p.damping_ratio_rotation));
  if (plan.types > 1)
    out.notes.push_back(deck::lammps_class_damping_note(plan.types, plan.class_error, "sphere"));
}

// The parameters block a user edits, and what is derived from it.
void lammps_3d_parameters(std::ostream& s, const SceneConfig& c, const Plan3& plan,
                          const Export3dOptions& o) {
  const auto& m = c.material;
  s << "\n# --- parameters (edit here) -------------------------------------------------\n"
    << "# Everything below is derived from this block: editing dt or nstep keeps the\n"
    << "# strain, the servo cap and the monitoring points right.\n"
    << "variable dt        equal " << exact(plan.dt) << "      # s\n"
    << deck::lammps_servo_dt(plan.demcal_dt, exact) << "variable nstep     equal " << plan.steps
    << "      # loading steps\n"
    << "variable strain    equal " << exact(c.test.vertical_strain)
    << "      # axial (z) strain over nstep, compression\n"
    << "variable monitor_points equal " << c.test.monitor_points << "      # rows of ${series}\n"
    << deck::lammps_material_variables(m, exact) << "variable sigma3    equal "
    << exact(c.test.lateral_stress) << "      # Pa\n"
    << "variable gain      equal " << exact(o.lateral_servo ? c.test.servo_gain : 0.0)
    << "      # servo gain (0: lateral walls fixed)\n"
    << "variable r_min     equal " << exact(plan.r_min) << "      # m\n"
    << "variable r_max     equal " << exact(plan.r_max) << "      # m, for the walls' bands\n";
  for (int sd = 0; sd < 6; ++sd)
    s << "variable " << kWall[sd] << "0    equal "
      << exact(sd % 2 == 0 ? plan.lo[sd / 2] : plan.hi[sd / 2])
      << (o.consolidate_in_deck ? "      # wall at the start of stage 1, m\n"
                                : "      # wall at the start, m\n");
  s << deck::series_variable(o)
    << "variable run_steps index ${nstep}      # -var run_steps 300 for a check\n";
  if (o.consolidate_in_deck) s << deck::lammps_consolidation_parameters(c.test);
}

// What is derived from the parameters block (and the start walls).
void lammps_3d_derived(std::ostream& s, const Plan3& plan) {
  s << "\n# --- derived (do not edit) ---------------------------------------------------\n"
    << "variable H0        equal $(v_zmax0-v_zmin0)\n"
    << "variable Wx0       equal $(v_xmax0-v_xmin0)\n"
    << "variable Wy0       equal $(v_ymax0-v_ymin0)\n"
    << deck::lammps_loading_derived(plan.wall_dashpot, exact, "sphere", plan.servo_carry)
    << "variable peak_every equal $(ceil(v_nstep/1000000))      # fix vector length <= 1e6\n"
    << deck::lammps_band("band_v", "v_strain*v_H0", "m, see the walls")
    << deck::lammps_band("band_x", "2*v_strain*v_Wx0")
    << deck::lammps_band("band_y", "2*v_strain*v_Wy0");
}

// Units, box, data file, contact law.
void lammps_3d_system(std::ostream& s, const SceneConfig& c, const Plan3& plan,
                      const Export3dOptions& o, ExportResult& out) {
  const auto& m = c.material;
  const double gamma_n = deck::contact_gamma_n(m, plan.m_mean);
  if (gamma_n > 0.0)
    out.notes.push_back(
        "contact damping mapped at the mean sphere mass; the walls carry no dashpots here "
        "(demcal's do), so a servo move meets kn_wall alone while the servo is demcal's: it "
        "divides by R = kn_wall + c/dt and carries (R - kn_wall)/R of the wall's last move "
        "(measured on hex_5x5, zeta_c 0.25: servo criterion 5e-4 and peak 5e-5 relative from "
        "demcal's; fcc_4x4x4, zeta_c 0.3: both equal to 5 digits; engines.md sections 20, 24)");
  s << deck::lammps_system_head(3, "f f f") << "newton          off\n"
    << "read_data       " << deck_files(o.deck_name).data << "\n"
    << "# sphere masses f_ms*rho*4/3*pi*r^3 (density column), inertia 2/5 m r^2\n"
    << deck::lammps_contact_law(gamma_n, plan.r_min, "");
}

// ---------------------------------------------------------------------------
// Stage 1: demcal's consolidation (triaxial.cpp consolidate_triaxial, the
// shared loop of scene/protocol_steps.hpp) in LAMMPS

/// Stage 1's six walls, in compute cons_wn's (cons_wf's) order (kWall).
std::vector<deck::ConsolidationWall> consolidation_walls() {
  const char* area[3] = {"v_cons_Ax", "v_cons_Ay", "v_cons_Az"};
  std::vector<deck::ConsolidationWall> walls;
  for (int sd = 0; sd < 6; ++sd) {
    const bool min = sd % 2 == 0;
    walls.push_back({kWall[sd], kAxis[sd / 2], min, sd + 1,
                     std::string(min ? "" : "-") + "c_cons_wf[" + std::to_string(sd + 1) + "]/" +
                         area[sd / 2]});
  }
  return walls;
}

/// The six walls servoed at sigma3 with demcal's per-step law (triaxial.cpp
/// servo_velocity: gain*(sigma3*A - F)/(R*max(1, n)), R = kn_wall + c/dt
/// (servo_resistance), cap servo_move_cap, A the wall's current area), light
/// damping, the criterion, the runs and the start walls of the loading.
void lammps_3d_consolidation(std::ostream& s, const SceneConfig& c, const Plan3& plan) {
  const double zeta = kConsolidationDampingRatio;
  // demcal's consolidation step: consolidation_alpha (0.2, shrunk for the
  // contact dashpots) times the sphere kernel's dt_crit, times the explicit
  // damper's factor.
  const auto& m = c.material;
  const double alpha = consolidation_alpha(m.contact_damping_ratio, 3, plan.r_min, plan.r_max);
  const double dt_light = deck::consolidation_dt(alpha, zeta, plan.dt_crit);
  const double dt_damped = deck::consolidation_dt(alpha, 1.0, plan.dt_crit);
  std::vector<double> light, critical;
  for (double g : plan.gamma_critical) {
    light.push_back(zeta * g);
    critical.push_back(g);
  }
  const std::vector<deck::ConsolidationWall> walls = consolidation_walls();
  s << "\n# --- stage 1: consolidation to isotropic sigma3 -------------------------------\n"
    << "# demcal's consolidation (demcal export --consolidate-in deck), run here so\n"
    << "# that it scales under MPI: all six walls servoed with the loading's law (each\n"
    << "# wall: move = gain*(sigma3*A - F)/(" << resist_name(plan) << "*max(1, n)) per step, ";
  if (plan.wall_dashpot > 0.0)
    s << "R = kn_wall +\n"
      << "# c/dt, c the wall dashpots' (the number in cons_rawv), plus (R - kn_wall)/R\n"
      << "# of its last move (demcal's consolidation servo), A its current\n";
  else
    s << "A its current\n";
  s << "# area, cap " << deck::servo_cap_text() << "), global damping zeta " << num(zeta)
    << " on translation (demcal also\n"
    << "# damps rotation; this LAMMPS cannot), particle friction 0 until static, then\n"
    << deck::lammps_consolidation_comment(zeta, "sphere", "xmin0 .. zmax0")
    << "if              \"${consolidate} == 0\" then \"jump SELF loading\"\n"
    << deck::lammps_consolidation_start(alpha, dt_light, c.test.consolidation_max_steps);
  for (int sd = 0; sd < 6; ++sd)
    s << "variable        cons_d" << kWall[sd] << " equal f_cons_servo[" << sd + 1
      << "]*(step-${cons_s0})\n";
  for (int sd = 0; sd < 6; ++sd) {
    const int a = sd / 2;
    std::string point = "0 0 0", normal = "0 0 0", move = "NULL NULL NULL";
    point.replace(2 * a, 1, std::string("${") + kWall[sd] + "0}");
    normal.replace(2 * a, 1, sd % 2 == 0 ? " 1" : "-1");
    move.replace(5 * a, 4, std::string("v_cons_d") + kWall[sd]);
    s << "region          cons_r" << kWall[sd] << " plane " << point << " " << normal
      << " side in move " << move << " units box\n";
  }
  for (int sd = 0; sd < 6; ++sd)
    s << "fix             cons_w" << kWall[sd]
      << " all wall/gran/region hooke/history ${kn_wall} ${kt_wall} 0 0 ${mu_wall} 0 region cons_r"
      << kWall[sd] << " contacts\n";
  s << "fix             cons_fcon all store/force\n"
    << deck::lammps_consolidation_viscous(light) << "\n"
    << deck::lammps_consolidation_reductions(walls);
  for (int sd = 0; sd < 6; ++sd)
    s << "variable        cons_" << kWall[sd] << " equal v_" << kWall[sd] << "0+v_cons_d"
      << kWall[sd] << "\n";
  for (int a = 0; a < 3; ++a)
    s << "variable        cons_L" << kAxis[a] << " equal v_cons_" << kWall[2 * a + 1] << "-v_cons_"
      << kWall[2 * a] << "\n";
  for (int a = 0; a < 3; ++a)
    s << "variable        cons_A" << kAxis[a] << " equal v_cons_L" << kAxis[(a + 1) % 3]
      << "*v_cons_L" << kAxis[(a + 2) % 3] << "\n";
  // each wall's move gain*(sigma3*A - F)/(R*max(1, n)), A its axis's
  // current area, in one vector formula (deck::lammps_consolidation_servo)
  // (R = kn_wall + c/dt with the wall dashpots: demcal's servo_resistance)
  const std::string resist =
      plan.wall_dashpot > 0.0 ? "(${kn_wall}+" + exact(plan.wall_dashpot) + "/dt)" : "${kn_wall}";
  // demcal's consolidation servo carries (R - kn_wall)/R of the last move,
  // R at this phase's step (0 without contact damping)
  const double carry_light = deck::servo_carry_at(m, plan.m_max, dt_light);
  const double carry_damped = deck::servo_carry_at(m, plan.m_max, dt_damped);
  s << deck::lammps_consolidation_servo(walls, {"cons_Ax", "cons_Ay", "cons_Az"}, "", resist,
                                        carry_light)
    << deck::lammps_consolidation_criterion(3, walls, {"x", "y", "z"})
    << deck::lammps_consolidation_runs(deck::contact_gamma_n(c.material, plan.m_mean), dt_damped,
                                       deck::lammps_consolidation_viscous(critical), carry_damped)
    << "# the loading starts from here: walls, step 0, spheres at rest. Each wall\n"
    << "# where its contacts put it (F = kn_wall * sum of overlaps, exact for these\n"
    << "# undamped walls), so the loading starts from the forces of the static state.\n";
  for (int sd = 0; sd < 6; ++sd)
    s << "variable        " << kWall[sd] << "0 delete\n"
      << "variable        " << kWall[sd] << "0 equal "
      << deck::lammps_consolidated_wall(walls[sd], sd) << "\n";
  s << deck::lammps_consolidation_end(walls, carry_light > 0.0
                                                 ? std::vector<std::string>{"cons_prev"}
                                                 : std::vector<std::string>{});
}

// The six walls, the contact-force store and the damping.
void lammps_3d_walls(std::ostream& s, const AlgorithmSpec& p, const Plan3& plan) {
  s << "# --- walls -------------------------------------------------------------------\n"
    << "# bottom: fixed plane; top: plane moving down at vtop; lateral: planes moved\n"
    << "# by the servo. Order: the walls, then the damping (the series recovers the\n"
    << "# contact force from the total force at monitoring steps). Wall contact\n"
    << "# arrays: [1] contact, [2-4] force on the sphere, [5-7] contact point.\n"
    << "variable        dzmax equal -${vtop}*step*dt\n";
  for (int sd = 0; sd < 4; ++sd)
    s << "variable        d" << kWall[sd] << " equal f_servo[" << sd + 1 << "]*step\n";
  s << "region          rxmin plane ${xmin0} 0 0  1 0 0 side in move v_dxmin NULL NULL units box\n"
    << "region          rxmax plane ${xmax0} 0 0 -1 0 0 side in move v_dxmax NULL NULL units box\n"
    << "region          rymin plane 0 ${ymin0} 0 0  1 0 side in move NULL v_dymin NULL units box\n"
    << "region          rymax plane 0 ${ymax0} 0 0 -1 0 side in move NULL v_dymax NULL units box\n"
    << "region          rzmax plane 0 0 ${zmax0} 0 0 -1 side in move NULL NULL v_dzmax units box\n"
    << "# Each wall acts on the spheres that can reach it (a wall fix loops over its\n"
    << "# group every step): those within band_v of the top or the bottom, band_x\n"
    << "# (band_y) of an x (y) wall at the start: the motion the test allows plus six\n"
    << "# radii. fix halt stops the run with an error should a sphere outside a band\n"
    << "# ever touch that wall (then widen the bands).\n";
  for (int sd = 0; sd < 6; ++sd) {
    // block bounds xlo xhi ylo yhi zlo zhi: the band along the wall's axis
    std::string bounds[6] = {"INF", "INF", "INF", "INF", "INF", "INF"};
    const int a = sd / 2;
    const std::string band = a == 2 ? "v_band_v" : std::string("v_band_") + kAxis[a];
    bounds[sd % 2 == 0 ? 2 * a + 1 : 2 * a] =
        std::string("$(v_") + kWall[sd] + (sd % 2 == 0 ? "0+" : "0-") + band + ")";
    s << "region          band" << kWall[sd] << " block";
    for (const std::string& b : bounds) s << " " << b;
    s << " units box\n";
  }
  for (int sd = 0; sd < 6; ++sd)
    s << "group           g" << kWall[sd] << " region band" << kWall[sd] << "\n";
  s << "group           gxy union gxmin gxmax gymin gymax\n"
    << "group           gz union gzmin gzmax\n";
  for (int sd = 0; sd < 6; ++sd)
    s << "group           n" << kWall[sd] << " subtract all g" << kWall[sd] << "\n";
  s << "fix             wzmin gzmin wall/gran hooke/history ${kn_wall} ${kt_wall} 0 0 ${mu_wall} "
       "0 zplane ${zmin0} NULL contacts\n";
  for (int sd : {5, 0, 1, 2, 3})
    s << "fix             w" << kWall[sd] << " g" << kWall[sd]
      << " wall/gran/region hooke/history ${kn_wall} ${kt_wall} 0 0 ${mu_wall} 0 region r"
      << kWall[sd] << " contacts\n";
  s << "\n";

  s << deck::lammps_translational_damping(p.damping_ratio_translation, plan.gamma_t, exact);
  s << "# LAMMPS >= 2022 only (absent in 29 Sep 2021): rotational damping D_r per class,\n"
    << "# N*m*s (zeta_r = " << num(p.damping_ratio_rotation) << ")\n";
  if (p.damping_ratio_rotation > 0.0) {
    s << "#fix            dampr all viscous/sphere " << exact(plan.gamma_r[0]);
    for (int k = 1; k < plan.types; ++k)
      s << " scale " << k + 1 << " " << exact(plan.gamma_r[k] / plan.gamma_r[0]);
    s << "\n\n";
  } else {
    s << "#   (zeta_r = 0: nothing to apply)\n\n";
  }
}

// The servo's input, wall positions and pressures, b and sigma reductions.
void lammps_3d_measures(std::ostream& s, const AlgorithmSpec& p, const Plan3& plan) {
  // Measures: wall forces for the servo and the pressures, one reduction per
  // axis; the stored lengths; the bands' clearance checks.
  s << "# --- measures ----------------------------------------------------------------\n"
    << "# the servo's and the peaks' input, reduced over the walls' bands (a\n"
    << "# reduction loops over every sphere for each of its columns, and adds those\n"
    << "# of its group): the four lateral walls' contacts (csn) and forces along\n"
    << "# their axes (csf), xmin xmax ymin ymax (a sphere outside a wall's band\n"
    << "# adds its zero); the z walls' forces (three global sums per step under\n"
    << "# MPI)\n"
    << "compute         csn gxy reduce sum f_wxmin[1] f_wxmax[1] f_wymin[1] f_wymax[1]\n"
    << "compute         csf gxy reduce sum f_wxmin[2] f_wxmax[2] f_wymin[3] f_wymax[3]\n"
    << "compute         csz gz reduce sum f_wzmin[4] f_wzmax[4]\n"
    << "# the box's lengths and height, stored once per step by fix geom (a double\n"
    << "# each; defined before every fix that reads them, so that they see the walls\n"
    << "# where the forces were computed)\n"
    << "variable        Lx_now equal " << wall_pos(1) << "-" << wall_pos(0) << "\n"
    << "variable        Ly_now equal " << wall_pos(3) << "-" << wall_pos(2) << "\n"
    << "variable        H_now equal " << kHeight << "\n"
    << "fix             geom all ave/time 1 1 1 v_Lx_now v_Ly_now v_H_now\n";
  // Wall positions and pressures (flat: positions from f_servo directly).
  for (int sd = 0; sd < 4; ++sd)
    s << "variable        wall_" << kWall[sd] << " equal " << wall_pos(sd) << "\n";
  s << "variable        wall_zmin equal ${zmin0}\n"
    << "variable        wall_zmax equal ${zmax0}-${vtop}*step*dt\n"
    << "variable        H equal " << kH << "\n"
    << "variable        Ax equal " << area_x() << "\n"
    << "variable        Ay equal " << area_y() << "\n"
    << "variable        Az equal " << area_z() << "\n"
    << "variable        p_xmin equal c_csf[1]/v_Ax\n"
    << "variable        p_xmax equal -c_csf[2]/v_Ax\n"
    << "variable        p_ymin equal c_csf[3]/v_Ay\n"
    << "variable        p_ymax equal -c_csf[4]/v_Ay\n"
    << "variable        p_zmin equal c_csz[1]/v_Az\n"
    << "variable        p_zmax equal -c_csz[2]/v_Az\n"
    << "variable        axial equal (v_p_zmin+v_p_zmax)/2\n"
    << "variable        lateral equal (v_p_xmin+v_p_xmax+v_p_ymin+v_p_ymax)/4\n"
    << "variable        ratio equal v_axial/v_lateral\n"
    << "# clearance of the spheres outside each band from its wall (> 0), checked at\n"
    << "# every monitoring step\n"
    << "compute         rad all property/atom radius\n";
  for (int sd = 0; sd < 6; ++sd) {
    const char ax = kAxis[sd / 2];
    const std::string w = std::string("v_wall_") + kWall[sd];
    s << "variable        gap_" << kWall[sd] << " atom "
      << (sd % 2 == 0 ? std::string(1, ax) + "-c_rad-" + w : w + "-" + ax + "-c_rad") << "\n";
  }
  for (int sd = 0; sd < 6; ++sd)
    s << "compute         clear_" << kWall[sd] << " n" << kWall[sd] << " reduce min v_gap_"
      << kWall[sd] << "\n"
      << "variable        clear_" << kWall[sd] << " equal c_clear_" << kWall[sd] << "\n"
      << "fix             halt_" << kWall[sd] << " all halt ${monitor_every} v_clear_" << kWall[sd]
      << " < 0.0 error hard\n";

  // The monitoring series: b and σ over the walls' contact arrays.
  s << "# b_ij = (1/V) sum_walls (x_i - c_i) f_j (contact point x, force f on the\n"
    << "# sphere, c the box centre); s_ij = b_ij - (1/V) sum_p (x_i - c_i) F_j, F the\n"
    << "# contact force (V (b - sigma) = sum_p x_p (x) F_p)\n"
    // the loading runs from step 0 (read_data, or reset_timestep after stage 1)
    << deck::lammps_contact_force_atom(3, p.damping_ratio_translation, plan.gamma_t, exact, "0");
  std::string reduce;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      s << "variable        bw" << kAxis[i] << kAxis[j] << " atom " << wall_sum(5 + i, 2 + j)
        << "\n"
        << "variable        mp" << kAxis[i] << kAxis[j] << " atom " << kAxis[i] << "*v_fc" << j + 1
        << "_a\n";
      reduce += std::string(" v_bw") + kAxis[i] + kAxis[j] + " v_mp" + kAxis[i] + kAxis[j];
    }
  for (int j = 0; j < 3; ++j)
    s << "variable        fw" << kAxis[j] << " atom " << wall_sum(2 + j, 0) << "\n";
  s << "compute         cn all contact/atom\n"
    << "compute         meas all reduce sum" << reduce
    << " v_fwx v_fwy v_fwz v_fc1_a v_fc2_a v_fc3_a c_cn\n"
    << "compute         ket all ke\n"
    << "compute         ker all erotate/sphere\n"
    << "variable        cx equal (v_wall_xmin+v_wall_xmax)/2\n"
    << "variable        cy equal (v_wall_ymin+v_wall_ymax)/2\n"
    << "variable        cz equal (v_wall_zmin+v_wall_zmax)/2\n"
    << "variable        V equal v_Ax*(v_wall_xmax-v_wall_xmin)\n";
}

// b and sigma per component, the monitoring series and the peaks.
void lammps_3d_series(std::ostream& s, const SceneConfig& c, const AlgorithmSpec& p,
                      const Plan3& plan) {
  // c_meas layout: [1..18] bw/mp pairs, [19..21] fw, [22..24] fc, [25] cn.
  s << b_and_sigma_3d("variable        ");
  std::string row = series_row_head_3d("strain_zz");
  s << "variable        strain_zz equal (v_H-v_H0)/v_H0\n"
    << "variable        ke equal c_ket+c_ker\n"
    << "variable        ke_rot equal c_ker\n"
    << "variable        lat_err equal (v_lateral-v_sigma3)/v_sigma3\n";
  for (int sd = 0; sd < 4; ++sd)
    s << "variable        err_" << kWall[sd] << " equal (v_p_" << kWall[sd]
      << "-v_sigma3)/v_sigma3\n";
  s << "variable        contacts equal c_meas[25]/2\n"
    << "variable        stepn equal step\n";
  row += series_row_tail_3d("");
  const std::string columns = series_columns_3d();

  s << "\n# --- monitoring series -------------------------------------------------------\n"
    << "# ${series}: every monitor_every steps and at the start; tension positive, SI,\n"
    << "# origin at the box centre. Columns:\n"
    << "#   step, strain_zz (H - H0)/H0\n"
    << "#   b_xx .. b_zz   boundary stress, row by row, from the six walls' contact arrays\n"
    << "#   s_xx .. s_zz   homogenized stress (V (b - sigma) = sum_p x_p (x) F_p)\n"
    << "#   kinetic_energy (translation + rotation, I = 2/5 m r^2), kinetic_energy_rotation [J]\n"
    << "#   lateral_stress_error  (mean of the four lateral pressures - sigma3)/sigma3\n"
    << "#   servo_error_xmin .. ymax  (p - sigma3)/sigma3 of each lateral wall\n"
    << "#   wall_xmin .. wall_zmax    wall positions [m]\n"
    << "#   p_xmin .. p_zmax          compressive wall pressures [Pa]\n"
    << "#   contacts                  sphere-sphere contacts\n"
    << "# the columns up to wall_zmax are those of demcal's series.csv (run_output.hpp)\n"
    << "# where LAMMPS measures them. The series and the peaks are fixes defined\n"
    << "# before the servo's fix ave/time, so that at each step they see the walls\n"
    << "# where the forces were computed (the servo's running mean updates after).\n"
    << deck::lammps_series_header("LAMMPS 3D deck", c.name, plan.n, p.damping_ratio_translation,
                                  plan.dt_crit, p.mass_scaling)
    << "fix             series all print ${monitor_every} \"" << row
    << "\" append ${series} screen no title \"" << columns << "\"\n"
    << "# the peaks over every peak_every steps: axial pressure and sigma1/sigma3\n"
    << "# (and the strain, for the axial peak's)\n"
    << "fix             peaks all vector ${peak_every} v_axial v_ratio v_strain_zz\n\n";
}

// The axial peak appended to the series, in demcal's keys (SeriesMetadata,
// the tracked peak: `demcal score` takes it as it takes demcal's own): the
// most compressive sigma_zz = -max(axial pressure), and the strain of its
// first step (the strain falls at every step): the largest strain among
// the rows at the peak (the others masked to -2).
std::string peak_metadata() {
  SeriesMetadata peak;
  peak.peak_stress_zz = "$(-max(f_peaks[1]))";
  peak.peak_strain_zz = "$(max(v_peak_strain))";
  std::string out =
      "variable        peak_strain vector (f_peaks[1]==max(f_peaks[1]))*f_peaks[3]+"
      "((f_peaks[1]==max(f_peaks[1]))-1)*2\n";
  for (const std::string& line : series_result_lines(peak))
    out += "print           \"" + line + "\" append ${series} screen no\n";
  return out;
}

// The servo's per-step moves, then the run and the peaks printed.
void lammps_3d_servo_and_run(std::ostream& s, const Plan3& plan) {
  s << "# --- servo -------------------------------------------------------------------\n"
    << "# demcal's servo, one move per step and wall toward the sample when p < sigma3:\n"
    << "#   move = gain*(sigma3*A - F)/(" << resist_name(plan) << "*max(1, n))"
    << (plan.servo_carry > 0.0 ? " + carry*u" : "") << ", clamped to +-cap,\n";
  if (plan.servo_carry > 0.0)
    s << "# R = kn_wall + c_wall/servo_dt (the wall dashpots too: resist, derived block),\n"
      << "# u the wall's last move (carry: derived block; fix servo_prev, after fix\n"
      << "# servo: at a step's end it still holds the step before's moves, 0 at the\n"
      << "# first step: the walls start the loading at rest),\n";
  else if (plan.wall_dashpot > 0.0)
    s << "# R = kn_wall + c_wall/servo_dt (the wall dashpots too: resist, derived block),\n";
  s << "# A = the wall's current area, F its force, n its contacts (compute csn, csf),\n"
    << "# per demcal step (servo_dt), so per step of dt that times dt/servo_dt:\n"
    << "# gain_kn*(sigma3*A - F)/max(1, n)" << (plan.servo_carry > 0.0 ? " + carry*u" : "")
    << " within +-cap_step (derived"
    << (plan.servo_carry > 0.0
            ? "\n# block; u, a move of this deck, is dt/servo_dt times demcal's already).\n"
            : " block).\n")
    << "# The four walls in one vector-style formula (elements xmin xmax ymin ymax;\n"
    << "# the max walls' with the opposite sign, so that each clamped element is\n"
    << "# the wall's move along +axis), parsed once per step for all four, with the\n"
    << "# numbers substituted now. The clamp reads the unclamped moves as doubles\n"
    << "# (a vector variable is evaluated once per step, then kept); the signs\n"
    << "# (internal variables, read without parsing) and the box's length across\n"
    << "# each wall (Ly for the x walls, Lx for the y walls: fix geom's doubles)\n"
    << "# come from fixes. This release has no min/max of two numbers: max(1, n) =\n"
    << "# n+!n for a contact count n, clamp(x) = (abs(x+c)-abs(x-c))/2.\n"
    << "# f_servo[k]: the running mean of the moves along +axis, times the step =\n"
    << "# the wall's displacement.\n"
    << "variable        one internal 1\n"
    << "variable        mone internal -1\n"
    << "fix             servo_sign all ave/time 1 1 1 v_one v_mone v_one v_mone\n"
    << "fix             servo_len all ave/time 1 1 1 f_geom[2] f_geom[2] f_geom[1] f_geom[1]\n"
    << "variable        rawv vector " << servo_raw_vector(plan.servo_carry > 0.0) << "\n"
    << "variable        movev vector " << deck::lammps_servo_clamp("v_rawv", "${cap_step}") << "\n";
  s << "fix             servo all ave/time 1 1 1 v_movev mode vector ave running\n";
  if (plan.servo_carry > 0.0) s << deck::lammps_previous_moves("servo_prev", "movev", 4);
  s << "\n";

  s << "# --- output and run ----------------------------------------------------------\n"
    << "thermo_style    custom step time v_strain_zz v_axial v_lateral v_ratio ke\n"
    << deck::lammps_thermo_modify() << "thermo          ${monitor_every}\n"
    << "run             ${run_steps}\n"
    << "variable        peak_axial equal max(f_peaks[1])\n"
    << "variable        peak_ratio equal max(f_peaks[2])\n"
    << "print           \"peak_axial_stress = ${peak_axial}\"\n"
    << "print           \"peak_ratio = ${peak_ratio}\"\n"
    << peak_metadata();
}

std::string lammps_deck(const SceneConfig& c, const AlgorithmSpec& p, const Plan3& plan,
                        const Export3dOptions& o, ExportResult& out) {
  std::ostringstream s;
  lammps_3d_limitations(s, c, p, plan, o, out);
  lammps_3d_parameters(s, c, plan, o);
  if (o.consolidate_in_deck) {
    lammps_3d_system(s, c, plan, o, out);
    lammps_3d_consolidation(s, c, plan);
    lammps_3d_derived(s, plan);
  } else {
    lammps_3d_derived(s, plan);
    lammps_3d_system(s, c, plan, o, out);
  }
  lammps_3d_walls(s, p, plan);
  lammps_3d_measures(s, p, plan);
  lammps_3d_series(s, c, p, plan);
  lammps_3d_servo_and_run(s, plan);
  return s.str();
}

// ---------------------------------------------------------------------------
// LIGGGHTS-PUBLIC 3.8

/// A rectangle p0, p0 + u, p0 + u + v, p0 + v as two facets (normal u × v).
std::string stl_rectangle(const std::string& name, const Eigen::Vector3d& p0,
                          const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  std::ostringstream s;
  const Eigen::Vector3d n = u.cross(v).normalized();
  auto vertex = [&](const Eigen::Vector3d& q) {
    s << "      vertex " << exact(q.x()) << " " << exact(q.y()) << " " << exact(q.z()) << "\n";
  };
  s << "solid " << name << "\n";
  for (int f = 0; f < 2; ++f) {
    s << "  facet normal " << num(n.x()) << " " << num(n.y()) << " " << num(n.z())
      << "\n    outer loop\n";
    vertex(p0);
    if (f == 0) {
      vertex(p0 + u);
      vertex(p0 + u + v);
    } else {
      vertex(p0 + u + v);
      vertex(p0 + v);
    }
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid " << name << "\n";
  return s.str();
}

/// The LIGGGHTS 3D deck's monitoring series (the LAMMPS 3D deck's columns,
/// demcal.series/1) from LIGGGHTS' per-atom wall forces: the six meshes are
/// one wall fix (LIGGGHTS allows one), `store_force yes` gives each sphere's
/// total wall force. `lateral_pos[sd]`: lateral wall sd's position (a
/// formula).
std::string liggghts_3d_series(const SceneConfig& c, const AlgorithmSpec& p, const Plan3& plan,
                               const Export3dOptions& o,
                               const std::array<std::string, 4>& lateral_pos, int monitor_every) {
  const char* mesh[6] = {"mxmin", "mxmax", "mymin", "mymax", "mbottom", "mtop"};
  std::ostringstream s;
  s << "\n# --- monitoring series (demcal score FILE) -----------------------------------\n"
    << "# ${series}: at the start and every " << monitor_every
    << " steps (demcal's monitoring points), the\n"
    << "# LAMMPS 3D deck's columns, tension positive, SI, origin at the box centre:\n"
    << "#   step, strain_zz (H - H0)/H0\n"
    << "#   b_xx .. b_zz   boundary stress (1/V) sum_walls (x^c - c) (x) f^c, row by row,\n"
    << "#                  from the spheres' wall forces (store_force yes)\n"
    << "#   s_xx .. s_zz   homogenized stress (V (b - sigma) = sum_p x_p (x) F_p, F_p the\n"
    << "#                  contact force, recovered below)\n"
    << "#   kinetic_energy (translation + rotation, I = 2/5 m r^2, LIGGGHTS' and demcal's\n"
    << "#                  sphere), kinetic_energy_rotation [J]\n"
    << "#   lateral_stress_error  (mean of the four lateral pressures - sigma3)/sigma3\n"
    << "#   servo_error_xmin .. ymax  (p - sigma3)/sigma3 of each lateral wall\n"
    << "#   wall_xmin .. wall_zmax    wall positions [m]\n"
    << "#   p_xmin .. p_zmax          compressive wall pressures on the current areas [Pa]\n"
    << "#                             (the meshes' own totals; at the start, the spheres')\n"
    << "#   contacts                  sphere-sphere contacts\n"
    << "# The six walls are one fix: a sphere's wall force is the sum over the walls it\n"
    << "# touches. Each component goes to the contact of the wall normal to it, (x, y,\n"
    << "# z) with that coordinate at the wall; a component no touched wall is normal to\n"
    << "# (friction) to the sphere's first touched wall (x, y, z order). Exact for\n"
    << "# frictionless walls and for spheres touching one wall; with wall friction a\n"
    << "# sphere on an edge or a corner has its tangential wall forces placed at one\n"
    << "# of its walls: approximated.\n"
    << "# Lever arm: LIGGGHTS applies a contact's tangential force at r_i - delta/2 as\n"
    << "# demcal does (walls: demcal r_i - delta, the same without wall friction).\n"
    << deck::series_variable(o) << "variable sigma3 equal " << exact(c.test.lateral_stress) << "\n"
    << "variable nstep equal " << plan.steps << "\n"
    << "variable dt equal " << exact(plan.dt) << "\n";
  for (int sd = 0; sd < 4; ++sd)
    s << "variable wall_" << kWall[sd] << " equal " << lateral_pos[sd] << "\n";
  s << "variable wall_zmin equal " << exact(plan.lo[2]) << "\n"
    << "variable wall_zmax equal " << exact(plan.hi[2]) << "-" << exact(plan.top_speed) << "*step*"
    << exact(plan.dt) << "\n"
    << "variable Hs equal v_wall_zmax-v_wall_zmin\n"
    << "variable Ax equal (v_wall_ymax-v_wall_ymin)*v_Hs\n"
    << "variable Ay equal (v_wall_xmax-v_wall_xmin)*v_Hs\n"
    << "variable Az equal (v_wall_xmax-v_wall_xmin)*(v_wall_ymax-v_wall_ymin)\n"
    << "variable cx equal (v_wall_xmin+v_wall_xmax)/2\n"
    << "variable cy equal (v_wall_ymin+v_wall_ymax)/2\n"
    << "variable cz equal (v_wall_zmin+v_wall_zmax)/2\n"
    << "variable V equal v_Az*v_Hs\n"
    << "compute pa all property/atom radius omegax omegay omegaz\n"
    << "# the walls a sphere touches (overlap > 0), per axis: T (0/1) and the wall's\n"
    << "# coordinate P\n";
  for (int sd = 0; sd < 6; ++sd) {
    const char ax = kAxis[sd / 2];
    s << "variable t" << sd << "_a atom (" << ax << (sd % 2 == 0 ? "-" : "+") << "c_pa[1])"
      << (sd % 2 == 0 ? "<" : ">") << "v_wall_" << kWall[sd] << "\n";
  }
  for (int a = 0; a < 3; ++a)
    s << "variable T" << kAxis[a] << "_a atom v_t" << 2 * a << "_a+v_t" << 2 * a + 1 << "_a\n"
      << "variable P" << kAxis[a] << "_a atom v_t" << 2 * a << "_a*v_wall_" << kWall[2 * a]
      << "+v_t" << 2 * a + 1 << "_a*v_wall_" << kWall[2 * a + 1] << "\n";
  for (int j = 0; j < 3; ++j)
    s << "variable fw" << kAxis[j] << "_a atom f_force_walls[" << j + 1 << "]\n";
  s << "# x^c_i f_j about the origin: the contact's coordinate i is the wall's where\n"
    << "# component j goes to a wall normal to i, the sphere's otherwise\n";
  auto T = [](int a) { return std::string("v_T") + kAxis[a] + "_a"; };
  for (int j = 0; j < 3; ++j) {
    const int k1 = j == 0 ? 1 : 0, k2 = j == 2 ? 1 : 2;
    for (int i = 0; i < 3; ++i) {
      std::string own;  // component j goes to a wall normal to axis i
      if (i == j)
        own = T(j);
      else if (i == k1)
        own = "(1-" + T(j) + ")*" + T(k1);
      else
        own = "(1-" + T(j) + ")*(1-" + T(k1) + ")*" + T(k2);
      s << "variable b" << kAxis[i] << kAxis[j] << "_a atom (" << kAxis[i] << "+" << own << "*(v_P"
        << kAxis[i] << "_a-" << kAxis[i] << "))*v_fw" << kAxis[j] << "_a\n";
    }
  }
  s << deck::lammps_contact_force_atom(3, p.damping_ratio_translation, plan.gamma_t, exact, "0");
  std::string reduce;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      s << "variable m" << kAxis[i] << kAxis[j] << "_a atom " << kAxis[i] << "*v_fc" << j + 1
        << "_a\n";
      reduce += std::string(" v_b") + kAxis[i] + kAxis[j] + "_a v_m" + kAxis[i] + kAxis[j] + "_a";
    }
  // the spheres' normal force on each wall (the pressures at the start)
  for (int sd = 0; sd < 6; ++sd)
    s << "variable n" << sd << "_a atom v_t" << sd << "_a*v_fw" << kAxis[sd / 2] << "_a\n";
  s << "variable ket_a atom 0.5*mass*(vx*vx+vy*vy+vz*vz)\n"
    << "variable ker_a atom 0.2*mass*c_pa[1]*c_pa[1]*(c_pa[2]*c_pa[2]+c_pa[3]*c_pa[3]+c_pa[4]*"
       "c_pa[4])\n"
    << "compute cn all contact/atom\n"
    << "# [1..18] b, m pairs row by row, [19..21] wall forces, [22..24] contact\n"
    << "# forces, [25..30] normal forces per wall, [31] [32] kinetic energies, [33] contacts\n"
    << "compute meas all reduce sum" << reduce
    << " &\n        v_fwx_a v_fwy_a v_fwz_a v_fc1_a v_fc2_a v_fc3_a v_n0_a v_n1_a v_n2_a v_n3_a "
       "v_n4_a v_n5_a &\n        v_ket_a v_ker_a c_cn\n";
  s << b_and_sigma_3d("variable ");
  std::string row = series_row_head_3d("strain_zz_s");
  // Pressures: the meshes' own totals (the force on a mesh is minus the
  // spheres'), available from the first step; at the start the spheres'
  // normal forces (no wall carries a tangential force yet).
  const char* area[3] = {"v_Ax", "v_Ay", "v_Az"};
  for (int sd = 0; sd < 6; ++sd) {
    const int a = sd / 2;
    const char* sign = sd % 2 == 0 ? "" : "-";
    s << "variable p_" << kWall[sd] << "_s equal " << sign << "((step>0)*(-f_" << mesh[sd] << "["
      << a + 1 << "])+(step==0)*c_meas[" << 25 + sd << "])/" << area[a] << "\n";
  }
  s << "variable lat_s equal (v_p_xmin_s+v_p_xmax_s+v_p_ymin_s+v_p_ymax_s)/4\n"
    << "variable lat_err equal (v_lat_s-v_sigma3)/v_sigma3\n";
  for (int sd = 0; sd < 4; ++sd)
    s << "variable err_" << kWall[sd] << " equal (v_p_" << kWall[sd] << "_s-v_sigma3)/v_sigma3\n";
  s << "variable strain_zz_s equal (v_Hs-" << exact(plan.hi[2] - plan.lo[2]) << ")/"
    << exact(plan.hi[2] - plan.lo[2]) << "\n"
    << "variable ke equal c_meas[31]+c_meas[32]\n"
    << "variable ke_rot equal c_meas[32]\n"
    << "variable contacts equal c_meas[33]/2\n"
    << "variable stepn equal step\n";
  row += series_row_tail_3d("_s");
  const std::string columns = series_columns_3d();
  s << deck::liggghts_series("LIGGGHTS 3D deck", c.name, plan.n, p.damping_ratio_translation,
                             plan.dt_crit, p.mass_scaling, monitor_every, row, columns);
  return s.str();
}

/// The particle file's box and the six walls' meshes (the files go to
/// `out`): the top (normal −z) and the bottom a little wider than the box;
/// the lateral walls from below the bottom to above the top, a little wider
/// than the box (the meshes cross at the edges; they do not touch each
/// other). Returns the mesh files by wall, kWall's order (xmin xmax ymin
/// ymax), then top, bottom.
std::array<std::string, 6> liggghts_3d_meshes(const Plan3& plan, const Export3dOptions& o,
                                              ExportResult& out) {
  const std::array<double, 3> ext{plan.hi[0] - plan.lo[0], plan.hi[1] - plan.lo[1],
                                  plan.hi[2] - plan.lo[2]};
  const DeckFiles files = deck_files(o.deck_name);
  const double mx = 0.1 * ext[0] + 2 * plan.r_max, my = 0.1 * ext[1] + 2 * plan.r_max;
  const double mz = 0.1 * ext[2] + 2 * plan.r_max;
  using V3 = Eigen::Vector3d;
  const V3 lo(plan.lo[0], plan.lo[1], plan.lo[2]), hi(plan.hi[0], plan.hi[1], plan.hi[2]);
  std::array<std::string, 6> mesh_file;
  const char* mesh_name[6] = {"xmin", "xmax", "ymin", "ymax", "top", "bottom"};
  for (int k = 0; k < 6; ++k) mesh_file[k] = files.mesh(mesh_name[k]);
  const double z0 = lo.z() - mz, zh = ext[2] + 2 * mz;
  out.files[mesh_file[0]] =
      stl_rectangle("xmin", V3(lo.x(), lo.y() - my, z0), V3(0, ext[1] + 2 * my, 0), V3(0, 0, zh));
  out.files[mesh_file[1]] =
      stl_rectangle("xmax", V3(hi.x(), lo.y() - my, z0), V3(0, 0, zh), V3(0, ext[1] + 2 * my, 0));
  out.files[mesh_file[2]] =
      stl_rectangle("ymin", V3(lo.x() - mx, lo.y(), z0), V3(0, 0, zh), V3(ext[0] + 2 * mx, 0, 0));
  out.files[mesh_file[3]] =
      stl_rectangle("ymax", V3(lo.x() - mx, hi.y(), z0), V3(ext[0] + 2 * mx, 0, 0), V3(0, 0, zh));
  out.files[mesh_file[5]] = stl_rectangle("bottom", V3(lo.x() - mx, lo.y() - my, lo.z()),
                                          V3(ext[0] + 2 * mx, 0, 0), V3(0, ext[1] + 2 * my, 0));
  out.files[mesh_file[4]] = stl_rectangle("top", V3(lo.x() - mx, lo.y() - my, hi.z()),
                                          V3(0, ext[1] + 2 * my, 0), V3(ext[0] + 2 * mx, 0, 0));
  return mesh_file;
}

/// The four lateral walls' meshes: servo meshes holding sigma3 on the
/// wall's current area (demcal's law, deck::liggghts_servo_kp and vel_max;
/// kp at the start from the contacts demcal counts), or fixed meshes
/// without the lateral servo.
void liggghts_3d_lateral_walls(std::ostream& s, const SceneConfig& c, const Plan3& plan,
                               const Export3dOptions& o,
                               const std::array<std::string, 6>& mesh_file, int wall_type,
                               double cap, bool carried) {
  const double vel_max = deck::liggghts_servo_vel_max(cap, plan.dt, plan.step_factor);
  const std::array<double, 3> ext{plan.hi[0] - plan.lo[0], plan.hi[1] - plan.lo[1],
                                  plan.hi[2] - plan.lo[2]};
  const Eigen::Vector3d centre(0.5 * (plan.lo[0] + plan.hi[0]), 0.5 * (plan.lo[1] + plan.hi[1]),
                               0.5 * (plan.lo[2] + plan.hi[2]));
  for (int sd = 0; sd < 4; ++sd) {
    const int a = sd / 2;
    const double area = ext[(a + 1) % 3] * ext[(a + 2) % 3];
    const double target = c.test.lateral_stress * area;
    const double kp = deck::liggghts_servo_kp(c.test.servo_gain, target, plan.servo_resist,
                                              plan.wall_contacts[sd], cap);
    Eigen::Vector3d com = centre;
    com[a] = sd % 2 == 0 ? plan.lo[a] : plan.hi[a];
    if (o.lateral_servo) {
      // sigma3 on the wall's current area: the other lateral axis' width
      // (its servo meshes' positions) times the height
      const int b = 1 - a;
      s << "variable ft_" << kWall[sd] << " equal " << (sd % 2 == 0 ? "" : "-")
        << exact(c.test.lateral_stress) << "*(f_m" << kWall[2 * b + 1] << "[" << 7 + b << "]-f_m"
        << kWall[2 * b] << "[" << 7 + b << "])*(" << exact(ext[2]) << "-" << exact(plan.top_speed)
        << "*step*" << exact(plan.dt) << ")\n";
      if (carried)  // moved by demcal's servo (deck::liggghts_carried_servo_run)
        s << "fix m" << kWall[sd] << " all mesh/surface/stress file " << mesh_file[sd] << " type "
          << wall_type << " reference_point " << exact(com.x()) << " " << exact(com.y()) << " "
          << exact(com.z()) << "\n";
      else
        s << "fix m" << kWall[sd] << " all mesh/surface/stress/servo file " << mesh_file[sd]
          << " type " << wall_type << " com " << exact(com.x()) << " " << exact(com.y()) << " "
          << exact(com.z()) << " ctrlPV force axis " << (a == 0 ? "1 0 0" : "0 1 0")
          << " target_val v_ft_" << kWall[sd] << " vel_max " << exact(vel_max) << " kp "
          << exact(kp) << "\n";
    } else {
      s << "fix m" << kWall[sd] << " all mesh/surface/stress file " << mesh_file[sd] << " type "
        << wall_type << "\n";
    }
  }
}

/// The loading run: with the lateral servo in chunks, each servo mesh's kp
/// set between them from its current contacts (deck::liggghts_servo_run);
/// one run without.
void liggghts_3d_run(std::ostream& s, const SceneConfig& c, const Plan3& plan,
                     const Export3dOptions& o, double cap, int monitor_every, double carry) {
  if (!o.lateral_servo) {
    s << "run ${run_steps}\n";
    return;
  }
  std::vector<deck::LiggghtsServoWall> walls;
  for (int sd = 0; sd < 4; ++sd) {
    // with contact damping the contacts are counted over the walls' bands
    const int a = sd / 2;
    const bool upper = sd % 2 == 1;
    walls.push_back(
        {std::string("m") + kWall[sd], std::string("ft_") + kWall[sd],
         std::string("t") + std::to_string(sd) + "_a", a,
         deck::liggghts_band(c.test.vertical_strain, plan.hi[a] - plan.lo[a], plan.r_max),
         upper ? plan.hi[a] : plan.lo[a], upper, std::string("v_wall_") + kWall[sd]});
  }
  if (carry > 0.0)
    s << deck::liggghts_carried_servo_run(walls, c.test.servo_gain, plan.servo_resist, carry, cap,
                                          plan.dt / plan.step_factor, "c_pa[1]", monitor_every,
                                          exact);
  else
    s << deck::liggghts_servo_run(walls, c.test.servo_gain, plan.servo_resist, cap, monitor_every,
                                  exact, resist_name(plan));
}

std::string liggghts_deck(const SceneConfig& c, const AlgorithmSpec& p, const Plan3& plan,
                          const Export3dOptions& o, const SphereWorld& w, ExportResult& out) {
  const auto& m = c.material;
  const int wall_type = plan.types + 1, ntypes = plan.types + 1;
  const double h0 = plan.hi[2] - plan.lo[2];
  out.files[deck_files(o.deck_name).data] = data_file("LIGGGHTS", c, plan, w, ntypes, "Atoms");
  const std::array<std::string, 6> mesh_file = liggghts_3d_meshes(plan, o, out);

  // Servo: demcal's law over the same loading time (deck::liggghts_servo_kp
  // and vel_max), the gain from each wall's current contacts, set between
  // chunks of the run (deck::liggghts_servo_run); at the start from the
  // contacts demcal counts.
  const double cap = servo_move_cap(plan.r_min);
  // R: kn_wall, and the wall dashpots' c/dt_demcal with contact damping;
  // then demcal's servo carries a share of the last move, which LIGGGHTS'
  // mesh servo cannot: the walls are moved by deck::liggghts_carried_servo_run.
  const bool dashpots = plan.wall_dashpot > 0.0;
  const double carry = servo_carry(m.wall.kn, plan.servo_resist);
  const bool carried = o.lateral_servo && carry > 0.0;
  std::ostringstream s;
  s << mapping_header(c, p, plan, o, "LIGGGHTS");
  s << "#\n# Checked with LIGGGHTS 3.8 (Debian). Differences from demcal:\n"
    << "#  - rotational damping: no fix here (zeta_r not applied).\n";
  if (carried)
    s << "#  - lateral walls: stress meshes moved by demcal's servo (fix move/mesh,\n"
      << "#    before the run): each step by gain*(sigma3*A - F)/(R*max(1, n)) +\n"
      << "#    carry*(its last move), clamped to +-cap, in demcal's step dt_demcal =\n"
      << "#    dt/f, A the wall's current area, n its current contacts; R = kn_wall +\n"
      << "#    c/dt_demcal = " << exact(plan.servo_resist) << " N/m: demcal's wall contacts\n"
      << "#    resist a move within its step by their dashpots too, c =\n"
      << "#    2*zeta_c*sqrt(kn_wall*m_max) = " << exact(plan.wall_dashpot)
      << " N*s/m (the heaviest sphere's);\n"
      << "#    carry = (R - kn_wall)/R = " << exact(carry) << ". The first move comes one\n"
      << "#    step after demcal's (the meshes have no force before the first step).\n";
  else {
    s << "#  - lateral walls: fix mesh/surface/stress/servo holds the wall force at\n"
      << "#    sigma3*A, A the wall's current area (target_val v_ft_WALL), demcal's\n"
      << "#    target (the force on the mesh along +axis: positive on a min wall).\n"
      << "#    LIGGGHTS moves it at vel_max*kp*(F_target - F)/|F_target|: vel_max =\n"
      << "#    cap/dt_demcal (dt_demcal = dt/f, demcal's step) and kp =\n"
      << "#    gain*|F_target|/(" << resist_name(plan) << "*max(1, n)*cap), n the wall's current "
      << "contacts,\n#    give demcal's wall velocity gain*(F_target - F)/(" << resist_name(plan)
      << "*max(1, n)*dt_demcal)\n"
      << "#    and its cap";
    if (dashpots)
      s << "; R = kn_wall + c/dt_demcal = " << exact(plan.servo_resist) << " N/m: demcal's\n"
        << "#    wall contacts resist a move within its step by their dashpots too, c =\n"
        << "#    2*zeta_c*sqrt(kn_wall*m_max) = " << exact(plan.wall_dashpot)
        << " N*s/m (the heaviest sphere's),\n#    and its servo divides by both";
    s << ". LIGGGHTS' kp is a number: the run goes in chunks of\n"
      << "#    ${servo_every} steps (one setup) and kp is set from the current n and\n"
      << "#    F_target between them (fix_modify servo/ctrlParam; at the start from\n"
      << "#    demcal's count): the gain lags demcal's by one chunk at most.\n";
  }
  s << "#  - translational damping per radius class via fix viscous ... scale.\n"
    << "# Run it with a screen (liggghts 3.8 crashes reading meshes with -screen none).\n"
    << "#  - the bottom is a fixed mesh (not a primitive plane) so that its force is\n"
    << "#    known: the axial stress is the mean of top and bottom, as demcal's (the\n"
    << "#    top alone reads 0.3 % higher at the peak on fcc_4x4x4: the damping drag\n"
    << "#    on the spheres that move with it).\n"
    << "# Thermo: p_axial = (p_top + p_bottom)/2, p_lat (mean of the four lateral\n"
    << "# walls), Pa, on the current areas; sigma1/sigma3 = p_axial/p_lat (no\n"
    << "# column: both are 0 at the start, before LIGGGHTS computes mesh forces).\n";
  if (carried)
    out.notes.push_back(
        "LIGGGHTS deck: the lateral walls moved by demcal's servo with its carry (contact "
        "damping), fix move/mesh; no rotational damping");
  else
    out.notes.push_back("LIGGGHTS deck: servo gain from the walls' current contacts, set every " +
                        std::to_string(deck::monitor_interval(plan.steps, c.test.monitor_points)) +
                        " steps; no rotational damping");
  if (!o.lateral_servo)
    out.notes.push_back("LIGGGHTS deck: lateral walls fixed (lateral_servo off)");
  s << deck::liggghts_preamble(3, "f f f", deck_files(o.deck_name).data, plan.r_min)
    << deck::liggghts_materials(m, plan.class_mass, plan.dt, exact)
    << "fix mbottom all mesh/surface/stress file " << mesh_file[5] << " type " << wall_type << "\n"
    << "fix mtop all mesh/surface/stress file " << mesh_file[4] << " type " << wall_type << "\n";
  liggghts_3d_lateral_walls(s, c, plan, o, mesh_file, wall_type, cap, carried);
  s << "fix walls all wall/gran model hooke/stiffness tangential history mesh n_meshes 6 meshes "
       "mbottom mtop mxmin mxmax mymin mymax store_force yes "
    << deck::liggghts_model_settings(m) << "\n"
    << "fix movetop all move/mesh mesh mtop linear 0 0 " << exact(-plan.top_speed) << "\n\n"
    << "fix integrate all nve/sphere\n"
    << deck::liggghts_translational_damping(p.damping_ratio_translation, plan.gamma_t, exact);
  // Wall positions: the servo meshes report theirs ([7..9]); the top moves
  // at the loading speed.
  auto wall_pos = [&](int sd) {
    if (!o.lateral_servo) return exact(sd % 2 == 0 ? plan.lo[sd / 2] : plan.hi[sd / 2]);
    return std::string("f_m") + kWall[sd] + "[" + std::to_string(7 + sd / 2) + "]";
  };
  const int monitor_every = deck::monitor_interval(plan.steps, c.test.monitor_points);
  s << "\nvariable H equal " << exact(h0) << "-" << exact(plan.top_speed) << "*step*dt\n"
    << "variable Wx equal " << wall_pos(1) << "-(" << wall_pos(0) << ")\n"
    << "variable Wy equal " << wall_pos(3) << "-(" << wall_pos(2) << ")\n"
    << "variable p_top equal f_mtop[3]/(v_Wx*v_Wy)\n"
    << "variable p_bottom equal -f_mbottom[3]/(v_Wx*v_Wy)\n"
    << "variable p_axial equal (v_p_top+v_p_bottom)/2\n"
    << "variable p_lat equal (-f_mxmin[1]+f_mxmax[1])/(4*v_Wy*v_H)+(-f_mymin[2]+f_mymax[2])/"
       "(4*v_Wx*v_H)\n"
    << "variable strain_zz equal (v_H-" << exact(h0) << ")/" << exact(h0) << "\n"
    << liggghts_3d_series(c, p, plan, o, {wall_pos(0), wall_pos(1), wall_pos(2), wall_pos(3)},
                          monitor_every)
    << "# LIGGGHTS 3.8 has no fix vector: the peaks are the largest p_axial and ratio\n"
    << "# over the thermo rows; -var thermo_every 1 for every step.\n"
    << "variable thermo_every index " << monitor_every << "\n"
    << "thermo_style custom step time ke v_strain_zz v_p_axial v_p_lat v_p_top v_p_bottom v_Wx "
       "v_Wy\n"
    << "thermo ${thermo_every}\n"
    << "variable run_steps index " << plan.steps << "\n";
  liggghts_3d_run(s, c, plan, o, cap, monitor_every, carried ? carry : 0.0);
  return s.str();
}

}  // namespace

ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const SphereWorld& world, const Export3dOptions& options) {
  if (config.dimension != 3)
    throw InputError(config.source, "dimension", "a 3D deck needs \"dimension\": 3");
  if (world.size() == 0) throw InputError("export", "prototype", "no particles");
  if (options.format != "lammps" && options.format != "liggghts")
    throw InputError("--format", "", "must be lammps or liggghts, got \"" + options.format + "\"");
  if (options.consolidate_in_deck && options.format != "lammps")
    throw InputError("--consolidate-in", "",
                     "deck: only the LAMMPS deck consolidates itself (LIGGGHTS 3.8 has no fix "
                     "halt and no servo with demcal's law; reports/engines.md)");
  if (options.consolidate_in_deck && !options.lateral_servo)
    throw InputError("export", "lateral_servo", "the deck's consolidation servoes every wall");
  const Plan3 plan = make_plan(config, params, world, options.max_types);
  ExportResult out = result_of(plan);
  if (options.format == "lammps") {
    out.files[deck_files(options.deck_name).data] =
        data_file("LAMMPS", config, plan, world, plan.types, "Atoms # sphere");
    out.deck = lammps_deck(config, params, plan, options, out);
    out.notes.push_back(
        "lateral servo walls emulated with variables (running sum of demcal's per-step servo "
        "move): one run command only");
  } else {
    out.deck = liggghts_deck(config, params, plan, options, world, out);
  }
  return out;
}

ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const TriaxialState& state, const Export3dOptions& options) {
  return export_3d_decks(config, params, state.world, options);
}

ExportResult export_3d_decks(const SceneConfig& config, const AlgorithmSpec& params,
                             const SphereAssembly& assembly, const Export3dOptions& options) {
  if (assembly.size() == 0) throw InputError("export", "prototype", "no particles");
  const SphereWorld world(sphere_material(config.material), assembly.x, assembly.y, assembly.z,
                          assembly.r, assembly.lo, assembly.hi);
  return export_3d_decks(config, params, world, options);
}

}  // namespace demcal
