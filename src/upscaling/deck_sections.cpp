#include "deck_sections.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"

namespace demcal::deck {

namespace {
std::string printed(const char* format, double v) {
  char b[40];
  std::snprintf(b, sizeof b, format, v);
  return b;
}
}  // namespace

std::string num(double v) { return printed("%.10g", v); }
std::string exact(double v) { return printed("%.17g", v); }
std::string fmt3(double v) { return printed("%.3g", v); }

RadiusClasses radius_class_bounds(const std::vector<double>& radii, int max_types) {
  RadiusClasses out;
  out.type = radius_classes(radii, std::max(1, max_types), &out.types);
  out.r_lo.assign(out.types, std::numeric_limits<double>::infinity());
  out.r_hi.assign(out.types, 0.0);
  for (size_t i = 0; i < radii.size(); ++i) {
    const int k = out.type[i] - 1;
    out.r_lo[k] = std::min(out.r_lo[k], radii[i]);
    out.r_hi[k] = std::max(out.r_hi[k], radii[i]);
  }
  return out;
}

DeckTiming deck_timing(const AlgorithmSpec& p, double dt_crit) {
  DeckTiming out;
  out.step_factor = dashpot_step_factor(p.damping_ratio_translation);
  out.dt = p.dt_ratio * out.step_factor * dt_crit;
  out.demcal_dt = p.dt_ratio * dt_crit;
  out.steps = deck_steps(p);
  return out;
}

int monitor_interval(int64_t steps, int monitor_points) {
  return static_cast<int>(std::max<int64_t>(1, steps / std::max(1, monitor_points)));
}

std::string header_opening(const std::string& code, const std::string& test,
                           const std::string& sample, const ExportOptions& o, double dt_ratio,
                           double step_factor, double dt_crit, double dt) {
  std::ostringstream s;
  s << "# ===========================================================================\n"
    << "# demcal " << DEMCAL_VERSION << " export: " << code << " input deck, " << test << "\n"
    << "# " << sample << "\n";
  if (!o.provenance.empty()) s << "# parameters: " << o.provenance << "\n";
  if (o.uncertified)
    s << comment_lines("# ",
                       "NOT CERTIFIED: the calibration of these parameters failed, and "
                       "they were exported anyway (--allow-failed)" +
                           (o.uncertified->empty() ? std::string(".") : ": " + *o.uncertified));
  s << "#\n"
    << "# How demcal's parameters map (demcal -> " << code << "):\n"
    << "#   dt = alpha * f * dt_crit = " << num(dt_ratio) << " * " << num(step_factor) << " * "
    << num(dt_crit) << " s = " << num(dt) << " s -> timestep\n";
  return s.str();
}

std::string comment_lines(const std::string& prefix, const std::string& text) {
  std::string clean;
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '&')
      clean += " and ";
    else
      clean += u < 0x20 || u >= 0x7f ? ' ' : ch == '"' ? '\'' : ch;
  }
  std::ostringstream s;
  std::istringstream words(clean);
  std::string line = prefix;
  for (std::string w; words >> w;) {
    if (line.size() > prefix.size() && line.size() + 1 + w.size() > 79) {
      s << line << "\n";
      line = prefix;
    }
    line += (line.size() > prefix.size() ? " " : "") + w;
  }
  if (line.size() > prefix.size()) s << line << "\n";
  return s.str();
}

std::string series_variable(const ExportOptions& o) {
  return "variable series    index " + deck_files(o.deck_name).series +
         "      # demcal score FILE; -var series NAME renames it\n";
}

std::string header_step_factor(const std::string& code, double step_factor, double zeta_t) {
  return "#     f = sqrt(1 + zeta_t^2) - zeta_t = " + num(step_factor) +
         " (zeta_t = " + num(zeta_t) + "): " + code + "'s fix viscous is explicit\n";
}

std::string header_contact_law(const Material& m) {
  return "#   kn = " + num(m.particle.kn) + " N/m, kt = " + num(m.particle.kt) +
         " N/m, mu = " + num(m.particle.friction) +
         " -> linear normal spring, incremental tangential spring, Coulomb cap\n"
         "#   contact (local) damping: " +
         (m.contact_damping_ratio > 0 ? num(m.contact_damping_ratio) + " of critical" : "none");
}

std::string header_wall_law(const Material& m) {
  return "#   walls: kn = " + num(m.wall.kn) + " N/m, kt = " + num(m.wall.kt) +
         " N/m, mu = " + num(m.wall.friction);
}

void set_plan_classes(PlanCommon& plan, const std::vector<double>& radii, int max_types) {
  plan.n = static_cast<int>(radii.size());
  RadiusClasses classes = radius_class_bounds(radii, max_types);
  plan.types = classes.types;
  plan.type = std::move(classes.type);
  plan.r_lo = std::move(classes.r_lo);
  plan.r_hi = std::move(classes.r_hi);
}

void set_plan_timing(PlanCommon& plan, const AlgorithmSpec& p, const Material& m, double m_max) {
  const DeckTiming timing = deck_timing(p, plan.dt_crit);
  plan.step_factor = timing.step_factor;
  plan.dt = timing.dt;
  plan.demcal_dt = timing.demcal_dt;
  plan.steps = timing.steps;
  plan.m_max = m_max;
  plan.wall_dashpot = servo_wall_dashpot(m, m_max);
  plan.servo_resist = servo_resistance(m, m_max, plan.demcal_dt);
  plan.servo_carry = servo_carry_at(m, m_max, plan.demcal_dt);
}

ExportResult plan_result(const PlanCommon& plan) {
  ExportResult out;
  out.dt = plan.dt;
  out.steps = plan.steps;
  out.step_factor = plan.step_factor;
  out.types = plan.types;
  out.damping_class_error = plan.class_error;
  const double step_factor = plan.step_factor;
  out.notes.push_back(
      "tangential contact forces are not carried over: the deck's contacts start with zero "
      "tangential springs (normal forces are in the positions)");
  if (step_factor < 1.0)
    out.notes.push_back(
        "timestep alpha*f and Nstep/f (f = sqrt(1 + zeta_t^2) - zeta_t = " + num(step_factor) +
        "): this engine's fix viscous is explicit and shrinks the stable step "
        "by f; the loading time, rate and strain are demcal's");
  return out;
}

