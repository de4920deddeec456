// Scoring: from a loading run's monitored series, how far it was from
// quasi-static, and which algorithmic parameter is to blame. Knows nothing
// of the search that uses it. Every component of b − σ is measured against a
// scale that makes it sensitive (the lateral ones against σ3), and oscillation
// and servo error are criteria of their own: the paper's single vertical
// measure passes runs whose peak is ~30 % off. Evidence and the choice of the
// default tolerances: reports/signature-atlas.md.
//
// Every measure is a relative number (0 = perfect), computed at the
// monitoring points after the first (the consolidated start is static by
// construction). Notation, per monitoring point k (tension positive, σ3 the
// lateral stress magnitude, s_yy(k) = max(|b_yy(k)|, σ3)):
//
//   g_xx = (b_xx − σ_xx)/σ3          lateral force balance
//   g_yy = (b_yy − σ_yy)/s_yy        vertical force balance (σ1's own scale)
//   g_s  = (sym b_xy − sym σ_xy)/σ3  shear force balance, symmetric parts
//   a    = (σ_xy − σ_yx)/σ3          moment balance
//   e_w  = (p_lateral walls − σ3)/σ3 boundary-control (servo) error
//
// V·(b − σ) = Σ_p x^p ⊗ F^p (World::net_force_moment()): the symmetric part
// of b − σ is the first moment of the particles' net forces (translational
// disequilibrium), the antisymmetric part of σ their net torques
// (rotational disequilibrium). Force balance therefore measures the
// symmetric part and moment balance the antisymmetric part: each index
// measures one thing.
//
// Each series is split into a trend (centred moving average over
// 2·kTrendHalfWidth+1 points) and noise (fourth differences). "Gap"
// measures are the largest |trend| over the loading beyond the noise floor
// (3 standard deviations of the averaged noise), so noise does not read as
// a gap; "noise" measures are robust standard deviations of the
// high-passed series (white noise of standard deviation s reads s).
// Force balance is taken up to the peak (the accuracy target is the peak;
// the whole-loading value is reported as force_balance_whole).
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"

