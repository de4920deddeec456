// `demcal export PARAMS.json --format lammps|liggghts [-o FILE]`: an input
// deck for the prototype run in another code, with the particle file it
// reads (demcal's consolidated state of the prototype) next to it. A 3D
// params.json (spheres, triaxial test) gives the 3D deck of its prototype.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "consolidate_in.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/export_3d.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {

namespace fs = std::filesystem;

/// Whether `file` is a deck demcal exported (its opening says so).
bool is_exported_deck(const fs::path& file) {
  std::ifstream in(file);
  std::string first, second;
  return std::getline(in, first) && std::getline(in, second) && first.rfind("# ===", 0) == 0 &&
         second.rfind("# demcal ", 0) == 0 && second.find(" export: ") != std::string::npos;
}

/// Whether a deck's text names `file` as a word (read_data FILE, mesh file
/// FILE, the header's "(FILE)").
bool names_file(const std::string& text, const std::string& file) {
  auto delimits = [](char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '"' || c == '\'' || c == '(' ||
           c == ')';
  };
  for (size_t at = text.find(file); at != std::string::npos; at = text.find(file, at + 1)) {
    const size_t end = at + file.size();
    if ((at == 0 || delimits(text[at - 1])) && (end == text.size() || delimits(text[end])))
      return true;
  }
  return false;
}

/// An export never overwrites another deck's files: the files it writes in
/// `dir` (the deck `deck` and `sides`, the files it reads) must be neither
/// an earlier export's deck other than `deck` nor a file such a deck reads
/// (a deck named FILE.data, or a deck of an older demcal naming its data
/// file after the deck's stem). Re-exporting a deck replaces it and its
/// own files. InputError (exit 2) naming the other deck.
void check_other_decks(const fs::path& dir, const std::string& deck,
                       const std::vector<std::string>& sides) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string other = e.path().filename().string();
    if (other == deck || !e.is_regular_file(ec) || e.file_size(ec) > (16u << 20) ||
        !is_exported_deck(e.path()))
      continue;
    if (std::find(sides.begin(), sides.end(), other) != sides.end())
      throw InputError(e.path().string(), "",
                       "an exported deck, which the deck " + deck +
                           " would overwrite with a file it reads; export to another name (-o)");
    const std::string text = read_text_file(e.path().string());
    std::vector<std::string> ours = sides;
    ours.push_back(deck);
    for (const std::string& name : ours)
      if (names_file(text, name))
        throw InputError(e.path().string(), "",
                         "this exported deck reads " + name + ", which exporting " + deck +
                             " would overwrite; export to another name (-o), or move that deck "
                             "and its files elsewhere first");
  }
}

/// Where the deck goes: -o FILE or demcal-NAME.FORMAT, checked writable now
/// (not after a consolidation) as every -o FILE is (check_output_file). The files it reads and
/// writes are named after the whole deck file name (deck_files: NAME.lammps.data,
/// NAME.lammps.series.csv, NAME.liggghts-top.stl, ...), so two decks in one
/// folder never share one; check_other_decks refuses what would overwrite
/// another deck's files.
fs::path deck_destination(const ExportCmdOptions& o, const SceneConfig& config, ExportOptions& eo) {
  if (o.format != "lammps" && o.format != "liggghts")
    throw InputError("--format", "", "must be lammps or liggghts, got \"" + o.format + "\"");
  const fs::path deck_fs(o.output.empty() ? "demcal-" + config.name + "." + o.format : o.output);
  check_output_file(deck_fs.string());
  eo.format = o.format;
  eo.deck_name = deck_fs.filename().string();
  check_other_decks(deck_fs.has_parent_path() ? deck_fs.parent_path() : fs::path("."), eo.deck_name,
                    {deck_files(eo.deck_name).data});
  return deck_fs;
}