double contact_gamma_n(const Material& m, double mass_mean) {
  if (m.contact_damping_ratio <= 0.0) return 0.0;
  return m.contact_damping_ratio * 2.0 * std::sqrt(m.particle.kn / (0.5 * mass_mean));
}

std::string lammps_rotational_damping_note(double zeta_r) {
  return "rotational damping zeta_r = " + num(zeta_r) +
         " not applied: LAMMPS 29 Sep 2021 has no rotational viscous fix "
         "(fix viscous/sphere is in later releases; the deck has the line, "
         "commented out)";
}

std::string lammps_class_damping_note(int types, double class_error, const std::string& what) {
  return "translational damping per radius class (" + std::to_string(types) +
         " atom types), at most " + fmt3(100 * class_error) + " % off demcal's per-" + what +
         " value";
}

std::string lammps_material_variables(const Material& m, NumberFormat f) {
  std::ostringstream s;
  s << "variable kn        equal " << f(m.particle.kn) << "\n"
    << "variable kt        equal " << f(m.particle.kt) << "\n"
    << "variable mu        equal " << f(m.particle.friction) << "\n"
    << "variable kn_wall   equal " << f(m.wall.kn) << "\n"
    << "variable kt_wall   equal " << f(m.wall.kt) << "\n"
    << "variable mu_wall   equal " << f(m.wall.friction) << "\n";
  return s.str();
}

std::string servo_cap_text() { return num(100.0 * kServoMoveCapRatio) + " % of r_min"; }

std::string lammps_loading_derived(double wall_dashpot, NumberFormat f, const std::string& particle,
                                   double carry) {
  std::string s =
      "variable vtop      equal $(v_strain*v_H0/(v_nstep*v_dt))      # m/s, top wall, down\n"
      "variable cap       equal $(" +
      num(kServoMoveCapRatio) +
      "*v_r_min)      # m per demcal step, its servo move cap\n"
      "# demcal's servo moves a wall per step of servo_dt; a step of dt moves it\n"
      "# dt/servo_dt as far, so that the walls answer as fast per unit of time\n"
      "variable servo_f   equal $(v_dt/v_servo_dt)\n"
      "variable cap_step  equal $(v_cap*v_servo_f)      # m per step of dt\n";
  if (wall_dashpot > 0.0) {
    s += "# demcal's wall contacts resist a move within its step by kn_wall and by\n"
         "# their dashpots' c_wall/servo_dt (contact damping: c_wall =\n"
         "# 2*zeta_c*sqrt(kn_wall*m_max), the heaviest " +
         particle +
         "'s); its servo divides by\n"
         "# both (without the dashpots it overshoots by gain*c_wall/(servo_dt*kn_wall)\n"
         "# per step), so does this deck's\n"
         "variable c_wall    equal " +
         f(wall_dashpot) +
         "      # N*s/m\n"
         "variable resist    equal $(v_kn_wall+v_c_wall/v_servo_dt)      # N/m, demcal's R\n"
         "variable gain_kn   equal $(v_gain*v_servo_f/v_resist)      # m/N per step of dt\n";
    if (carry > 0.0)
      s += "# and a wall already moving has its dashpots' force c_wall*v in its F, so\n"
           "# demcal's servo carries (R - kn_wall)/R of each move into the next (its\n"
           "# servo_carry at servo_dt; a number, as c_wall: export again for another\n"
           "# kn_wall): a steady error then moves a wall as the law with kn_wall alone\n"
           "variable carry     equal " +
           exact(carry) + "\n";
  } else {
    s += "variable gain_kn   equal $(v_gain*v_servo_f/v_kn_wall)      # m/N per step of dt\n";
  }
  s += "variable monitor_every equal "
       "$(floor((1+v_nstep/v_monitor_points+abs(1-v_nstep/v_monitor_points))/2))\n";
  return s;
}

std::string lammps_servo_dt(double servo_dt, NumberFormat f) {
  return "variable servo_dt  equal " + f(servo_dt) +
         "      # s, demcal's step: its servo law is per servo_dt (keep)\n";
}

std::string lammps_thermo_modify() { return "thermo_modify   norm no flush yes\n"; }

std::string lammps_system_head(int dimension, const std::string& boundary) {
  std::ostringstream s;
  s << "\n# --- system ------------------------------------------------------------------\n"
    << "units           si\n"
    << "dimension       " << dimension << "\n"
    << "boundary        " << boundary << "\n"
    << "atom_style      sphere\n"
    << "atom_modify     map array\n"
    << "comm_modify     vel yes\n";
  return s.str();
}

std::string lammps_contact_law(double gamma_n, double r_min, const std::string& integrate_args) {
  std::ostringstream s;
  s << "pair_style      gran/hooke/history ${kn} ${kt} " << num(gamma_n) << " 0.0 ${mu} 0\n"
    << "pair_coeff      * *\n"
    << "neighbor        " << num(0.3 * r_min) << " bin\n"
    << "neigh_modify    delay 0 every 1 check yes\n"
    << "timestep        ${dt}\n\n"
    << "fix             integrate all nve/sphere";
  if (!integrate_args.empty()) s << " " << integrate_args;
  s << "\n\n";
  return s.str();
}

namespace {
/// fix viscous's scale ratio of type k+1 as the deck prints it.
std::string viscous_scale(const std::vector<double>& gamma_t, size_t k, NumberFormat f) {
  return f(gamma_t[k] / gamma_t[0]);
}
}  // namespace