namespace demcal {

/// Half-width of the moving average that separates a series' trend from
/// its noise (monitoring points).
inline constexpr int kTrendHalfWidth = 4;

/// Tolerances a quasi-static run must meet. Defaults are chosen from the
/// evidence of reports/signature-atlas.md: on the shipped scenes (hex_10x10,
/// random_400) every run that passes all four reproduces the converged
/// quasi-static peak within 2 %. They cannot guarantee it alone (nothing
/// measured on one run can): the calibration adds a convergence
/// certificate (Nstep doubled, Richardson estimate).
struct Tolerances {
  double force_balance = 0.008;  ///< max |trend| of g_xx, g_yy, g_s up to the peak
  double moment_balance = 1e-5;  ///< RMS of a = (σxy − σyx)/σ3
  double servo = 0.0025;         ///< max |trend| of e_w
  double oscillation = 1e-3;     ///< robust noise of g_xx, g_yy, g_s (largest)
};

struct Criteria {
  /// Paper's form: RMS(b_yy − σ_yy)/RMS(b_yy) over the raw series.
  double force_balance_paper = 0.0;
  /// Max |trend| of g_xx, g_yy, g_s (symmetric shear) over the loading up
  /// to the peak (the whole loading when the peak is at its end).
  double force_balance_xx = 0.0, force_balance_yy = 0.0, force_balance_shear = 0.0;
  /// The same, largest of the three, over the whole loading (post-peak
  /// included): reported; over-strict on wider samples, see §6.5 of the atlas.
  double force_balance_whole = 0.0;
  /// Max |trend| of the raw off-diagonal gaps (b_xy − σ_xy)/σ3, (b_yx − σ_yx)/σ3:
  /// reported for completeness; they also carry the moment imbalance.
  double force_balance_xy = 0.0, force_balance_yx = 0.0;
  double force_balance = 0.0;  ///< max of xx, yy, shear: the criterion
  /// RMS of g_xx over the raw series (the earlier form, for comparison).
  double force_balance_xx_rms = 0.0;
  double moment_balance = 0.0;        ///< RMS(a): the criterion
  double moment_balance_trend = 0.0;  ///< max |trend(a)|: steady asymmetry
  double moment_noise = 0.0;          ///< robust noise of a: rotational chatter
  double servo = 0.0;                 ///< max |trend(e_w)|: the criterion
  double servo_rms = 0.0;             ///< RMS(e_w)
  /// Interior lateral stress against σ3: max |trend((−σ_xx − σ3)/σ3)| =
  /// servo error + lateral gap. The effective confinement error.
  double interior_lateral = 0.0;
  /// Transient noise where b and σ disagree: largest robust noise of g_xx,
  /// g_yy, g_s.
  double oscillation = 0.0;
  double oscillation_xx = 0.0, oscillation_yy = 0.0, oscillation_shear = 0.0;
  /// Noise b_yy and σ_yy share (zigzag, stick-slip), over RMS(b_yy): the
  /// covariance of their high-passed series, sqrt(max(0, N(b+σ)² − N(b−σ)²)/4)
  /// with N an RMS (not median) noise without its largest 5 %, so sparse
  /// serrations count and a single failure drop does not.
  double zigzag = 0.0;
  /// Noise of the servo error (the walls chattering).
  double servo_noise = 0.0;
  /// Post-peak softening (b_yy_end − peak)/|peak| ≥ 0 and the post-peak
  /// spread: ~0 both for a perfectly plastic plateau.
  double post_peak_softening = 0.0;
  double plateau_spread = 0.0;
  /// Median share of the rotational kinetic energy in the kinetic energy:
  /// near 1 when the explicit scheme's rotational mode chatters (Δt beyond
  /// its limit), low when rotational damping holds the rotations.
  double rotational_energy_share = 0.0;
  /// Median KE / elastic energy: a dynamic (inertia-dominated) run.
  double kinetic_energy_ratio_median = 0.0;
  /// Other codes' measures, for comparison.
  double kinetic_energy_ratio_max = 0.0;  ///< max KE / elastic energy
  double unbalanced_force_ratio_mean = 0.0;
  double unbalanced_force_ratio_max = 0.0;
  double inertial_number_max = 0.0;
  /// Peak (b_yy, negative) and, when a reference is given, its relative
  /// error (|peak| − |reference|)/|reference|: positive when the strength
  /// is over-predicted.
  double peak_stress_yy = 0.0;
  double peak_strain_yy = 0.0;
  std::optional<double> peak_error;
  int points = 0;  ///< monitoring points scored (after the first)
  /// Measures the series could not give (another engine's series without
  /// the column: `demcal score`), by their to_json key, with what is missing,
  /// e.g. "servo" → "no column lateral_stress_error (nor p_left and
  /// p_right)". Their members hold 0 and mean nothing: to_json leaves them
  /// out (as peak_error without a reference) and lists them under
  /// "not_available", excesses() and the diagnosis do not read them, and a
  /// Score names the criteria among them not_checked. Empty for demcal's
  /// own runs. 3D adds "rotational_drag" (TriaxialCriteria).
  std::map<std::string, std::string> not_available;
  bool available(const std::string& key) const { return !not_available.count(key); }
  /// For the diagnosis' words: the pair of σ moment_balance measured (3D:
  /// the plane's whose asymmetry is largest).
  std::string moment_pair = "sigma_xy and sigma_yx";
  /// 3D: the rotational drag when it, folded in, sets moment_balance
  /// (scored_criteria()): the diagnosis then names the drag, not an
  /// asymmetry of σ.
  std::optional<double> moment_from_drag;
  /// 3D: how the asymmetry a comes, RMS(a)/median(|a|) over the plane
  /// moment_balance measured (burst_ratio(); compute_triaxial_criteria sets
  /// it, 2D leaves it unset and keeps the 2D atlas' chatter thresholds). A
  /// steady asymmetry, the rotational drag's, reads 1-1.5; the rotational
  /// chatter of a step at its stability limit comes in bursts, 9 and more
  /// (reports/signature-atlas-3d.md, 2026-12-04): the 3D diagnosis names
  /// the chatter from it.
  std::optional<double> moment_burst;
};

struct Diagnosis {
  /// "steps", "dt", "damping_translation", "damping_rotation",
  /// "mass_scaling", or "none" (quasi-static).
  std::string parameter;
  std::string direction;    ///< "increase", "decrease" or ""
  double confidence = 0.0;  ///< 0..1
  std::string message;      ///< one sentence for a user
  std::string signature;    ///< the pattern seen, short (wording of reports/signature-atlas.md §5)
};

/// Each criterion divided by its tolerance (≤ 1 passes); 0 for a criterion
/// the series could not give (Criteria::not_available).
struct Excesses {
  double force_balance = 0.0, moment_balance = 0.0, servo = 0.0, oscillation = 0.0;
  double worst() const;
  /// "force balance", "moment balance", "servo" or "oscillation": the worst.
  std::string worst_name() const;
};
Excesses excesses(const Criteria& criteria, const Tolerances& tolerances);

struct Score {
  Criteria criteria;
  bool diverged = false;
  bool complete = true;  ///< false when the run stopped early
  /// Every criterion checked within tolerance, not diverged.
  bool passed = false;
  /// The criteria not checked, for want of data (Criteria::not_available
  /// among force_balance, moment_balance, servo, oscillation and, 3D,
  /// rotational_drag), with what is missing.
  std::map<std::string, std::string> not_checked;
  /// excesses(criteria, tolerances).worst(): the largest value/tolerance
  double worst_excess = 0.0;
  double completed_fraction = 1.0;  ///< steps_run / steps_planned
  double particle_steps = 0.0;      ///< cost of the run as planned
  Diagnosis diagnosis;
};

/// Criteria of a series. `reference_peak` (b_yy, negative) adds peak_error.
Criteria compute_criteria(const LoadingResult& run, double lateral_stress,
                          std::optional<double> reference_peak = std::nullopt);
Criteria compute_criteria(const std::vector<MonitorPoint>& series, double lateral_stress,
                          std::optional<double> reference_peak = std::nullopt);
/// The algorithmic parameters the diagnosis reads, each known or not: a
/// series from another engine may not say them (`demcal score`), and an
/// unknown one is never read as 0 (a missing damping ratio is not an
/// undamped run). From an AlgorithmSpec all are known.
struct RunParameters {
  std::optional<double> dt_ratio, damping_ratio_translation, damping_ratio_rotation, mass_scaling;
  RunParameters() = default;
  RunParameters(const AlgorithmSpec& a)  // NOLINT(google-explicit-constructor): all known
      : dt_ratio(a.dt_ratio),
        damping_ratio_translation(a.damping_ratio_translation),
        damping_ratio_rotation(a.damping_ratio_rotation),
        mass_scaling(a.mass_scaling) {}
};
/// How a run ended, whatever its dimension: what a Score needs besides the
/// criteria.
struct RunOutcome {
  bool diverged = false, stopped_early = false;
  int64_t steps_run = 0, steps_planned = 0;
  int64_t particles = 0;
  RunParameters parameters;
};
/// The Score of a run's criteria (score_run and score_triaxial_run call it).
Score score_of(const Criteria& criteria, const RunOutcome& run, const Tolerances& tolerances);
Score score_run(const LoadingResult& run, double lateral_stress, const Tolerances& tolerances,
                std::optional<double> reference_peak = std::nullopt);
/// Relative error of a (negative) peak b_yy against a reference,
/// (reference − peak)/|reference|: positive when the strength is
/// over-predicted; nothing without a (non-zero) reference.
std::optional<double> peak_error_of(double peak, std::optional<double> reference);
/// The parameter most likely out of bounds, from the pattern of measures
/// (the paper's signatures as our kernel shows them: reports/signature-atlas.md
/// §5 and §7).
///
/// The pattern names the class of fault (divergence, rotational chatter,
/// dynamic run, noise, loading too fast for the walls, rotational drag,
/// translational drag); when the run's parameters are given (score_run
/// gives them) they pick the knob within the class, e.g. a drag gap with
/// ζ_t = 4 is "damping_translation decrease", with α = 0.02 "dt increase".
/// A parameter not known is not read; measures not available
/// (Criteria::not_available) are not either.
Diagnosis diagnose(const Criteria& criteria, const Tolerances& tolerances, bool diverged,
                   const RunParameters& parameters = {});
/// The algorithmic parameters a run was made with (α from Δt/Δt_crit).
AlgorithmSpec run_parameters(const LoadingResult& run);
/// The same from a run's integration, Δt_crit and planned steps (2D and 3D
/// runs alike).
AlgorithmSpec run_parameters(const Integration& integration, double dt_crit, int64_t steps_planned);

/// The force-balance measures (g_xx, g_yy, g_s) and the moment-balance
/// measure a of one monitoring point, as compute_criteria() takes them.
std::array<double, 3> force_balance_terms(const MonitorPoint& point, double s3);
double moment_term(const MonitorPoint& point, double s3);

/// Certain failure before a run ends (the calibration's early stop). Fed the
/// monitoring points in order, it says when the finished run could no longer
/// pass, from bounds that hold whatever the rest of the run does:
///  - moment balance: the RMS over the M points is at least
///    sqrt(Σ a² so far / M);
///  - force balance: the trend at point k (a centred average, final once
///    k + kTrendHalfWidth points are in) counts in the final maximum when k
///    is before the running peak (the final peak can only come later); the
///    noise floor subtracted from it is at most the oscillation tolerance, or
///    the run fails oscillation anyway.
/// It stops when a bound exceeds `factor` × the tolerance (servo error has
/// no such bound: its floor is not limited by any criterion).
class EarlyFailure {
 public:
  EarlyFailure(const Tolerances& tolerances, double factor, int monitor_points, double s3);
  /// Add the next point (the consolidated start first); true once failed.
  bool add(const MonitorPoint& point);

