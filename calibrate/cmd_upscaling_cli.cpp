// Command-line registration of upscale, verify, scaling, export and rev
// (issue #6), kept out of main.cpp so that it needs two lines there.
#include <CLI/CLI.hpp>
#include <memory>

#include "commands.hpp"
#include "demcal/scene/config.hpp"
#include "option_checks.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {

/// verify's and export's --prototype FILE or --particles N, not both.
void add_prototype_options(CLI::App* command, UpscaledParamsOptions& o) {
  auto* prototype = command->add_option("--prototype", o.prototype,
                                        "the prototype's particle file (CSV x,y,r; 3D: x,y,z,r)");
  command
      ->add_option("--particles", o.particles,
                   "a generated prototype of N particles; not with --prototype")
      ->check(whole_number(1, kMaxParticles))
      ->excludes(prototype);
}

/// What upscale, verify and export read about params.json after the
/// prototype: --allow-failed, --config, --set, --law, --exponent.
void add_params_options(CLI::App* command, UpscaledParamsOptions& o) {
  command->add_flag("--allow-failed", o.allow_failed,
                    "use the parameters of a params.json whose calibration failed (success "
                    "false: passed, not certified); refused without it");
  command->add_option("--config", o.config, "scene config, if params.json carries none");
  command->add_option("--set", o.sets, "override a config key: section.key=value");
  auto* law =
      command->add_option("--law", o.law, "scaling.json of demcal scaling: use its measured law");
  command
      ->add_option("--exponent", o.exponent,
                   "Nstep ~ N^exponent (default: 1 for disks, 2/3 for spheres); not with --law")
      ->check(real_above(0.0, kMaxExponent))
      ->excludes(law);
}

}  // namespace