std::string lammps_translational_damping(double zeta_t, const std::vector<double>& gamma_t,
                                         NumberFormat f) {
  std::ostringstream s;
  s << "# --- global damping ----------------------------------------------------------\n";
  if (zeta_t > 0.0) {
    s << "# gamma per class, N*s/m:";
    for (double g : gamma_t) s << " " << num(g);
    // one "scale type ratio" keyword per type after the first
    s << "\nfix             dampt all viscous " << f(gamma_t[0]);
    for (size_t k = 1; k < gamma_t.size(); ++k)
      s << " scale " << k + 1 << " " << viscous_scale(gamma_t, k, f);
    s << "\n";
  } else {
    s << "# zeta_t = 0: no translational damping\n";
  }
  return s.str();
}

std::string lammps_contact_force_atom(int dimension, double zeta_t,
                                      const std::vector<double>& gamma_t, NumberFormat f,
                                      const std::string& first_step) {
  std::ostringstream s;
  s << "# the contact force F (pairs and walls) on each particle, from the total\n"
    << "# force f at the end of the step: fix viscous adds -gamma*v(t+dt/2) and the\n"
    << "# step ends with v = v(t+dt/2) + dt*f/(2m), so F = f + gamma*(v - dt*f/(2m));\n"
    << "# at a run's first step (its setup) v is the start velocity: F = f + gamma*v\n";
  const char* axis = "xyz";
  if (zeta_t > 0.0) {
    // gamma[type] = gamma_one*scale, the product fix viscous forms
    s << "variable        gam_a atom ";
    if (gamma_t.size() == 1) {
      s << f(gamma_t[0]);
    } else {
      for (size_t k = 0; k < gamma_t.size(); ++k) {
        if (k > 0) s << "+";
        s << f(gamma_t[0]);
        if (k > 0) s << "*" << viscous_scale(gamma_t, k, f);
        s << "*(type==" << k + 1 << ")";
      }
    }
    s << "\n"
      << "variable        hdt equal (step>" << first_step << ")*0.5*dt\n";
    for (int d = 0; d < dimension; ++d)
      s << "variable        fc" << d + 1 << "_a atom f" << axis[d] << "+v_gam_a*(v" << axis[d]
        << "-v_hdt*f" << axis[d] << "/mass)\n";
  } else {
    for (int d = 0; d < dimension; ++d)
      s << "variable        fc" << d + 1 << "_a atom f" << axis[d] << "\n";
  }
  return s.str();
}

std::string lammps_wall_sum(const std::vector<std::string>& fixes, int a, int b) {
  std::string out;
  for (const std::string& w : fixes) {
    if (!out.empty()) out += "+";
    out += "f_" + w + "[" + std::to_string(a) + "]";
    if (b > 0) out += "*f_" + w + "[" + std::to_string(b) + "]";
  }
  return out;
}

std::string lammps_servo_raw_of_load(const std::string& load, const std::string& minus_force,
                                     const std::string& count_max, const std::string& resist) {
  return "${gain}*(" + load + minus_force + ")/(" + resist + "*" + count_max + ")";
}

std::string lammps_servo_raw_folded(const std::string& load, const std::string& minus_force,
                                    const std::string& count_max) {
  return "${gain_kn}*(" + load + minus_force + ")/" + count_max;
}

std::string lammps_count_max_one(const std::string& count) {
  return "(" + count + "+!" + count + ")";
}

std::string lammps_band(const std::string& name, const std::string& motion,
                        const std::string& comment) {
  std::string line = "variable " + name;
  line.resize(std::max<size_t>(line.size() + 1, 19), ' ');
  line += "equal $(" + motion + "+6*v_r_max)";
  if (!comment.empty()) line += "      # " + comment;
  return line + "\n";
}

std::string lammps_servo_clamp(const std::string& x, const std::string& cap) {
  return "(abs(" + x + "+" + cap + ")-abs(" + x + "-" + cap + "))/2";
}

std::string lammps_series_header(const std::string& deck, const std::string& scene, int particles,
                                 double zeta_t, double dt_crit, double mass_scaling,
                                 const std::string& lever_arm) {
  SeriesMetadata m;
  m.writer = deck;
  m.scene = scene;
  m.particles = particles;
  m.lateral_stress = "${sigma3}";
  m.steps = "${nstep}";
  m.dt = "${dt}";
  m.dt_crit = num(dt_crit);
  m.damping_ratio_translation = num(zeta_t);
  m.damping_ratio_rotation = "0";
  m.mass_scaling = num(mass_scaling);
  m.moment_lever_arm = lever_arm;
  // The first line starts the file, the others are appended to it.
  std::string out;
  for (const std::string& line : series_metadata_lines(m))
    out += "print           \"" + line + "\" " + (out.empty() ? "file" : "append") +
           " ${series} screen no\n";
  return out;
}

std::string lammps_consolidation_parameters(const TestSpec& test) {
  std::ostringstream s;
  s << "# stage 1, the consolidation (demcal's test.consolidation_* values):\n"
    << "variable consolidate index 1      # 0: skip it (the particles are at sigma3)\n"
    << "variable cons_tol  equal " << num(test.consolidation_tolerance)
    << "      # largest wall stress error / sigma3\n"
    << "variable cons_unbalanced equal " << num(test.consolidation_unbalanced)
    << "      # mean|F_p| / mean|f_c|\n"
    << "variable cons_max_steps equal " << test.consolidation_max_steps << "\n"
    << "variable cons_check equal 200      # steps between checks\n";
  return s.str();
}

double consolidation_dt(double alpha, double zeta, double dt_crit) {
  return alpha * dashpot_step_factor(zeta) * dt_crit;
}

