// `demcal sweep CONFIG [--jobs N] [-o DIR]`: the signature atlas
// (demcal/search/sweep.hpp; reports/signature-atlas.md), on a 2D or a 3D scene. The config's
// algorithm block is the benchmark; every other case changes one parameter.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/sweep.hpp"
#include "output_folder.hpp"

namespace demcal::cli {

int cmd_sweep(const SweepOptions& options) {
  // 2D (disks, biaxial test) and 3D (spheres, triaxial test): one sweep.
  SceneConfig config = load_config(options.config, options.sets);
  const bool three_d = config.dimension == 3;
  const std::string dir = options.out_dir.empty() ? "demcal-sweep-" + config.name : options.out_dir;
  OutputFolder::check(dir);  // an unwritable -o fails now, not after the sweep

  SweepSettings settings;
  settings.jobs = options.jobs;
  settings.tolerances = default_tolerances(config);  // 3D: the triaxial ones
  settings.accuracy = config.calibration.accuracy;
  settings.progress = [](int k, int n, const std::string& name, double seconds) {
    std::cerr << "  [" << k << "/" << n << "] " << name << " (" << std::fixed
              << std::setprecision(1) << seconds << " s)\n";
  };
  // The consolidated state, once (progress lines only when it is slow, as
  // for `demcal run`: bad input stays one line); the cases around the
  // config's algorithm block.
  auto sweep = [&](const auto& state, double alpha_stable, const char* what) {
    // The benchmark is the config's algorithm block as given: past the
    // stable step it is bad input, as for `demcal run` (the atlas's own
    // cases beyond it are meant).
    require_stable_step(config, estimated_stable_dt_ratio(state, config.algorithm), false);
    const std::vector<SweepCase> cases = atlas_cases(config.algorithm, alpha_stable);
    // Its time as check and run print it (print_consolidation_time).
    std::cerr << "sweep " << config.name << ": " << state.world.size() << " " << what
              << " consolidated once, in " << state.steps << " steps (" << std::setprecision(3);
    print_consolidation_time(std::cerr, state.wall_time_s, state.from_cache);
    std::cerr << "); " << cases.size() << " trials, benchmark Nstep " << config.algorithm.steps
              << ", alpha_stable " << alpha_stable << "\n";
    return run_sweep(config, state, cases, settings);
  };
  SweepResult result;
  if (three_d) {
    const SphereAssembly assembly = make_sphere_assembly(config);
    const TriaxialState state =
        consolidate_triaxial(config, assembly, consolidation_progress(options.progress_every_s));
    result =
        sweep(state, estimated_stable_dt_ratio(state, config.algorithm), "spheres (3D, triaxial)");
  } else {
    Assembly assembly = make_assembly(config);
    const ConsolidatedState state = consolidate(
        config, assembly,
        ConsolidationOptions{.progress = consolidation_progress(options.progress_every_s)});
    result = sweep(state, state.world.stability_estimate().dt_ratio_stable, "particles");
  }

  {
    OutputFolder out(dir);  // all files replaced together, or none
    std::set<std::string> written;
    for (const auto& r : result.cases) {
      out.write("series/" + r.spec.name + ".csv", r.run.series_csv);
      written.insert(r.spec.name + ".csv");
    }
    // An earlier sweep's α-scan series that this one does not write (their
    // names follow the estimated stable step) would pass for this sweep's
    // cases: they go with the rest. Every other name a sweep writes is
    // fixed, so it is replaced; anything else in series/ is not a sweep's
    // and stays.
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir + "/series", ec))
      if (e.is_regular_file() && e.path().extension() == ".csv" &&
          e.path().filename().string().rfind("alpha_", 0) == 0 &&
          !written.count(e.path().filename().string()))
        out.retire("series/" + e.path().filename().string());
    out.write("evidence.csv", evidence_csv(result));
    nlohmann::json j = to_json(result);
    j["config_sha256"] = sha256_hex(config.text);
    j["version"] = DEMCAL_VERSION;
    out.write("atlas.json", j.dump(2) + "\n");
    out.write("atlas.md", atlas_markdown(result));
    out.commit();
  }

  const double s3 = config.test.lateral_stress;
  std::cout << std::setprecision(4) << "sweep " << config.name << ": " << result.cases.size()
            << " trials in " << result.wall_time_s << " s on " << result.jobs << " threads\n"
            << "  converged peak sigma1/sigma3 " << -result.reference.peak_stress_yy / s3
            << (result.reference.converged ? "" : " (NOT converged)") << "\n"
            << "  false passes " << result.false_passes << ", false rejects "
            << result.false_rejects << "\n";
  for (const auto& r : result.cases) {
    if (r.spec.group != "benchmark" && r.spec.group != "atlas") continue;
    std::ostringstream line;
    line << "  " << std::left << std::setw(18) << r.spec.name << std::right;
    if (r.run.diverged) {
      line << "  diverged          ";
    } else {
      line << "  peak " << std::fixed << std::setprecision(3) << std::setw(7)
           << -r.score.criteria.peak_stress_yy / s3;
      if (r.score.criteria.peak_error)
        line << " " << std::showpos << std::setprecision(1) << std::setw(6)
             << 100.0 * *r.score.criteria.peak_error << "%" << std::noshowpos;
    }
    line << "  " << (r.score.passed ? "PASS" : "FAIL") << "  " << r.score.diagnosis.parameter
         << (r.score.diagnosis.direction.empty() ? "" : " " + r.score.diagnosis.direction);
    std::cout << line.str() << "\n";
  }
  std::cout << "  wrote " << dir << "/atlas.md, atlas.json, evidence.csv, series/*.csv\n";
  return 0;
}

}  // namespace demcal::cli
