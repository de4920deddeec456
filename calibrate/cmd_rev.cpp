// `demcal rev [CONFIG] [--prototype FILE] --particles N [--method cut|generate]`:
// a REV from the user's prototype, consolidated to σ3, with a report of how
// representative it is; disks (x,y,r) for a 2D config, spheres (x,y,z,r, a
// box window, the triaxial consolidation) for a 3D one (`"dimension": 3`).
// Writes DIR/rev.csv (the REV's particles),
// DIR/rev.json (representativeness) and DIR/rev-config.json, a scene config
// that calibrates on the REV and names the prototype, so that
//   demcal rev CONFIG --prototype P.csv -o R && demcal calibrate R/rev-config.json
// is the whole path from a user's assembly to its parameters.
#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/rev_3d.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {

// What a REV of either dimension leaves for the files: the REV's particles
// as CSV, its consolidation and the comparison.
struct RevOutcome {
  std::string method;
  std::string csv;
  int particles = 0;
  ConsolidationRecord consolidation;  ///< the REV's (a cache read's time when from_cache)
  Representativeness representativeness;
};

// A consolidation (the prototype's or the REV's, disks or spheres) as the
// other commands say it: `announce` ("consolidating ...") only when it
// consolidates, not before a read from the cache (consolidate_announced),
// then its steps and time (print_consolidated: a cache read's labelled);
// progress lines as run prints them (--progress). On every core from
// kThreadsFrom particles, as export's prototype (prototype_consolidation_threads):
// a generated 20 000-sphere prototype is most of rev's time. `announce`
// gets the threads (ConsolidationOptions::threads).
template <class AnyAssembly>
auto said_consolidation(const SceneConfig& config, const AnyAssembly& assembly, const char* what,
                        double progress_every_s, const std::function<void(int)>& announce) {
  const ConsolidationOptions co{.threads = prototype_consolidation_threads(assembly.size()),
                                .progress = consolidation_progress(progress_every_s)};
  const auto state = consolidate_announced(config, assembly, co, [&] { announce(co.threads); });
  print_consolidated(std::cerr, "demcal rev: ", what, state.steps, state.wall_time_s,
                     state.from_cache);
  std::cerr << "\n";
  return state;
}

void announce_rev(int64_t particles, const char* noun) {
  std::cerr << "demcal rev: consolidating the REV of " << particles << " " << noun
            << " to sigma3\n";
}

// A generated REV is a gas of --particles particles at the prototype's
// aspect (rev_gas_aspect): one that never consolidates is refused before
// it is made, by the rule a config's assembly.count and assembly.aspect
// are held to (gas_layers_fault). Checked on the prototype as read or
// generated, before any consolidation, and again on a generated
// prototype once consolidated (its box is the one the REV's gas takes).
template <class AnyAssembly>
void require_rev_gas(int dimension, const RevOptions& ro, const AnyAssembly& proto) {
  if (ro.method != "generate") return;
  const std::string problem = gas_layers_problem(
      dimension, static_cast<int>(std::min<int64_t>(ro.particles, kMaxParticles)),
      rev_gas_aspect(proto),
      dimension == 3 ? "the prototype's sqrt(width*depth)/height" : "the prototype's width/height");
  if (!problem.empty())
    throw InputError("--particles", "",
                     "a REV generated as a gas of " + std::to_string(ro.particles) +
                         (dimension == 3 ? " spheres: " : " disks: ") + problem);
}

// `ready` is called once the prototype is read and checked, before any
// consolidation (it checks the output folder); `every_s`: seconds between
// the consolidations' progress lines.
RevOutcome rev_2d(const SceneConfig& config, const std::string& file, const RevOptions& ro,
                  PrototypeSource& source, double every_s, const std::function<void()>& ready) {
  Assembly proto = prototype_assembly(config, 0, file, &source);
  if (source.kind == "rev")
    throw InputError(config.source, "prototype",
                     "names no prototype: give prototype.file or prototype.particles, or "
                     "--prototype FILE");
  require_rev_gas(2, ro, proto);
  // A REV cut from a particle file keeps the file's positions and radii,
  // which never went through make_assembly's checks: cut now,
  // checked before any work, and that cut consolidated (a file's prototype
  // is dense: not consolidated below). A generated prototype was checked
  // when made; a generated REV is a gas at the origin.
  std::optional<Assembly> cut;
  if (ro.method == "cut" && source.kind == "file") {
    cut = unconsolidated_rev(proto, ro);
    check_assembly(config, *cut, "the REV", source.file);
  }
  ready();
  if (!proto.dense) {  // a generated gas is no packing to cut from or compare with
    proto =
        assembly_of(said_consolidation(config, proto, "the prototype", every_s, [&](int threads) {
                      std::cerr << "demcal rev: consolidating the prototype first ("
                                << source.description << ", "
                                << consolidation_threads_words(threads)
                                << "): a loose gas takes long\n";
                    }).world);
    require_rev_gas(2, ro, proto);
  }
  std::cerr << "demcal rev: "
            << (ro.method == "cut" ? "cutting a REV of about " : "generating a REV of ")
            << ro.particles << " particles from " << source.description << "\n";
  const auto consolidated = [&](const Assembly& raw) {
    return said_consolidation(config, raw, "the REV", every_s,
                              [&](int) { announce_rev(raw.size(), "particles"); });
  };
  const RevResult r =
      cut ? make_rev(proto, ro, *cut, consolidated) : make_rev(proto, ro, consolidated);
  return {r.method, particle_csv(r.assembly), r.assembly.size(), consolidation_record(r.state),
          r.representativeness};
}