std::string lammps_consolidation_comment(double zeta, const std::string& particle,
                                         const std::string& start_walls) {
  std::ostringstream s;
  s << "# mu until static again; the frictionless phase at most until step\n"
    << "# cons_cut (friction goes on there if it is not static: a frictionless\n"
    << "# packing at sigma3 can creep for far longer), critical damping (zeta 1,\n"
    << "# timestep * f(1)/f(" << num(zeta) << ")) from step cons_switch on if not static by\n"
    << "# then: cons_quarter, or cons_capped when the frictionless phase was cut\n"
    << "# there (demcal's run_consolidation). Static: every wall\n"
    << "# within cons_tol of sigma3 and the unbalanced-force ratio mean|F_p| / mean\n"
    << "# |f_c| below cons_unbalanced (demcal's test.consolidation_* values), checked\n"
    << "# every cons_check steps by fix halt; |f_c| of a " << particle << " contact is its normal\n"
    << "# force (compute pair/local; the tangential part left out: a stricter ratio).\n"
    << "# The end state's walls become " << start_walls << " of the loading, whose step\n"
    << "# count starts at 0; the pair contacts keep their tangential springs, the\n"
    << "# walls' start at zero. Progress: the thermo lines (cons_err, cons_ufr).\n";
  return s.str();
}

std::string lammps_consolidation_start(double alpha, double dt_light, int64_t max_steps) {
  std::ostringstream s;
  s << "variable        cap equal $(" << num(kServoMoveCapRatio) << "*v_r_min)\n"
    << "timestep        " << num(dt_light) << "      # alpha*f(zeta)*dt_crit, alpha " << num(alpha)
    << "\n"
    << "variable        cons_s0 equal $(step)\n"
    << "# runs end on check steps, where the criterion's computes are current\n"
    << lammps_consolidation_quarter(alpha, max_steps);
  return s.str();
}

std::string lammps_consolidation_quarter(double alpha, int64_t max_steps) {
  const double shrink = consolidation_step_shrink(alpha);
  // demcal switches at its first check at or after critical_damping_after
  // (a multiple of cons_check: its checks come every 200 steps from 0), and
  // never beyond the budget; one formula with and without contact dashpots
  // (S = 1: floor(cons_max_steps/4), critical_damping_after's unshrunk
  // branch); min(a, b) = (a+b-abs(a-b))/2 (LAMMPS 2021 has no min of two
  // numbers), exact for these whole numbers
  std::ostringstream s;
  s << "# critical damping from the first check at or after a quarter of the budget\n";
  if (shrink < 1.0)
    s << "# in the simulated time of the undamped step: the contact dashpots shrink\n"
      << "# this step by " << num(shrink) << " (alpha " << num(alpha) << " instead of "
      << num(AlgorithmSpec{}.dt_ratio) << "), so\n"
      << "# (cons_max_steps/4)/" << num(shrink) << " steps (demcal's critical_damping_after: step ";
  else
    s << "# (demcal's critical_damping_after: step ";
  s << critical_damping_after(max_steps, shrink) << "\n"
    << "# at cons_max_steps " << max_steps << "), at most the budget's last check,\n"
    << "# the first at or after cons_max_steps (demcal's consolidation, too, ends there)\n"
    << "variable        cons_last equal $(v_cons_check*ceil(v_cons_max_steps/v_cons_check))\n"
    << "variable        cons_after equal "
       "$(v_cons_check*ceil(ceil(floor(v_cons_max_steps/4)/"
    << exact(shrink) << ")/v_cons_check))\n"
    << "variable        cons_quarter equal "
       "$((v_cons_after+v_cons_last-abs(v_cons_after-v_cons_last))/2)\n"
    << "# a frictionless phase cut at cons_cut: critical damping from the first\n"
    << "# check at or after twice demcal's critical_damping_after, at most the budget\n"
    << "variable        cons_after2 equal "
       "$(v_cons_check*ceil(2*ceil(floor(v_cons_max_steps/4)/"
    << exact(shrink) << ")/v_cons_check))\n"
    << "variable        cons_capped equal "
       "$((v_cons_after2+v_cons_last-abs(v_cons_after2-v_cons_last))/2)\n"
    << "# the frictionless phase ends at cons_quarter, at most at the first check at\n"
    << "# or after half the budget (friction keeps about the other half; demcal's\n"
    << "# frictionless_phase_cut: step " << frictionless_phase_cut(max_steps, shrink) << ")\n"
    << "variable        cons_half equal "
       "$(v_cons_check*ceil(floor(v_cons_max_steps/2)/v_cons_check))\n"
    << "variable        cons_cut equal "
       "$((v_cons_quarter+v_cons_half-abs(v_cons_quarter-v_cons_half))/2)\n";
  return s.str();
}

std::string lammps_consolidation_viscous(const std::vector<double>& gamma) {
  std::string out = "fix cons_damp all viscous " + num(gamma[0]);
  for (size_t k = 1; k < gamma.size(); ++k)
    out += " scale " + std::to_string(k + 1) + " " + num(gamma[k] / gamma[0]);
  return out;
}

std::string lammps_consolidation_reductions(const std::vector<ConsolidationWall>& walls) {
  std::string n, f;
  for (const ConsolidationWall& w : walls) {
    n += " f_cons_w" + w.name + "[1]";
    f += " f_cons_w" + w.name + "[" + std::to_string(2 + (w.axis - 'x')) + "]";
  }
  return "# each wall's contacts (cons_wn) and force along its axis on the particles\n"
         "# (cons_wf), one column per wall\n"
         "compute         cons_wn all reduce sum" +
         n + "\ncompute         cons_wf all reduce sum" + f + "\n";
}

double servo_carry_at(const Material& m, double m_max, double dt) {
  return servo_carry(m.wall.kn, servo_resistance(m, m_max, dt));
}

std::string lammps_servo_carried(const std::string& prev) { return "+${carry}*" + prev; }

std::string lammps_previous_moves(const std::string& fix, const std::string& movev, size_t count) {
  std::string s = "fix             " + fix + " all ave/time 1 1 1";
  for (size_t k = 0; k < count; ++k) s += " v_" + movev + "[" + std::to_string(k + 1) + "]";
  return s + "\n";
}