/// Writes the deck and the files it reads together (never a new deck beside
/// an old data file) and says what was written and how to run it.
void write_deck(const fs::path& deck_fs, const ExportCmdOptions& o, const ExportResult& r,
                int particles, const char* what) {
  const fs::path dir = deck_fs.has_parent_path() ? deck_fs.parent_path() : fs::path(".");
  std::vector<std::string> sides;
  for (const auto& file : r.files) sides.push_back(file.first);
  check_other_decks(dir, deck_fs.filename().string(), sides);
  {
    OutputFolder out(dir.string());
    for (const auto& [name, content] : r.files) out.write(name, content);
    out.write(deck_fs.filename().string(), r.deck);
    out.commit();
  }
  std::cout << "wrote " << deck_fs.string() << " (" << o.format << ", " << particles << " " << what
            << ", timestep " << r.dt << " s, " << r.steps << " steps, " << r.types
            << " radius class(es))";
  for (const auto& [name, content] : r.files) std::cout << ", " << (dir / name).string();
  std::cout << "\n";
  // What could not be carried over exactly: on stderr (diagnostics), once.
  for (const auto& note : r.notes) std::cerr << "demcal export: note: " << note << "\n";
  std::cout << "  run it in its folder: cd " << dir.string() << " && "
            << (o.format == "lammps" ? "lmp" : "liggghts") << " -in " << deck_fs.filename().string()
            << "\n";
}

/// consolidate_in_deck (the rule: consolidate_in.hpp), and says on stderr
/// when the deck consolidates the prototype.
bool deck_consolidates(const ExportCmdOptions& o, int particles) {
  const bool in_deck = consolidate_in_deck(o.consolidate_in, o.format, o.no_consolidate, particles);
  if (in_deck)
    std::cerr << "demcal export: " << particles
              << " particles: the deck consolidates the prototype to sigma3 itself (stage 1, under "
                 "MPI; --consolidate-in demcal does it here instead)\n";
  return in_deck;
}

/// demcal's consolidation of a prototype (disks or spheres): every core
/// from kThreadsFrom particles, progress on stderr. "consolidating ..." is
/// said only when it consolidates (not before a read from the
/// consolidation cache), then its steps and time (print_consolidated: a
/// cache read's labelled).
template <class AnyAssembly>
auto export_consolidated(const ExportCmdOptions& o, const SceneConfig& config,
                         const AnyAssembly& proto, const std::string& what, const char* kernel) {
  ConsolidationOptions co;
  co.threads = prototype_consolidation_threads(proto.size());
  co.progress = consolidation_progress(o.progress_every_s);
  const auto state = consolidate_announced(config, proto, co, [&] {
    std::cerr << "demcal export: consolidating the prototype (" << what
              << ") to sigma3 with demcal's " << kernel << ", "
              << consolidation_threads_words(co.threads)
              << (o.format == "lammps"
                      ? " (--consolidate-in deck leaves it to the LAMMPS deck, under "
                        "MPI)\n"
                      : "\n");
  });
  print_consolidated(std::cerr, "demcal export: ", "", state.steps, state.wall_time_s,
                     state.from_cache);
  std::cerr << "\n";
  return state;
}

/// The deck's Nstep and where it came from, 2D and 3D, on stderr: "demcal
/// export: 2500 steps upscaled from 100 particles / 1000 steps (linear law,
/// exponent 1: LAW'S SOURCE)"; for a prototype of the REV's `n` particles
/// (factor 1), that nothing is upscaled (rev_size_steps_words); nothing for
/// the REV itself.
void print_upscaled_steps(const PrototypeSource& source, int64_t n, const AlgorithmSpec& up,
                          const RevParams& rev, const ScalingLaw& law, const char* what) {
  if (source.kind == "rev") return;
  if (n == rev.particles) {
    std::cerr << "demcal export: " << rev_size_steps_words(up.steps, rev.particles, what) << "\n";
    return;
  }
  std::cerr << "demcal export: " << up.steps << " steps upscaled from " << rev.particles << " "
            << what << " / " << rev.params.steps << " steps (" << law.name() << " law, exponent "
            << law.exponent << ": " << law.source << ")\n";
}

