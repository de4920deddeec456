// The report's first part: title, the answer at a glance, the parameter
// table, the criteria, the certificate, the evidence and how to reproduce.
#include <algorithm>
#include <cmath>
#include <optional>

#include "demcal/io/format.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "html.hpp"
#include "sections.hpp"

namespace demcal::report {

void write_title(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  const std::string title = "demcal calibration report: " + in.scene;
  d.raw_html(page_head(title));
  d.heading(1, title);
  d.raw_html(std::string("<div class=\"banner ") + (S.success ? "ok" : "bad") + "\">" +
             esc(std::string(S.success ? "SUCCESS" : "FAILURE") + ": " + S.message) + "</div>\n");
  d.md << "**" << (S.success ? "SUCCESS" : "FAILURE") << "**: " << S.message << "\n\n";
  const std::string line =
      "Scene " + in.scene + ", " + grouped(in.particles) +
      (f.dimension == 3 ? " spheres (REV, triaxial test); " : " particles (REV); ") +
      std::to_string(S.trials.size()) + " trials (" + std::to_string(S.trials_run) + " run, " +
      std::to_string(S.trials_reused) + " reused from an earlier run), strategy " +
      to_string(S.strategy) + ", " + num(S.wall_time_s, 3) +
      " s in this invocation. σ3 = " + kpa(in.lateral_stress) + ".";
  d.para(line, "small");
}

namespace {

/// "Use α …, Nstep … (… steps per particle) on the REV; Nstep … for the
/// …-particle prototype."
std::string use_line(const ReportInput& in) {
  const auto& S = in.summary;
  return std::string(S.success ? "Use " : "Best found (not certified): ") + params_text(S.best) +
         " (" + num(static_cast<double>(S.best.steps) / std::max<double>(1, in.particles), 4) +
         " steps per particle) on the REV" +
         (in.prototype_particles > in.particles && in.particles > 0
              ? "; Nstep " +
                    grouped(std::llround(static_cast<double>(S.best.steps) *
                                         static_cast<double>(in.prototype_particles) /
                                         static_cast<double>(in.particles))) +
                    " for the " + grouped(in.prototype_particles) + "-particle prototype."
              : ".");
}

}  // namespace

void write_at_a_glance(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  std::vector<std::string> glance;
  if (f.have_best) {
    glance.push_back(use_line(in));
    const Excesses r =
        excesses(f.result ? f.result->score->criteria : S.best_trial.score.criteria, in.tolerances);
    glance.push_back("Every criterion within tolerance: worst " + r.worst_name() + " at " +
                     fixed(100.0 * r.worst(), 0) + " % of its tolerance.");
  }
  if (S.certificate.steps > 0)
    glance.push_back(
        "Convergence certificate " + std::string(S.certificate.passed ? "passed" : "FAILED") +
        ": Nstep doubled moves the peak by " + pct(S.certificate.steps_doubled_peak_change, 2) +
        (S.certificate.steps_halved_peak_change
             ? ", Nstep halved by " + pct(*S.certificate.steps_halved_peak_change, 2) +
                   ", error estimate "
             : std::string(", Richardson error estimate ")) +
        pct(S.certificate.richardson_error, 2) + " against the " + pct(in.accuracy, 0) +
        " target.");
  if (in.reference && f.best_peak_error)
    glance.push_back("Against a converged reference (--evidence): peak error " +
                     signed_pct(*f.best_peak_error, 2) + ".");
  const Point* base = f.baseline();
  if (base && f.have_best)
    glance.push_back(
        "The paper's recipe (α 0.2, ζ 1, Nstep doubled until it passes) costs " +
        num(base->cost / std::max(1.0, S.best_trial.score.particle_steps), 3) +
        "× as many particle-steps per run" +
        (base->peak_error ? " (peak error " + signed_pct(*base->peak_error, 2) + ")." : "."));
  if (!glance.empty()) d.bullets(glance);
  d.raw_html(
      "<nav class=\"small\"><a href=\"#answer\">answer</a><a href=\"#panels\">panels</a>"
      "<a href=\"#diagnosis\">diagnosis</a><a href=\"#history\">search history</a>"
      "<a href=\"#speed\">speed vs accuracy</a><a href=\"#upscaling\">upscaling</a>"
      "<a href=\"#assembly\">assembly</a><a href=\"#trials\">all trials</a></nav>\n");
}

namespace {

/// The REV and prototype blocks of params.json as table cells, "n/a" where
/// a value is missing.
struct ParamsCells {
  const nlohmann::json& P;