std::string lammps_consolidation_servo(const std::vector<ConsolidationWall>& walls,
                                       const std::vector<std::string>& area,
                                       const std::string& area_tail, const std::string& resist,
                                       double carry) {
  std::ostringstream s;
  s << "# The servo, one move per step and wall toward the sample when p < sigma3:\n";
  if (carry > 0.0)
    s << "#   move = gain*(sigma3*A - F)/(R*max(1, n)) + carry*u, clamped to +-cap,\n"
      << "# u the wall's last move (demcal's consolidation servo,\n"
      << "# servo_velocity: demcal's walls have dashpots, whose force of\n"
      << "# a moving wall is in its F, so a move carries carry = (R - kn_wall)/R of the\n"
      << "# last; these walls have none, the law is demcal's; R at this step's dt, and\n"
      << "# cons_carry with it from the switch to critical damping; u is 0 before the\n"
      << "# first step, the walls start at rest, then kept by fix cons_prev, after fix\n"
      << "# cons_servo: at this step's end it still holds the step before's),\n";
  else
    s << "#   move = gain*(sigma3*A - F)/(R*max(1, n)), clamped to +-cap,\n";
  s << "# all walls in one vector-style formula (elements in cons_wn's order; a max\n"
    << "# wall's with the opposite sign, so that each clamped element is the wall's\n"
    << "# move along +axis), parsed once per step for all, the clamp reading the\n"
    << "# unclamped moves as doubles (a vector variable is evaluated once per step,\n"
    << "# then kept). Each wall's area factor is the value a per-wall formula reads\n"
    << "# (a v_ reference goes through text: cons_*q read it so), stored once per\n"
    << "# step by fix cons_geom and laid out per wall by fix cons_len; the signs are\n"
    << "# internal variables. No min/max of two numbers in this release: max(1, n)\n"
    << "# = n+!n for a contact count n, clamp(x) = (abs(x+cap)-abs(x-cap))/2.\n";
  std::string geom, len, sign;
  for (size_t a = 0; a < area.size(); ++a) {
    s << "variable        " << area[a] << "q equal v_" << area[a] << "\n";
    geom += " v_" + area[a] + "q";
  }
  for (size_t k = 0; k < walls.size(); ++k) {
    len += " f_cons_geom[" + std::to_string(k / 2 + 1) + "]";
    sign += walls[k].min ? " v_cons_one" : " v_cons_mone";
  }
  s << "fix             cons_geom all ave/time 1 1 1" << geom << "\n"
    << "fix             cons_len all ave/time 1 1 1" << len << "\n"
    << "variable        cons_one internal 1\n"
    << "variable        cons_mone internal -1\n"
    << "fix             cons_sign all ave/time 1 1 1" << sign << "\n";
  if (carry > 0.0) s << "variable        cons_carry equal " << exact(carry) << "\n";
  s << "variable        cons_rawv vector "
    << lammps_servo_raw_of_load("f_cons_sign*${sigma3}*f_cons_len" + area_tail, "-c_cons_wf",
                                lammps_count_max_one("c_cons_wn"), resist)
    << (carry > 0.0 ? "+v_cons_carry*f_cons_prev" : "") << "\n"
    << "variable        cons_movev vector " << lammps_servo_clamp("v_cons_rawv") << "\n"
    << "fix             cons_servo all ave/time 1 1 1 v_cons_movev mode vector ave running\n";
  if (carry > 0.0) s << lammps_previous_moves("cons_prev", "cons_movev", walls.size());
  return s.str();
}

namespace {
/// max(a, b) = (a+b+abs(a-b))/2: no max() of two numbers in this release.
std::string max_of(const std::string& a, const std::string& b) {
  return "(" + a + "+" + b + "+abs(" + a + "-" + b + "))/2";
}
}  // namespace

std::string lammps_consolidation_criterion(int dimension,
                                           const std::vector<ConsolidationWall>& walls,
                                           const std::vector<std::string>& axis_names) {
  std::ostringstream s;
  s << "# the static criterion\n";
  for (const ConsolidationWall& w : walls)
    s << "variable        cons_p" << w.name << " equal " << w.pressure << "\n";
  auto components = [&](const std::string& of, int first) {
    std::string out;
    for (int d = 0; d < dimension; ++d)
      out += (d ? "+" : "") + of + "[" + std::to_string(first + d) + "]^2";
    return "sqrt(" + out + ")";
  };
  s << "variable        cons_fnet atom " << components("f_cons_fcon", 1) << "\n"
    << "variable        cons_fw atom \"";
  for (size_t k = 0; k < walls.size(); ++k) {
    if (k > 0) s << (k % 2 == 0 ? "+&\n                " : "+");
    s << components("f_cons_w" + walls[k].name, 2);
  }
  s << "\"\n"
    << "compute         cons_pair all pair/local force cutoff radius\n"
    << "compute         cons_nc all contact/atom\n"
    << "compute         cons_fp all reduce sum c_cons_pair\n"
    << "compute         cons_at all reduce sum v_cons_fnet v_cons_fw c_cons_nc\n"
    << "# (x==0) is 1 for x = 0: no contacts yet (a gas) gives ratio 0, as in demcal\n"
    << "variable        cons_nct equal c_cons_at[3]/2";
  for (const ConsolidationWall& w : walls) s << "+c_cons_wn[" << w.column << "]";
  s << "\n"
    << "variable        cons_fct equal c_cons_fp+c_cons_at[2]\n"
    << "variable        cons_ufr equal (c_cons_at[1]/atoms)*(v_cons_nct+(v_cons_nct==0))/"
       "(v_cons_fct+(v_cons_fct==0))\n"
    << "# largest wall stress error: max(a, b) = (a+b+abs(a-b))/2 (no max() of two\n"
    << "# numbers in this release)\n";
  for (const ConsolidationWall& w : walls)
    s << "variable        cons_e" << w.name << " equal abs(v_cons_p" << w.name << "-v_sigma3)\n";
  for (size_t a = 0; a < axis_names.size(); ++a)
    s << "variable        cons_e" << axis_names[a] << " equal "
      << max_of("v_cons_e" + walls[2 * a].name, "v_cons_e" + walls[2 * a + 1].name) << "\n";
  std::string acc = axis_names[0];
  for (size_t a = 1; a < axis_names.size(); ++a) {
    const std::string m = max_of("v_cons_e" + acc, "v_cons_e" + axis_names[a]);
    if (a + 1 == axis_names.size()) {
      s << "variable        cons_err equal " << m << "/v_sigma3\n";
    } else {
      acc += axis_names[a];
      s << "variable        cons_e" << acc << " equal " << m << "\n";
    }
  }
  s << "# sums over each wall's contacts for its position at the end (";
  for (int d = 0; d < dimension; ++d)
    s << (d ? ", " : "") << "r -+ "
      << "xyz"[d];
  s << ")\n"
    << "compute         cons_rad all property/atom radius\n";
  std::string pos;
  for (const ConsolidationWall& w : walls) {
    const std::string v = std::string("cons_r") + w.axis + (w.min ? "n" : "p");
    s << "variable        " << v << " atom (c_cons_rad" << (w.min ? "-" : "+") << w.axis
      << ")*f_cons_w" << w.name << "[1]\n";
    pos += " v_" + v;
  }
  s << "compute         cons_pos all reduce sum" << pos << "\n"
    << "# (the last term only computes cons_pos on the check steps: current at a halt)\n"
    << "variable        cons_static equal (v_cons_err<v_cons_tol)&&(v_cons_ufr<v_cons_unbalanced)"
       "&&(c_cons_pos[1]==c_cons_pos[1])\n"
    << "fix             cons_halt all halt ${cons_check} v_cons_static > 0.5 error continue "
       "message no\n"
    << "thermo_style    custom step dt v_cons_err v_cons_ufr";
  for (const ConsolidationWall& w : walls) s << " v_cons_p" << w.name;
  s << " ke\n" << lammps_thermo_modify() << "thermo          $(10*v_cons_check)\n";
  return s.str();
}

