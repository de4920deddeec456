// `demcal stability [CONFIG] [--from F --to T --points P --steps S] [-o DIR]`:
// the stability scan (demcal/stability_scan.hpp), 2D or 3D. Writes DIR/stability.json
// and DIR/stability.md; prints the measured limit against the estimate.
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/stability_scan.hpp"
#include "output_folder.hpp"

namespace demcal::cli {

int cmd_stability(const StabilityOptions& o) {
  if (!(o.scan.to > o.scan.from)) throw InputError("--to", "", "must be larger than --from");
  // 2D (disks, biaxial test) and 3D (spheres, triaxial test) alike.
  SceneConfig config = load_config(o.config, o.sets);
  const std::string dir = o.out_dir.empty() ? "demcal-stability-" + config.name : o.out_dir;
  OutputFolder::check(dir);  // an unwritable -o fails now, not after the scan

  // The REV consolidated, said as the other commands say it: "consolidating
  // ..." only when it consolidates, not before a read from the cache
  // (consolidate_announced), then its steps and time (print_consolidated:
  // a cache read's labelled); progress lines as run prints them
  // (--progress, every 2 s).
  auto consolidated = [&](const auto& assembly, const char* what) {
    const ConsolidationOptions co{.progress = consolidation_progress(o.progress_every_s)};
    const auto state = consolidate_announced(config, assembly, co, [&] {
      std::cerr << "stability " << config.name << ": consolidating " << assembly.size() << " "
                << what << "\n";
    });
    print_consolidated(std::cerr, "stability " + config.name + ": ", "", state.steps,
                       state.wall_time_s, state.from_cache);
    std::cerr << "\n";
    return state;
  };
  const StabilityScanOptions& options = o.scan;
  StabilityScanResult r;
  if (config.dimension == 3)
    r = stability_scan(config, consolidated(make_sphere_assembly(config), "spheres (3D, triaxial)"),
                       options);
  else
    r = stability_scan(config, consolidated(make_assembly(config), "particles"), options);

  nlohmann::json j = to_json(r);
  j["scene"] = config.name;
  j["config_sha256"] = sha256_hex(config.text);
  j["version"] = DEMCAL_VERSION;
  {
    OutputFolder out(dir);
    out.write("stability.json", j.dump(2) + "\n");
    out.write("stability.md", stability_markdown(r, config.name));
    out.commit();
  }

  int diverged = 0;
  for (const auto& t : r.trials) diverged += t.diverged ? 1 : 0;
  std::cout << std::setprecision(4) << "stability " << config.name << ": estimate alpha "
            << r.dt_ratio_estimate << " (Gershgorin " << r.dt_ratio_gershgorin << ")";
  if (r.ratio() > 0.0)
    std::cout << ", measured: stable at " << r.dt_ratio_last_stable << ", diverged at "
              << r.dt_ratio_first_diverged << " (" << r.ratio() << " x the estimate)";
  else if (!r.trials.empty() && r.trials.front().diverged)
    std::cout << ", diverged already at the first rung: lower --from";
  else
    std::cout << ", no divergence up to the last rung: raise --to";
  std::cout << "\n  " << r.trials.size() << " trials, " << diverged << " diverged, "
            << r.stable_above_limit << " stable above the limit, " << r.wall_time_s << " s; wrote "
            << dir << "/stability.json, " << dir << "/stability.md\n";
  if (const std::string caveat = beyond_estimate_caveat(r); !caveat.empty())
    std::cout << "  " << caveat << "\n";
  return 0;
}

}  // namespace demcal::cli