RevOutcome rev_3d(const SceneConfig& config, const std::string& file, const RevOptions& ro,
                  PrototypeSource& source, double every_s, const std::function<void()>& ready) {
  SphereAssembly proto = prototype_spheres(config, 0, file, &source);
  if (source.kind == "rev")
    throw InputError(config.source, "prototype",
                     "names no prototype: give prototype.file or prototype.particles, or "
                     "--prototype FILE (CSV x,y,z,r)");
  if (ro.method == "cut" && ro.particles > proto.size())  // before a long consolidation
    throw InputError(source.kind == "file" ? source.file : config.source, "",
                     "asked for a REV of " + std::to_string(ro.particles) +
                         " spheres, the prototype has only " + std::to_string(proto.size()));
  require_rev_gas(3, ro, proto);
  std::optional<SphereAssembly> cut;  // as in 2D
  if (ro.method == "cut" && source.kind == "file") {
    cut = unconsolidated_rev(proto, ro);
    check_sphere_assembly(config, *cut, "the REV", source.file);
  }
  ready();
  if (source.kind == "generated") {  // a generated gas is no packing to cut from or compare with
    proto = sphere_assembly_of(
        said_consolidation(config, proto, "the prototype", every_s, [&](int threads) {
          std::cerr << "demcal rev: consolidating the prototype first (" << source.description
                    << ", " << consolidation_threads_words(threads)
                    << "): a loose gas takes long\n";
        }).world);
    require_rev_gas(3, ro, proto);
  }
  std::cerr << "demcal rev: " << (ro.method == "cut" ? "cutting a box" : "generating a")
            << " REV of " << (ro.method == "cut" ? "about " : "") << ro.particles
            << " spheres from " << source.description << "\n";
  const auto consolidated = [&](const SphereAssembly& raw) {
    return said_consolidation(config, raw, "the REV", every_s,
                              [&](int) { announce_rev(raw.size(), "spheres"); });
  };
  const SphereRevResult r =
      cut ? make_rev(proto, ro, *cut, consolidated) : make_rev(proto, ro, consolidated);
  return {r.method, sphere_csv(r.assembly), r.assembly.size(), consolidation_record(r.state),
          r.representativeness};
}

}  // namespace

int cmd_rev(const RevCmdOptions& o) {
  namespace fs = std::filesystem;
  SceneConfig config = load_config(o.config, o.sets);
  if (o.particles < 2) throw InputError("--particles", "", "needs at least 2 particles");
  if (o.method != "cut" && o.method != "generate")
    throw InputError("--method", "", "must be cut or generate, got \"" + o.method + "\"");
  if (!o.prototype.empty() && !fs::exists(o.prototype))
    throw InputError(o.prototype, "", "cannot open particle file");
  const std::string dir = o.out_dir.empty() ? "demcal-rev-" + config.name : o.out_dir;
  RevOptions ro;
  ro.particles = o.particles;
  ro.method = o.method;
  ro.seed = config.calibration.seed;
  PrototypeSource source;
  // A bad -o fails once the prototype is read, before any consolidation,
  // and leaves no folder.
  auto check_folder = [&] { OutputFolder::check(dir); };
  const RevOutcome r =
      config.dimension == 3
          ? rev_3d(config, o.prototype, ro, source, o.progress_every_s, check_folder)
          : rev_2d(config, o.prototype, ro, source, o.progress_every_s, check_folder);

  // The three files together or none (a failure leaves no folder it made).
  OutputFolder out(dir);
  out.write("rev.csv", r.csv);
  nlohmann::json report{
      {"schema", "demcal.rev/1"},
      {"scene", config.name},
      {"dimension", config.dimension},
      {"method", r.method},
      {"prototype", {{"source", source.kind}, {"description", source.description}}},
      {"particles", r.particles},
      {"consolidation", consolidation_json(r.consolidation)},
      {"representativeness", to_json(r.representativeness)}};
  out.write("rev.json", report.dump(2) + "\n");
  // A config that calibrates on the REV and upscales to the prototype.
  nlohmann::json c = to_json(config);
  c["name"] = config.name + "-rev" + std::to_string(r.particles);
  c["assembly"] = {{"type", "file"}, {"file", "rev.csv"}};
  if (source.kind == "file")
    c["prototype"] = {{"particles", 0}, {"file", fs::absolute(source.file).string()}};
  else
    c["prototype"] = {{"particles", source.particles}};
  out.write("rev-config.json", c.dump(2) + "\n");
  out.commit();

  const auto& rep = r.representativeness;
  std::cout << "REV of " << r.particles << (config.dimension == 3 ? " spheres (" : " particles (")
            << r.method;
  // A cut window's edge passes between layers of the prototype, never
  // through one (cut_window.hpp): a lattice's REV holds whole layers.
  if (r.particles != o.particles)
    std::cout << "; asked for " << o.particles
              << ", the nearest count whose window cuts between the prototype's layers";
  std::cout << ") from " << source.description << "\n  " << rep.verdict << "\n  wrote " << dir
            << "/rev.csv, rev.json, rev-config.json (demcal calibrate " << dir
            << "/rev-config.json)\n";
  return 0;
}

}  // namespace demcal::cli