  std::optional<double> get(const char* block, const char* key) const {
    if (!P.is_object() || !P.contains(block) || !P[block].is_object()) return std::nullopt;
    const auto& b = P[block];
    if (!b.contains(key) || !b[key].is_number()) return std::nullopt;
    return b[key].get<double>();
  }
  std::string cell(const char* block, const char* key) const {
    const auto v = get(block, key);
    return v ? num(*v, 4) : std::string("n/a");
  }
  std::string int_cell(const char* block, const char* key) const {
    const auto v = get(block, key);
    return v ? grouped(static_cast<int64_t>(std::llround(*v))) : std::string("n/a");
  }
  std::string time_cell(const char* block) const {
    const auto a = get(block, "steps"), b = get(block, "dt");
    return a && b ? num(*a * *b, 4) : std::string("n/a");
  }
  /// A row: name, symbol, unit, REV, prototype.
  std::vector<std::string> row(const char* name, const char* symbol, const char* unit,
                               const char* key) const {
    return {name, symbol, unit, cell("rev", key), cell("prototype", key)};
  }
};

void write_parameter_table(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  const ParamsCells p{in.params};
  std::vector<std::vector<std::string>> rows{
      {"particles", "N", "-", p.int_cell("rev", "particles"), p.int_cell("prototype", "particles")},
      p.row("time step ratio", "α = Δt/Δt_crit", "-", "dt_ratio"),
      p.row("time step", "Δt", "s", "dt"),
      p.row("critical time step", "Δt_crit = 2·sqrt(m_min/kn)", "s", "dt_crit"),
      {"loading steps", "Nstep", "-", p.int_cell("rev", "steps"), p.int_cell("prototype", "steps")},
      {"loading time", "Nstep·Δt", "s", p.time_cell("rev"), p.time_cell("prototype")},
      p.row("translational damping ratio", "ζ_t = D_t/D_t^crit", "-", "damping_ratio_translation"),
      p.row("translational damping", "D_t (lightest particle)", "N·s/m", "damping_translation"),
      p.row("rotational damping ratio", "ζ_r = D_r/D_r^crit", "-", "damping_ratio_rotation"),
      p.row("rotational damping", "D_r (lightest particle)", "N·m·s", "damping_rotation"),
      p.row("mass scaling", "f_ms", "-", "mass_scaling")};
  d.table({"parameter", "symbol", "unit",
           S.success     ? "REV (calibrated)"
           : f.have_best ? "REV (passed, NOT certified)"
                         : "REV (none: no trial passed)",
           "prototype (upscaled)"},
          rows);
  d.para(
      "Damping is per particle: every particle gets the same ratio ζ, D = ζ·D^crit with "
      "D_t^crit = 2·sqrt(kn·m) and D_r^crit = 2·sqrt(kt·r²·I) of that particle; the absolute "
      "values above are the lightest particle's. The prototype keeps the multipliers and "
      "scales Nstep with the particle count. The search never proposed α beyond " +
          (in.dt_ratio_max > 0 ? num(in.dt_ratio_max, 3) : std::string("n/a")) +
          " (0.95 of the stable α = " + num(S.dt_ratio_stable, 3) +
          " estimated from the contact stiffnesses, translation and rotation).",
      "small");
}

void write_criteria(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& S = in.summary;
  const Tolerances& tol = in.tolerances;
  d.heading(3, std::string("Criteria reached (") + (S.success ? "calibrated" : "best") +
                   " run) against their tolerances");
  if (!f.have_best) {
    d.para("No trial passed every criterion: there is no calibrated parameter set.");
    return;
  }
  // The rerun's criteria (every field; a trial reloaded by --resume
  // carries only those trials.jsonl keeps). Same run, same numbers.
  const auto& c = f.result ? f.result->score->criteria : S.best_trial.score.criteria;
  auto row = [&](const std::string& name, const std::string& meaning, double v, double t) {
    return std::vector<std::string>{
        name, meaning, num(v, 3), num(t, 3), fixed(v / t, 2) + "×", v <= t ? "pass" : "FAIL"};
  };
  const bool d3 = f.dimension == 3;
  std::vector<std::vector<std::string>> rows{
      row("force balance", "max of the three below: max |trend| of b − σ", c.force_balance,
          tol.force_balance),
      d3 ? row("  lateral xx, yy", "(b_xx − σ_xx)/σ3 and (b_yy − σ_yy)/σ3, the larger",
               c.force_balance_xx, tol.force_balance)
         : row("  lateral xx", "(b_xx − σ_xx)/σ3", c.force_balance_xx, tol.force_balance),
      d3 ? row("  axial zz", "(b_zz − σ_zz)/max(|b_zz|, σ3)", c.force_balance_yy, tol.force_balance)
         : row("  vertical yy", "(b_yy − σ_yy)/max(|b_yy|, σ3)", c.force_balance_yy,
               tol.force_balance),
      d3 ? row("  shear", "sym(b − σ)_ij/σ3, the largest of xy, xz, yz", c.force_balance_shear,
               tol.force_balance)
         : row("  shear", "sym(b − σ)_xy/σ3", c.force_balance_shear, tol.force_balance),
      d3 ? row("moment balance",
               "RMS (σ_ij − σ_ji)/σ3, the largest of the three pairs, or tolerance × rotational "
               "drag/" +
                   num(kRotationalDragTolerance) +
                   " if larger (the drag: the rotational damping's share of the axial power)",
               c.moment_balance, tol.moment_balance)
         : row("moment balance", "RMS (σ_xy − σ_yx)/σ3", c.moment_balance, tol.moment_balance),
      d3 ? row("servo", "max |trend| (wall stress − σ3)/σ3, the largest of the four lateral walls",
               c.servo, tol.servo)
         : row("servo", "max |trend| (lateral wall stress − σ3)/σ3", c.servo, tol.servo),
      row("oscillation", "robust noise of the force-balance gaps", c.oscillation, tol.oscillation)};
  d.table({"criterion", "measure", "value", "tolerance", "value/tolerance", "verdict"}, rows);
  std::vector<std::vector<std::string>> comparison{
      {d3 ? "paper's force balance RMS(b_zz − σ_zz)/RMS(b_zz)"
          : "paper's force balance RMS(b_yy − σ_yy)/RMS(b_yy)",
       num(c.force_balance_paper, 3)},
      {d3 ? "interior lateral stress error (σ_xx and σ_yy against σ3, the larger)"
          : "interior lateral stress error (σ_xx against σ3)",
       num(c.interior_lateral, 3)},
      {d3 ? "zigzag (noise b_zz and σ_zz share)" : "zigzag (noise b_yy and σ_yy share)",
       num(c.zigzag, 3)},
      {"kinetic / elastic energy, max", num(c.kinetic_energy_ratio_max, 3)},
      {"unbalanced-force ratio, mean / max",
       num(c.unbalanced_force_ratio_mean, 3) + " / " + num(c.unbalanced_force_ratio_max, 3)},
      {"inertial number, max", num(c.inertial_number_max, 3)},
      {peak_label(f, PeakKind::every_step),
       peak_text(f.axial, c.peak_stress_yy, c.peak_strain_yy, f.dimension)}};
  // Only the lattices have a closed-form peak (hexagonal, FCC): a random
  // packing has none, so no row rather than an empty one.
  if (in.analytical_peak)
    comparison.push_back(
        {d3 ? "analytical peak (walled FCC lattice, rotation locked; Thornton 1979)"
            : "analytical peak (rotation locked, walled box)",
         kpa(*in.analytical_peak)});
  d.table({"for comparison (not criteria)", "value"}, comparison);
}

/// Nstep of the certificate's doubled (`factor` 2) or halved (0.5) run as
/// the search ran it (rounded like every trial's, so not exactly factor ×
/// Nstep): the certificate trial with the result's multipliers.
int64_t certificate_steps(const CalibrationSummary& S, double factor) {
  const auto& C = S.certificate;
  const double planned = factor * static_cast<double>(C.steps);
  int64_t steps = std::llround(planned);
  for (const auto& t : S.trials)
    if (t.phase == TrialPhase::certificate && t.params.dt_ratio == S.best.dt_ratio &&
        t.params.damping_ratio_translation == S.best.damping_ratio_translation &&
        t.params.damping_ratio_rotation == S.best.damping_ratio_rotation &&
        std::abs(static_cast<double>(t.params.steps) / planned - 1.0) < 2e-3)
      steps = t.params.steps;
  return steps;
}

void write_certificate(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& C = in.summary.certificate;
  d.heading(3, "Convergence certificate");
  if (C.steps <= 0) {
    d.para("No certificate: no passing parameter set to certify.");
    return;
  }
  std::vector<std::vector<std::string>> rows{
      {"peak " + f.axial + " at Nstep = " + grouped(C.steps), kpa(C.peak)},
      {"peak " + f.axial + " at 2·Nstep = " + grouped(certificate_steps(in.summary, 2.0)),
       kpa(C.peak_doubled)},
      {"change |P(N) − P(2N)|/|P(2N)|", pct(C.steps_doubled_peak_change, 3)}};
  if (C.peak_halved && C.steps_halved_peak_change) {
    // 3D: the third level (search/calibration.hpp, Certificate).
    rows.push_back(
        {"peak " + f.axial + " at Nstep/2 = " + grouped(certificate_steps(in.summary, 0.5)),
         kpa(*C.peak_halved)});
    rows.push_back({"change |P(N/2) − P(N)|/|P(N)|", pct(*C.steps_halved_peak_change, 3)});
    rows.push_back(
        {"error estimate of P(N): the larger of 2 × |P(N) − P(2N)| and the halved "
         "change (each equals it when the error ∝ 1/Nstep)",
         pct(C.richardson_error, 3)});
  } else {
    rows.push_back({"Richardson error estimate of P(N), 2 × change (error ∝ 1/Nstep)",
                    pct(C.richardson_error, 3)});
  }
  rows.push_back({"accuracy target", pct(in.accuracy, 2)});
  rows.push_back({"certificate", C.passed ? "pass" : "FAIL"});
  d.table({"check", "value"}, rows);
}

void write_reference_evidence(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  if (!in.reference) return;
  const auto& R = *in.reference;
  const auto& e = f.best_peak_error;
  std::vector<std::vector<std::string>> rows{
      {"peak " + f.axial + " at 8·Nstep = " + grouped(R.coarse.params.steps),
       kpa(R.coarse.score.criteria.peak_stress_yy)},
      {"peak " + f.axial + " at 16·Nstep = " + grouped(R.fine.params.steps),
       kpa(R.fine.score.criteria.peak_stress_yy)},
      {"converged reference 2·P(16N) − P(8N)", kpa(R.peak)},
      {"calibrated peak error against the reference", e ? signed_pct(*e, 2) : std::string("n/a")},
      {"within the accuracy target",
       e ? (std::abs(*e) <= in.accuracy ? "yes" : "no") : std::string("n/a")}};
  if (in.analytical_peak)
    rows.push_back({"reference against the analytical peak (rotation locked)",
                    signed_pct((*in.analytical_peak - R.peak) / std::abs(*in.analytical_peak), 1)});
  d.heading(3, "Evidence: converged reference (--evidence)");
  d.table({"check", "value"}, rows);
}

void write_baseline_evidence(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  if (!in.baseline) return;
  const auto& B = *in.baseline;
  const auto& S = in.summary;
  const Point* base = f.baseline();
  std::string text;
  if (B.passed && base) {
    text = "The paper's recipe done mechanically (α = 0.2, ζ_t = ζ_r = 1, Nstep doubled from " +
           grouped(B.trials.front().params.steps) +
           " until every criterion passes) passes at Nstep = " + grouped(B.params.steps) + ": " +
           sci(base->cost) + " particle-steps per run against " +
           sci(S.best_trial.score.particle_steps) + " calibrated (" +
           num(base->cost / std::max(1.0, S.best_trial.score.particle_steps), 3) + "× the cost)";
    if (base->peak_error)
      text += ", peak error " + signed_pct(*base->peak_error, 2) + " against the reference";
    text += "; the recipe's search itself cost " + sci(B.particle_steps_total) +
            " particle-steps in " + std::to_string(B.trials.size()) + " trials.";
  } else {
    text = "The paper's recipe done mechanically (α = 0.2, ζ_t = ζ_r = 1, Nstep doubled " +
           std::to_string(B.trials.size()) + " times) never passed every criterion (" +
           sci(B.particle_steps_total) + " particle-steps spent).";
  }
  d.heading(3, "Evidence: the paper's recipe (--evidence)");
  d.para(text);
}

void write_reproduce(Doc& d, const ReportFacts& f) {
  const ReportInput& in = *f.in;
  const auto& P = in.params;
  d.heading(3, "Reproduce");
  d.code(in.command);
  std::vector<std::string> items;
  if (P.is_object()) {
    if (P.contains("config_sha256"))
      items.push_back("config SHA-256 " + P["config_sha256"].get<std::string>());
    if (P.contains("seed")) items.push_back("seed " + P["seed"].dump());
    if (P.contains("version")) items.push_back("demcal " + P["version"].get<std::string>());
  }
  items.push_back(
      "the result does not depend on --jobs; --resume reuses every finished trial of "
      "DIR/trials.jsonl");
  d.bullets(items);
}

}  // namespace

void write_answer(Doc& d, const ReportFacts& f) {
  const auto& S = f.in->summary;
  d.heading(2,
            S.success     ? "The answer: calibrated parameters"
            : f.have_best ? "The answer: best parameters found, NOT certified (see the "
                            "certificate below)"
                          : "The answer: no parameter set passed",
            "answer");
  write_parameter_table(d, f);
  write_criteria(d, f);
  write_certificate(d, f);
  write_reference_evidence(d, f);
  write_baseline_evidence(d, f);
  write_reproduce(d, f);
}

}  // namespace demcal::report
