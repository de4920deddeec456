// Pieces of text the 2D deck writer (export.cpp) and the 3D deck writer
// (export_3d.cpp) share: one home each, so that a change to a number's
// format, the contact law's mapping or a block of a deck is made once.
// Private to the upscaling layer. Where the two decks differ in a detail
// (the dimension, the boundary, the number format), it is a parameter.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "demcal/kernel/material.hpp"
#include "demcal/upscaling/export.hpp"

namespace demcal::deck {

/// A number in a deck: 10 significant digits (num), 17 (exact: round-trips
/// a double), 3 (fmt3: for prose).
std::string num(double v);
std::string exact(double v);
std::string fmt3(double v);

/// How a writer formats the numbers of a block: num or exact.
using NumberFormat = std::string (*)(double);

/// The radius classes of a deck (one atom type each, radius_classes) and
/// each class's smallest and largest radius (index type−1).
struct RadiusClasses {
  int types = 0;
  std::vector<int> type;  // per particle, 1-based
  std::vector<double> r_lo, r_hi;
};
RadiusClasses radius_class_bounds(const std::vector<double>& radii, int max_types);

/// The deck's step and run length: both engines apply fix viscous
/// explicitly (the force from the half-step velocity), which shrinks the
/// stable step by f = dashpot_step_factor(zeta_t); demcal's damping is
/// semi-implicit. The deck runs at alpha·f·dt_crit for Nstep/f steps: the
/// same loading time, rate and strain, the same stability margin as demcal.
struct DeckTiming {
  double step_factor = 1.0, dt = 0.0;
  double demcal_dt = 0.0;  ///< α·Δt_crit: demcal's step, the servo law's time unit
  int64_t steps = 0;
};
/// The run length is deck_steps(p) (export.hpp), the one home of Nstep/f.
DeckTiming deck_timing(const AlgorithmSpec& p, double dt_crit);

/// What the 2D and the 3D plan (export.cpp's Plan, export_3d.cpp's Plan3)
/// share, set once for both by set_plan_classes and set_plan_timing.
struct PlanCommon {
  int n = 0, types = 0;
  std::vector<int> type;           // per particle, 1-based
  std::vector<double> r_lo, r_hi;  // per class (index type−1)
  double r_min = 0.0, r_max = 0.0, dt_crit = 0.0;
  double step_factor = 1.0;  // f = sqrt(1 + zeta_t^2) - zeta_t: explicit fix viscous
  double dt = 0.0;
  double demcal_dt = 0.0;  // α·Δt_crit: demcal's step, the servo law's time unit
  int64_t steps = 0;
  double top_speed = 0.0;                // [m/s], downward
  std::vector<double> gamma_t, gamma_r;  // per class [N·s/m], [N·m·s]
  std::vector<double> class_mass;        // per class, at its mid radius [kg]
  double class_error = 0.0;
  // The servo's (as the scene's servo_velocity): the heaviest particle's
  // mass m_max [kg] at the mass scaling, the wall dashpots' c [N·s/m]
  // (servo_wall_dashpot, 0 without contact damping), R = kn_wall +
  // c/demcal_dt [N/m] (servo_resistance), and the share of its last move
  // that the servo carries into the next (servo_carry_at demcal_dt, 0
  // without contact damping).
  double m_max = 0.0, wall_dashpot = 0.0, servo_resist = 0.0, servo_carry = 0.0;
};

/// A plan's count and radius classes (radius_class_bounds of `radii`).
void set_plan_classes(PlanCommon& plan, const std::vector<double>& radii, int max_types);

/// A plan's step and run length (deck_timing at plan.dt_crit, which must be
/// set) and its servo's figures at the heaviest particle's mass `m_max`.
void set_plan_timing(PlanCommon& plan, const AlgorithmSpec& p, const Material& m, double m_max);

/// Steps between two monitoring rows: Nstep / monitor_points, at least 1.
int monitor_interval(int64_t steps, int monitor_points);

/// The mapping header's opening: the banner naming the engine (`code`),
/// the test (`test`, e.g. "2D biaxial test") and the sample (`sample`, one
/// line without "# "), the parameters' provenance (o.provenance), that they
/// are not certified and why (o.uncertified, when set), and the step line
/// dt = alpha·f·dt_crit.
std::string header_opening(const std::string& code, const std::string& test,
                           const std::string& sample, const ExportOptions& o, double dt_ratio,
                           double step_factor, double dt_crit, double dt);

/// `text` as deck comment lines, each `prefix` then words up to 79
/// characters: a character LAMMPS' reader would act on even in a comment
/// (a control character, a line's closing `&`, a `"`) or a non-ASCII byte
/// is replaced, so the text cannot end the comment.
std::string comment_lines(const std::string& prefix, const std::string& text);

/// The deck's `variable series index FILE` line: its monitoring series,
/// deck_files(o.deck_name).series unless `-var series NAME` renames it.
std::string series_variable(const ExportOptions& o);

/// The mapping header's line on the step factor f (the engine's explicit
/// fix viscous).
std::string header_step_factor(const std::string& code, double step_factor, double zeta_t);

/// The mapping header's lines on the particles' contact law and the
/// contact damping (the last line left open for the writer's detail).
std::string header_contact_law(const Material& m);

/// The mapping header's walls' contact law (the line left open).
std::string header_wall_law(const Material& m);

/// The figures every export reports (the files and deck are added after),
/// with the notes both writers give: the tangential springs start at zero,
/// and the step factor f when the explicit damping shrinks the step.
ExportResult plan_result(const PlanCommon& plan);

/// The pair style's gamma_n for demcal's contact damping: demcal
/// ratio·2·sqrt(kn·m_eff), LAMMPS m_eff·gamma_n, so gamma_n =
/// ratio·2·sqrt(kn/m_eff), taken at the mean mass (m_eff = m/2); 0 without.
double contact_gamma_n(const Material& m, double mass_mean);

/// The note when zeta_r > 0: LAMMPS 29 Sep 2021 has no rotational viscous fix.
std::string lammps_rotational_damping_note(double zeta_r);

/// The note when the damping goes per radius class (atom type); `what` is
/// the particle's kind in "demcal's per-WHAT value" (particle, sphere).
std::string lammps_class_damping_note(int types, double class_error, const std::string& what);

/// LAMMPS parameters block: the particles' and the walls' contact laws
/// (variables kn kt mu kn_wall kt_wall mu_wall).
std::string lammps_material_variables(const Material& m, NumberFormat f);

/// The servo's move cap as the decks' comments state it: "P % of r_min",
/// P = 100·kServoMoveCapRatio (scene/biaxial.hpp).
std::string servo_cap_text();

/// LAMMPS derived block: the top wall's speed, the servo's cap and gain
/// and the monitoring interval (from the parameters block). demcal's servo
/// law is per demcal step, servo_dt (a parameter: α·Δt_crit); the deck's
/// step dt is f·servo_dt (the engine's damping needs f < 1, engines.md §7),
/// so a step moves a wall dt/servo_dt times demcal's per-step move
/// (`gain_kn`, `cap_step`): over the same loading time the walls answer as
/// fast as demcal's, and editing dt keeps that (without the factor, the
/// walls were corrected 1/f times as often and the servo error read f times
/// demcal's).
/// `wall_dashpot` > 0: demcal's wall contacts' dashpot c (contact damping;
/// servo_wall_dashpot, scene/biaxial.hpp): demcal's servo divides by
/// R = kn_wall + c/servo_dt, as demcal's (servo_resistance), and the block
/// derives it from `c_wall` (written with `f`); the 3D servo likewise
/// (triaxial.cpp), `particle` names the heaviest one ("disc", "sphere"),
/// and `carry` is demcal's servo_carry at servo_dt (servo_carry_at), the
/// share of its last move that demcal's servo carries into the next (the
/// block defines `carry`, written with 17 digits; lammps_servo_carried).
/// 0: R = kn_wall, nothing carried.
std::string lammps_loading_derived(double wall_dashpot = 0.0, NumberFormat f = num,
                                   const std::string& particle = "disc", double carry = 0.0);
/// The loading servo's carried term, "+${carry}*" `prev` (`prev` the walls'
/// last moves, a vector: the deck's fix of them, defined after the fix that
/// sums the moves, so that at a step's end it still holds the step
/// before's), appended to the unclamped move before the clamp: demcal's
/// servo_velocity, move = law + carry*u, clamped. Per step of dt: the last
/// move u is dt/servo_dt times demcal's, as the law's move is, so the
/// carry (of demcal's step) multiplies it as it is.
std::string lammps_servo_carried(const std::string& prev);
/// `fix FIX all ave/time 1 1 1 v_MOVEV[1] .. v_MOVEV[count]`: the walls'
/// moves of this step, which the servo's formula reads as the last ones at
/// the next (0 before the first step: the walls start at rest).
std::string lammps_previous_moves(const std::string& fix, const std::string& movev, size_t count);
/// The parameters block's line of servo_dt (demcal's step, s).
std::string lammps_servo_dt(double servo_dt, NumberFormat f);

/// LAMMPS: the thermo_modify line of every LAMMPS deck's progress lines
/// (stage 1's and the loading's, 2D and 3D): totals, not per atom (norm
/// no), and each line flushed to the log and the screen as it is printed
/// (flush yes: one fflush per thermo line, every 2 000 steps in stage 1).
/// Without the flush a log file, and the screen when it is a file (mpirun
/// in a batch job), is written in 4 KiB blocks: stage 1's header promises
/// progress in these lines, and a run stopped by a signal (a batch job's
/// time limit, Ctrl-C, kill) loses the last block, tens of lines: a 10 000
/// disk stage 1 stopped at 30 s showed step 6 000 in its log and had passed
/// 12 000 (reports/engines.md §28, where this misread §27's cost per step).
std::string lammps_thermo_modify();

/// LAMMPS system block, head: units, dimension, boundary, atom style.
std::string lammps_system_head(int dimension, const std::string& boundary);

/// LAMMPS system block, tail: the contact law (gamma_n of contact_gamma_n),
/// the neighbour list, the timestep and the integrator (fix nve/sphere
/// with `integrate_args`, e.g. "disc").
std::string lammps_contact_law(double gamma_n, double r_min, const std::string& integrate_args);

/// LAMMPS global damping block, translational part: fix viscous per radius
/// class (gamma_t[k] for type k+1), or a comment when zeta_t = 0.
std::string lammps_translational_damping(double zeta_t, const std::vector<double>& gamma_t,
                                         NumberFormat f);

/// LAMMPS: the contact force F_p (pairs and walls) on each particle at a
/// monitoring step, as atom-style variables fc1_a .. fcD_a (D the
/// dimension), recovered from the total force instead of a per-step `fix
/// store/force`. fix viscous adds -gamma·v(t+dt/2) at post_force and
/// velocity Verlet ends the step with v = v(t+dt/2) + dt·f/(2m), so
/// F = f + gamma·(v - dt·f/(2m)); at a run's first step (its setup,
/// `first_step`, e.g. "${step0}") v is the start velocity: F = f + gamma·v.
/// gamma per type as fix viscous takes it (gamma_t[0] times each type's
/// printed scale); without damping (zeta_t = 0) F = f.
std::string lammps_contact_force_atom(int dimension, double zeta_t,
                                      const std::vector<double>& gamma_t, NumberFormat f,
                                      const std::string& first_step);

/// LAMMPS: the sum over the wall fixes `fixes` (e.g. "wleft") of
/// f_FIX[a], times f_FIX[b] when b > 0: an atom-style variable's formula.
std::string lammps_wall_sum(const std::vector<std::string>& fixes, int a, int b);

/// LAMMPS: demcal's servo move of one wall in one step, toward the sample
/// when its pressure is below sigma3: gain*(sigma3*A - F)/(kn_wall*max(1,
/// n)), clamped to ±cap, in two formulas: the unclamped move and clamp(x)
/// of a formula x, (abs(x+cap)-abs(x-cap))/2 (this release has no min/max
/// of two numbers). A deck stores the unclamped moves in a vector variable
/// (doubles, evaluated once per step) and clamps those: the raw formula is
/// parsed once per step. `cap` the cap's variable (the loading's
/// ${cap_step}: see lammps_loading_derived).
std::string lammps_servo_clamp(const std::string& x, const std::string& cap = "${cap}");
/// The unclamped move with the target load sigma3*A given whole (`load`,
/// e.g. a fix's stored value of sigma3*A) and max(1, n) given as a formula
/// (`count_max`): gain*(load - F)/(kn_wall*count_max), `minus_force` the
/// term that subtracts F (e.g. "-c_cs[2]"). `resist` replaces kn_wall (e.g.
/// "(${kn_wall}+c/dt)" with wall dashpots). Per step of demcal's own
/// consolidation (stage 1).
std::string lammps_servo_raw_of_load(const std::string& load, const std::string& minus_force,
                                     const std::string& count_max,
                                     const std::string& resist = "${kn_wall}");
/// The unclamped move with gain/kn_wall folded into one constant (the
/// deck's derived `gain_kn`): gain_kn*(load - F)/count_max, `count_max`
/// max(1, n) as a formula (lammps_count_max_one). The same law as
/// lammps_servo_raw_of_load, rounded once less, per step of the deck's dt
/// (gain_kn carries dt/servo_dt: lammps_loading_derived): the loading's
/// servo in the 2D and 3D decks.
std::string lammps_servo_raw_folded(const std::string& load, const std::string& minus_force,
                                    const std::string& count_max);
/// max(1, n) of a contact count n (a sum of ones: an integer-valued double)
/// as n+!n: n for n >= 1, 1 for n = 0 (`!` is 1 for 0, else 0), the same
/// double as (1+n+abs(1-n))/2 and, times kn_wall, as kn_wall*(1+n+abs(1-n))/2
/// = kn_wall*max(1, n) (2n/2 is exact), with fewer tokens for the parser.
std::string lammps_count_max_one(const std::string& count);

/// LAMMPS: a wall's band depth (the particles a moving wall acts on lie
/// within it of the wall's start), `motion` (the wall's largest travel in the
/// test, a formula of the parameters) plus six of the largest radii: the
/// line `variable NAME equal $(MOTION+6*v_r_max)`, with `comment` after it.
std::string lammps_band(const std::string& name, const std::string& motion,
                        const std::string& comment = "");

/// LAMMPS: the series file's header (print lines of SeriesMetadata's
/// lines, scene/run_output.hpp), what `demcal score`
/// reads about the run: the deck (`deck`, e.g. "LAMMPS 3D deck"), scene,
/// particles, sigma3, Nstep, dt, dt_crit (the lightest particle's, at the
/// mass scaling), the damping ratios applied (zeta_r 0: no rotational
/// fix), f_ms, the lever arm the engine applies a contact's tangential
/// force at (LAMMPS: r_i). Every deck, 2D and 3D, gives dt_crit and f_ms:
/// without them the diagnosis of `demcal score` does not know the time-step
/// ratio dt/dt_crit (the deck's alpha*f) nor the mass scaling, and cannot
/// blame a small step or heavy masses (scoring.cpp, diagnose).
std::string lammps_series_header(const std::string& deck, const std::string& scene, int particles,
                                 double zeta_t, double dt_crit, double mass_scaling,
                                 const std::string& lever_arm = "radius");

/// Stage 1 of a deck that consolidates itself (LAMMPS; export.cpp in 2D,
/// export_3d.cpp in 3D): demcal's consolidation (scene/protocol_steps.hpp)
/// with every wall a `fix cons_wNAME wall/gran/region ... contacts` servoed
/// at sigma3. What the writers share is written here once.
struct ConsolidationWall {
  std::string name;      ///< fix cons_w<name>, e.g. "l" (2D left), "xmin"
  char axis = 'x';       ///< the wall's axis
  bool min = true;       ///< inward normal +axis (left, bottom, x min ...)
  int column = 0;        ///< its contacts c_cons_wn[column], its force c_cons_wf[column]
  std::string pressure;  ///< its compressive pressure [Pa], an equal-style formula
};

/// Stage 1's per-wall sums over the particles (walls in pairs, min then max,
/// axis by axis; wall k is column k+1): compute cons_wn, each wall's contact
/// count, and compute cons_wf, its force along its axis on the particles
/// (f_cons_wNAME[1] and [2 + axis]).
std::string lammps_consolidation_reductions(const std::vector<ConsolidationWall>& walls);

/// Stage 1's servo: every wall's move per step, gain*(sigma3*A - F)/(R*max(1,
/// n)) clamped to ±cap, in one vector-style formula (cons_rawv, clamped by
/// cons_movev; element k is wall k's move along +axis, the max walls' computed
/// with the opposite sign), summed by fix cons_servo (f_cons_servo[k], the
/// running mean). `area`: one equal-style variable per axis whose value (read
/// as a `v_` reference reads it, through text) times `area_tail` is the area
/// of that axis's walls (2D: "cons_H", "cons_W" and "*${thick}"; 3D:
/// "cons_Ax" .. "cons_Az" and ""); `resist` R, e.g. "${kn_wall}". Each element
/// is, bit for bit, the per-wall formula lammps_servo_move(A, ∓F, n) (negated
/// for a max wall). `carry` > 0 (contact damping): demcal's consolidation
/// servo (servo_velocity, scene/biaxial.hpp), the raw move plus
/// v_cons_carry (defined here as `carry`, servo_carry_at stage 1's
/// light step) times the wall's previous clamped move (fix cons_prev, after
/// cons_servo, 0 before the first step); 0: the per-step law alone.
std::string lammps_consolidation_servo(const std::vector<ConsolidationWall>& walls,
                                       const std::vector<std::string>& area,
                                       const std::string& area_tail, const std::string& resist,
                                       double carry = 0.0);
/// The carry of demcal's servo at its step `dt`: servo_carry(kn_wall, R),
/// R = servo_resistance(m, m_max, dt), the R that the deck's raw move
/// divides by (stage 1: kn_wall + c/dt at its step; the loading: at
/// servo_dt, demcal's step); 0 without contact damping.
double servo_carry_at(const Material& m, double m_max, double dt);

/// Stage 1's lines in the parameters block: consolidate (1: run it), the
/// scene's test.consolidation_* values (cons_tol, cons_unbalanced,
/// cons_max_steps) and cons_check (demcal's 200 steps between checks).
std::string lammps_consolidation_parameters(const TestSpec& test);

/// The step of stage 1 at damping ratio zeta: alpha·f(zeta)·dt_crit (the
/// explicit damper's factor, as the loading's deck_timing).
double consolidation_dt(double alpha, double zeta, double dt_crit);

/// Stage 1's cons_quarter, cons_capped, cons_cut and cons_last (runs end on
/// check steps): the budget's last check (the first at or after
/// cons_max_steps, where demcal's consolidation ends), and the check from which the
/// friction phase runs at critical damping, demcal's (scene/biaxial.hpp, critical_damping_after;
/// cons_capped: the first check at or after twice it, the switch when the
/// frictionless phase was cut at cons_cut): the first
/// check at or after a quarter of cons_max_steps in the simulated time of
/// the undamped step, (cons_max_steps/4)/S steps, S the step shrink
/// (consolidation_step_shrink: 1 without contact dashpots), at most the
/// last, computed by LAMMPS from cons_max_steps with S's 17 digits (the
/// same doubles as demcal's); and cons_cut, where a frictionless phase not
/// yet static ends: cons_quarter, at most the first check at or after half
/// the budget (frictionless_phase_cut). `alpha`: stage 1's, demcal's consolidation α
/// (shrunk for contact dashpots); `max_steps` the exported budget, for the
/// comment.
std::string lammps_consolidation_quarter(double alpha, int64_t max_steps);

/// Stage 1's fix viscous per radius class, gamma[k] for type k+1.
std::string lammps_consolidation_viscous(const std::vector<double>& gamma);

/// The end of stage 1's header comment, 2D and 3D: friction phases,
/// critical damping from cons_quarter (the step's factor f(1)/f(zeta)), the
/// static criterion, what the loading takes from the end state. `particle`
/// names one ("particle", "sphere"), `start_walls` the loading's start
/// walls ("xl0 xr0 yb0 yt0", "xmin0 .. zmax0").
std::string lammps_consolidation_comment(double zeta, const std::string& particle,
                                         const std::string& start_walls);

/// Stage 1's first lines after its jump: the servo's cap (kServoMoveCapRatio
/// r_min), the light step `dt_light` (alpha·f(zeta)·dt_crit), the start step
/// cons_s0, and cons_quarter, cons_capped, cons_cut and cons_last
/// (lammps_consolidation_quarter).
std::string lammps_consolidation_start(double alpha, double dt_light, int64_t max_steps);

/// Stage 1's static criterion, demcal's: every wall within cons_tol of
/// sigma3 and the unbalanced-force ratio mean|F_p|/mean|f_c| below
/// cons_unbalanced, checked every cons_check steps by fix halt; the per-wall
/// sums that place each wall at the end (compute cons_pos); the thermo line.
/// `axis_names`: one name per axis for the largest error of its two walls
/// (walls are given in pairs, min then max, axis by axis).
std::string lammps_consolidation_criterion(int dimension,
                                           const std::vector<ConsolidationWall>& walls,
                                           const std::vector<std::string>& axis_names);

/// Stage 1's runs, demcal's run_consolidation: frictionless until static,
/// at most until cons_cut, then friction on until static; critical
/// damping (`critical`: its fix viscous line, step dt_damped) in the
/// friction phase from cons_quarter, or cons_capped when the frictionless
/// phase was cut (lammps_consolidation_quarter), none when that is the
/// budget's end; quit 2 when the budget is spent. `carry_damped` > 0: the
/// servo's carry (lammps_consolidation_servo's cons_carry) from the switch
/// on, servo_carry_at dt_damped.
std::string lammps_consolidation_runs(double gamma_n, double dt_damped, const std::string& critical,
                                      double carry_damped = 0.0);

/// Where stage 1 leaves a wall (i its index in `walls`, cons_pos's column
/// i+1): placed by its contacts, F = kn_wall·sum of overlaps (exact for
/// the undamped walls), as an immediate $(...) expression.
std::string lammps_consolidated_wall(const ConsolidationWall& wall, int i);

/// Stage 1's end after the start walls are set: particles at rest, stage
/// 1's fixes, computes and regions removed (`extra_fixes` besides the
/// walls', servo, damping and force store), step 0, the loading's step,
/// label loading.
std::string lammps_consolidation_end(const std::vector<ConsolidationWall>& walls,
                                     const std::vector<std::string>& extra_fixes);

/// LIGGGHTS: atom style, boundary, communication, units (and dimension 2
/// for `dimension` 2), the data file and the neighbour list.
std::string liggghts_preamble(int dimension, const std::string& boundary,
                              const std::string& data_name, double r_min);

/// LIGGGHTS: the materials (types 1..K the radius classes, of mass
/// class_mass[k − 1] each; type K + 1 the walls'), the granular pair style
/// and the timestep. The normal dashpot is demcal's per type pair:
/// gamman_abs = ζ_c·2·sqrt(kn·m_eff), m_eff = m_i·m_j/(m_i + m_j) between
/// classes and m_i against a wall (with the wall's kn), as the kernels'
/// contact law; 0 without contact damping. No tangential dashpot (demcal
/// has none).
std::string liggghts_materials(const Material& m, const std::vector<double>& class_mass, double dt,
                               NumberFormat f);

/// LIGGGHTS: the hooke/stiffness model's settings for the pair style and
/// every wall fix: absolute damping (gamman_abs is a damping coefficient),
/// no tangential damping, and with contact damping `limitForce on` (the
/// normal force never pulls: demcal's max(0, kn·δ − c·v_n)).
std::string liggghts_model_settings(const Material& m);

/// LIGGGHTS: fix viscous per radius class (nothing when zeta_t = 0).
std::string liggghts_translational_damping(double zeta_t, const std::vector<double>& gamma_t,
                                           NumberFormat f);

/// LIGGGHTS: the series file (`demcal score` reads it): its header,
/// lammps_series_header's keys (the same print lines run in LIGGGHTS 3.8)
/// with the lever arm LIGGGHTS applies a contact's tangential force at,
/// r_i - delta/2 as demcal (its surface model's cri; walls too, where demcal
/// takes the wall's distance r_i - delta: the same without wall friction);
/// a `fix print` of `row` every `every` steps under the title `columns`;
/// and the start's row, which LIGGGHTS 3.8's fix print does not write at
/// setup, printed after a `run 0`.
std::string liggghts_series(const std::string& deck, const std::string& scene, int particles,
                            double zeta_t, double dt_crit, double mass_scaling, int every,
                            const std::string& row, const std::string& columns);

/// LIGGGHTS: a lateral servo mesh (fix mesh/surface/stress/servo) and
/// what its gain is made of: `fix` its id, `target` its equal-style target
/// force variable (the force on the mesh along +axis), `touch` a per-atom
/// variable, 1 on the particles that overlap it (the series' own).
struct LiggghtsServoWall {
  std::string fix, target, touch;
  int axis = 0;  // the wall's normal: 0 x, 1 y
  // With contact damping (liggghts_carried_servo_run) the count n reads
  // the particles within `band` of the wall's start `start` only; `upper`
  // the wall bounds the sample from above along its axis; `position` the
  // equal-style variable (v_...) of its current position.
  double band = 0.0, start = 0.0;
  bool upper = false;
  std::string position;
};

/// The band of particles that can touch a lateral wall during the loading,
/// as the LAMMPS decks' walls (lammps_band): the wall's motion bound,
/// 2·strain·width (strain the loading's vertical strain, width the sample's
/// across the wall at the start), and 6·r_max.
double liggghts_band(double strain, double width, double r_max);

/// LIGGGHTS' servo law (MeshModuleStressServo, 3.8) moves a mesh at
/// vel_max·kp·(F_target − F)/|F_target| per unit time. With vel_max =
/// cap/Δt_demcal (Δt_demcal = dt/step_factor: demcal's step, the engine's
/// divided by f) and kp = gain·|F_target|/(kn_wall·max(1, n)·cap), a wall
/// moves at demcal's velocity gain·(F_target − F)/(kn_wall·max(1, n)·Δt_demcal),
/// capped at demcal's cap/Δt_demcal: over the same loading time, demcal's
/// servo (per engine step: f times demcal's per-step move). `resist` is
/// the R demcal's servo divides by in place of kn_wall: kn_wall + c/Δt_demcal
/// with contact damping, 2D and 3D (servo_resistance, scene/biaxial.hpp).
double liggghts_servo_vel_max(double cap, double dt, double step_factor);
double liggghts_servo_kp(double gain, double force_target, double resist, int contacts, double cap);

/// LIGGGHTS: the loading run, `${run_steps}` steps in chunks of `every`
/// (run ... pre no every: one setup, the chunks continue the trajectory
/// exactly), each wall's kp set between chunks (fix_modify
/// servo/ctrlParam) from its current contacts and target, the formula of
/// liggghts_servo_kp: the gain lags demcal's by `every` steps at most.
/// `resist` R as in liggghts_servo_kp, `resist_name` how the deck's
/// comment names it.
std::string liggghts_servo_run(const std::vector<LiggghtsServoWall>& walls, double gain,
                               double resist, double cap, int every, NumberFormat f,
                               const std::string& resist_name = "kn_wall");

/// LIGGGHTS with contact damping: demcal's servo carries `carry` =
/// servo_carry(kn_wall, R) of a wall's last move (scene/biaxial.hpp), which
/// LIGGGHTS 3.8's mesh servo cannot (its law is kp, ki, kd on the error:
/// reports/engines.md §25). The lateral walls are then plain stress meshes
/// (fix mesh/surface/stress with reference_point at the wall's centre, so
/// f_FIX[7..9] is its position as the servo mesh's) moved by fix move/mesh
/// linear/variable at demcal's velocity: each step's end stores a wall's
/// move along +axis u = clamp(gain*(F_target + F)/(R*max(1, n)) + carry*u',
/// +-cap) (fix servo_w the move before the clamp, then fix servo_u u: one-step
/// ave/time fixes), F the mesh's force along +axis, n its current contacts
/// (compute nservo), u' its last move (servo_u's last value), 0 at the run's
/// first step; the mesh moves at u/dt_demcal in the next. n is counted
/// every step over the wall's band only (compute nservo_FIX over the static
/// group band_FIX: the particles whose centre lies within wall.band of the
/// wall's start); the loading run goes in chunks of `check_every` steps
/// (one setup: the chunks continue the trajectory exactly) and stops with
/// an error (print, quit) at a chunk's end if a particle outside a band
/// touches its wall (`radius` the per-atom radius reference, c_pa[1]).
std::string liggghts_carried_servo_run(const std::vector<LiggghtsServoWall>& walls, double gain,
                                       double resist, double carry, double cap, double dt_demcal,
                                       const std::string& radius, int check_every, NumberFormat f);

}  // namespace demcal::deck
