// The subcommands of issue #6 (REV, upscaling, verification, export): their
// options and the helpers they share. Registered on the command line by
// add_upscaling_commands() (cmd_upscaling_cli.cpp), declared in commands.hpp.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/upscaling/upscaling.hpp"

namespace demcal::cli {

/// What upscale, verify and export read alike: a calibration's params.json
/// and the prototype it is upscaled to (registered by add_params_options and
/// add_prototype_options, cmd_upscaling_cli.cpp).
struct UpscaledParamsOptions {
  std::string params;     ///< params.json of a calibration
  std::string prototype;  ///< the prototype's particle file
  int64_t particles = 0;  ///< or its particle count
  std::string config;     ///< scene config when params.json carries none
  std::vector<std::string> sets;
  std::string law;            ///< scaling.json whose "law" to use
  double exponent = 0.0;      ///< or an explicit exponent (0: params' or linear)
  bool allow_failed = false;  ///< use a params.json with "success": false
};

struct UpscaleOptions : UpscaledParamsOptions {
  std::string output;  ///< "" or "-": stdout
};
int cmd_upscale(const UpscaleOptions& options);

struct VerifyOptions : UpscaledParamsOptions {
  std::string out_dir;
  double max_minutes = 8.0;  ///< refuse loading runs estimated beyond this
  /// Consolidate the prototype, write DIR/prototype.csv and stop: a
  /// prototype prepared once for later verify and export runs.
  bool consolidate_only = false;
  /// "NXxNY": the prototype is --prototype mirror-tiled NX×NY times.
  std::string tile;
  /// "demcal" (the kernel) or "lammps": export the deck, run it with lmp
  /// (under mpirun -np `np` when np > 1) and score its series.
  std::string engine = "demcal";
  int np = 1;
  /// Threads for the 3D prototype's loading run (0: one below kThreadsFrom
  /// spheres, else the faster of one and all cores, measured on the
  /// prototype; results are bit-identical for any count).
  int threads = 0;
  /// Seconds between the consolidation's progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_verify(const VerifyOptions& options);

struct ScalingOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string sizes = "25,100,400,1600";
  int64_t calibrate_max = 400;  ///< larger sizes are only checked forward
  std::string out_dir;          ///< report folder (default demcal-scaling-NAME)
  std::string work_dir;         ///< per-size work (default: out_dir)
  int jobs = 0;
  int max_trials = 0;
  bool resume = false;
  bool quiet = false;
  /// Seconds between the consolidations' progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_scaling(const ScalingOptions& options);

struct ExportCmdOptions : UpscaledParamsOptions {
  std::string format = "lammps";
  std::string output;
  bool no_consolidate = false;
  /// Where the prototype is consolidated: demcal (its kernel, before
  /// writing), deck (a first stage of the LAMMPS deck) or auto (demcal:
  /// the rule is consolidate_in.hpp's).
  std::string consolidate_in = "auto";
  /// Seconds between demcal's consolidation progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_export(const ExportCmdOptions& options);

struct RevCmdOptions {
  std::string config;
  std::vector<std::string> sets;
  std::string prototype;
  int64_t particles = 400;
  std::string method = "cut";
  std::string out_dir;
  /// Seconds between the consolidations' progress lines on stderr.
  double progress_every_s = kProgressEverySeconds;
};
int cmd_rev(const RevCmdOptions& options);

/// The scene a params.json was calibrated on: --config, else its "config"
/// object, else the embedded default when the scene names match; nothing
/// when none applies.
std::optional<SceneConfig> params_scene(const nlohmann::json& params, const std::string& path,
                                        const std::string& config_path,
                                        const std::vector<std::string>& sets);
/// Before `command` (upscale, verify, export) uses the params.json at
/// `path`: a failed calibration's ("success": false) is refused
/// (require_calibrated: exit 2, the file and the field named), or with
/// `allow_failed` used with a warning on stderr.
void check_calibrated(const std::string& path, bool allow_failed, const char* command);
/// What `command` (upscale, verify, export) checks before it runs, in this
/// order: the --set keys (require_distinct_set_keys: a command-line
/// mistake, before any file is read); check_calibrated(); the params.json
/// read in full
/// (read_params_file); with a params.json that carries its config, a
/// --config that differs from it (compared as parsed: a copy of the same
/// file passes) and any --set: refused by upscale (it records that config
/// as its result's), a warning from verify and export (they run what they
/// are given; --set warns for material and test keys, what the multipliers
/// were calibrated for); a --set of a calibrated algorithm key (never
/// used: the parameters are the rev's, upscaled; lock_rotation is used by
/// the consolidation): a warning; a --law measured on another scene than the
/// params.json's: a note naming both. Notes and warnings on stderr,
/// "demcal COMMAND: ...".
void check_params_options(const UpscaledParamsOptions& options, const char* command);
/// params_scene(), or an InputError asking for --config when there is none.
SceneConfig required_scene(const nlohmann::json& params, const std::string& path,
                           const std::string& config, const std::vector<std::string>& sets);
/// The prototype to use: --prototype FILE or --particles N when given, else
/// the one params.json (at `params_path`) names (its file, else its
/// particle count); `origin` says which gave the count, for its errors
/// (--particles, or params.json's prototype.particles).
struct NamedPrototype {
  std::string file;
  int64_t particles = 0;
  CountOrigin origin{"--particles", ""};
};
NamedPrototype named_prototype(const nlohmann::json& params, const std::string& params_path,
                               const std::string& file, int64_t particles);

/// The scaling law: --exponent, else --law scaling.json, else params.json's
/// "upscaling" block, else the default law of its dimension (the command
/// line takes one of --exponent and --law).
ScalingLaw resolve_law(const nlohmann::json& params, const std::string& params_path,
                       const std::string& law_path, double exponent);

/// The prototype's notes on stderr, "demcal COMMAND: note: ...", where
/// they apply: a count `asked` for (--particles, or params.json's
/// prototype.particles; 0 for a file) that the generator could not make
/// exactly (it makes whole lattices and rows: 300 spheres asked, 256 made),
/// and below_rev_note().
void print_prototype_notes(const char* command, int64_t asked, int64_t n_rev, int64_t n_proto,
                           const ScalingLaw& law);

}  // namespace demcal::cli
