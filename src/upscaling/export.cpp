#include "demcal/upscaling/export.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <sstream>

#include "deck_sections.hpp"
#include "demcal/scene/biaxial.hpp"

namespace demcal {

namespace {

using deck::fmt3;
using deck::num;

/// Everything both decks need, computed once.
struct Plan : deck::PlanCommon {
  double areal_density = 0.0;  // f_ms·ρ·t [kg/m²]
  double width0 = 0.0, height0 = 0.0;
  int thermo_every = 1;
  ParticleScales scales;
};

Plan make_plan(const SceneConfig& c, const AlgorithmSpec& p, const Assembly& a, int max_types) {
  Plan plan;
  deck::set_plan_classes(plan, a.r, max_types);
  plan.scales = particle_scales(a.r, c.material, p.mass_scaling);
  plan.r_min = plan.scales.radius_min;
  plan.r_max = plan.scales.radius_max;
  plan.dt_crit = plan.scales.dt_crit;
  // alpha*f for Nstep/f steps: the engines' fix viscous is explicit; the
  // servo's mass is the heaviest disc's (as scene/biaxial.cpp computes it).
  deck::set_plan_timing(plan, p, c.material,
                        disk_mass(disk_areal_density(c.material, p.mass_scaling), plan.r_max));
  plan.areal_density = p.mass_scaling * c.material.density * c.material.thickness;
  plan.width0 = a.right - a.left;
  plan.height0 = a.top - a.bottom;
  plan.top_speed =
      c.test.vertical_strain * plan.height0 / (static_cast<double>(plan.steps) * plan.dt);
  // D_t = ζ_t·2·sqrt(kn·m) ∝ r and D_r = ζ_r·2·sqrt(kt·r²·I) ∝ r³ for discs
  // of one density: each class gets the value of its mid radius, which
  // bounds the error by (r_hi − r_lo)/(r_hi + r_lo) for D_t.
  const double kn = c.material.particle.kn, kt = c.material.particle.kt;
  for (int k = 0; k < plan.types; ++k) {
    const double r = 0.5 * (plan.r_lo[k] + plan.r_hi[k]);
    const double m = plan.areal_density * std::numbers::pi * r * r;
    plan.class_mass.push_back(m);
    plan.gamma_t.push_back(p.damping_ratio_translation * 2.0 * std::sqrt(kn * m));
    plan.gamma_r.push_back(p.damping_ratio_rotation * 2.0 *
                           std::sqrt(kt * r * r * 0.5 * m * r * r));
    plan.class_error =
        std::max(plan.class_error, (plan.r_hi[k] - plan.r_lo[k]) / (plan.r_hi[k] + plan.r_lo[k]));
  }
  plan.thermo_every = deck::monitor_interval(plan.steps, c.test.monitor_points);
  return plan;
}

std::string mapping_header(const SceneConfig& c, const AlgorithmSpec& p, const Plan& plan,
                           const ExportOptions& o, const std::string& code) {
  std::ostringstream s;
  const auto& m = c.material;
  s << deck::header_opening(code, "2D biaxial test",
                            "scene " + c.name + "; prototype " + std::to_string(plan.n) +
                                " particles (" + deck_files(o.deck_name).data + ")",
                            o, p.dt_ratio, plan.step_factor, plan.dt_crit, plan.dt)
    << "#     dt_crit = 2 sqrt(m_min/kn) of the smallest disc (r = " << num(plan.r_min) << " m)\n"
    << deck::header_step_factor(code, plan.step_factor, p.damping_ratio_translation)
    << "#       (the drag -gamma*v uses the half-step velocity), which shrinks a damped\n"
    << "#       oscillator's stable step from 2/omega to f*2/omega; demcal damps\n"
    << "#       semi-implicitly (f = 1). At demcal's alpha a well-damped calibration\n"
    << "#       chatters here (measured: alpha 0.286, zeta_t 1.107, force balance 0.195\n"
    << "#       FAIL in LAMMPS); alpha*f keeps demcal's margin to the stable step.\n"
    << "#   Nstep = " << p.steps << " / f = " << plan.steps
    << " loading steps (upscaled, then / f: the same loading\n"
    << "#     time Nstep*dt, so the same rate and strain) -> run length; the top wall moves\n"
    << "#     eps * H0 / (Nstep * dt) = " << num(c.test.vertical_strain) << " * "
    << num(plan.height0) << " / (" << plan.steps << " * " << num(plan.dt)
    << ") = " << num(plan.top_speed) << " m/s\n"
    << deck::header_contact_law(m) << " -> gamma_n"
    << (m.contact_damping_ratio > 0 ? " (per pair in demcal; mean mass here)" : " = gamma_t = 0")
    << "\n"
    << "#   zeta_t = " << num(p.damping_ratio_translation)
    << ": D_t = zeta_t * 2 sqrt(kn m_i), per particle (proportional to r)\n"
    << "#     -> global viscous damping per radius class (atom type): " << plan.types
    << " class(es), gamma of the class's mid radius,\n"
    << "#        largest error against the per-particle value " << fmt3(100 * plan.class_error)
    << " %\n"
    << "#   zeta_r = " << num(p.damping_ratio_rotation)
    << ": D_r = zeta_r * 2 sqrt(kt r^2 I), per particle (proportional to r^3)\n"
    << "#   mass scaling f_ms = " << num(p.mass_scaling)
    << " -> areal density f_ms*rho*t = " << num(plan.areal_density)
    << " kg/m^2 (rho = " << num(m.density) << " kg/m^3, t = " << num(m.thickness) << " m)\n"
    << deck::header_wall_law(m) << "; bottom fixed, top at constant speed,\n"
    << "#     left/right servo-controlled to sigma3 = " << num(c.test.lateral_stress)
    << " Pa (gain " << num(c.test.servo_gain) << ")\n"
    << "#   stresses: tension positive in demcal; the thermo columns below give the\n"
    << "#     compressive wall pressures (positive) instead\n";
  if (o.consolidate_in_deck) {
    s << "# The particle file holds the prototype as generated (walls at its box): stage 1\n"
      << "# of this deck consolidates it to isotropic sigma3 as demcal does (see there),\n"
      << "# under MPI, before the loading. Run it with -in (the stage skips itself with\n"
      << "# jump SELF), e.g. mpirun -np 4 lmp -in THIS_DECK.\n"
      << "# ===========================================================================\n";
    return s.str();
  }
  s << "# The particle file holds the state demcal consolidated to sigma3 (walls at its\n"
    << "# box); the run starts loading from it. Not carried over: the tangential\n"
    << "# contact forces (the tangential springs' histories, particle-particle and\n"
    << "# particle-wall) start at zero here, where demcal's consolidated state had\n"
    << "# them; the normal forces (overlaps) are in the positions. The first steps of\n"
    << "# the loading mobilise them again (small at a static, isotropic start).\n"
    << "# ===========================================================================\n";
  return s.str();
}

/// The figures of a plan every export reports (the files are added after).
ExportResult result_of(const Plan& plan) { return deck::plan_result(plan); }

// ---------------------------------------------------------------------------
// LAMMPS (29 Sep 2021)

/// Whether the deck's top and bottom wall forces can be recomputed from the
/// overlaps: the wall fixes carry no damping (gamma_n = gamma_t = 0 in
/// every `fix wall/gran`: demcal's contact damping is not mapped to the
/// walls), so with no tangential force (mu_wall = 0 or kt_wall = 0) a
/// wall's force on a particle is kn_wall·(r − distance) along the normal,
/// at the foot of the normal. Otherwise the deck keeps the walls' contact
/// arrays (`contacts`), which carry the tangential part.
bool normal_only_walls(const Material& m) { return m.wall.friction == 0.0 || m.wall.kt == 0.0; }

/// The LAMMPS deck's monitoring series: b, sigma, kinetic energy, wall
/// stresses, servo error and torque sum at every monitoring interval, in the
/// CSV that `demcal score` reads (include/demcal/scoring/external_series.hpp).
constexpr const char* kColumns =
    "step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy,kinetic_energy,"
    "kinetic_energy_rotation,lateral_stress_error,p_left,p_right,p_bottom,p_top,wall_left,"
    "wall_right,wall_bottom,wall_top,torque_stress";

std::string lammps_series_block(const SceneConfig& c, const AlgorithmSpec& p, const Plan& plan) {
  std::ostringstream s;
  s << "# --- monitoring series (demcal score FILE) -----------------------------------\n"
    << "# Written to ${series} every monitor_every steps (and at the start), one row\n"
    << "# per monitoring point, tension positive, SI units, origin at the box centre:\n"
    << "#   step, strain_yy          (H - H0)/H0\n"
    << "#   b_xx b_xy b_yx b_yy      boundary stress (1/V) sum_wall x^c (x) f^c, from the\n"
    << "#                            walls' contact arrays (contact point, force) or,\n"
    << "#                            for frictionless top and bottom walls, their overlaps\n"
    << "#   s_xx s_xy s_yx s_yy      homogenized stress, from the identity\n"
    << "#                            V (b - sigma) = sum_p (x_p - c) (x) F_p, F_p the\n"
    << "#                            contact force (before damping, recovered below)\n"
    << "#   kinetic_energy           translation + rotation, disc inertia m r^2/2 [J]\n"
    << "#   kinetic_energy_rotation\n"
    << "#   lateral_stress_error     ((p_left + p_right)/2 - sigma3)/sigma3 (servo)\n"
    << "#   p_left p_right p_bottom p_top  compressive wall pressures [Pa]\n"
    << "#   wall_left wall_right wall_bottom wall_top  wall positions [m]\n"
    << "#   torque_stress            sum of the particles' contact torques / V [Pa]\n"
    << "# Approximated: LAMMPS applies a contact's tangential force at the lever arm\n"
    << "# r_i (demcal: r_i - delta/2), so s_xy - s_yx carries a static term\n"
    << "# -sum_c delta_c f_t,c / V that no algorithmic parameter removes; demcal score\n"
    << "# measures moment balance on torque_stress (zero at rotational equilibrium in\n"
    << "# either code) and reports that floor apart.\n"
    << "variable        epsyy equal (v_H-v_H0)/v_H0\n"
    << "variable        cx equal (v_xl+v_xr)/2\n"
    << "variable        cy equal (v_yb0+v_yt)/2\n"
    << "variable        V  equal v_W*v_H*v_thick\n";
  const bool normal_only = normal_only_walls(c.material);
  // The walls' b terms: the lateral walls' contact arrays; the top and
  // bottom walls' from their arrays or, frictionless, from the overlaps
  // (force fy*_a on the particle at the foot of the normal (x, wall)).
  const std::vector<std::string> arrays =
      normal_only ? std::vector<std::string>{"wleft", "wright"}
                  : std::vector<std::string>{"wleft", "wright", "wtop", "wbottom"};
  auto wall_sum = [&](int a, int b) { return deck::lammps_wall_sum(arrays, a, b); };
  const std::string fy_tb = normal_only ? "+v_fyt_a+v_fyb_a" : "";
  s << "variable        bxx_a atom " << wall_sum(5, 2) << "\n"
    << "variable        bxy_a atom " << wall_sum(5, 3)
    << (normal_only ? "+x*(v_fyt_a+v_fyb_a)" : "") << "\n"
    << "variable        byx_a atom " << wall_sum(6, 2) << "\n"
    << "variable        byy_a atom " << wall_sum(6, 3)
    << (normal_only ? "+v_yt*v_fyt_a+${yb0}*v_fyb_a" : "") << "\n"
    << "variable        fwx_a atom " << wall_sum(2, 0) << "\n"
    << "variable        fwy_a atom " << wall_sum(3, 0) << fy_tb << "\n"
    << deck::lammps_contact_force_atom(2, p.damping_ratio_translation, plan.gamma_t, num,
                                       "${step0}")
    << "variable        mxx_a atom x*v_fc1_a\n"
    << "variable        mxy_a atom x*v_fc2_a\n"
    << "variable        myx_a atom y*v_fc1_a\n"
    << "variable        myy_a atom y*v_fc2_a\n"
    << "compute         pa all property/atom radius omegaz tqz\n"
    << "variable        ker_a atom 0.25*mass*c_pa[1]*c_pa[1]*c_pa[2]*c_pa[2]\n"
    << "compute         meas all reduce sum v_bxx_a v_bxy_a v_byx_a v_byy_a v_fwx_a v_fwy_a &\n"
    << "                v_mxx_a v_mxy_a v_myx_a v_myy_a v_fc1_a v_fc2_a v_ker_a c_pa[3]\n"
    << "compute         ket all ke\n"
    << "variable        b_xx equal (c_meas[1]-v_cx*c_meas[5])/v_V\n"
    << "variable        b_xy equal (c_meas[2]-v_cx*c_meas[6])/v_V\n"
    << "variable        b_yx equal (c_meas[3]-v_cy*c_meas[5])/v_V\n"
    << "variable        b_yy equal (c_meas[4]-v_cy*c_meas[6])/v_V\n"
    << "variable        s_xx equal v_b_xx-(c_meas[7]-v_cx*c_meas[11])/v_V\n"
    << "variable        s_xy equal v_b_xy-(c_meas[8]-v_cx*c_meas[12])/v_V\n"
    << "variable        s_yx equal v_b_yx-(c_meas[9]-v_cy*c_meas[11])/v_V\n"
    << "variable        s_yy equal v_b_yy-(c_meas[10]-v_cy*c_meas[12])/v_V\n"
    << "variable        ke equal c_ket+c_meas[13]\n"
    << "variable        ke_rot equal c_meas[13]\n"
    << "variable        servo_err equal ((v_pl+v_pr)/2-v_sigma3)/v_sigma3\n"
    << "variable        torque equal c_meas[14]/v_V\n"
    << "variable        stepn equal step\n";
  const std::string row =
      "${stepn},${epsyy},${b_xx},${b_xy},${b_yx},${b_yy},${s_xx},${s_xy},${s_yx},${s_yy},"
      "${ke},${ke_rot},${servo_err},${pl},${pr},${pb},${pt},${xl},${xr},${yb0},${yt},${torque}";
  s << "# the header: what demcal score needs to know about the run (not repeated by\n"
    << "# the continuation of a split run, which appends its rows)\n"
    << "if              \"${continued} != 0\" then \"jump SELF series_rows\"\n"
    << deck::lammps_series_header("LAMMPS deck", c.name, plan.n, p.damping_ratio_translation,
                                  plan.dt_crit, p.mass_scaling)
    << "fix             series all print ${monitor_every} \"" << row
    << "\" append ${series} screen no title \"" << kColumns << "\"\n"
    << "jump            SELF series_done\n"
    << "label           series_rows\n"
    << "# a continuation: its rows from the next monitoring step on (the first part\n"
    << "# wrote the row of the step it ended at), after a comment line instead of the\n"
    << "# column header (fix print always opens its file with a title line)\n"
    << "variable        series_next equal (floor(step/v_monitor_every)+1)*v_monitor_every\n"
    << "fix             series all print v_series_next \"" << row
    << "\" append ${series} screen no title \"# continued from a restart: the rows go on\"\n"
    << "label           series_done\n\n";
  return s.str();
}

// The walls, the servo's input and the measured wall stresses of the LAMMPS
// deck: text only, every number comes from the deck's parameters block.
std::string lammps_walls(bool normal_only) {
  // `contacts` on the top and bottom walls only where their tangential
  // force must be read back (the lateral walls always: the servo's input).
  const char* tb_contacts = normal_only ? "\n" : " contacts\n";
  std::ostringstream s;
  s << "# --- walls -------------------------------------------------------------------\n"
       "# top: a plane moving down at vtop; left/right: planes moved by the servo.\n"
       "# The fix order matters: the walls, then the damping (the series recovers\n"
       "# the contact force from the total force at monitoring steps).\n"
       "# (evaluated every step: the constants substituted now, ${...}; in this\n"
       "# release a v_ reference formats the other variable to text and back)\n"
       "variable dytop  equal -${dy_step}*step\n"
       "# (elapsed: the steps of this run, step-${step0}, one word to parse;\n"
       "# f_servol, f_servor: the lateral walls' mean moves, fix servol/servor)\n"
       "variable dxl    equal f_servol*elapsed\n"
       "variable dxr    equal f_servor*elapsed\n"
       "region          rtop   plane 0 ${yt0} 0  0 -1 0 side in move NULL v_dytop NULL units box\n"
       "region          rleft  plane ${xl_now} 0 0  1 0 0  side in move v_dxl NULL NULL units box\n"
       "region          rright plane ${xr_now} 0 0  -1 0 0 side in move v_dxr NULL NULL units box\n"
       "# Each wall acts on the particles that can reach it (a wall fix loops over\n"
       "# its group every step): those within band_v of the top or the bottom,\n"
       "# band_h of a lateral wall at the start. fix halt stops the run with an\n"
       "# error should a particle outside a band ever touch that wall (then widen\n"
       "# the bands).\n"
       "region          bandtop block INF INF $(v_yt0-v_band_v) INF INF INF units box\n"
       "region          bandbottom block INF INF INF $(v_yb0+v_band_v) INF INF units box\n"
       "region          bandleft block INF $(v_xl0+v_band_h) INF INF INF INF units box\n"
       "region          bandright block $(v_xr0-v_band_h) INF INF INF INF INF units box\n"
       "group           gtop region bandtop\n"
       "group           gbottom region bandbottom\n"
       "group           gleft region bandleft\n"
       "group           gright region bandright\n"
       "group           gside union gleft gright\n"
       "group           ntop subtract all gtop\n"
       "group           nbottom subtract all gbottom\n"
       "group           nleft subtract all gleft\n"
       "group           nright subtract all gright\n";
  if (normal_only)
    s << "# The top and bottom wall forces are recomputed from the overlaps at\n"
         "# monitoring steps (exact for these frictionless, undamped walls): an edited\n"
         "# mu_wall needs the walls' contact arrays, i.e. a new export.\n"
         "if              \"${mu_wall} != 0 && ${kt_wall} != 0\" then &\n"
         "                \"print 'demcal deck: exported for frictionless walls (the top and "
         "bottom wall forces come from the overlaps): export again with the wall friction'\" "
         "\"quit 2\"\n";
  s << "fix             wbottom gbottom wall/gran hooke/history ${kn_wall} ${kt_wall} 0 0 "
       "${mu_wall} 0 yplane ${yb0} NULL"
    << tb_contacts
    << "fix             wtop gtop wall/gran/region hooke/history ${kn_wall} ${kt_wall} 0 0 "
       "${mu_wall} 0 region rtop"
    << tb_contacts
    << "fix             wleft gleft wall/gran/region hooke/history ${kn_wall} ${kt_wall} 0 0 "
       "${mu_wall} 0 region rleft contacts\n"
       "fix             wright gright wall/gran/region hooke/history ${kn_wall} ${kt_wall} 0 0 "
       "${mu_wall} 0 region rright contacts\n"
       "# wall contact arrays: [1] contacts, [2] [3] force on the particle, [5] [6]\n"
       "# contact point\n"
       "# the servo's input, the left and the right wall side by side (a vector\n"
       "# each, for the servo's vector formula): their contacts, their forces on\n"
       "# the particles (x)\n"
       "compute         cn gside reduce sum f_wleft[1] f_wright[1]\n"
       "compute         cf gside reduce sum f_wleft[2] f_wright[2]\n"
       "variable        xl equal v_xl_now+v_dxl\n"
       "variable        xr equal v_xr_now+v_dxr\n"
       "variable        yt equal v_yt0+v_dytop\n"
       "variable        H  equal v_yt-v_yb0\n"
       "variable        W  equal v_xr-v_xl\n"
       "compute         rad all property/atom radius\n";
  if (normal_only)
    s << "# top and bottom: the force on a particle is kn_wall * overlap along the\n"
         "# wall's normal (y), at the foot of the normal (x, wall)\n"
         "variable        ovt_a atom c_rad-(v_yt-y)\n"
         "variable        ovb_a atom c_rad-(y-${yb0})\n"
         "variable        fyt_a atom -${kn_wall}*v_ovt_a*(v_ovt_a>0)\n"
         "variable        fyb_a atom ${kn_wall}*v_ovb_a*(v_ovb_a>0)\n"
         "compute         ct gtop reduce sum v_fyt_a\n"
         "compute         cb gbottom reduce sum v_fyb_a\n"
         "variable        pt equal -c_ct/(v_W*v_thick)\n"
         "variable        pb equal c_cb/(v_W*v_thick)\n";
  else
    s << "compute         ct gtop reduce sum f_wtop[1] f_wtop[3]\n"
         "compute         cb gbottom reduce sum f_wbottom[1] f_wbottom[3]\n"
         "variable        pt equal -c_ct[2]/(v_W*v_thick)\n"
         "variable        pb equal c_cb[2]/(v_W*v_thick)\n";
  s << "variable        pl equal c_cf[1]/(v_H*v_thick)\n"
       "variable        pr equal -c_cf[2]/(v_H*v_thick)\n"
       "# clearance of the particles outside each band from its wall (> 0)\n"
       "variable        gap_top atom v_yt-y-c_rad\n"
       "variable        gap_bottom atom y-c_rad-v_yb0\n"
       "variable        gap_left atom x-c_rad-v_xl\n"
       "variable        gap_right atom v_xr-x-c_rad\n"
       "compute         clear_top ntop reduce min v_gap_top\n"
       "compute         clear_bottom nbottom reduce min v_gap_bottom\n"
       "compute         clear_left nleft reduce min v_gap_left\n"
       "compute         clear_right nright reduce min v_gap_right\n"
       "variable        clear_top equal c_clear_top\n"
       "variable        clear_bottom equal c_clear_bottom\n"
       "variable        clear_left equal c_clear_left\n"
       "variable        clear_right equal c_clear_right\n";
  return s.str();
}

/// demcal's servo law (scene/biaxial.cpp, servo_velocity) in the deck: the
/// unclamped move and its clamp of both lateral walls as two vector-style
/// formulas (each parsed once per step for both walls), summed every step by
/// fix servol and servor (lammps_run); the walls' displacements at the end of
/// the run for the restart args. `carry` (contact damping): each move carries
/// ${carry} of the wall's last (fix servo_prev, lammps_run), as demcal's
/// servo_velocity does, and the restart args carry the last moves too.
std::string lammps_servo(bool carry) {
  // (gain/kn_wall)*(sigma3*H*t - F)/max(1, n) per wall, sigma3*H*t =
  // load0 - load_step*step stored by fix servo_load, F the wall's force on
  // the sample: c_cf[1] for the left wall (it pushes the particles +x),
  // -c_cf[2] for the right one (-x). The right element is computed with the
  // opposite sign, gain_kn*(-sigma3*H*t - c_cf[2])/(...), exactly minus the
  // right wall's move, and its clamp is exactly minus the clamp of the move
  // (clamp(-x) = -clamp(x) bit for bit): fix servol and servor keep the
  // displacements' signs, left +x, right -x, as dxl and dxr use them.
  const std::string load = "${load0}-${load_step}*step";
  std::string raw = deck::lammps_servo_raw_folded("f_servo_sign*f_servo_load", "-c_cf",
                                                  deck::lammps_count_max_one("c_cn"));
  // the right element's carried move is minus the right wall's too:
  // -(law + carry*u) = (-law) + carry*(-u) bit for bit
  if (carry) raw += deck::lammps_servo_carried("${servo_carried}");
  std::ostringstream s;
  s << "# demcal's servo, one move per step toward the sample when p < sigma3:\n";
  if (carry)
    s << "#   move = gain*(sigma3*H*t - F)/(R*max(1, n)) + carry*u, clamped to +-cap,\n"
      << "# R = kn_wall + the wall dashpots' c_wall/servo_dt (contact damping), u the\n"
      << "# wall's last move (carry: derived block), per demcal step (servo_dt), so per\n"
      << "# step of dt that times dt/servo_dt: gain_kn*(load0 - load_step*step - F)/\n"
      << "# max(1, n) + carry*u within +-cap_step (u, a move of this deck, is dt/servo_dt\n"
      << "# times demcal's already; constants folded in the derived block: every number\n"
      << "# in a per-step formula costs a parse),\n";
  else
    s << "#   move = gain*(sigma3*H*t - F)/(R*max(1, n)), clamped to +-cap,\n"
      << "# R = kn_wall (+ the wall dashpots' c_wall/servo_dt with contact damping),\n"
      << "# per demcal step (servo_dt), so per step of dt that times dt/servo_dt:\n"
      << "# gain_kn*(load0 - load_step*step - F)/max(1, n) within +-cap_step (constants\n"
      << "# folded in the derived block: every number in a per-step formula costs a parse),\n";
  s << "# F the wall force, n its contacts; the wall's displacement is the sum of\n"
    << "# the moves (running mean times the steps of this run, dxl and dxr above).\n"
    << "# Both walls in one vector-style formula (elements: left, right; the\n"
    << "# right one with the opposite sign, so that the moves are displacements\n"
    << "# along x), parsed once per step for both (parsing is what a step of\n"
    << "# this deck pays for), with the numbers substituted now. The clamp reads\n"
    << "# the unclamped moves as doubles (a vector variable is evaluated once per\n"
    << "# step, then kept); the target load and the signs come from fixes\n"
    << "# (doubles; the signs are internal variables, read without parsing).\n"
    << "# rawv is the first variable of the deck (see its top: LAMMPS finds a\n"
    << "# v_ name by a linear search). This release has no min/max of two\n"
    << "# numbers: max(1, n) = n+!n for a contact count n (!n: 1 for n = 0,\n"
    << "# else 0), clamp(x) = (abs(x+cap)-abs(x-cap))/2.\n"
    << "variable        one internal 1\n"
    << "variable        mone internal -1\n"
    << "fix             servo_sign all ave/time 1 1 1 v_one v_mone\n"
    << "variable        load equal " << load << "\n"
    << "fix             servo_load all ave/time 1 1 1 v_load\n";
  if (carry)
    s << "# u: fix servo_prev (after fix servol/servor: at a step's end it still holds\n"
      << "# the step before's moves, the walls' displacements along x), 0 at a run's\n"
      << "# first step (the walls start the loading at rest); a continuation's first\n"
      << "# step carries the moves of the step before it instead (ul_now, ur_now: its\n"
      << "# restart args; servo_ul, servo_ur: this run's, for the args)\n"
      << "variable        servo_carried string f_servo_prev\n"
      << "variable        servo_ul equal f_servo_prev[1]\n"
      << "variable        servo_ur equal f_servo_prev[2]\n"
      << "if              \"${continued} != 0\" then &\n"
      << "                \"variable servo_ul0 internal ${ul_now}\" &\n"
      << "                \"variable servo_ur0 internal ${ur_now}\" &\n"
      << "                \"fix servo_u0 all ave/time 1 1 1 v_servo_ul0 v_servo_ur0\" &\n"
      << "                \"variable servo_carried string (f_servo_prev+!elapsed*f_servo_u0)\" &\n"
      << "                \"variable servo_ul equal f_servo_prev[1]+!elapsed*v_servo_ul0\" &\n"
      << "                \"variable servo_ur equal f_servo_prev[2]+!elapsed*v_servo_ur0\"\n";
  s << "variable        rawv vector " << raw << "\n"
    << "variable        movev vector " << deck::lammps_servo_clamp("v_rawv", "${cap_step}") << "\n"
    << "# the lateral walls' displacements at the run's last step (fix servo_end\n"
    << "# evaluates them there only, before fix servol/servor add that step's move):\n"
    << "# the restart args put a continuation's walls where this run's last step\n"
    << "# had them (to the last bit), and the continuation's servo takes that\n"
    << "# step's move again from there"
    << (carry ? ", with the moves of the step before (servo_ul,\n# servo_ur)\n" : "\n")
    << "variable        end_every equal $((1+v_run_steps+abs(1-v_run_steps))/2)\n"
    << "fix             servo_end all ave/time ${end_every} 1 ${end_every} v_dxl v_dxr"
    << (carry ? " v_servo_ul v_servo_ur\n" : "\n")
    << "# (fix servol and servor, which sum the moves, are defined after fix series\n"
    << "# below)\n\n";
  return s.str();
}

/// A 2D data file after its title line, both engines: the counts, the box
/// (half a width of room left and right, a tenth of the height above and
/// below, the disc thickness in z), the `atoms` heading and the rows "id type
/// diameter density x y z" (density: the areal density f_ms·ρ·t).
std::string data_file_2d(const SceneConfig& c, const Assembly& a, const Plan& plan, int ntypes,
                         const char* atoms) {
  const auto& m = c.material;
  std::ostringstream d;
  const double mx = 0.5 * plan.width0, my = 0.1 * plan.height0;
  d << plan.n << " atoms\n"
    << ntypes << " atom types\n\n"
    << num(a.left - mx) << " " << num(a.right + mx) << " xlo xhi\n"
    << num(a.bottom - my) << " " << num(a.top + my) << " ylo yhi\n"
    << num(-0.5 * m.thickness) << " " << num(0.5 * m.thickness) << " zlo zhi\n\n"
    << atoms << "\n\n";
  char line[160];
  for (int i = 0; i < plan.n; ++i) {
    std::snprintf(line, sizeof line, "%d %d %.17g %.10g %.17g %.17g 0\n", i + 1, plan.type[i],
                  2.0 * a.r[i], plan.areal_density, a.x[i], a.y[i]);
    d << line;
  }
  return d.str();
}

// Data file: atom_style sphere rows "id type diameter density x y z"; the
// density column is overwritten by set density/disc below.
std::string lammps_data_file(const SceneConfig& c, const Assembly& a, const Plan& plan,
                             bool consolidated) {
  return std::string("LAMMPS data file written by demcal ") + DEMCAL_VERSION + " (scene " + c.name +
         (consolidated ? ", consolidated to sigma3)\n\n"
                       : ", as generated: the deck consolidates it)\n\n") +
         data_file_2d(c, a, plan, plan.types, "Atoms # sphere");
}

/// What this LAMMPS cannot do as demcal does, in the deck's header; the
/// same facts go to `out.notes` (stderr at export).
std::string lammps_limitations(const AlgorithmSpec& p, const Plan& plan, ExportResult& out) {
  std::ostringstream s;
  s << "#\n# What this LAMMPS cannot do as demcal does, and what the deck does instead:\n"
    << "#  - rotational damping: this release (29 Sep 2021) has no rotational viscous fix;\n";
  if (p.damping_ratio_rotation > 0.0) {
    s << "#    zeta_r = " << num(p.damping_ratio_rotation)
      << " is NOT applied. LAMMPS releases from 2022 on have fix viscous/sphere:\n"
      << "#    uncomment the line marked viscous/sphere below there.\n";
    out.notes.push_back(deck::lammps_rotational_damping_note(p.damping_ratio_rotation));
  } else {
    s << "#    not needed here, the calibrated zeta_r is 0.\n";
  }
  s << "#  - damping is applied explicitly by fix viscous (force -gamma*v from the\n"
    << "#    velocity-Verlet half-step velocity), semi-implicitly by demcal's central\n"
    << "#    difference: same continuous equation; the timestep carries the factor f\n"
    << "#    above so that the explicit drag does not cost the stability margin.\n"
    << "#  - servo walls are not native: the lateral walls are fix wall/gran/region\n"
    << "#    planes whose displacement is the running sum of demcal's per-step servo\n"
    << "#    move gain*(sigma3 - p)*H*t/(R*n_contacts)";
  if (plan.servo_carry > 0.0)
    s << " plus (R - kn_wall)/R of the\n"
      << "#    wall's last move (contact damping: demcal's wall dashpots), capped at\n"
      << "#    " << deck::servo_cap_text()
      << ", kept by fix ave/time (running mean times the steps of\n"
      << "#    this run); a split run restarts it from the walls' positions and last\n"
      << "#    moves (see restart_from).\n";
  else
    s << ", capped at " << deck::servo_cap_text() << ",\n"
      << "#    kept by fix ave/time (running mean times the steps of this run); a split\n"
      << "#    run restarts it from the walls' positions (see restart_from).\n";
  s << "#  - the moving walls act on bands of particles near them (see the walls).\n";
  if (plan.types > 1) {
    s << "#  - per-particle damping D_t ~ sqrt(m): fix viscous has one gamma per atom type,\n"
      << "#    so the particles are grouped in " << plan.types << " radius classes (types 1.."
      << plan.types << ").\n";
    out.notes.push_back(deck::lammps_class_damping_note(plan.types, plan.class_error, "particle"));
  }
  out.notes.push_back(
      "lateral servo walls emulated with variables (running sum of demcal's per-step servo "
      "move); a split run carries their positions in its restart args");
  return s.str();
}

/// The block a user edits; every other number of the deck derives from it.
std::string lammps_parameters(const SceneConfig& c, const Assembly& a, const Plan& plan,
                              const ExportOptions& o) {
  const auto& m = c.material;
  const char* wall_style = o.consolidate_in_deck ? "index " : "equal ";
  const DeckFiles files = deck_files(o.deck_name);
  std::ostringstream s;
  s << "\n# --- parameters (edit here) -------------------------------------------------\n"
    << "# Everything below the block is derived from it: editing dt or nstep keeps the\n"
    << "# strain, the loading rate per step count, the servo cap and the monitoring\n"
    << "# points right.\n"
    << "variable dt        equal " << num(plan.dt) << "      # s\n"
    << deck::lammps_servo_dt(plan.demcal_dt, num) << "variable nstep     equal " << plan.steps
    << "      # loading steps Nstep\n"
    << "variable strain    equal " << num(c.test.vertical_strain)
    << "      # total vertical strain over nstep\n"
    << "variable monitor_points equal " << c.test.monitor_points
    << "      # rows of the series file\n"
    << deck::lammps_material_variables(m, num) << "variable thick     equal " << num(m.thickness)
    << "      # disc thickness t, m\n"
    << "variable sigma3    equal " << num(c.test.lateral_stress) << "      # Pa\n"
    << "variable gain      equal " << num(c.test.servo_gain) << "\n"
    << "variable r_min     equal " << num(plan.r_min) << "      # m, smallest radius\n"
    << "variable r_max     equal " << num(plan.r_max)
    << "      # m, largest radius\n"
    // With stage 1 the start walls are those it ends with, kept as index
    // variables: a continued run gets them on its command line (restart args).
    << "variable xl0       " << wall_style << num(a.left) << "      # walls at the start, m\n"
    << "variable xr0       " << wall_style << num(a.right) << "\n"
    << "variable yb0       " << wall_style << num(a.bottom) << "\n"
    << "variable yt0       " << wall_style << num(a.top) << "\n"
    << deck::series_variable(o)
    << "# A split run: the first part writes ${restart_out} and ${restart_out}.args at its\n"
    << "# end; continue it with  lmp $(cat " << files.restart_args << ") -in THIS_DECK\n"
    << "# (the args give continued, restart_from, series and the lateral walls' positions,\n"
    << (plan.servo_carry > 0.0 ? "# xl_now, xr_now, and their last moves, ul_now, ur_now).\n"
                               : "# xl_now, xr_now).\n")
    << "variable continued index 0      # 1: continue from ${restart_from}\n"
    << "variable restart_from index " << files.restart << "\n"
    << "variable restart_out index " << files.restart << "\n"
    << "variable xl_now    index ${xl0}      # lateral walls where this run starts\n"
    << "variable xr_now    index ${xr0}\n";
  if (plan.servo_carry > 0.0)
    s << "variable ul_now    index 0      # their moves at the step before it (m, along x)\n"
      << "variable ur_now    index 0\n";
  s << "variable run_steps index ${nstep}      # run up to this step; -var run_steps 300 for a "
       "check\n";
  if (o.consolidate_in_deck) s << deck::lammps_consolidation_parameters(c.test);
  return s.str();
}

/// Quantities LAMMPS derives from the parameters block (and the start walls).
std::string lammps_derived(const Plan& plan) {
  std::ostringstream s;
  s << "\n# --- derived (do not edit) ---------------------------------------------------\n"
    << "variable H0        equal $(v_yt0-v_yb0)\n"
    << deck::lammps_loading_derived(plan.wall_dashpot, num, "disc", plan.servo_carry)
    << deck::lammps_band("band_v", "v_strain*v_H0", "m, see the walls")
    << deck::lammps_band("band_h", "2*v_strain*(v_xr0-v_xl0)")
    << "# the per-step constants of the top wall's move and the servo, folded now\n"
    << "# (a number in a formula evaluated every step costs a parse there)\n"
    << "variable dy_step   equal $(v_vtop*v_dt)      # m, the top wall's move per step\n"
    << "variable load0     equal $(v_sigma3*v_thick*v_H0)      # N, sigma3*H*t at the start\n"
    << "variable load_step equal $(v_sigma3*v_thick*v_vtop*v_dt)      # N, its decrease per step\n";
  return s.str();
}

/// The pair style's gamma_n for demcal's contact damping: demcal
/// ratio·2·sqrt(kn·m_eff), LAMMPS m_eff·gamma_n, so gamma_n =
/// ratio·2·sqrt(kn/m_eff), taken at the mean mass (m_eff = m/2); 0 without.
double contact_gamma_n(const SceneConfig& c, const Plan& plan) {
  return deck::contact_gamma_n(c.material, plan.scales.mass_mean);
}

/// Units, particles (data file or restart), masses, contact law, integrator.
std::string lammps_system(const SceneConfig& c, const Plan& plan, const ExportOptions& o,
                          ExportResult& out) {
  const double gamma_n = contact_gamma_n(c, plan);
  if (gamma_n > 0.0)
    out.notes.push_back(
        "contact damping mapped at the mean particle mass; the walls carry no dashpots here "
        "(demcal's do), so a servo move meets kn_wall alone while the servo is demcal's: it "
        "divides by R = kn_wall + c/dt and carries (R - kn_wall)/R of the wall's last move "
        "(measured on hex_5x5, zeta_c 0.25: servo criterion 5e-4 and peak 5e-5 relative from "
        "demcal's; fcc_4x4x4, zeta_c 0.3: both equal to 5 digits; engines.md sections 20, 24)");
  std::ostringstream s;
  s << deck::lammps_system_head(2, "f f p")
    << "if              \"${continued} == 0\" then \"read_data " << deck_files(o.deck_name).data
    << "\" else \"read_restart ${restart_from}\"\n"
    << "variable        step0 equal $(step)\n"
    << "# disc masses m = f_ms*rho*t*pi*r^2 and inertia m*r^2/2 (fix nve/sphere disc)\n"
    << "set             type 1*" << plan.types << " density/disc " << num(plan.areal_density)
    << "\n\n"
    << deck::lammps_contact_law(gamma_n, plan.r_min, "disc");
  return s.str();
}

/// Global damping per radius class (fix viscous ... scale), then enforce2d.
std::string lammps_damping(const AlgorithmSpec& p, const Plan& plan) {
  std::ostringstream s;
  s << deck::lammps_translational_damping(p.damping_ratio_translation, plan.gamma_t, num);
  if (p.damping_ratio_rotation > 0.0) {
    s << "# LAMMPS >= 2022 only (absent in 29 Sep 2021): rotational damping, N*m*s\n"
      << "#fix            dampr all viscous/sphere " << num(plan.gamma_r[0]);
    for (int k = 1; k < plan.types; ++k)
      s << " scale " << k + 1 << " " << num(plan.gamma_r[k] / plan.gamma_r[0]);
    s << "\n";
  }
  s << "fix             twod all enforce2d\n\n";
  return s.str();
}

/// Stage 1's step and servo resistance: demcal's consolidation (alpha 0.2,
/// shrunk for contact dashpots, scene/biaxial.cpp) times the explicit
/// damper's factor f(zeta) (Plan), at the light and at critical damping.
struct ConsolidationSteps {
  double alpha = 0.0, dt_light = 0.0, dt_damped = 0.0;
  std::string resist;  ///< the servo's R: kn_wall (+ the wall dashpots' c/dt)
  /// the servo's carry at dt_light and dt_damped (0 without contact damping)
  double carry_light = 0.0, carry_damped = 0.0;
};

ConsolidationSteps consolidation_steps(const SceneConfig& c, const Plan& plan) {
  const auto& m = c.material;
  ConsolidationSteps st;
  st.alpha = consolidation_alpha(m.contact_damping_ratio, 2, plan.r_min, plan.r_max);
  st.dt_light = deck::consolidation_dt(st.alpha, kConsolidationDampingRatio, plan.dt_crit);
  st.dt_damped = deck::consolidation_dt(st.alpha, 1.0, plan.dt_crit);
  // the wall dashpots' c (servo_wall_dashpot: demcal's formula)
  st.resist =
      plan.wall_dashpot > 0.0 ? "(${kn_wall}+" + num(plan.wall_dashpot) + "/dt)" : "${kn_wall}";
  st.carry_light = deck::servo_carry_at(m, plan.m_max, st.dt_light);
  st.carry_damped = deck::servo_carry_at(m, plan.m_max, st.dt_damped);
  return st;
}

/// Stage 1's fix viscous at damping ratio z, per radius class.
std::string consolidation_viscous(const SceneConfig& c, const Plan& plan, double z) {
  std::vector<double> gamma;
  for (int k = 0; k < plan.types; ++k) {
    const double r = 0.5 * (plan.r_lo[k] + plan.r_hi[k]);
    gamma.push_back(
        z * 2.0 *
        std::sqrt(c.material.particle.kn * plan.areal_density * std::numbers::pi * r * r));
  }
  return deck::lammps_consolidation_viscous(gamma);
}

/// Stage 1's walls, in compute cons_wn's (cons_wf's) order.
std::vector<deck::ConsolidationWall> consolidation_walls() {
  return {{"l", 'x', true, 1, "c_cons_wf[1]/(v_cons_H*v_thick)"},
          {"r", 'x', false, 2, "-c_cons_wf[2]/(v_cons_H*v_thick)"},
          {"b", 'y', true, 3, "c_cons_wf[3]/(v_cons_W*v_thick)"},
          {"t", 'y', false, 4, "-c_cons_wf[4]/(v_cons_W*v_thick)"}};
}

/// Stage 1's walls and servo: four planes moved by demcal's per-step law.
std::string lammps_consolidation_walls(const SceneConfig& c, const Plan& plan,
                                       const ConsolidationSteps& st) {
  const double zeta = kConsolidationDampingRatio;
  const double alpha = st.alpha, dt_light = st.dt_light;
  // move = gain*(sigma3*L*t - F)/(R*max(1, n)), clamped to +-cap, per wall
  // (deck::lammps_consolidation_servo): L the wall's length (H for left and
  // right, W for bottom and top), F, n its force on the particles and
  // contacts (compute cons_wf, cons_wn: left, right, bottom, top)
  const std::vector<deck::ConsolidationWall> walls = consolidation_walls();
  std::ostringstream s;
  s << "# --- stage 1: consolidation to isotropic sigma3 -------------------------------\n"
    << "# demcal's consolidation (demcal export --consolidate-in deck), run here so\n"
    << "# that it scales under MPI: all four walls servoed with the loading's law\n"
    << "# (each wall: move = gain*(sigma3*L*t - F)/(" << (plan.wall_dashpot > 0.0 ? "R" : "kn_wall")
    << "*max(1, n)) per step, ";
  if (plan.wall_dashpot > 0.0)
    s << "R =\n# kn_wall + c/dt, c the wall dashpots' (demcal's servo_resistance), plus\n"
      << "# (R - kn_wall)/R of its last move (demcal's consolidation servo), cap\n";
  else
    s << "cap\n";
  s << "# " << deck::servo_cap_text() << "), global damping zeta " << num(zeta)
    << " on translation (demcal also damps\n"
    << "# rotation; this LAMMPS cannot), particle friction 0 until static, then\n"
    << deck::lammps_consolidation_comment(zeta, "particle", "xl0 xr0 yb0 yt0")
    << "if              \"${consolidate} == 0 || ${continued} != 0\" then \"jump SELF "
       "loading\"\n"
    << deck::lammps_consolidation_start(alpha, dt_light, c.test.consolidation_max_steps)
    << "variable        cons_dxl equal f_cons_servo[1]*(step-${cons_s0})\n"
    << "variable        cons_dxr equal f_cons_servo[2]*(step-${cons_s0})\n"
    << "variable        cons_dyb equal f_cons_servo[3]*(step-${cons_s0})\n"
    << "variable        cons_dyt equal f_cons_servo[4]*(step-${cons_s0})\n"
    << "region          cons_rl plane ${xl0} 0 0  1 0 0 side in move v_cons_dxl NULL NULL "
       "units box\n"
    << "region          cons_rr plane ${xr0} 0 0 -1 0 0 side in move v_cons_dxr NULL NULL "
       "units box\n"
    << "region          cons_rb plane 0 ${yb0} 0 0  1 0 side in move NULL v_cons_dyb NULL "
       "units box\n"
    << "region          cons_rt plane 0 ${yt0} 0 0 -1 0 side in move NULL v_cons_dyt NULL "
       "units box\n";
  const char* w[] = {"l", "r", "b", "t"};
  for (const char* x : w)
    s << "fix             cons_w" << x << " all wall/gran/region hooke/history ${kn_wall} "
      << "${kt_wall} 0 0 ${mu_wall} 0 region cons_r" << x << " contacts\n";
  s << "fix             cons_fcon all store/force\n"
    << consolidation_viscous(c, plan, zeta) << "\n"
    << "fix             cons_twod all enforce2d\n"
    << deck::lammps_consolidation_reductions(walls)
    << "variable        cons_xl equal v_xl0+v_cons_dxl\n"
    << "variable        cons_xr equal v_xr0+v_cons_dxr\n"
    << "variable        cons_yb equal v_yb0+v_cons_dyb\n"
    << "variable        cons_yt equal v_yt0+v_cons_dyt\n"
    << "variable        cons_H equal v_cons_yt-v_cons_yb\n"
    << "variable        cons_W equal v_cons_xr-v_cons_xl\n"
    << deck::lammps_consolidation_servo(walls, {"cons_H", "cons_W"}, "*${thick}", st.resist,
                                        st.carry_light);
  return s.str();
}

/// Stage 1's end: the loading's start walls, particles at rest, step 0
/// (`carry`: the servo's fix cons_prev goes too).
std::string lammps_consolidation_end(bool carry) {
  const std::vector<deck::ConsolidationWall> walls = consolidation_walls();
  const char* start[] = {"xl0", "xr0", "yb0", "yt0"};
  std::ostringstream s;
  s << "# the loading starts from here: walls, step 0, particles at rest. Each wall\n"
    << "# where its contacts put it (F = kn_wall * sum of overlaps, exact for these\n"
    << "# undamped walls), so the loading starts from the forces of the static state.\n";
  for (const char* v : start) s << "variable        " << v << " delete\n";
  for (int i = 0; i < 4; ++i)
    s << "variable        " << start[i] << " index " << deck::lammps_consolidated_wall(walls[i], i)
      << "\n";
  s << "variable        xl_now delete\n"
    << "variable        xr_now delete\n"
    << "variable        xl_now index ${xl0}\n"
    << "variable        xr_now index ${xr0}\n"
    << deck::lammps_consolidation_end(walls,
                                      carry ? std::vector<std::string>{"cons_twod", "cons_prev"}
                                            : std::vector<std::string>{"cons_twod"});
  return s.str();
}

/// Stage 1 of a deck that consolidates itself (ExportOptions::
/// consolidate_in_deck): demcal's consolidation (scene/biaxial.cpp) in
/// LAMMPS, under MPI. Four walls servoed to sigma3 with demcal's per-step law,
/// frictionless until static, then with friction until static again; light
/// global damping, critical after a quarter of the budget; static = every
/// wall within cons_tol of sigma3 and the unbalanced-force ratio below
/// cons_unbalanced, checked every cons_check steps (fix halt). At the end the
/// walls' positions become the loading's start walls and the step count 0.
std::string lammps_consolidation(const SceneConfig& c, const Plan& plan, double gamma_n) {
  const ConsolidationSteps st = consolidation_steps(c, plan);
  return lammps_consolidation_walls(c, plan, st) +
         deck::lammps_consolidation_criterion(2, consolidation_walls(), {"h", "v"}) +
         deck::lammps_consolidation_runs(gamma_n, st.dt_damped, consolidation_viscous(c, plan, 1.0),
                                         st.carry_damped) +
         lammps_consolidation_end(st.carry_light > 0.0);
}

/// Thermo, the run up to run_steps, and the restart a split run continues
/// (with stage 1, the args also carry the start walls it found).
std::string lammps_run(bool consolidate_in_deck, bool carry) {
  std::ostringstream s;
  s << "# the servo's running sums of the moves, after fix series: a row prints the\n"
    << "# lateral walls where this step's forces had them (the sum before this\n"
    << "# step's move), in a single run and in a continued one alike; one fix per\n"
    << "# wall, a scalar each (dxl and dxr read them every step: no index to parse)\n"
    << "fix             servol all ave/time 1 1 1 v_movev[1] ave running\n"
    << "fix             servor all ave/time 1 1 1 v_movev[2] ave running\n";
  if (carry)
    s << "# the moves of this step, the servo's last ones at the next (with contact\n"
      << "# damping it carries them)\n"
      << deck::lammps_previous_moves("servo_prev", "movev", 2);
  s << "# the clearance checks, last in the fix list (the fixes above are found by\n"
    << "# name every step, by a linear search)\n"
    << "fix             halt_top all halt ${monitor_every} v_clear_top < 0.0 error hard\n"
    << "fix             halt_bottom all halt ${monitor_every} v_clear_bottom < 0.0 error hard\n"
    << "fix             halt_left all halt ${monitor_every} v_clear_left < 0.0 error hard\n"
    << "fix             halt_right all halt ${monitor_every} v_clear_right < 0.0 error hard\n"
    << "\n"
    << "# --- output and run ----------------------------------------------------------\n"
    << "# p_left, p_right: lateral wall pressures (servo target sigma3); p_top: axial\n"
    << "variable        epsyy equal (v_H-v_H0)/v_H0\n"
    << "thermo_style    custom step dt time v_epsyy v_pt v_pl v_pr v_W v_H ke\n"
    << deck::lammps_thermo_modify() << "thermo          ${monitor_every}\n"
    << "run             ${run_steps} upto\n"
    << "write_restart   ${restart_out}\n"
    << "print           \"-var continued 1 -var restart_from ${restart_out} -var series "
       "${series} -var xl_now "
       "$(v_xl_now+f_servo_end[1]) -var xr_now $(v_xr_now+f_servo_end[2])"
    << (carry ? " -var ul_now $(f_servo_end[3]) -var ur_now $(f_servo_end[4])" : "")
    << (consolidate_in_deck ? " -var xl0 ${xl0} -var xr0 ${xr0} -var yb0 ${yb0} -var yt0 ${yt0}"
                            : "")
    << "\" file ${restart_out}.args screen no\n";
  return s.str();
}

ExportResult lammps(const SceneConfig& c, const AlgorithmSpec& p, const Assembly& a,
                    const ExportOptions& o) {
  const Plan plan = make_plan(c, p, a, o.max_types);
  ExportResult out = result_of(plan);
  out.files[deck_files(o.deck_name).data] = lammps_data_file(c, a, plan, !o.consolidate_in_deck);
  std::ostringstream s;
  s << mapping_header(c, p, plan, o, "LAMMPS") << lammps_limitations(p, plan, out)
    << "# (the servo's per-step formula, defined below, comes first in LAMMPS'\n"
    << "# variable list: a formula finds a v_ name by a linear search)\n"
    << "variable rawv      vector 0\n\n"
    << lammps_parameters(c, a, plan, o);
  if (o.consolidate_in_deck)
    s << lammps_system(c, plan, o, out) << lammps_consolidation(c, plan, contact_gamma_n(c, plan))
      << lammps_derived(plan);
  else
    s << lammps_derived(plan) << lammps_system(c, plan, o, out);
  const bool carry = plan.servo_carry > 0.0;
  s << lammps_walls(normal_only_walls(c.material)) << lammps_servo(carry) << lammps_damping(p, plan)
    << lammps_series_block(c, p, plan) << lammps_run(o.consolidate_in_deck, carry);
  out.deck = s.str();
  return out;
}

// ---------------------------------------------------------------------------
// LIGGGHTS-PUBLIC 3.x (runs with LIGGGHTS 3.8; servo not tuned)

std::string stl_rectangle(const std::string& name, double x0, double y0, double x1, double y1,
                          double z0, double z1) {
  // A vertical rectangle from (x0, y0) to (x1, y1), z0..z1, as two facets.
  std::ostringstream s;
  const double nx = y1 - y0, ny = -(x1 - x0);
  const double len = std::hypot(nx, ny);
  auto v = [&](double x, double y, double z) {
    s << "      vertex " << num(x) << " " << num(y) << " " << num(z) << "\n";
  };
  s << "solid " << name << "\n";
  for (int f = 0; f < 2; ++f) {
    s << "  facet normal " << num(nx / len) << " " << num(ny / len) << " 0\n    outer loop\n";
    if (f == 0) {
      v(x0, y0, z0);
      v(x1, y1, z0);
      v(x1, y1, z1);
    } else {
      v(x0, y0, z0);
      v(x1, y1, z1);
      v(x0, y0, z1);
    }
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid " << name << "\n";
  return s.str();
}

/// The LIGGGHTS deck's monitoring series: the LAMMPS deck's file (kColumns,
/// demcal.series/1), at demcal's monitoring points, from LIGGGHTS' per-atom
/// wall forces (`store_force yes`; the mesh walls are one fix: top, left and
/// right add up on a particle, split at the corners with the meshes' own
/// totals) and the total force.
std::string liggghts_series_block(const SceneConfig& c, const AlgorithmSpec& p, const Plan& plan,
                                  const Assembly& a, const ExportOptions& o) {
  const auto& m = c.material;
  const std::string t = num(m.thickness);
  std::ostringstream s;
  s << "\n# --- monitoring series (demcal score FILE) -----------------------------------\n"
    << "# Written to ${series} at the start and every " << plan.thermo_every
    << " steps (demcal's monitoring points),\n"
    << "# the LAMMPS deck's columns, tension positive, SI units, origin at the box centre:\n"
    << "#   step, strain_yy          (H - H0)/H0\n"
    << "#   b_xx b_xy b_yx b_yy      boundary stress (1/V) sum_wall (x^c - c) (x) f^c, from\n"
    << "#                            the walls' per-atom forces (store_force yes): a lateral\n"
    << "#                            wall's contact at (x_wall, y), the top's and the\n"
    << "#                            bottom's at (x, y_wall), the foot of the normal\n"
    << "#   s_xx s_xy s_yx s_yy      homogenized stress, from the identity\n"
    << "#                            V (b - sigma) = sum_p (x_p - c) (x) F_p, F_p the\n"
    << "#                            contact force (before damping, recovered below)\n"
    << "#   kinetic_energy           translation + rotation, disc inertia m r^2/2: LIGGGHTS\n"
    << "#   kinetic_energy_rotation  3.8's fix nve/sphere rotates with m r^2/2 under\n"
    << "#                            dimension 2 (as demcal), so this is the energy of its\n"
    << "#                            motion [J]\n"
    << "#   lateral_stress_error     ((p_left + p_right)/2 - sigma3)/sigma3 (servo)\n"
    << "#   p_left p_right p_bottom p_top  compressive wall pressures on the current\n"
    << "#                            height and width [Pa]\n"
    << "#   wall_left wall_right wall_bottom wall_top  wall positions [m]\n"
    << "#   torque_stress            sum of the particles' contact torques / V [Pa]\n"
    << "# The top, left and right walls are one fix (LIGGGHTS allows one mesh wall fix):\n"
    << "# a particle touching one of them has all its force there; a corner particle's\n"
    << "# is split with the meshes' own totals (below). Exact with and without wall\n"
    << "# friction while each top corner holds one particle at most; approximated\n"
    << "# (the corner's particles at their mean position) when more touch both walls.\n"
    << "# Lever arm: LIGGGHTS applies a contact's tangential force at r_i - delta/2 as\n"
    << "# demcal does (walls: r_i - delta/2, demcal r_i - delta; the same without wall\n"
    << "# friction), so s_xy - s_yx = torque_stress: no lever-arm floor (the LAMMPS deck\n"
    << "# has one).\n"
    << deck::series_variable(o) << "variable sigma3 equal " << num(c.test.lateral_stress) << "\n"
    << "variable nstep equal " << plan.steps << "\n"
    << "variable dt equal " << num(plan.dt) << "\n"
    << "variable yb equal " << num(a.bottom) << "\n"
    << "variable yt equal " << num(a.top) << "-" << num(plan.top_speed) << "*step*" << num(plan.dt)
    << "\n"
    << "variable xl equal f_mleft[7]\n"
    << "variable xr equal f_mright[7]\n"
    << "variable H equal v_yt-v_yb\n"
    << "variable W equal v_xr-v_xl\n"
    << "variable cx equal (v_xl+v_xr)/2\n"
    << "variable cy equal (v_yb+v_yt)/2\n"
    << "variable V equal v_W*v_H*" << t << "\n"
    << "variable epsyy equal (v_H-" << num(plan.height0) << ")/" << num(plan.height0) << "\n"
    << "compute pa all property/atom radius omegaz tqz\n"
    << "# the walls a particle touches (overlap > 0); a corner particle touches a\n"
    << "# lateral wall and the top at once, the others one mesh wall at most\n"
    << "variable ll_a atom (x-c_pa[1])<v_xl\n"
    << "variable lr_a atom (x+c_pa[1])>v_xr\n"
    << "variable lt_a atom (y+c_pa[1])>v_yt\n"
    << "variable cl_a atom v_ll_a*v_lt_a\n"
    << "variable cr_a atom v_lr_a*v_lt_a\n"
    << "variable one_a atom 1-v_cl_a-v_cr_a\n"
    << "variable sl_a atom v_ll_a*(1-v_lt_a)\n"
    << "variable sr_a atom v_lr_a*(1-v_lt_a)\n"
    << "variable st_a atom v_lt_a*(1-v_ll_a)*(1-v_lr_a)\n"
    << "# its one wall's contact point: (x_wall, y) on a lateral wall, (x, y_top)\n"
    << "variable xc_a atom v_ll_a*v_xl+v_lr_a*v_xr+v_lt_a*x\n"
    << "variable yc_a atom (v_ll_a+v_lr_a)*y+v_lt_a*v_yt\n"
    << "# wall forces on the particle: the meshes' (top, left, right), the bottom's\n"
    << "variable fwx_a atom f_force_walls[1]\n"
    << "variable fwy_a atom f_force_walls[2]\n"
    << "variable fbx_a atom f_force_bottom[1]\n"
    << "variable fby_a atom f_force_bottom[2]\n"
    << "variable fx_a atom v_fwx_a+v_fbx_a\n"
    << "variable fy_a atom v_fwy_a+v_fby_a\n"
    << "# x^c (x) f^c about the origin of the one-wall particles' contacts and the\n"
    << "# bottom's (at (x, y_bottom)); the corners' below\n"
    << "variable bxx_a atom v_one_a*v_xc_a*v_fwx_a+x*v_fbx_a\n"
    << "variable bxy_a atom v_one_a*v_xc_a*v_fwy_a+x*v_fby_a\n"
    << "variable byx_a atom v_one_a*v_yc_a*v_fwx_a+v_yb*v_fbx_a\n"
    << "variable byy_a atom v_one_a*v_yc_a*v_fwy_a+v_yb*v_fby_a\n"
    << deck::lammps_contact_force_atom(2, p.damping_ratio_translation, plan.gamma_t, num, "0")
    << "variable mxx_a atom x*v_fc1_a\n"
    << "variable mxy_a atom x*v_fc2_a\n"
    << "variable myx_a atom y*v_fc1_a\n"
    << "variable myy_a atom y*v_fc2_a\n"
    << "variable ket_a atom 0.5*mass*(vx*vx+vy*vy)\n"
    << "variable ker_a atom 0.25*mass*c_pa[1]*c_pa[1]*c_pa[2]*c_pa[2]\n";
  // The per-particle sums: [16..20] the one-wall particles' forces per wall,
  // [21..25] and [26..30] the left and right corners' forces, positions, count.
  for (const char* w : {"sl", "sr"})
    s << "variable " << w << "x_a atom v_" << w << "_a*v_fwx_a\n"
      << "variable " << w << "y_a atom v_" << w << "_a*v_fwy_a\n";
  s << "variable sty_a atom v_st_a*v_fwy_a\n";
  for (const char* w : {"cl", "cr"})
    s << "variable " << w << "x_a atom v_" << w << "_a*v_fwx_a\n"
      << "variable " << w << "y_a atom v_" << w << "_a*v_fwy_a\n"
      << "variable " << w << "X_a atom v_" << w << "_a*x\n"
      << "variable " << w << "Y_a atom v_" << w << "_a*y\n";
  s << "compute meas all reduce sum v_bxx_a v_bxy_a v_byx_a v_byy_a v_fx_a v_fy_a &\n"
    << "        v_mxx_a v_mxy_a v_myx_a v_myy_a v_fc1_a v_fc2_a v_ket_a v_ker_a c_pa[3] &\n"
    << "        v_slx_a v_sly_a v_srx_a v_sry_a v_sty_a &\n"
    << "        v_clx_a v_cly_a v_clX_a v_clY_a v_cl_a v_crx_a v_cry_a v_crX_a v_crY_a v_cr_a &\n"
    << "        v_fby_a\n"
    << "# A corner particle's force is two walls' (one mesh wall fix): its lateral\n"
    << "# wall's part is that wall's total (the mesh's own, -f_m on the particles)\n"
    << "# less its one-wall particles', the rest the top's. At the start the meshes\n"
    << "# have no totals yet and no wall carries a tangential force (the tangential\n"
    << "# springs start at zero): the corners' x force is the lateral wall's.\n"
    << "# Positions: the mean over a corner's particles (one in a packed sample:\n"
    << "# exact; more share the wall forces as if at their mean).\n"
    << "variable gLx equal (step>0)*(-f_mleft[1]-c_meas[16])+(step==0)*c_meas[21]\n"
    << "variable gLy equal (step>0)*(-f_mleft[2]-c_meas[17])\n"
    << "variable gRx equal (step>0)*(-f_mright[1]-c_meas[18])+(step==0)*c_meas[26]\n"
    << "variable gRy equal (step>0)*(-f_mright[2]-c_meas[19])\n"
    << "variable tLx equal c_meas[21]-v_gLx\n"
    << "variable tLy equal c_meas[22]-v_gLy\n"
    << "variable tRx equal c_meas[26]-v_gRx\n"
    << "variable tRy equal c_meas[27]-v_gRy\n"
    << "variable xcl equal c_meas[23]/(c_meas[25]+(c_meas[25]==0))\n"
    << "variable ycl equal c_meas[24]/(c_meas[25]+(c_meas[25]==0))\n"
    << "variable xcr equal c_meas[28]/(c_meas[30]+(c_meas[30]==0))\n"
    << "variable ycr equal c_meas[29]/(c_meas[30]+(c_meas[30]==0))\n"
    << "variable kxx equal v_xl*v_gLx+v_xcl*v_tLx+v_xr*v_gRx+v_xcr*v_tRx\n"
    << "variable kxy equal v_xl*v_gLy+v_xcl*v_tLy+v_xr*v_gRy+v_xcr*v_tRy\n"
    << "variable kyx equal v_ycl*v_gLx+v_yt*v_tLx+v_ycr*v_gRx+v_yt*v_tRx\n"
    << "variable kyy equal v_ycl*v_gLy+v_yt*v_tLy+v_ycr*v_gRy+v_yt*v_tRy\n"
    << "variable b_xx equal (c_meas[1]+v_kxx-v_cx*c_meas[5])/v_V\n"
    << "variable b_xy equal (c_meas[2]+v_kxy-v_cx*c_meas[6])/v_V\n"
    << "variable b_yx equal (c_meas[3]+v_kyx-v_cy*c_meas[5])/v_V\n"
    << "variable b_yy equal (c_meas[4]+v_kyy-v_cy*c_meas[6])/v_V\n"
    << "variable s_xx equal v_b_xx-(c_meas[7]-v_cx*c_meas[11])/v_V\n"
    << "variable s_xy equal v_b_xy-(c_meas[8]-v_cx*c_meas[12])/v_V\n"
    << "variable s_yx equal v_b_yx-(c_meas[9]-v_cy*c_meas[11])/v_V\n"
    << "variable s_yy equal v_b_yy-(c_meas[10]-v_cy*c_meas[12])/v_V\n"
    << "variable ke equal c_meas[13]+c_meas[14]\n"
    << "variable ke_rot equal c_meas[14]\n"
    << "variable torque equal c_meas[15]/v_V\n"
    << "variable pl equal (c_meas[16]+v_gLx)/(v_H*" << t << ")\n"
    << "variable pr equal -(c_meas[18]+v_gRx)/(v_H*" << t << ")\n"
    << "variable pt equal -(c_meas[20]+v_tLy+v_tRy)/(v_W*" << t << ")\n"
    << "variable pb equal c_meas[31]/(v_W*" << t << ")\n"
    << "variable servo_err equal ((v_pl+v_pr)/2-v_sigma3)/v_sigma3\n"
    << "variable stepn equal step\n";
  const std::string row =
      "${stepn},${epsyy},${b_xx},${b_xy},${b_yx},${b_yy},${s_xx},${s_xy},${s_yx},${s_yy},"
      "${ke},${ke_rot},${servo_err},${pl},${pr},${pb},${pt},${xl},${xr},${yb},${yt},${torque}";
  s << "# the header: what demcal score needs to know about the run\n"
    << deck::liggghts_series("LIGGGHTS deck", c.name, plan.n, p.damping_ratio_translation,
                             plan.dt_crit, p.mass_scaling, plan.thermo_every, row, kColumns);
  return s.str();
}

/// The 2D LIGGGHTS deck's data file. LIGGGHTS with dimension 2 computes a
/// particle's mass as π·r²·density: the areal density f_ms·ρ·t gives the
/// disc's mass f_ms·ρ·t·π·r².
std::string liggghts_data_2d(const SceneConfig& c, const Plan& plan, const Assembly& a,
                             int ntypes) {
  return std::string("LIGGGHTS data file written by demcal ") + DEMCAL_VERSION + " (scene " +
         c.name + ")\n\n" + data_file_2d(c, a, plan, ntypes, "Atoms");
}

/// The 2D LIGGGHTS deck's header: the mapping, how its servo follows
/// demcal's (LIGGGHTS' mesh servo, or with contact damping demcal's carried
/// law, `carry` > 0) and the differences from demcal.
std::string liggghts_header_2d(const SceneConfig& c, const AlgorithmSpec& p, const Plan& plan,
                               const ExportOptions& o, double carry, int n_left, int n_right) {
  const bool carried = carry > 0.0;
  std::ostringstream s;
  s << mapping_header(c, p, plan, o, "LIGGGHTS");
  s << "#\n# Checked with LIGGGHTS 3.8 (Debian): on a 25-disc sample it scores as demcal's\n"
    << "# run (same verdict, peak within 1 %: a test, where liggghts is installed;\n"
    << "# reports/engines.md). It writes demcal's monitoring series: demcal score\n"
    << "# " << deck_files(o.deck_name).series << "\n";
  if (carried)
    s << "# Servo: demcal's law with contact damping (below, before the run): each step\n"
      << "# a lateral wall moves by gain*(F_target - F)/(R*max(1, n)) + carry*(its last\n"
      << "# move), clamped to +-cap, n its current contacts, in demcal's step\n"
      << "# dt_demcal = dt/f. R = kn_wall + c/dt_demcal = " << num(plan.servo_resist) << " N/m:\n"
      << "# demcal's wall contacts resist a move within its step by their dashpots\n"
      << "# too, c = 2*zeta_c*sqrt(kn_wall*m_max) = " << num(plan.wall_dashpot)
      << " N*s/m (the heaviest disc's);\n"
      << "# carry = (R - kn_wall)/R = " << num(carry)
      << ". F_target = sigma3*H*t follows the current\n"
      << "# height (v_ftl), demcal's target.\n";
  else
    s << "# Servo: LIGGGHTS moves the mesh at vel_max * kp * (F_target - F)/|F_target|;\n"
      << "# vel_max = cap/dt_demcal (dt_demcal = dt/f, demcal's step) and\n"
      << "# kp = gain*|F_target|/(R*max(1, n)*cap), n the wall's current contacts,\n"
      << "# give demcal's wall velocity gain*(F_target - F)/(R*max(1, n)*dt_demcal)\n"
      << "# and its cap; R = kn_wall\n"
      << "# LIGGGHTS' kp is a number: the run goes in chunks of\n"
      << "# ${servo_every} steps (one setup) and kp is set from the current n and\n"
      << "# F_target between them (fix_modify servo/ctrlParam; at the start from\n"
      << "# demcal's counts, " << n_left << " left and " << n_right << " right): the gain\n"
      << "# lags demcal's by one chunk at most. F_target = sigma3*H*t follows the\n"
      << "# current height (target_val v_ftl), demcal's target.\n";
  s << "# Run it with a screen (liggghts 3.8 crashes reading meshes with -screen none).\n"
    << "# Differences from demcal:\n"
    << "#  - rotation: LIGGGHTS 3.8's fix nve/sphere takes the disc's inertia m r^2/2\n"
    << "#    under dimension 2 (as demcal); masses are disc masses (pi r^2 * areal density).\n"
    << "#  - rotational damping (zeta_r = " << num(p.damping_ratio_rotation)
    << ") has no fix here and is not applied.\n";
  if (carried)
    s << "#  - the servo's first move comes one step after demcal's (the meshes have\n"
      << "#    no force before the first step).\n";
  else
    s << "#  - the servo's gain follows the contacts every ${servo_every} steps (demcal:\n"
      << "#    every step).\n";
  s << "#  - translational damping per radius class via fix viscous ... scale.\n";
  return s.str();
}

ExportResult liggghts(const SceneConfig& c, const AlgorithmSpec& p, const Assembly& a,
                      const ExportOptions& o) {
  const Plan plan = make_plan(c, p, a, o.max_types);
  const auto& m = c.material;
  ExportResult out = result_of(plan);
  const int wall_type = plan.types + 1;
  const int ntypes = plan.types + 1;
  // The lateral walls' contacts at the start (the particles overlapping
  // each) and the servo gains that make LIGGGHTS' mesh servo move as
  // demcal's (see the deck's header); the deck sets them from the current
  // contacts as it runs.
  int n_left = 0, n_right = 0;
  for (int i = 0; i < plan.n; ++i) {
    if (a.x[i] - a.r[i] <= a.left + 1e-9 * a.r[i]) ++n_left;
    if (a.x[i] + a.r[i] >= a.right - 1e-9 * a.r[i]) ++n_right;
  }
  const double force_target = c.test.lateral_stress * plan.height0 * m.thickness;
  const double cap = servo_move_cap(plan.r_min);
  const double kp_left =
      deck::liggghts_servo_kp(c.test.servo_gain, force_target, plan.servo_resist, n_left, cap);
  const double kp_right =
      deck::liggghts_servo_kp(c.test.servo_gain, force_target, plan.servo_resist, n_right, cap);
  const double vel_max = deck::liggghts_servo_vel_max(cap, plan.dt, plan.step_factor);
  // With contact damping demcal's servo carries a share of the wall's last
  // move, which LIGGGHTS' mesh servo cannot: the walls are then moved by
  // deck::liggghts_carried_servo_run.
  const double carry = servo_carry(m.wall.kn, plan.servo_resist);
  const bool carried = carry > 0.0;

  const DeckFiles files = deck_files(o.deck_name);
  out.files[files.data] = liggghts_data_2d(c, plan, a, ntypes);
  const double z0 = -0.5 * m.thickness, z1 = 0.5 * m.thickness;
  const double ylo = a.bottom - 0.1 * plan.height0, yhi = a.top + 0.1 * plan.height0;
  const double xlo = a.left - 0.5 * plan.width0, xhi = a.right + 0.5 * plan.width0;
  const std::string top = files.mesh("top"), left = files.mesh("left"), right = files.mesh("right");
  out.files[top] = stl_rectangle("top", xhi, a.top, xlo, a.top, z0, z1);
  out.files[left] = stl_rectangle("left", a.left, ylo, a.left, yhi, z0, z1);
  out.files[right] = stl_rectangle("right", a.right, yhi, a.right, ylo, z0, z1);

  // demcal's servo target sigma3*H*t on the current height H (the top wall
  // moves down at top_speed from the start).
  const std::string target = num(c.test.lateral_stress * m.thickness) + "*(" + num(plan.height0) +
                             "-" + num(plan.top_speed) + "*step*" + num(plan.dt) + ")";
  std::ostringstream s;
  s << liggghts_header_2d(c, p, plan, o, carry, n_left, n_right);
  s << deck::liggghts_preamble(2, "f f p", files.data, plan.r_min)
    << deck::liggghts_materials(m, plan.class_mass, plan.dt, num)
    << "# the lateral walls' target forces, sigma3*H*t (left +x, right -x)\n"
    << "variable ftl equal " << target << "\n"
    << "variable ftr equal -" << target << "\n"
    << "fix bottom all wall/gran model hooke/stiffness tangential history primitive type "
    << wall_type << " yplane " << num(a.bottom) << " store_force yes "
    << deck::liggghts_model_settings(m) << "\n"
    << "fix mtop all mesh/surface/stress file " << top << " type " << wall_type << "\n";
  if (carried)
    s << "# the lateral walls: stress meshes, their reference point the wall's centre\n"
      << "# (f_mleft[7]), moved by demcal's servo (fix move/mesh, before the run)\n"
      << "fix mleft all mesh/surface/stress file " << left << " type " << wall_type
      << " reference_point " << num(a.left) << " " << num(0.5 * (a.bottom + a.top)) << " 0\n"
      << "fix mright all mesh/surface/stress file " << right << " type " << wall_type
      << " reference_point " << num(a.right) << " " << num(0.5 * (a.bottom + a.top)) << " 0\n";
  else
    s << "fix mleft all mesh/surface/stress/servo file " << left << " type " << wall_type << " com "
      << num(a.left) << " " << num(0.5 * (a.bottom + a.top))
      << " 0 ctrlPV force axis 1 0 0 target_val v_ftl vel_max " << num(vel_max) << " kp "
      << num(kp_left) << "\n"
      << "fix mright all mesh/surface/stress/servo file " << right << " type " << wall_type
      << " com " << num(a.right) << " " << num(0.5 * (a.bottom + a.top))
      << " 0 ctrlPV force axis 1 0 0 target_val v_ftr vel_max " << num(vel_max) << " kp "
      << num(kp_right) << "\n";
  s << "fix walls all wall/gran model hooke/stiffness tangential history mesh n_meshes 3 meshes "
       "mtop mleft mright store_force yes "
    << deck::liggghts_model_settings(m) << "\n"
    << "fix movetop all move/mesh mesh mtop linear 0 " << num(-plan.top_speed) << " 0\n\n"
    << "fix integrate all nve/sphere\n";
  s << deck::liggghts_translational_damping(p.damping_ratio_translation, plan.gamma_t, num)
    << "fix twod all enforce2d\n"
    << liggghts_series_block(c, p, plan, a, o)
    << "# thermo: the meshes' own forces (from the first step on): p_top axial,\n"
    << "# p_left and p_right lateral, on the current width and height (Pa)\n"
    << "variable p_top equal f_mtop[2]/(v_W*" << num(m.thickness) << ")\n"
    << "variable p_left equal -f_mleft[1]/(v_H*" << num(m.thickness) << ")\n"
    << "variable p_right equal f_mright[1]/(v_H*" << num(m.thickness) << ")\n"
    << "thermo_style custom step dt time ke v_p_top v_p_left v_p_right v_xl v_xr\n"
    << "thermo " << plan.thermo_every << "\n"
    << "variable run_steps index " << plan.steps << "\n";
  // with contact damping the contacts are counted over the walls' bands
  const double band = deck::liggghts_band(c.test.vertical_strain, plan.width0, plan.r_max);
  const std::vector<deck::LiggghtsServoWall> servo_walls{
      {"mleft", "ftl", "ll_a", 0, band, a.left, false, "v_xl"},
      {"mright", "ftr", "lr_a", 0, band, a.right, true, "v_xr"}};
  if (carried)
    s << deck::liggghts_carried_servo_run(servo_walls, c.test.servo_gain, plan.servo_resist, carry,
                                          cap, plan.dt / plan.step_factor, "c_pa[1]",
                                          plan.thermo_every, num);
  else
    s << deck::liggghts_servo_run(servo_walls, c.test.servo_gain, plan.servo_resist, cap,
                                  plan.thermo_every, num, "kn_wall");
  out.deck = s.str();
  return out;
}

}  // namespace

int64_t deck_steps(const AlgorithmSpec& params) {
  return std::max<int64_t>(1, std::llround(static_cast<double>(params.steps) /
                                           dashpot_step_factor(params.damping_ratio_translation)));
}

std::vector<int> radius_classes(const std::vector<double>& radii, int max_types, int* types) {
  const int n = static_cast<int>(radii.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return radii[a] < radii[b]; });
  std::vector<int> type(n, 1);
  // Equal radii (to 1e-9 relative) are one value.
  std::vector<int> value(n, 0);
  int distinct = 0;
  for (int k = 0; k < n; ++k) {
    if (k > 0 && radii[order[k]] > radii[order[k - 1]] * (1.0 + 1e-9)) ++distinct;
    value[order[k]] = distinct;
  }
  ++distinct;
  const int classes = std::max(1, std::min(max_types, distinct));
  if (classes == distinct) {
    for (int i = 0; i < n; ++i) type[i] = value[i] + 1;
  } else {
    // Equal-count classes over the sorted radii, never splitting a value.
    int cls = 0, in_class = 0;
    for (int k = 0; k < n; ++k) {
      const bool new_value = k > 0 && value[order[k]] != value[order[k - 1]];
      if (new_value && in_class >= (n * (cls + 1)) / classes - (n * cls) / classes &&
          cls + 1 < classes) {
        ++cls;
        in_class = 0;
      }
      type[order[k]] = cls + 1;
      ++in_class;
    }
  }
  if (types) *types = n > 0 ? *std::max_element(type.begin(), type.end()) : 0;
  return type;
}

DeckFiles deck_files(const std::string& deck) {
  DeckFiles f;
  f.deck = deck;
  f.data = deck + ".data";
  f.series = deck + ".series.csv";
  f.restart = deck + ".restart";
  f.restart_args = f.restart + ".args";  // the deck writes ${restart_out}.args
  return f;
}

ExportResult export_deck(const SceneConfig& config, const AlgorithmSpec& params,
                         const Assembly& assembly, const ExportOptions& options) {
  if (assembly.size() == 0) throw InputError("export", "prototype", "no particles");
  if (options.format == "lammps") return lammps(config, params, assembly, options);
  if (options.format == "liggghts") return liggghts(config, params, assembly, options);
  throw InputError("--format", "", "must be lammps or liggghts, got \"" + options.format + "\"");
}

}  // namespace demcal