std::string lammps_consolidation_runs(double gamma_n, double dt_damped, const std::string& critical,
                                      double carry_damped) {
  // The quarter may be the budget's end (lammps_consolidation_quarter, a
  // shrunk step's): then stage 1 never switches, as demcal's. Phase 1 runs
  // no step beyond cons_last: phase 0 may end at the budget's last check or
  // the one before, and phase 1's first check interval then reaches or
  // passes cons_last; a run of 0 steps would leave the criterion's computes
  // stale ("Compute used in variable between runs is not current"), one up
  // to a step already passed is an error. demcal's consolidation, too,
  // stops after phase 1's first check when that is at or past its budget.
  const std::string before_last = " && $(step) < ${cons_last}";
  // with the servo's carry, the carry of the critical step's R
  const std::string carry =
      carry_damped > 0.0 ? " \"variable cons_carry equal " + exact(carry_damped) + "\"" : "";
  std::ostringstream s;
  s << "# phase 0: frictionless\n"
    << "pair_style      gran/hooke/history ${kn} ${kt} " << num(gamma_n) << " 0.0 0 0\n"
    << "variable        cons_critical equal 0\n"
    << "run             ${cons_cut} upto\n"
    << "if              \"${cons_static} == 0 && $(step) >= ${cons_last}\" then \"print 'demcal "
       "deck: consolidation (frictionless) did not reach a static state in ${cons_max_steps} "
       "steps: raise cons_max_steps'\" \"quit 2\"\n"
    << "variable        cons_switch equal ${cons_quarter}\n"
    << "if              \"${cons_static} == 0\" then \"variable cons_switch equal "
       "${cons_capped}\"\n"
    << "# phase 1: friction on (at least one check interval)\n"
    << "pair_style      gran/hooke/history ${kn} ${kt} " << num(gamma_n) << " 0.0 ${mu} 0\n"
    << "if              \"$(step+v_cons_check) <= ${cons_switch}\" "
       "then \"run ${cons_switch} upto\" else \"run ${cons_check}\"\n"
    << "if              \"${cons_static} == 0 && ${cons_switch} < ${cons_last}\" then \""
    << critical << "\" &\n"
    << "                \"timestep " << num(dt_damped) << "\" \"variable cons_critical equal 1\""
    << carry << "\n"
    << "if              \"${cons_static} == 0" << before_last
    << "\" then \"run ${cons_last} upto\"\n"
    << "if              \"${cons_static} == 0\" then \"print 'demcal deck: consolidation did "
       "not reach a static state in ${cons_max_steps} steps: raise cons_max_steps'\" \"quit 2\"\n"
    << "print           \"demcal deck: consolidated in $(step-v_cons_s0) steps (wall stress "
       "error ${cons_err}, unbalanced-force ratio ${cons_ufr})\"\n";
  return s.str();
}

std::string lammps_consolidated_wall(const ConsolidationWall& w, int i) {
  const std::string n = "c_cons_wn[" + std::to_string(w.column) + "]";
  const std::string f = "c_cons_wf[" + std::to_string(w.column) + "]";
  const std::string pos = "c_cons_pos[" + std::to_string(i + 1) + "]";
  return w.min ? "$((" + f + "/v_kn_wall-" + pos + ")/" + n + ")"
               : "$((" + pos + "+" + f + "/v_kn_wall)/" + n + ")";
}

std::string lammps_consolidation_end(const std::vector<ConsolidationWall>& walls,
                                     const std::vector<std::string>& extra_fixes) {
  std::ostringstream s;
  s << "velocity        all set 0 0 0\n"
    << "set             group all omega 0 0 0\n"
    << "unfix           cons_halt\n";
  for (const char* c :
       {"cons_at", "cons_pos", "cons_rad", "cons_fp", "cons_nc", "cons_pair", "cons_wn", "cons_wf"})
    s << "uncompute       " << c << "\n";
  for (const char* f : {"cons_servo", "cons_sign", "cons_len", "cons_geom"})
    s << "unfix           " << f << "\n";
  for (const std::string& f : extra_fixes) s << "unfix           " << f << "\n";
  s << "unfix           cons_damp\n"
    << "unfix           cons_fcon\n";
  for (const ConsolidationWall& w : walls) s << "unfix           cons_w" << w.name << "\n";
  for (const ConsolidationWall& w : walls) s << "region          cons_r" << w.name << " delete\n";
  s << "variable        cap delete\n"
    << "reset_timestep  0\n"
    << "timestep        ${dt}\n"
    << "label           loading\n\n";
  return s.str();
}