 private:
  Tolerances tolerances_;
  double factor_, s3_;
  int monitor_points_;
  int points_ = 0;  // added so far, the start included
  double peak_ = 0.0;
  int peak_index_ = -1;  // of the most compressive b_yy so far (series index)
  std::array<std::vector<double>, 3> g_;
  size_t next_trend_ = kTrendHalfWidth;  // next g index whose trend is checked
  double moment_sum_ = 0.0;
  bool failed_ = false;
};

/// The largest value/tolerance of the criteria that come from the loading
/// rate (force balance, servo, moment balance): at fixed multipliers they
/// fall like 1/Nstep (reports/optimizers.md), so a run at Nstep = N
/// predicts the smallest passing Nstep N·rate_excess.
double rate_excess(const Criteria& criteria, const Tolerances& tolerances);

/// Constraint values for a constrained search, one per criterion in the
/// order force balance, moment balance, servo, oscillation:
/// log(value/tolerance), ≤ 0 when met. A diverged run gives +3 for each; a
/// run stopped early at least +0.1.
std::array<double, 4> constraint_values(const Score& score, const Tolerances& tolerances);

/// The cost term of objective(): log10(particle-steps)/20, in [0, 1] for
/// up to 10²⁰ particle-steps; linear in log Nstep, as the search is.
double cost_term(double particle_steps);

/// What the NLopt strategies of the search minimise over
/// x = (α, log10 Nstep, ζ_t, ζ_r): log10 Nstep (the cost, linear in the
/// search variable). Constrained strategies (cobyla, auglag) add the
/// constraint_values() as constraints; unconstrained ones (penalty, the
/// direct global phase) set `penalised` and minimise
///   log10 Nstep + 10·Σ max(0, g_c).
/// The model strategy minimises a predicted Nstep (calibration.cpp).
double search_objective(int64_t steps, const Score& score, const Tolerances& tolerances,
                        bool penalised);

/// The quasi-static error of a peak whose error decays like 1/Nstep
/// (measured: reports/optimizers.md), from two runs with Nstep and
/// refinement·Nstep: Richardson extrapolation.
///   Limit:  P(∞) ≈ (n_fine·P_fine − n_coarse·P_coarse)/(n_fine − n_coarse).
///   Error of the coarse run, relative: r/(r − 1)·|P_coarse − P_fine|/|P_fine|
///   with r = refinement (2 for Nstep doubled: twice the change).
double richardson_limit(double n_coarse, double p_coarse, double n_fine, double p_fine);
double richardson_error(double relative_change, double refinement = 2.0);

/// A ranking of runs for atlases and reports (the sweep's `objective`, the
/// report's trial table), lower is better, always finite:
///   passed:         f = c                         ∈ [0, 1]
///   finished, not:  f = 1 + 0.9·V/(1 + V) + 0.1·c ∈ (1, 2)
///   diverged:       f = 3 − completed_fraction    ∈ [2, 3]
/// with c = cost_term(P), P the particle-steps planned (among quasi-static
/// runs the cheapest wins), V = Σ max(0, log(value/tolerance))
/// over the four criteria (how far the run is from passing; a run stopped
/// early counts V ≥ 0.1). Every passing run beats every failing one, every
/// finished run beats every diverged one, and a run that diverged later
/// beats one that diverged sooner.
double objective(const Score& score, const Tolerances& tolerances);

/// Robust noise level of a series: the median of |fourth differences|
/// (x_{k−2} − 4x_{k−1} + 6x_k − 4x_{k+1} + x_{k+2}, zero for any cubic: a
/// smoothly curving response is not noise), scaled so that white noise of
/// standard deviation s gives s.
double robust_noise(const std::vector<double>& series);
/// How a series comes in bursts: RMS over the median of |x|, 1 for a
/// steady level, about 1.5 for white noise, large when a few points carry
/// the mean square; 0 for an empty or all-zero series, +∞ for a median of 0
/// under a nonzero RMS (bursts above a zero floor).
double burst_ratio(const std::vector<double>& series);
/// RMS noise level from the same fourth differences, the largest fraction
/// `trim` of them left out (sparse serrations count, one or two isolated
/// events do not), scaled so that white noise of std s gives s.
double rms_noise(const std::vector<double>& series, double trim = 0.0);
/// Centred moving average of half-width h; the window shrinks
/// symmetrically at the ends, so a linear series is its own trend.
std::vector<double> moving_trend(const std::vector<double>& series, int half_width);

/// b − σ from the identity V·(b − σ) = Σ_p x^p ⊗ F^p: the force-balance gap
/// of a world state without recomputing either stress.
Eigen::Matrix2d force_balance_gap(const World& world);
/// Consistency of a world state with that identity: ‖(b − σ) −
/// net_force_moment()‖ / max(‖b‖, tiny). ~1e-12 for a consistent kernel.
/// Disks (2D) and spheres (3D, SphereWorld::net_force_moment()) alike.
double gap_identity_residual(const World& world);
class SphereWorld;
double gap_identity_residual(const SphereWorld& world);

/// Every field of Criteria (peak included) by its name; a measure not
/// available is left out, and "not_available" (only when some are) maps
/// its key to what is missing.
nlohmann::json to_json(const Criteria& criteria);
/// The inverse of to_json(Criteria) (a trial record read back on resume);
/// keys missing (older records) keep their defaults, "not_available" is
/// read back, a wrong type throws nlohmann::json::exception.
Criteria criteria_from_json(const nlohmann::json& json);
nlohmann::json to_json(const Tolerances& tolerances);
nlohmann::json to_json(const Diagnosis& diagnosis);

}  // namespace demcal
