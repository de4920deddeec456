// `demcal score FILE [--lateral-stress PA] [-o DIR]`: the criteria, verdict
// and diagnosis of a monitoring series written by another engine (the
// exported LAMMPS deck's series.csv, 2D or 3D, or any code writing the
// documented CSV) or by `demcal run` (its metadata carry what the run was
// scored with), as `demcal run` prints them for its own runs;
// DIR/summary.json.
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/scoring/external_series.hpp"
#include "output_folder.hpp"
#include "print_criteria.hpp"

namespace demcal::cli {

int cmd_score(const ScoreOptions& o) {
  namespace fs = std::filesystem;
  // A folder, a device (/dev/zero would never end), a fifo: one line, exit 2.
  const std::string text = read_text_file(o.file);
  std::optional<double> s3;
  if (o.lateral_stress > 0.0) s3 = o.lateral_stress;
  const ExternalSeries series = parse_external_series(text, o.file, s3);
  // The command line wins over the file, but a sigma3 other than the one
  // the run was loaded at scores another test: say so.
  if (const auto file_s3 = series.meta.find("lateral_stress");
      s3 && file_s3 != series.meta.end() && std::strtod(file_s3->second.c_str(), nullptr) != *s3)
    std::cerr << "demcal score: warning: --lateral-stress " << num(*s3, 10) << " replaces the "
              << file_s3->second << " Pa of " << o.file
              << "'s # lateral_stress line: the criteria are scored against " << num(*s3, 10)
              << " Pa\n";
  const std::string dir =
      o.out_dir.empty() ? "demcal-score-" + fs::path(o.file).stem().string() : o.out_dir;
  OutputFolder::check(dir);
  const Tolerances tolerances = series.dimension == 3 ? triaxial_tolerances() : Tolerances{};
  // --reference-peak, else the file's (demcal's own runs write theirs).
  std::optional<double> reference = series.reference_peak;
  if (o.reference_peak != 0.0) reference = -std::abs(o.reference_peak);
  const ExternalScore scored = score_external(series, tolerances, reference);
  {
    OutputFolder out(dir);
    out.write("summary.json", external_summary(series, scored, tolerances).dump(2) + "\n");
    out.commit();
  }
  const Score& score = scored.score;
  const auto& c = score.criteria;
  const double sigma3 = series.lateral_stress;
  const bool is_3d = series.dimension == 3;
  const size_t points = is_3d ? series.triaxial.series.size() : series.run.series.size();
  const int64_t steps = is_3d ? series.triaxial.steps_run : series.run.steps_run;
  const int64_t planned = is_3d ? series.triaxial.steps_planned : series.run.steps_planned;
  // A measure the series cannot give: "n/a (no column X)", never a number.
  auto value = [&](const char* key, double v) {
    std::ostringstream s;
    s << std::setprecision(4);
    if (c.available(key))
      s << v;
    else
      s << "n/a (" << c.not_available.at(key) << ")";
    return s.str();
  };
  std::cout << std::setprecision(4) << "series " << o.file << ": "
            << (is_3d ? "3D (triaxial), " : "") << points << " monitoring points, " << steps
            << (score.complete ? "" : " of " + std::to_string(planned)) << " steps"
            << (score.complete ? "" : " (incomplete)") << "\n";
  print_peak(std::cout, is_3d, c.peak_stress_yy, c.peak_strain_yy, sigma3);
  std::cout << ")\n";
  const int64_t divergence_step =
      is_3d ? series.triaxial.divergence_step : series.run.divergence_step;
  if (score.diverged) {
    // As `demcal run` prints the run that wrote it.
    print_unscored_criteria(std::cout, divergence_step, planned, c, !is_3d);
  } else if (scored.planes) {
    print_triaxial_criteria(std::cout, *scored.planes, c);
    std::cout << "  tolerances: force balance " << tolerances.force_balance << ", moment balance "
              << tolerances.moment_balance << ", servo " << tolerances.servo << ", oscillation "
              << tolerances.oscillation
              << " and rotational drag 0.003 folded into moment balance (the 3D defaults)\n";
  } else {
    std::cout << "  force balance " << c.force_balance << " (tol " << tolerances.force_balance
              << "; paper form " << c.force_balance_paper << "), moment balance "
              << c.moment_balance << " (tol " << tolerances.moment_balance << "), servo "
              << value("servo", c.servo) << " (tol " << tolerances.servo << "), oscillation "
              << c.oscillation << " (tol " << tolerances.oscillation << ")\n";
  }
  std::cout << "  kinetic/elastic energy max "
            << value("kinetic_energy_ratio_max", c.kinetic_energy_ratio_max)
            << ", unbalanced-force ratio mean "
            << value("unbalanced_force_ratio_mean", c.unbalanced_force_ratio_mean)
            << ", inertial number max " << value("inertial_number_max", c.inertial_number_max)
            << "\n";
  if (c.peak_error)
    std::cout << "  peak error against " << *reference << " Pa: " << 100.0 * *c.peak_error
              << " %\n";
  // The verdict with its real reason: a diverged run's as `demcal run`
  // prints it, the divergence's own reason (its rows' or its metadata's)
  // beside it; an incomplete one's diagnosis (of the steps it has) apart.
  std::cout << "  " << score_verdict(series, scored) << "\n";
  if (score.diverged) {
    std::cout << "  DIVERGED"
              << (divergence_step >= 0 ? " at step " + std::to_string(divergence_step) : "") << ": "
              << series.divergence_reason << "\n";
  } else if (!score.complete) {
    std::cout << "  on the steps it has: " << score.diagnosis.message << "\n";
  }
  std::cout << "  wrote " << dir << "/summary.json\n";
  return score.passed ? 0 : 1;
}

}  // namespace demcal::cli