std::string liggghts_preamble(int dimension, const std::string& boundary,
                              const std::string& data_name, double r_min) {
  std::ostringstream s;
  s << "\natom_style      granular\n"
    << "atom_modify     map array\n"
    << "boundary        " << boundary << "\n"
    << "newton          off\n"
    << "communicate     single vel yes\n"
    << "units           si\n";
  if (dimension == 2) s << "dimension       2\n";
  s << "read_data       " << data_name << "\n"
    << "neighbor        " << num(0.3 * r_min) << " bin\n"
    << "neigh_modify    delay 0\n\n";
  return s.str();
}

std::string liggghts_model_settings(const Material& m) {
  return std::string("absolute_damping on tangential_damping off") +
         (m.contact_damping_ratio > 0.0 ? " limitForce on" : "");
}

std::string liggghts_materials(const Material& m, const std::vector<double>& class_mass, double dt,
                               NumberFormat f) {
  const int classes = static_cast<int>(class_mass.size());
  const int ntypes = classes + 1, wall_type = ntypes;
  // The value of a type pair: per class pair and against the wall.
  auto pair_matrix = [&](auto value) {
    std::ostringstream s;
    for (int i = 1; i <= ntypes; ++i)
      for (int j = 1; j <= ntypes; ++j)
        s << " " << f(value(i, j, i == wall_type || j == wall_type));
    return s.str();
  };
  auto constant = [](double pp, double pw) {
    return [=](int, int, bool wall) { return wall ? pw : pp; };
  };
  const double zeta = m.contact_damping_ratio;
  auto dashpot = [&](int i, int j, bool wall) {
    if (zeta <= 0.0 || (i == wall_type && j == wall_type)) return 0.0;
    if (wall) return zeta * critical_damping_translation(m.wall.kn, class_mass[std::min(i, j) - 1]);
    return zeta * critical_damping_translation(m.particle.kn,
                                               reduced_mass(class_mass[i - 1], class_mass[j - 1]));
  };
  std::ostringstream s;
  s << "# type " << wall_type << " is the walls' material\n"
    << "fix m1 all property/global kn peratomtypepair " << ntypes
    << pair_matrix(constant(m.particle.kn, m.wall.kn)) << "\n"
    << "fix m2 all property/global kt peratomtypepair " << ntypes
    << pair_matrix(constant(m.particle.kt, m.wall.kt)) << "\n";
  if (zeta > 0.0)
    s << "# contact damping zeta_c = " << f(zeta)
      << ": gamman_abs = zeta_c*2*sqrt(kn*m_eff) per type pair, each class's\n"
         "# mass at its mid radius, m_eff = m_i*m_j/(m_i + m_j), m_i against a wall\n";
  s << "fix m3 all property/global gamman_abs peratomtypepair " << ntypes << pair_matrix(dashpot)
    << "\n"
    << "fix m4 all property/global gammat_abs peratomtypepair " << ntypes
    << pair_matrix(constant(0, 0)) << "\n"
    << "fix m5 all property/global coefficientFriction peratomtypepair " << ntypes
    << pair_matrix(constant(m.particle.friction, m.wall.friction)) << "\n\n"
    << "pair_style gran model hooke/stiffness tangential history " << liggghts_model_settings(m)
    << "\n"
    << "pair_coeff * *\n"
    << "timestep " << f(dt) << "\n\n";
  return s.str();
}

std::string liggghts_translational_damping(double zeta_t, const std::vector<double>& gamma_t,
                                           NumberFormat f) {
  if (zeta_t <= 0.0) return "";
  std::ostringstream s;
  s << "fix dampt all viscous " << f(gamma_t[0]);
  for (size_t k = 1; k < gamma_t.size(); ++k)
    s << " scale " << k + 1 << " " << f(gamma_t[k] / gamma_t[0]);
  s << "\n";
  return s.str();
}

std::string liggghts_series(const std::string& deck, const std::string& scene, int particles,
                            double zeta_t, double dt_crit, double mass_scaling, int every,
                            const std::string& row, const std::string& columns) {
  std::ostringstream s;
  s << lammps_series_header(deck, scene, particles, zeta_t, dt_crit, mass_scaling,
                            "radius - overlap/2")
    << "fix series all print " << every << " \"" << row << "\" append ${series} screen no title \""
    << columns << "\"\n"
    << "# The start's row: this fix print does not print at the run's setup, and a\n"
    << "# variable may read a compute between runs only if the last run computed it\n"
    << "# (the thermo line below does)\n"
    << "thermo_style custom step c_meas[1]\n"
    << "run 0\n"
    << "print \"" << row << "\" append ${series} screen no\n\n";
  return s.str();
}

double liggghts_servo_vel_max(double cap, double dt, double step_factor) {
  return cap * step_factor / dt;
}

double liggghts_servo_kp(double gain, double force_target, double resist, int contacts,
                         double cap) {
  return gain * std::abs(force_target) / (resist * std::max(1, contacts) * cap);
}

std::string liggghts_servo_run(const std::vector<LiggghtsServoWall>& walls, double gain,
                               double resist, double cap, int every, NumberFormat f,
                               const std::string& resist_name) {
  std::ostringstream s;
  s << "# The servo's gain follows each lateral wall's current contacts n (the\n"
    << "# particles overlapping it) and target, as demcal's: between chunks of\n"
    << "# ${servo_every} steps, kp = gain*|F_target|/(" << resist_name << "*max(1, n)*cap)\n"
    << "compute nservo all reduce sum";
  for (const LiggghtsServoWall& w : walls) s << " v_" << w.touch;
  s << "\n";
  std::string modify;
  for (size_t k = 0; k < walls.size(); ++k) {
    const std::string n = "c_nservo[" + std::to_string(k + 1) + "]";
    s << "variable kp_" << walls[k].fix << " equal " << f(gain) << "*abs(v_" << walls[k].target
      << ")/(" << f(resist) << "*(" << n << "+(" << n << "<1))*" << f(cap) << ")\n";
    modify += " \"fix_modify " + walls[k].fix + " servo/ctrlParam ${kp_" + walls[k].fix + "} 0 0\"";
  }
  s << "variable servo_every index " << every << "\n"
    << "run ${run_steps} pre no post no every ${servo_every}" << modify << "\n";
  return s.str();
}

