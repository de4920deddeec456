// `demcal check` and `demcal run`, and the config loading every command shares.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/scoring/triaxial_scoring.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "print_criteria.hpp"

namespace demcal::cli {

namespace {

namespace fs = std::filesystem;

/// The three stable step estimates `demcal check` prints, 2D and 3D.
void print_stable_steps(const StabilityEstimate& est) {
  std::cout << std::setprecision(6) << "  stable dt_ratio (Lanczos, rotation coupled) "
            << est.dt_ratio_stable << "\n"
            << "  stable dt_ratio (Gershgorin bound)         " << est.dt_ratio_stable_gershgorin
            << "\n"
            << "  stable dt_ratio (translation only)         " << est.dt_ratio_stable_translation
            << "\n";
}

void print_scales(const SceneConfig& config, const World& world) {
  const ReferenceScales s = world.reference_scales();
  std::cout << "scene " << config.name << ": " << world.size() << " particles\n"
            << "  dt_crit                 " << s.dt_crit << " s  (2 sqrt(m_min/kn))\n"
            << "  damping_translation_crit " << s.damping_translation_crit
            << " N s/m (2 sqrt(kn m_min))\n"
            << "  damping_rotation_crit   " << s.damping_rotation_crit
            << " N m s (2 sqrt(kt r^2 I), m_min)\n";
}

}  // namespace

void require_stable_step(const SceneConfig& config, double stable, bool allow_unstable) {
  if (allow_unstable) return;
  require_stable_dt_ratio(
      config.algorithm.dt_ratio, stable, source_of(config, "algorithm.dt_ratio"),
      "algorithm.dt_ratio",
      std::string("use a smaller value; ") +
          (config.dimension == 2 ? "`demcal stability` measures the limit, " : "") +
          "`demcal run --allow-unstable` runs it anyway");
}

namespace {

/// "3000 steps"; a run that stopped short: "143 of 3000 steps"; a diverged
/// one in the words of its other lines (divergence_words), with the steps
/// it completed: "diverged at step 144 of 3000 (143 steps completed)".
template <class Point>
std::string steps_words(const LoadingRun<Point>& run) {
  std::ostringstream s;
  if (run.diverged) {
    s << divergence_words(run.divergence_step, run.steps_planned) << " (" << run.steps_run
      << (run.steps_run == 1 ? " step" : " steps") << " completed)";
    return s.str();
  }
  s << run.steps_run;
  if (run.steps_run != run.steps_planned) s << " of " << run.steps_planned;
  s << " steps";
  return s.str();
}

/// A run's files, 2D and 3D: summary.json; series.csv with the metadata
/// `demcal score` needs to score it as this run; final.vtk unless
/// output.vtk is off (an earlier run's retired then, not left as this one's).
template <class Run, class FinalState>
void write_run_files(const std::string& dir, const SceneConfig& config,
                     const nlohmann::json& summary, const Run& run,
                     std::optional<double> reference_peak, const FinalState& final_state) {
  OutputFolder out(dir);
  out.write("summary.json", summary.dump(2) + "\n");
  out.write("series.csv",
            series_csv(series_metadata(config.name, config.test, run, reference_peak), run.series));
  if (config.output.vtk)
    out.write("final.vtk", world_vtk(final_state, "demcal " + config.name));
  else
    out.retire("final.vtk");
  out.commit();
}

/// A run's last lines, 2D and 3D: the verdict with its diagnosis, the wall
/// time and speed, the files written, and where it diverged if it did.
template <class Run, class State>
void print_run_tail(const Score& score, const Run& run, const State& state,
                    const nlohmann::json& summary, const std::string& dir,
                    const SceneConfig& config) {
  std::cout << "  " << (score.passed ? "PASS" : "FAIL") << ": " << score.diagnosis.message << "\n"
            << "  wall time " << run.wall_time_s << " s (consolidation ";
  print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
  std::cout << ", " << state.steps << " steps), " << summary["particle_steps_per_s"].get<double>()
            << " particle-steps/s\n"
            << "  wrote " << dir << "/summary.json, series.csv"
            << (config.output.vtk ? ", final.vtk" : "") << "\n";
  if (run.diverged)
    std::cout << "  DIVERGED at step " << run.divergence_step << ": " << to_string(run.divergence)
              << "\n";
}

}  // namespace

namespace {

// ---- 3D: spheres, triaxial test -------------------------------------------

TriaxialState consolidate_3d(const SceneConfig& config, double progress_every_s) {
  const SphereAssembly assembly = make_sphere_assembly(config);
  return consolidate_triaxial(config, assembly, consolidation_progress(progress_every_s));
}

void print_scales_3d(const SceneConfig& config, const SphereWorld& world) {
  const ReferenceScales s = world.reference_scales();
  std::cout << "scene " << config.name << " (3D, triaxial): " << world.size() << " spheres\n"
            << "  mass_min                " << s.mass_min << " kg (rho (4/3) pi r^3 f_ms)\n"
            << "  dt_crit                 " << s.dt_crit << " s  (2 sqrt(m_min/kn))\n"
            << "  damping_translation_crit " << s.damping_translation_crit
            << " N s/m (2 sqrt(kn m_min))\n"
            << "  damping_rotation_crit   " << s.damping_rotation_crit
            << " N m s (2 sqrt(kt r^2 I), I = (2/5) m r^2, m_min)\n";
}

int check_3d(const SceneConfig& config, double progress_every_s) {
  const TriaxialState state = consolidate_3d(config, progress_every_s);
  require_stable_step(config, estimated_stable_dt_ratio(state, config.algorithm), false);
  std::cout << "config " << config.source << ": valid\n";
  // The scales at the config's mass scaling, from the kernel's masses.
  SphereWorld probe = state.world;
  AlgorithmSpec a = config.algorithm;
  a.dt_ratio = std::min(a.dt_ratio, 0.1);
  probe.set_integration(integration_for(probe, a));
  probe.update_forces();
  print_scales_3d(config, probe);
  const StabilityEstimate est = probe.stability_estimate();
  std::cout << "  consolidated in " << state.steps << " steps (" << std::setprecision(3);
  print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
  std::cout << "), box " << state.extent0[0] << " x " << state.extent0[1] << " x "
            << state.extent0[2] << " m\n";
  print_stable_steps(est);
  if (auto r = analytical_peak_ratio_3d(config))
    std::cout << "  analytical peak sigma1/sigma3 " << *r << " (walled FCC, Thornton), "
              << fcc_peak_ratio(config.material.particle.friction)
              << " (periodic); rotation locked\n";
  return 0;
}

int run_3d(const SceneConfig& config, const std::string& out_dir, bool allow_unstable,
           double progress_every_s) {
  const SphereAssembly assembly = make_sphere_assembly(config);
  const std::string dir = out_dir.empty() ? "demcal-run-" + config.name : out_dir;
  OutputFolder::check(dir);  // an unwritable -o fails now, not after the run
  const TriaxialState state =
      consolidate_triaxial(config, assembly, consolidation_progress(progress_every_s));
  require_stable_step(config, estimated_stable_dt_ratio(state, config.algorithm), allow_unstable);
  SphereWorld final_state = state.world;
  const TriaxialResult run =
      run_triaxial_loading(state, config.test, config.algorithm, {}, &final_state);
  const double s3 = config.test.lateral_stress;
  // The step-level peak, as the calibration's trials score it; its error
  // against theory where theory applies (rotation locked, FCC).
  const std::optional<double> reference_peak = reference_peak_3d(config);
  const TriaxialCriteria c = compute_triaxial_criteria(run, s3, reference_peak);
  const Tolerances tolerances = triaxial_tolerances();
  // The criteria judged (the rotational drag folded in), as `demcal score`
  // judges the run's series.csv.
  const Score score = score_triaxial_run(run, c, tolerances);
  const bool within = score.passed;
  nlohmann::json summary = triaxial_run_summary(config, state, run, c, score, tolerances);
  write_run_files(dir, config, summary, run, reference_peak, final_state);
  const Criteria& m = score.criteria;
  std::cout << std::setprecision(4) << "scene " << config.name
            << " (3D, triaxial): " << run.particles << " spheres, " << steps_words(run) << ", dt "
            << run.integration.dt << " s\n";
  print_peak(std::cout, true, run.peak_stress_zz, run.peak_strain_zz, s3);
  std::cout << "; against the lateral wall stress " << run.peak_ratio << ")\n";
  if (auto a = analytical_peak_ratio_3d(config))
    std::cout << "  analytical (walled FCC, Thornton, rotation locked) sigma1/sigma3 " << *a
              << "\n";
  if (run.diverged)
    print_unscored_criteria(std::cout, run.divergence_step, run.steps_planned, m, false);
  else
    print_triaxial_criteria(std::cout, c, score.criteria);
  std::cout << "  kinetic/elastic energy max " << m.kinetic_energy_ratio_max
            << ", unbalanced-force ratio mean " << m.unbalanced_force_ratio_mean
            << ", inertial number max " << m.inertial_number_max << "\n";
  if (!run.diverged)  // a diverged run's criteria are not scored: no worst one
    std::cout << "  " << (within ? "WITHIN" : "OUTSIDE") << " the 3D default tolerances"
              << (within ? "" : " (worst: " + summary["verdict"]["worst"].get<std::string>() + ")")
              << ". " << kTriaxialVerdictNote << "\n";
  print_run_tail(score, run, state, summary, dir, config);
  return score.passed ? 0 : 1;  // as `demcal score` judges the run's series.csv
}

}  // namespace

void require_prototype(const SceneConfig& config) {
  if (config.dimension == 3)
    prototype_spheres(config);
  else
    prototype_assembly(config);
}

int cmd_check(const std::string& path, const std::vector<std::string>& sets,
              double progress_every_s) {
  SceneConfig config = load_config(path, sets);
  require_prototype(config);  // before the consolidation: what calibrate reads after its search
  if (config.dimension == 3) return check_3d(config, progress_every_s);
  Assembly assembly = make_assembly(config);
  const ConsolidatedState state = consolidate(
      config, assembly, ConsolidationOptions{.progress = consolidation_progress(progress_every_s)});
  require_stable_step(config, estimated_stable_dt_ratio(state, config.algorithm), false);
  std::cout << "config " << config.source << ": valid\n";
  print_scales(config, state.world);
  const StabilityEstimate est = state.world.stability_estimate();
  std::cout << "  consolidated in " << state.steps << " steps (" << std::setprecision(3);
  print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
  std::cout << "), box " << state.width0 << " x " << state.height0 << " m\n";
  print_stable_steps(est);
  if (auto peak = analytical_peak_stress(config)) {
    std::cout << "  analytical peak sigma1/sigma3 " << -*peak / config.test.lateral_stress
              << " (walled box), " << hexagonal_peak_ratio(config.material.particle.friction)
              << " (periodic); rotation locked\n";
  }
  return 0;
}

int cmd_run(const std::string& path, const std::vector<std::string>& sets,
            const std::string& out_dir, bool allow_unstable, double progress_every_s) {
  SceneConfig config = load_config(path, sets);
  if (config.dimension == 3) return run_3d(config, out_dir, allow_unstable, progress_every_s);
  Assembly assembly = make_assembly(config);
  const std::string dir = out_dir.empty() ? "demcal-run-" + config.name : out_dir;
  OutputFolder::check(dir);  // an unwritable -o fails now, not after the run
  const ConsolidatedState state = consolidate(
      config, assembly, ConsolidationOptions{.progress = consolidation_progress(progress_every_s)});
  require_stable_step(config, estimated_stable_dt_ratio(state, config.algorithm), allow_unstable);
  World final_state = state.world;
  const LoadingResult run = run_loading(state, config.test, config.algorithm, {}, &final_state);
  const Tolerances tolerances;
  const std::optional<double> reference_peak = analytical_peak_stress(config);
  const Score score = score_run(run, config.test.lateral_stress, tolerances, reference_peak);
  nlohmann::json summary = run_summary(config, run, score);
  summary["tolerances"] = to_json(tolerances);
  summary["consolidation"] = consolidation_json(state);
  summary["config_sha256"] = sha256_hex(config.text);
  summary["version"] = DEMCAL_VERSION;
  write_run_files(dir, config, summary, run, reference_peak, final_state);

  const auto& c = score.criteria;
  std::cout << std::setprecision(4) << "scene " << config.name << ": " << run.particles
            << " particles, " << steps_words(run) << ", dt " << run.integration.dt << " s\n";
  print_peak(std::cout, false, c.peak_stress_yy, c.peak_strain_yy, config.test.lateral_stress);
  std::cout << ")\n";
  if (auto a = analytical_peak_stress(config))
    std::cout << "  analytical (walled, rotation locked) sigma1/sigma3 "
              << -*a / config.test.lateral_stress << "\n";
  if (run.diverged)
    print_unscored_criteria(std::cout, run.divergence_step, run.steps_planned, c, true);
  else
    std::cout << "  force balance " << c.force_balance << " (paper form " << c.force_balance_paper
              << "), moment balance " << c.moment_balance << ", servo " << c.servo
              << ", oscillation " << c.oscillation << "\n";
  print_run_tail(score, run, state, summary, dir, config);
  // Exit 1 on FAIL (a diverged run fails), as `demcal score` judges the
  // run's series.csv; the files are written either way.
  return score.passed ? 0 : 1;
}

}  // namespace demcal::cli
