// `demcal rev [CONFIG] [--prototype FILE] --particles N [--method cut|generate]`:
// a REV from the user's prototype, consolidated to σ3, with a report of how
// representative it is. Writes DIR/rev.csv (the REV's particles),
// DIR/rev.json (representativeness) and DIR/rev-config.json, a scene config
// that calibrates on the REV and names the prototype, so that
//   demcal rev CONFIG --prototype P.csv -o R && demcal calibrate R/rev-config.json
// is the whole path from a user's assembly to its parameters.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

int cmd_rev(const RevCmdOptions& o) {
  namespace fs = std::filesystem;
  SceneConfig config = load_scene(o.config, o.sets);
  if (o.particles < 2) throw InputError("--particles", "", "needs at least 2 particles");
  if (o.method != "cut" && o.method != "generate")
    throw InputError("--method", "", "must be cut or generate, got \"" + o.method + "\"");
  if (!o.prototype.empty() && !fs::exists(o.prototype))
    throw InputError(o.prototype, "", "cannot open particle file");
  PrototypeSource source;
  Assembly proto = prototype_assembly(config, 0, o.prototype, &source);
  if (source.kind == "rev")
    throw InputError(config.source, "prototype",
                     "names no prototype: give prototype.file or prototype.particles, or "
                     "--prototype FILE");
  const std::string dir = o.out_dir.empty() ? "demcal-rev-" + config.name : o.out_dir;
  OutputFolder::check(dir);  // a bad -o fails now, and leaves no folder
  if (!proto.dense) {
    // A generated gas is no packing to cut from or compare with.
    std::cerr << "demcal rev: consolidating the prototype first (" << source.description
              << "): a loose gas takes long\n";
    proto = assembly_of(consolidate(config, proto).world);
  }
  RevOptions ro;
  ro.particles = o.particles;
  ro.method = o.method;
  ro.seed = config.calibration.seed;
  std::cerr << "demcal rev: " << (o.method == "cut" ? "cutting" : "generating") << " a REV of "
            << o.particles << " particles from " << source.description
            << ", consolidating it to sigma3\n";
  const RevResult r = make_rev(config, proto, ro);

  // The three files together or none (a failure leaves no folder it made).
  OutputFolder out(dir);
  out.write("rev.csv", particle_csv(r.assembly));
  nlohmann::json report{
      {"schema", "demcal.rev/1"},
      {"scene", config.name},
      {"method", r.method},
      {"prototype", {{"source", source.kind}, {"description", source.description}}},
      {"particles", r.assembly.size()},
      {"consolidation", {{"steps", r.state.steps}, {"wall_time_s", r.state.wall_time_s}}},
      {"representativeness", to_json(r.representativeness)}};
  out.write("rev.json", report.dump(2) + "\n");
  // A config that calibrates on the REV and upscales to the prototype.
  nlohmann::json c = to_json(config);
  c["name"] = config.name + "-rev" + std::to_string(r.assembly.size());
  c["assembly"] = {{"type", "file"}, {"file", "rev.csv"}};
  if (source.kind == "file")
    c["prototype"] = {{"particles", 0}, {"file", fs::absolute(source.file).string()}};
  else
    c["prototype"] = {{"particles", source.particles}};
  out.write("rev-config.json", c.dump(2) + "\n");
  out.commit();

  const auto& rep = r.representativeness;
  std::cout << "REV of " << r.assembly.size() << " particles (" << r.method << ") from "
            << source.description << "\n  " << rep.verdict << "\n  wrote " << dir
            << "/rev.csv, rev.json, rev-config.json (demcal calibrate " << dir
            << "/rev-config.json)\n";
  return 0;
}

}  // namespace demcal::cli