double liggghts_band(double strain, double width, double r_max) {
  return 2.0 * strain * width + 6.0 * r_max;
}

std::string liggghts_carried_servo_run(const std::vector<LiggghtsServoWall>& walls, double gain,
                                       double resist, double carry, double cap, double dt_demcal,
                                       const std::string& radius, int check_every, NumberFormat f) {
  std::ostringstream s;
  s << "# demcal's servo with contact damping (servo_velocity): each step a lateral\n"
    << "# wall moves along +axis by u = clamp(gain*(F_target + F)/(R*max(1, n))\n"
    << "# + carry*u', +-cap) in demcal's step dt_demcal, F the force on its mesh\n"
    << "# along +axis, n its current contacts, u' its last move: demcal's wall\n"
    << "# dashpots put the force c*v of a moving wall into F, so a move carries\n"
    << "# carry = (R - kn_wall)/R of the last and a steady error moves the wall at\n"
    << "# the undamped law's speed. At each step's end fix servo_w stores the move\n"
    << "# before the clamp (once: the clamp reads it four times), from u' = fix\n"
    << "# servo_u's last value (0 before its first), then servo_u stores u (fix\n"
    << "# ave/time runs in the fixes' order); the mesh moves at u/dt_demcal in the\n"
    << "# next step (fix move/mesh linear/variable), as LIGGGHTS' mesh servo would\n"
    << "# with kp, which cannot carry a move. The walls start at rest: u = 0 at the\n"
    << "# run's start, where the meshes have no force yet.\n"
    << "# n is counted every step over the particles that can touch the wall only:\n"
    << "# those whose centre is within the wall's band of its start (group band_W;\n"
    << "# band = 2*strain*width + 6*r_max, the LAMMPS decks'). Every ${band_check}\n"
    << "# steps the run checks that no particle outside a band touches its wall\n"
    << "# (clearance gap_W >= 0 over group out_W) and stops with an error if one\n"
    << "# does: then n would miss it; widen the bands.\n";
  const char coord[] = {'x', 'y', 'z'};
  std::string out_of_band;
  for (const LiggghtsServoWall& w : walls) {
    const std::string lo = w.upper ? f(w.start - w.band) : "INF";
    const std::string hi = w.upper ? "INF" : f(w.start + w.band);
    s << "region rband_" << w.fix << " block";
    for (int a = 0; a < 3; ++a) s << " " << (a == w.axis ? lo + " " + hi : "INF INF");
    s << " units box\n"
      << "group band_" << w.fix << " region rband_" << w.fix << "\n"
      << "group out_" << w.fix << " subtract all band_" << w.fix << "\n"
      << "compute nservo_" << w.fix << " band_" << w.fix << " reduce sum v_" << w.touch << "\n"
      << "variable gap_" << w.fix << " atom ";
    if (w.upper)
      s << w.position << "-" << coord[w.axis] << "-" << radius << "\n";
    else
      s << coord[w.axis] << "-" << radius << "-" << w.position << "\n";
    s << "compute clear_" << w.fix << " out_" << w.fix << " reduce min v_gap_" << w.fix << "\n";
    out_of_band += (out_of_band.empty() ? "" : "+") + ("(c_clear_" + w.fix + "<0)");
  }
  std::string raw_moves, moves;
  for (size_t k = 0; k < walls.size(); ++k) {
    const LiggghtsServoWall& w = walls[k];
    const std::string i = std::to_string(k + 1);
    const std::string n = "c_nservo_" + w.fix, raw = "f_servo_w[" + i + "]", c = f(cap);
    s << "variable sw_" << w.fix << " equal (step>0)*(" << f(gain) << "*(v_" << w.target << "+f_"
      << w.fix << "[" << w.axis + 1 << "])/(" << f(resist) << "*(" << n << "+(" << n << "<1)))+"
      << f(carry) << "*f_servo_u[" << i << "])\n"
      << "variable su_" << w.fix << " equal " << raw << "*(abs(" << raw << ")<=" << c << ")+" << c
      << "*(" << raw << ">" << c << ")-" << c << "*(" << raw << "<-" << c << ")\n";
    raw_moves += " v_sw_" + w.fix;
    moves += " v_su_" + w.fix;
  }
  s << "fix servo_w all ave/time 1 1 1" << raw_moves << "\n"
    << "fix servo_u all ave/time 1 1 1" << moves << "\n"
    << "variable servo_zero equal 0\n";
  for (size_t k = 0; k < walls.size(); ++k) {
    const LiggghtsServoWall& w = walls[k];
    s << "variable sv_" << w.fix << " equal f_servo_u[" << k + 1 << "]/" << f(dt_demcal) << "\n"
      << "fix smove_" << w.fix << " all move/mesh mesh " << w.fix << " linear/variable";
    for (int a = 0; a < 3; ++a) s << (a == w.axis ? " v_sv_" + w.fix : " v_servo_zero");
    s << "\n";
  }
  s << "variable band_out equal " << out_of_band << "\n"
    << "variable band_msg string '\"demcal deck: a particle outside the band of a lateral wall "
       "touches it, so the servo contact count misses it: widen the bands (band_W regions)\"'\n"
    << "variable band_check index " << check_every << "\n"
    << "run ${run_steps} pre no post no every ${band_check} "
       "'if \"${band_out} > 0\" then \"print ${band_msg}\" quit'\n";
  return s.str();
}

}  // namespace demcal::deck
