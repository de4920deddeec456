// `demcal score` on series that do not carry everything (another engine's,
// or a hand-written one): what a missing column or metadata key would give
// is unknown, never 0 — left out of summary.json, "n/a (no column X)" on
// the terminal, a criterion it is not checked (and the verdict says so),
// and the diagnosis never built on it (a series without damping ratios is
// not an undamped run). The verdict of a series that did not end as
// planned says why (incomplete: the steps it ran; diverged: the reason its
// rows or its metadata give). In 3D the diagnosis names what failed: the
// pair of σ that differs, or the rotational drag.
//
// Each test runs the demcal program on a small synthetic file whose
// criteria are known by construction (b = σ, static rows, or one gap put
// in on purpose).
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "demcal/scoring/external_series.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "support/files.hpp"
#include "support/process.hpp"

namespace demcal {
namespace {

namespace fs = std::filesystem;

constexpr double kS3 = 1e5;

/// What one 2D row holds beyond b = σ = diag(−σ3, −σ3(1 + 0.01 k)).
struct Row2d {
  double lateral_gap = 0.0;  ///< b_xx − σ_xx [Pa]
  double asymmetry = 0.0;    ///< σ_xy = a/2, σ_yx = −a/2 [Pa]
};

/// A 2D series: σ3, the `metadata` lines, the required columns (and
/// `extra_columns`, `extra_values` in every row), 41 rows evenly from step 0
/// to `last_step`.
std::string series_2d(const std::string& metadata, int last_step, const Row2d& r,
                      const std::string& extra_columns = "", const std::string& extra_values = "") {
  std::ostringstream f;
  f << "# lateral_stress = " << kS3 << "\n" << metadata;
  f << "step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy" << extra_columns << "\n";
  for (int k = 0; k <= 40; ++k) {
    const int step = k * last_step / 40;
    const double byy = -kS3 * (1.0 + 0.01 * k);
    const double gap = k == 0 ? 0.0 : r.lateral_gap;
    const double a = k == 0 ? 0.0 : r.asymmetry;
    f << step << "," << -1e-4 * k << "," << -kS3 << ",0,0," << byy << "," << -kS3 - gap << ","
      << 0.5 * a << "," << -0.5 * a << "," << byy << extra_values << "\n";
  }
  return f.str();
}

/// `demcal score FILE -o out` on `text` in a fresh folder: the exit status,
/// stdout, and summary.json (null when none was written).
struct Scored {
  int status = -1;
  std::string out;
  nlohmann::json summary;
};
Scored score(const std::string& tag, const std::string& text) {
  const test::TempDir dir("score_missing_" + tag);
  test::write_text(dir / "series.csv", text);
  const test::RunResult r = test::run_demcal({"score", "series.csv", "-o", "out"}, dir.path());
  Scored s{r.status, r.out + r.err, nullptr};
  if (fs::exists(dir / "out" / "summary.json"))
    s.summary = test::read_json(dir / "out" / "summary.json");
  return s;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// --- 6. missing optional data is unknown, not 0 ---------------------------

TEST(ScoreMissingData, AServoErrorNotInTheSeriesIsNotCheckedNotZero) {
  // The required columns only: no lateral_stress_error, no p_left/p_right.
  const Scored s = score("servo", series_2d("# steps = 400\n", 400, {}));
  ASSERT_EQ(s.status, 0) << s.out;  // every criterion checked passes (b = σ)
  const nlohmann::json& c = s.summary.at("criteria");
  EXPECT_FALSE(c.contains("servo")) << c.dump();
  EXPECT_FALSE(c.contains("servo_rms"));
  ASSERT_TRUE(c.contains("not_available")) << c.dump();
  EXPECT_TRUE(has(c["not_available"].value("servo", ""), "no column lateral_stress_error"));
  ASSERT_TRUE(s.summary.contains("not_checked")) << s.summary.dump();
  EXPECT_TRUE(s.summary["not_checked"].contains("servo"));
  EXPECT_TRUE(has(s.out, "servo n/a (no column lateral_stress_error")) << s.out;
  // The verdict does not claim the servo passed.
  EXPECT_TRUE(has(s.out, "PASS: quasi-static on the criteria checked")) << s.out;
  EXPECT_TRUE(has(s.out, "not checked: servo (no column lateral_stress_error")) << s.out;
  EXPECT_FALSE(has(s.out, "every criterion is within tolerance")) << s.out;
  // With the column, it is checked and a number again (the control).
  const Scored with =
      score("servo_with", series_2d("# steps = 400\n", 400, {}, ",lateral_stress_error", ",0"));
  EXPECT_EQ(with.summary.at("criteria").at("servo").get<double>(), 0.0);
  EXPECT_FALSE(with.summary.contains("not_checked"));
  EXPECT_TRUE(has(with.out, "every criterion is within tolerance")) << with.out;
}

TEST(ScoreMissingData, TheDecksMissingColumnsLeaveTheirMeasuresOut) {
  // The exported LAMMPS and LIGGGHTS decks' 2D columns: no elastic_energy,
  // unbalanced_force_ratio nor inertial_number.
  const Scored s = score("deck", series_2d("# steps = 400\n", 400, {},
                                           ",kinetic_energy,kinetic_energy_rotation,"
                                           "lateral_stress_error,p_left,p_right",
                                           ",1e-9,1e-10,0,1e5,1e5"));
  ASSERT_EQ(s.status, 0) << s.out;
  const nlohmann::json& c = s.summary.at("criteria");
  for (const char* key :
       {"kinetic_energy_ratio_median", "kinetic_energy_ratio_max", "unbalanced_force_ratio_mean",
        "unbalanced_force_ratio_max", "inertial_number_max"})
    EXPECT_FALSE(c.contains(key)) << key << ": " << c.dump();
  EXPECT_EQ(c.at("not_available").value("kinetic_energy_ratio_max", ""),
            "no column elastic_energy");
  EXPECT_EQ(c.at("not_available").value("inertial_number_max", ""), "no column inertial_number");
  // What the columns do give is there: the rotational share, the servo.
  EXPECT_NEAR(c.at("rotational_energy_share").get<double>(), 0.1, 1e-12);
  EXPECT_TRUE(c.contains("servo"));
  EXPECT_FALSE(s.summary.contains("not_checked"));
  EXPECT_TRUE(has(s.out, "kinetic/elastic energy max n/a (no column elastic_energy)")) << s.out;
  EXPECT_TRUE(has(s.out, "inertial number max n/a (no column inertial_number)")) << s.out;
}

TEST(ScoreMissingData, NoDampingRatiosIsNotAnUndampedRun) {
  // A steady asymmetry σxy − σyx = 6e-4 σ3 (60 times its tolerance), b − σ
  // without noise: with ζ_t = ζ_r = 0 given it is "undamped rotations
  // ring"; with no damping ratios given the pattern decides (no noise: not
  // ringing) and nothing says the run is undamped.
  const Row2d asym{0.0, 60.0};
  const Scored unknown = score("no_damping", series_2d("# steps = 400\n", 400, asym));
  const Scored undamped =
      score("undamped", series_2d("# steps = 400\n# damping_ratio_translation = 0\n"
                                  "# damping_ratio_rotation = 0\n",
                                  400, asym));
  const Scored damped = score("damped", series_2d("# steps = 400\n# damping_ratio_translation = 1\n"
                                                  "# damping_ratio_rotation = 1\n",
                                                  400, asym));
  ASSERT_EQ(unknown.status, 1) << unknown.out;
  const nlohmann::json& d = unknown.summary.at("diagnosis");
  EXPECT_FALSE(has(d.at("message").get<std::string>(), "undamped")) << d.dump();
  EXPECT_NE(d.at("parameter"), "damping_translation") << d.dump();
  // ζ = 1 given reads as no ratio given does here; ζ = 0 given is undamped.
  EXPECT_EQ(damped.summary.at("diagnosis").at("parameter"), d.at("parameter"));
  EXPECT_EQ(undamped.summary.at("diagnosis").at("parameter"), "damping_translation");
  EXPECT_TRUE(
      has(undamped.summary.at("diagnosis").at("message").get<std::string>(), "(almost) undamped"));
}

TEST(ScoreMissingData, NoCriticalStepIsNotASmallStep) {
  // A smooth lateral gap (5 times the tolerance), the walls on target: with
  // dt and dt_crit given (α = 0.02) the small step is to blame; with dt
  // alone α is not known and it is not read as 0.
  const Row2d gap{0.04 * kS3, 0.0};
  const std::string servo_columns = ",lateral_stress_error";
  const Scored unknown =
      score("no_dt_crit", series_2d("# steps = 400\n# dt = 1e-7\n", 400, gap, servo_columns, ",0"));
  const Scored small = score("small_dt", series_2d("# steps = 400\n# dt = 1e-7\n# dt_crit = 5e-6\n",
                                                   400, gap, servo_columns, ",0"));
  ASSERT_EQ(unknown.status, 1) << unknown.out;
  EXPECT_EQ(small.summary.at("diagnosis").at("parameter"), "dt") << small.out;
  EXPECT_EQ(unknown.summary.at("diagnosis").at("parameter"), "steps") << unknown.out;
}

// --- 9. the verdict says why ----------------------------------------------

TEST(ScoreVerdict, AnIncompleteSeriesFailsForBeingIncomplete) {
  // Rows to step 100 of 400 planned (a run cut short), b = σ throughout.
  const Scored s =
      score("incomplete", series_2d("# steps = 400\n", 100, {}, ",lateral_stress_error", ",0"));
  ASSERT_EQ(s.status, 1) << s.out;
  EXPECT_FALSE(s.summary.at("complete").get<bool>());
  EXPECT_EQ(s.summary.at("verdict_line"),
            "FAIL: incomplete: the series ran 100 of the 400 steps planned");
  EXPECT_TRUE(has(s.out, "  FAIL: incomplete: the series ran 100 of the 400 steps planned\n"))
      << s.out;
  // The criteria of the steps it has are said as such, never as the verdict.
  EXPECT_FALSE(has(s.out, "FAIL: quasi-static")) << s.out;
  EXPECT_TRUE(has(s.out, "on the steps it has: quasi-static")) << s.out;
}

TEST(ScoreVerdict, ADivergenceIsToldByItsOwnReason) {
  // demcal's energy ledger stopped the run: finite rows, the reason in the
  // metadata. Nothing there is "non-finite".
  const std::string reason = "energy created by the integrator (step beyond the stable one)";
  const Scored ledger = score("ledger", series_2d("# steps = 400\n# divergence_step = 200\n"
                                                  "# divergence = " +
                                                      reason + "\n",
                                                  200, {}, ",lateral_stress_error", ",0"));
  ASSERT_EQ(ledger.status, 1) << ledger.out;
  // The verdict as `demcal run` says it, the reason as its run's summary.
  EXPECT_TRUE(has(ledger.out, "  FAIL: the run diverged")) << ledger.out;
  EXPECT_TRUE(has(ledger.out, "  DIVERGED at step 200: " + reason + "\n")) << ledger.out;
  EXPECT_FALSE(has(ledger.out, "non-finite")) << ledger.out;
  EXPECT_EQ(ledger.summary.at("divergence").at("reason"), reason);
  // An engine that blew up writes non-finite values: that is its reason.
  std::string text = series_2d("# steps = 400\n", 400, {}, ",lateral_stress_error", ",0");
  const auto row = text.find("\n200,") + 1;
  ASSERT_NE(row, std::string::npos + 1);
  text.replace(row, text.find('\n', row) - row, "200,-0.002,nan,nan,nan,nan,nan,nan,nan,nan,nan");
  const Scored blown = score("blown", text);
  ASSERT_EQ(blown.status, 1) << blown.out << text;
  EXPECT_TRUE(has(blown.out,
                  "  DIVERGED at step 200: non-finite values in the series' row of "
                  "step 200\n"))
      << blown.out;
}

// --- 3D --------------------------------------------------------------------

/// A 3D series: b = σ = diag(−σ3, −σ3, −σ3(1 + 0.01 k)) but for σ_ij = `a`/2,
/// σ_ji = −`a`/2 (i, j the pair named, −1 for none), then `extra` columns
/// with `extra_values`.
std::string series_3d(const std::string& metadata, int pi, int pj, double a,
                      const std::string& extra_columns = "", const std::string& extra_values = "") {
  std::ostringstream f;
  f << "# lateral_stress = " << kS3 << "\n# steps = 400\n" << metadata << "step,strain_zz";
  const char* axis = "xyz";
  for (const char* t : {"b_", "s_"})
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f << "," << t << axis[i] << axis[j];
  f << extra_columns << "\n";
  for (int k = 0; k <= 40; ++k) {
    const double diag[3] = {-kS3, -kS3, -kS3 * (1.0 + 0.01 * k)};
    f << k * 10 << "," << -1e-4 * k;
    for (int t = 0; t < 2; ++t)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          double v = i == j ? diag[i] : 0.0;
          if (t == 1 && k > 0 && i == pi && j == pj) v += 0.5 * a;
          if (t == 1 && k > 0 && i == pj && j == pi) v -= 0.5 * a;
          f << "," << v;
        }
    f << extra_values << "\n";
  }
  return f.str();
}

const std::string kWallErrors =
    ",servo_error_xmin,servo_error_xmax,servo_error_ymin,servo_error_ymax";

TEST(ScoreMissingData3d, NoServoNoDragColumnsAreNotCheckedNotZero) {
  const Scored s = score("3d_bare", series_3d("", -1, -1, 0.0));
  ASSERT_EQ(s.status, 0) << s.out;
  EXPECT_FALSE(s.summary.at("criteria").contains("servo")) << s.summary.dump();
  const nlohmann::json& planes = s.summary.at("criteria_planes");
  EXPECT_FALSE(planes.contains("rotational_drag")) << planes.dump();
  EXPECT_FALSE(planes.contains("translational_drag"));
  for (const auto& w : planes.at("servo_walls")) EXPECT_TRUE(w.is_null()) << planes.dump();
  ASSERT_TRUE(s.summary.contains("not_checked"));
  EXPECT_TRUE(s.summary["not_checked"].contains("servo"));
  EXPECT_TRUE(s.summary["not_checked"].contains("rotational_drag"));
  EXPECT_TRUE(has(s.out, "rotational drag n/a (no column axial_power)")) << s.out;
  EXPECT_TRUE(has(s.out, "x min n/a (no column servo_error_xmin, nor p_xmin)")) << s.out;
  EXPECT_TRUE(has(s.out, "not checked: rotational_drag")) << s.out;
}

TEST(ScoreDiagnosis3d, NamesTheRotationalDragNotAPairThatAgrees) {
  // Every pair of σ agrees; the rotational damping takes 1 % of the axial
  // wall's power (3.3 times its tolerance): the drag fails moment balance.
  const Scored s = score(
      "3d_drag", series_3d("", -1, -1, 0.0, kWallErrors + ",damping_power_rotation,axial_power",
                           ",0,0,0,0,0.01,1"));
  ASSERT_EQ(s.status, 1) << s.out;
  const std::string m = s.summary.at("diagnosis").at("message").get<std::string>();
  EXPECT_FALSE(has(m, "sigma_xy and sigma_yx")) << m;
  EXPECT_TRUE(has(m, "the rotational damping takes 1 % of the axial wall's power")) << m;
  EXPECT_EQ(s.summary.at("diagnosis").at("parameter"), "damping_rotation");
}

TEST(ScoreDiagnosis3d, NamesThePairThatDiffers) {
  // σ_xz − σ_zx = 6e-4 σ3, the other pairs agree, no drag.
  const Scored s = score(
      "3d_pair", series_3d("", 0, 2, 60.0, kWallErrors + ",damping_power_rotation,axial_power",
                           ",0,0,0,0,0,1"));
  ASSERT_EQ(s.status, 1) << s.out;
  const std::string m = s.summary.at("diagnosis").at("message").get<std::string>();
  EXPECT_TRUE(has(m, "sigma_xz and sigma_zx")) << m;
  EXPECT_FALSE(has(m, "sigma_xy and sigma_yx")) << m;
}

TEST(ScoreDiagnosis3d, AReferencePeakInTheSeriesGivesThePeakError) {
  // The peak is −1.4 σ3 at the last row; a reference of 1.25 σ3 (either
  // sign) makes it 12 % over-predicted.
  const Scored s = score(
      "3d_ref", series_3d("# reference_peak = 125000\n", -1, -1, 0.0,
                          kWallErrors + ",damping_power_rotation,axial_power", ",0,0,0,0,0,1"));
  ASSERT_TRUE(s.summary.at("criteria").contains("peak_error")) << s.summary.dump();
  EXPECT_NEAR(s.summary["criteria"]["peak_error"].get<double>(), 0.12, 1e-12);
  EXPECT_TRUE(has(s.out, "peak error against -1.25e+05 Pa: 12 %")) << s.out;
}

// --- the record's JSON form -------------------------------------------------

TEST(ScoreMissingData, CriteriaNotAvailableRoundTrip) {
  Criteria c;
  c.servo = 0.0;
  c.not_available = {{"servo", "no column lateral_stress_error"}};
  const nlohmann::json j = to_json(c);
  EXPECT_FALSE(j.contains("servo"));
  const Criteria back = criteria_from_json(j);
  EXPECT_FALSE(back.available("servo"));
  EXPECT_EQ(back.not_available, c.not_available);
  EXPECT_EQ(to_json(back), j);
  // A criterion not available weighs nothing in the excesses.
  c.servo = 1.0;  // a value it cannot have read: not used
  EXPECT_EQ(excesses(c, Tolerances{}).servo, 0.0);
}

}  // namespace
}  // namespace demcal