std::function<int()> add_upscaling_commands(CLI::App& app) {
  auto up = std::make_shared<UpscaleOptions>();
  auto* upscale = app.add_subcommand(
      "upscale", "the calibrated parameters for a prototype of N particles (or a particle file)");
  upscale->add_option("params", up->params, "params.json of a calibration")->required();
  auto* up_particles =
      upscale->add_option("--particles", up->particles, "the prototype's particle count")
          ->check(whole_number(1, kMaxParticles));
  upscale
      ->add_option("--prototype", up->prototype,
                   "the prototype's particle file (CSV x,y,r; 3D: x,y,z,r); not with --particles")
      ->excludes(up_particles);
  add_params_options(upscale, *up);
  upscale->add_option("-o,--output", up->output, "write params.json here (default stdout)")
      ->check(non_empty_path());

  auto ve = std::make_shared<VerifyOptions>();
  auto* verify =
      app.add_subcommand("verify", "run the prototype with the upscaled parameters and score it");
  verify->add_option("params", ve->params, "params.json of a calibration")->required();
  add_prototype_options(verify, *ve);
  add_params_options(verify, *ve);
  verify->add_option("-o,--output", ve->out_dir, "output folder (default demcal-verify-NAME)")
      ->check(non_empty_path());
  verify
      ->add_option("--max-minutes", ve->max_minutes,
                   "refuse a loading run estimated longer than this (default 8)")
      ->check(real_above(0.0, kMaxMinutes));
  verify->add_flag("--consolidate-only", ve->consolidate_only,
                   "2D: consolidate the prototype, write DIR/prototype.csv, and stop");
  verify->add_option("--tile", ve->tile,
                     "2D: NXxNY, mirror-tile the --prototype packing into a larger test "
                     "prototype");
  verify->add_option("--engine", ve->engine,
                     "demcal (default) or, 2D, lammps: run the exported deck with lmp and score "
                     "it");
  verify->add_option("--np", ve->np, "2D: MPI ranks for --engine lammps (mpirun -np N; default 1)")
      ->check(CLI::Range(1, 4096));
  verify
      ->add_option("--threads", ve->threads,
                   "3D: threads for the prototype's loading run (default 0: 1 below " +
                       std::to_string(kThreadsFrom) +
                       " spheres, else the faster of 1 and all cores, measured on the prototype)")
      ->check(CLI::Range(0, 4096));
  add_progress_option(verify, ve->progress_every_s);

  auto sc = std::make_shared<ScalingOptions>();
  auto* scaling = app.add_subcommand(
      "scaling", "calibrate at several sizes, fit Nstep against N, check the law forward");
  add_scene_options(scaling, sc->config, sc->sets);
  scaling->add_option("--sizes", sc->sizes, "particle counts (default 25,100,400,1600)");
  scaling
      ->add_option("--calibrate-max", sc->calibrate_max,
                   "calibrate sizes up to this count; larger ones are checked forward only "
                   "(default 400)")
      ->check(whole_number(1, kMaxParticles));
  scaling->add_option("-o,--output", sc->out_dir, "report folder (default demcal-scaling-NAME)")
      ->check(non_empty_path());
  scaling->add_option("--work", sc->work_dir, "per-size work folder (default: the -o folder)")
      ->check(non_empty_path());
  scaling->add_option("-j,--jobs", sc->jobs, "trials in parallel (default: cores)")
      ->check(whole_number(1, kMaxJobs));
  scaling
      ->add_option("--max-trials", sc->max_trials,
                   "the search's trials per size at most, from 12 (default: config)")
      ->check(whole_number(kMinSearchTrials, kMaxTrials, kMinSearchTrialsWhy));
  scaling->add_flag("--resume", sc->resume, "reuse the sizes already done in the work folder");
  scaling->add_flag("-q,--quiet", sc->quiet, "no progress lines on stderr");
  add_progress_option(scaling, sc->progress_every_s);

  auto ex = std::make_shared<ExportCmdOptions>();
  auto* exp = app.add_subcommand("export", "an input deck for LAMMPS or LIGGGHTS");
  exp->add_option("params", ex->params, "params.json of a calibration")->required();
  // Values are checked by the command (exit 2, one message), not by CLI11.
  exp->add_option("--format", ex->format, "lammps (default) or liggghts");
  exp->add_option("-o,--output", ex->output, "the deck (default demcal-NAME.FORMAT)")
      ->check(non_empty_path());
  add_prototype_options(exp, *ex);
  add_params_options(exp, *ex);
  exp->add_flag("--no-consolidate", ex->no_consolidate,
                "write the prototype as read (it is already consolidated to sigma3)");
  exp->add_option("--consolidate-in", ex->consolidate_in,
                  "demcal, deck (LAMMPS: the deck's first stage, under MPI) or auto (the default, "
                  "which is demcal: its kernel is faster than the deck's stage on the same cores)");
  add_progress_option(exp, ex->progress_every_s);

  auto rv = std::make_shared<RevCmdOptions>();
  auto* rev = app.add_subcommand(
      "rev", "cut or generate a REV from the prototype and report how representative it is");
  add_scene_options(rev, rv->config, rv->sets);
  rev->add_option("--prototype", rv->prototype,
                  "the prototype's particle file (CSV x,y,r; 3D: x,y,z,r)");
  rev->add_option("--particles", rv->particles, "particles in the REV (default 400)")
      ->check(whole_number(1, kMaxParticles));
  rev->add_option("--method", rv->method, "cut (a window of the prototype) or generate");
  rev->add_option("-o,--output", rv->out_dir, "output folder (default demcal-rev-NAME)")
      ->check(non_empty_path());
  add_progress_option(rev, rv->progress_every_s);

  // After the --set keys (a command-line mistake, before any file), a
  // failed calibration's params.json is refused before anything else is
  // read or written (its "success" named), unless --allow-failed; then the
  // options that read it are checked against it (check_params_options).
  return [=]() -> int {
    if (upscale->parsed()) {
      check_params_options(*up, "upscale");
      return cmd_upscale(*up);
    }
    if (verify->parsed()) {
      check_params_options(*ve, "verify");
      return cmd_verify(*ve);
    }
    if (scaling->parsed()) return cmd_scaling(*sc);
    if (exp->parsed()) {
      check_params_options(*ex, "export");
      return cmd_export(*ex);
    }
    if (rev->parsed()) return cmd_rev(*rv);
    return -1;
  };
}

}  // namespace demcal::cli