/// A 3D params.json: the deck of the prototype it names (--prototype FILE
/// or --particles N override it; without any, the REV itself), Nstep
/// upscaled by the scaling law (resolve_law: --exponent, --law, else
/// params.json's, for spheres by default N^(2/3): default_law(3)),
/// consolidated as in 2D: by the LAMMPS deck's stage 1 (--consolidate-in
/// deck) or by demcal's sphere kernel (threads, progress).
int export_3d(const ExportCmdOptions& o, const nlohmann::json& params, const RevParams& rev,
              const SceneConfig& config) {
  if (o.no_consolidate)
    throw InputError("--no-consolidate", "",
                     "3D: the prototype is consolidated, by demcal or by the deck's stage 1 "
                     "(--consolidate-in)");
  Export3dOptions eo;
  const fs::path deck_fs = deck_destination(o, config, eo);
  eo.uncertified = uncertified_reason(params);
  const ScalingLaw law = resolve_law(params, o.params, o.law, o.exponent);
  auto [file, particles, count_origin] =
      named_prototype(params, o.params, o.prototype, o.particles);
  PrototypeSource source;
  const SphereAssembly proto = prototype_spheres(config, particles, file, &source, count_origin);
  check_prototype_assembly(config, proto, source);  // consolidated, here or by the deck
  eo.consolidate_in_deck = deck_consolidates(o, proto.size());
  const AlgorithmSpec up = upscale(rev.params, rev.particles, proto.size(), law);
  print_prototype_notes("export", particles, rev.particles, proto.size(), law);
  eo.provenance = o.params + " (REV " + std::to_string(rev.particles) + " spheres, " +
                  std::to_string(rev.params.steps) + " steps; " + law.name() + " law, exponent " +
                  std::to_string(law.exponent) + ")";
  print_upscaled_steps(source, proto.size(), up, rev, law, "spheres");
  if (eo.consolidate_in_deck) {
    const ExportResult r = export_3d_decks(config, up, proto, eo);
    write_deck(deck_fs, o, r, proto.size(), "spheres");
    return 0;
  }
  const TriaxialState state =
      export_consolidated(o, config, proto, source.description, "sphere kernel");
  const ExportResult r = export_3d_decks(config, up, state, eo);
  write_deck(deck_fs, o, r, state.world.size(), "spheres");
  return 0;
}

}  // namespace

int cmd_export(const ExportCmdOptions& o) {
  const nlohmann::json params = read_params_file(o.params);
  const RevParams rev = rev_params_from_json(params, o.params);
  const SceneConfig config = required_scene(params, o.params, o.config, o.sets);
  if (config.dimension == 3) return export_3d(o, params, rev, config);
  ExportOptions eo;
  const fs::path deck_fs = deck_destination(o, config, eo);
  eo.uncertified = uncertified_reason(params);
  const ScalingLaw law = resolve_law(params, o.params, o.law, o.exponent);
  auto [file, particles, count_origin] =
      named_prototype(params, o.params, o.prototype, o.particles);
  PrototypeSource source;
  Assembly proto = prototype_assembly(config, particles, file, &source, count_origin);
  // Consolidated here or by the deck, unless --no-consolidate (as given).
  if (!o.no_consolidate) check_prototype_assembly(config, proto, source);
  const AlgorithmSpec up = upscale(rev.params, rev.particles, proto.size(), law);
  print_prototype_notes("export", particles, rev.particles, proto.size(), law);
  print_upscaled_steps(source, proto.size(), up, rev, law, "particles");
  eo.provenance = o.params + " (REV " + std::to_string(rev.particles) + " particles, " +
                  std::to_string(rev.params.steps) + " steps; " + law.name() + " law, exponent " +
                  std::to_string(law.exponent) + ")";
  eo.consolidate_in_deck = deck_consolidates(o, proto.size());
  if (!eo.consolidate_in_deck && !o.no_consolidate) {
    const ConsolidatedState state =
        export_consolidated(o, config, proto, source.description, "kernel");
    proto = assembly_of(state.world);
  }
  const ExportResult r = export_deck(config, up, proto, eo);
  write_deck(deck_fs, o, r, proto.size(), "particles");
  return 0;
}

}  // namespace demcal::cli
