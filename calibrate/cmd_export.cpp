// `demcal export PARAMS.json --format lammps|liggghts [-o FILE]`: an input
// deck for the prototype run in another code, with the particle file it
// reads (demcal's consolidated state of the prototype) next to it.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

/// Above this many particles `--consolidate-in auto` leaves the consolidation
/// to the LAMMPS deck: demcal's kernel consolidates single-threaded, and
/// beyond a few thousand particles that takes minutes (reports/engines.md §8).
constexpr int kDeckConsolidationAbove = 2000;

int cmd_export(const ExportCmdOptions& o) {
  namespace fs = std::filesystem;
  const nlohmann::json params = read_params_file(o.params);
  const RevParams rev = rev_params_from_json(params, o.params);
  if (o.format != "lammps" && o.format != "liggghts")
    throw InputError("--format", "", "must be lammps or liggghts, got \"" + o.format + "\"");
  const SceneConfig config = required_scene(params, o.params, o.config, o.sets);
  const ScalingLaw law = resolve_law(params, o.params, o.law, o.exponent);
  auto [file, particles] = named_prototype(params, o.prototype, o.particles);
  PrototypeSource source;
  Assembly proto = prototype_assembly(config, particles, file, &source);
  const AlgorithmSpec up = upscale(rev.params, rev.particles, proto.size(), law);

  const std::string deck_path =
      o.output.empty() ? "demcal-" + config.name + "." + o.format : o.output;
  const fs::path deck_fs(deck_path);
  if (fs::is_directory(deck_fs)) throw InputError(deck_path, "", "is a folder; give a file name");
  // An unwritable destination fails now, not after the consolidation.
  OutputFolder::check(deck_fs.has_parent_path() ? deck_fs.parent_path().string() : ".");
  ExportOptions eo;
  eo.format = o.format;
  const std::string ext = deck_fs.extension().string();
  const bool known = ext == ".lammps" || ext == ".liggghts" || ext == ".in" || ext == ".lmp";
  eo.data_name = (known ? deck_fs.stem() : deck_fs.filename()).string() + ".data";
  eo.provenance = o.params + " (REV " + std::to_string(rev.particles) + " particles, " +
                  std::to_string(rev.params.steps) + " steps; " + law.name() + " law, exponent " +
                  std::to_string(law.exponent) + ")";

  if (o.consolidate_in != "auto" && o.consolidate_in != "demcal" && o.consolidate_in != "deck")
    throw InputError("--consolidate-in", "",
                     "must be demcal, deck or auto, got \"" + o.consolidate_in + "\"");
  if (o.consolidate_in == "deck" && o.format != "lammps")
    throw InputError("--consolidate-in", "", "deck: only the LAMMPS deck consolidates itself");
  if (o.consolidate_in != "auto" && o.no_consolidate)
    throw InputError("--consolidate-in", "",
                     "the prototype is not consolidated with --no-consolidate");
  eo.consolidate_in_deck =
      !o.no_consolidate &&
      (o.consolidate_in == "deck" || (o.consolidate_in == "auto" && o.format == "lammps" &&
                                      proto.size() > kDeckConsolidationAbove));
  if (eo.consolidate_in_deck) {
    std::cerr << "demcal export: " << proto.size() << " particles"
              << (o.consolidate_in == "auto"
                      ? " (more than " + std::to_string(kDeckConsolidationAbove) + ")"
                      : std::string())
              << ": the deck consolidates the prototype to sigma3 itself (stage 1, under MPI; "
                 "--consolidate-in demcal does it here instead)\n";
  } else if (!o.no_consolidate) {
    std::cerr << "demcal export: consolidating the prototype (" << source.description
              << ") to sigma3 with demcal's kernel, single-threaded (--consolidate-in deck "
                 "leaves it to the LAMMPS deck, under MPI)\n";
    const ConsolidatedState state = consolidate(config, proto);
    std::cerr << "demcal export: consolidated in " << state.steps << " steps, " << state.wall_time_s
              << " s\n";
    proto = assembly_of(state.world);
  }
  const ExportResult r = export_deck(config, up, proto, eo);
  const fs::path dir = deck_fs.has_parent_path() ? deck_fs.parent_path() : fs::path(".");
  {
    // The deck and the files it reads (data file, meshes) replace those of
    // an earlier export together: never a new deck beside an old data file.
    OutputFolder out(dir.string());
    for (const auto& [name, content] : r.files) out.write(name, content);
    out.write(deck_fs.filename().string(), r.deck);
    out.commit();
  }
  std::cout << "wrote " << deck_path << " (" << o.format << ", " << proto.size()
            << " particles, timestep " << r.dt << " s, " << r.steps << " steps, " << r.types
            << " radius class(es))";
  for (const auto& [name, content] : r.files) std::cout << ", " << (dir / name).string();
  std::cout << "\n";
  // What could not be carried over exactly: on stderr (diagnostics), once.
  for (const auto& note : r.notes) std::cerr << "demcal export: note: " << note << "\n";
  std::cout << "  run it in its folder: cd " << dir.string() << " && "
            << (o.format == "lammps" ? "lmp" : "liggghts") << " -in " << deck_fs.filename().string()
            << "\n";
  return 0;
}

}  // namespace demcal::cli
