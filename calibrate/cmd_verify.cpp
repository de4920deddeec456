// `demcal verify PARAMS.json [--prototype FILE | --particles N]`: run the
// prototype itself with the upscaled parameters and score it with the
// calibration's criteria. The cost is estimated and shown before anything
// runs; beyond --max-minutes the command refuses (exit 2).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/external_series.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/scoring/trial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/trial_runner.hpp"
#include "demcal/upscaling/export.hpp"
#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/rev.hpp"
#include "demcal/upscaling/upscaling.hpp"
#include "output_folder.hpp"
#include "print_criteria.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {
/// Single-thread kernel speed assumed before anything has run (measured
/// 3–4·10⁷ on this machine; the estimate is then refined from the
/// consolidation).
constexpr double kAssumedSpeed = 3e7;
/// LAMMPS on the exported 2D deck, one rank: a step costs
/// kLammpsStepCost (the deck's fixes, variables and servo, whatever the
/// size) plus one particle-step per particle at kLammpsSpeed. Measured
/// (wall time, load 7 on 2 cores): 21, 30, 62 and 393 µs a step at 25, 100,
/// 400 and 1 600 disks; 29 µs at 100 disks (353 442 steps in 10.4 s); on a
/// quiet machine 5.2 ms at 20 022 disks (reports/engines.md §3.2). The
/// model reads 26, 45, 120, 420 µs and 5.0 ms: within 2x, on the high side.
/// (The bare granular step of reports/performance.md runs 2–3 times faster
/// than the deck.)
constexpr double kLammpsSpeed = 4e6;      // particle-steps/s
constexpr double kLammpsStepCost = 2e-5;  // s a step
/// Particles a rank from which MPI ranks share the deck's work: 2 ranks ran
/// it 1.91x faster on 20 022 disks (reports/engines.md §3.2); below, no
/// speed-up is assumed (100 disks on 2 ranks ran 5.6x slower than on one).
constexpr double kLammpsParticlesPerRank = 1e4;
/// Wall time the ranks' exchanges add to every step (s): 100 disks on 2
/// ranks took 166 µs a step against 29 µs on one rank (2 shared cores).
constexpr double kLammpsMpiStepCost = 1.5e-4;

/// The estimated wall time of the LAMMPS deck's loading: `steps` (the
/// deck's) of `n` particles on `np` ranks.
double lammps_estimate_s(int64_t n, int64_t steps, int np) {
  const double particles = static_cast<double>(n);
  const double ranks =
      std::clamp(particles / kLammpsParticlesPerRank, 1.0, static_cast<double>(np));
  return static_cast<double>(steps) * (kLammpsStepCost + particles / (kLammpsSpeed * ranks) +
                                       (np > 1 ? kLammpsMpiStepCost : 0.0));
}

/// The first executable `name` on PATH, or "".
std::string find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream s(path ? path : "");
  for (std::string dir; std::getline(s, dir, ':');) {
    const std::filesystem::path p = std::filesystem::path(dir) / name;
    if (std::filesystem::exists(p) && ::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

/// series.csv's metadata for a prototype run of verify (`demcal score`
/// reads it: the same criteria and verdict as verify's).
template <class Run>
SeriesMetadata verify_metadata(const SceneConfig& config, const Run& run) {
  SeriesMetadata m = series_metadata(config.name, config.test, run);
  m.writer = "demcal verify";
  return m;
}

/// verify.json's opening, 2D and 3D, either engine: the schema, the scene,
/// the params file, the prototype (its `n` particles and their source), the
/// REV, the upscaling to `n`, the upscaled parameters `up` at the
/// prototype's `scales`, and the prototype's consolidation `state`
/// (consolidation_json: its steps, wall time and from_cache, as in `run`'s
/// summary.json).
template <class State>
nlohmann::json verify_head(const VerifyOptions& o, const SceneConfig& config, int64_t n,
                           const PrototypeSource& source, const RevParams& rev,
                           const ScalingLaw& law, const AlgorithmSpec& up,
                           const ParticleScales& scales, const State& state) {
  return {{"schema", "demcal.verify/1"},
          {"scene", config.name},
          {"params_file", o.params},
          {"prototype",
           {{"particles", n}, {"source", source.kind}, {"description", source.description}}},
          {"rev", {{"particles", rev.particles}, {"steps", rev.params.steps}}},
          {"upscaling", upscaling_block(rev.particles, n, law)},
          {"params", param_block(up, scales)},
          {"consolidation", consolidation_json(state)}};
}

/// `verify --engine lammps`: the exported deck of the consolidated
/// prototype, run by lmp in DIR/lammps, its series scored; the deck's
/// header says NOT CERTIFIED as export's does for a failed calibration's
/// `params` (--allow-failed).
int verify_in_lammps(const VerifyOptions& o, const nlohmann::json& params,
                     const SceneConfig& config, const ConsolidatedState& state,
                     const AlgorithmSpec& up, const std::string& dir, const std::string& lmp,
                     double estimate_s, nlohmann::json out) {
  namespace fs = std::filesystem;
  ExportOptions eo;
  eo.deck_name = "deck.lammps";  // it reads deck.lammps.data, writes deck.lammps.series.csv
  eo.provenance = o.params;
  eo.uncertified = uncertified_reason(params);  // --allow-failed: the header says so
  const DeckFiles files = deck_files(eo.deck_name);
  const ExportResult deck = export_deck(config, up, assembly_of(state.world), eo);
  const fs::path work = fs::path(dir) / "lammps";
  make_output_dir(work.string());
  write_file_atomic((work / files.deck).string(), deck.deck);
  for (const auto& [name, content] : deck.files) write_file_atomic((work / name).string(), content);
  // OpenMPI refuses to start as root unless told; other MPIs ignore these.
  const std::string launch =
      o.np > 1 ? "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np " +
                     std::to_string(o.np) + " "
               : "";
  const std::string cmd = "cd '" + work.string() + "' && " + launch + "'" + lmp + "' -in " +
                          files.deck + " -log log.lammps -screen none >/dev/null 2>&1";
  std::cerr << "demcal verify: running the exported deck: " << cmd << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  const int raw = std::system(cmd.c_str());
  const double engine_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!(WIFEXITED(raw) && WEXITSTATUS(raw) == 0))
    throw std::runtime_error("LAMMPS failed (status " + std::to_string(raw) + "); see " +
                             (work / "log.lammps").string());
  std::ifstream in(work / files.series, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const ExternalSeries series =
      parse_external_series(text.str(), (work / files.series).string(), std::nullopt);
  const Tolerances tolerances = default_tolerances(config);
  const ExternalScore scored = score_external(series, tolerances);
  const Score& score = scored.score;
  out["engine"] = {{"name", "lammps"},
                   {"np", o.np},
                   {"deck", (work / files.deck).string()},
                   {"wall_time_s", engine_s},
                   {"estimated_s", estimate_s},
                   {"steps", deck.steps},
                   {"dt", deck.dt},
                   {"step_factor", deck.step_factor},
                   {"notes", deck.notes}};
  // Everything `demcal score` writes of this series, in its one JSON form
  // (external_summary): the verdict line, the criteria a column was missing
  // for (not_checked), a divergence's step and reason; verify's own schema.
  const nlohmann::json summary = external_summary(series, scored, tolerances);
  for (const auto& [key, value] : summary.items())
    if (key != "schema") out[key] = value;
  write_file_atomic(dir + "/verify.json", out.dump(2) + "\n");
  const auto& c = score.criteria;
  std::cout << (score.passed ? "PASS" : "FAIL") << " in LAMMPS (" << o.np
            << (o.np > 1 ? " ranks" : " rank") << "): prototype of " << state.world.size()
            << " particles, " << deck.steps << " steps (alpha " << up.dt_ratio * deck.step_factor
            << " = " << up.dt_ratio << " * f, f " << deck.step_factor
            << " for the explicit fix viscous; zeta_t " << up.damping_ratio_translation
            << "; zeta_r not applied by this LAMMPS)\n"
            << "  force balance " << c.force_balance << " (tol " << tolerances.force_balance
            << "), moment balance " << c.moment_balance << " (tol " << tolerances.moment_balance
            << ", lever-arm floor RMS " << scored.lever_arm_floor_rms << " not counted), servo "
            << c.servo << " (tol " << tolerances.servo << "), oscillation " << c.oscillation
            << " (tol " << tolerances.oscillation << ")\n";
  print_peak(std::cout, false, c.peak_stress_yy, std::nullopt, config.test.lateral_stress);
  std::cout << ")\n"
            << "  " << score.diagnosis.message << "\n"
            << "  LAMMPS " << engine_s << " s (estimated " << estimate_s << " s); wrote " << dir
            << "/verify.json, prototype.csv, " << work.string() << "/ (" << files.deck << ", "
            << files.series << ", log.lammps)\n";
  return score.passed ? 0 : 1;
}

/// The loading rate of `world` with `params` on this machine now, from a
/// short timed run of a copy (particle-steps/s): the 3D estimate printed
/// before anything long runs.
double probe_rate(const SphereWorld& world, const AlgorithmSpec& params, int threads) {
  SphereWorld probe = world;
  probe.set_threads(threads);
  probe.set_integration(integration_for(probe, params));
  probe.step(5);  // neighbour lists built, threads started
  // About 2e6 particle-steps (a few hundredths of a second on one core):
  // a probe of a small prototype over a few milliseconds read the load of
  // the moment, not the rate.
  const int64_t steps = std::clamp<int64_t>(2000000 / std::max(1, probe.size()), 5, 20000);
  // The steps it took: the copy is the prototype before its consolidation,
  // and a lattice left unconfined can stop early (its ledger reads energy
  // created within ~160 steps); counted as asked, the stopped steps read
  // as a rate 10-15x too high.
  const int64_t before = probe.steps_taken();
  const auto t0 = std::chrono::steady_clock::now();
  probe.step(steps);
  const double s = seconds_since(t0);
  const int64_t taken = probe.steps_taken() - before;
  return s > 0.0 ? static_cast<double>(taken) * probe.size() / s : 0.0;
}

/// The peak of the REV's calibrated run as params.json records it.
std::optional<double> rev_peak(const nlohmann::json& params) {
  const auto c = params.find("criteria");
  if (c == params.end() || !c->is_object() || !c->contains("peak_stress_yy") ||
      !(*c)["peak_stress_yy"].is_number())
    return std::nullopt;
  return (*c)["peak_stress_yy"].get<double>();
}

/// verify.json and series.csv of one run, replaced together.
void write_verify_files(const std::string& dir, const nlohmann::json& verify,
                        const std::string& series) {
  OutputFolder files(dir);
  files.write("verify.json", verify.dump(2) + "\n");
  files.write("series.csv", series);
  files.commit();
}

/// `demcal verify` on 3D params: the spheres of the prototype consolidated
/// by the sphere kernel, loaded with the upscaled parameters on `threads`
/// threads, scored with the triaxial criteria, the peak against the REV's.
/// The verdict line and the four criteria against their tolerances, 2D and 3D.
void print_verdict(bool passed, const std::string& prototype, const AlgorithmSpec& up,
                   const Criteria& c, const Tolerances& tolerances) {
  std::cout << (passed ? "PASS" : "FAIL") << ": " << prototype << ", " << up.steps
            << " steps (alpha " << up.dt_ratio << ", zeta_t " << up.damping_ratio_translation
            << ", zeta_r " << up.damping_ratio_rotation << ")\n"
            << "  force balance " << c.force_balance << " (tol " << tolerances.force_balance
            << "), moment balance " << c.moment_balance << " (tol " << tolerances.moment_balance
            << "), servo " << c.servo << " (tol " << tolerances.servo << "), oscillation "
            << c.oscillation << " (tol " << tolerances.oscillation << ")\n";
}

int verify_3d(const VerifyOptions& o, const nlohmann::json& params, const RevParams& rev,
              const SceneConfig& config, const ScalingLaw& law) {
  if (o.engine != "demcal")
    throw InputError("--engine", "",
                     "3D: verify runs demcal's sphere kernel only, not " + quoted_value(o.engine) +
                         (o.engine == "lammps"     ? " (`demcal export` writes the LAMMPS 3D deck)"
                          : o.engine == "liggghts" ? " (`demcal export --format liggghts` writes "
                                                     "the LIGGGHTS 3D deck)"
                                                   : ""));
  if (o.np != 1)
    throw InputError("--np", "",
                     "MPI ranks are for --engine lammps, 2D only; 3D verify runs demcal's sphere "
                     "kernel (--threads)");
  if (!o.tile.empty()) throw InputError("--tile", "", "tiles 2D prototype files only");
  if (o.consolidate_only)
    throw InputError("--consolidate-only", "", "2D only (3D prototypes are consolidated per run)");
  // An unusable -o fails before anything is printed or probed.
  const std::string dir = o.out_dir.empty() ? "demcal-verify-" + config.name : o.out_dir;
  OutputFolder::check(dir);
  auto [file, particles, count_origin] =
      named_prototype(params, o.params, o.prototype, o.particles);
  PrototypeSource source;
  const SphereAssembly proto = prototype_spheres(config, particles, file, &source, count_origin);
  check_prototype_assembly(config, proto, source);  // before the probes and the run
  const int64_t n = proto.size();
  const AlgorithmSpec up = upscale(rev.params, rev.particles, n, law);
  print_prototype_notes("verify", particles, rev.particles, n, law);
  const double particle_steps = static_cast<double>(n) * static_cast<double>(up.steps);
  const SphereWorld world(sphere_material(config.material), proto.x, proto.y, proto.z, proto.r,
                          proto.lo, proto.hi);
  // --threads, else one thread below kThreadsFrom spheres and, from there,
  // the faster of one thread and all cores, measured now: on a loaded
  // machine the threads' barriers can cost more than they share.
  int threads = o.threads;
  double rate = 0.0;
  if (threads > 0) {
    rate = probe_rate(world, up, threads);
  } else {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    threads = 1;
    rate = probe_rate(world, up, 1);
    if (cores > 1 && n >= kThreadsFrom) {
      const double rate_all = probe_rate(world, up, cores);
      std::cerr << "demcal verify: probe: " << rate << " particle-steps/s on 1 thread, " << rate_all
                << " on " << cores << "\n";
      if (rate_all > rate) threads = cores, rate = rate_all;
    }
  }
  const double estimate_s = rate > 0.0 ? particle_steps / rate : 0.0;
  std::cerr << "demcal verify: prototype " << source.description << "; ";
  if (n == rev.particles)
    std::cerr << rev_size_steps_words(up.steps, rev.particles, "spheres") << "\n";
  else
    std::cerr << up.steps << " steps upscaled (" << law.name() << " law, exponent " << law.exponent
              << ": " << law.source << ") from " << rev.particles << " spheres / "
              << rev.params.steps << " steps\n";
  std::cerr << "demcal verify: loading = " << particle_steps << " particle-steps, estimated "
            << estimate_s / 60.0 << " min at " << rate
            << " particle-steps/s (measured now on the prototype, " << threads
            << " thread(s); plus the consolidation)\n";
  if (estimate_s > 60.0 * o.max_minutes)
    throw InputError("--max-minutes", "",
                     "the loading of " + std::to_string(n) + " spheres over " +
                         std::to_string(up.steps) + " steps is estimated at " +
                         num(estimate_s / 60.0) + " min, beyond the budget of " +
                         num(o.max_minutes) + " min; raise --max-minutes to run it");

  const auto t0 = std::chrono::steady_clock::now();
  // "consolidating ..." only before a consolidation, not before a read
  // from the cache (consolidate_announced); progress lines (--progress). On
  // the loading's threads: the state is the same bit for bit on any count,
  // and a large prototype's consolidation is most of verify's time.
  const ConsolidationOptions co{.threads = threads,
                                .progress = consolidation_progress(o.progress_every_s)};
  TriaxialState state = consolidate_announced(config, proto, co, [&] {
    std::cerr << "demcal verify: consolidating the prototype ("
              << (threads == 1 ? std::string("single-threaded")
                               : "on " + std::to_string(threads) + " threads")
              << (source.kind == "generated" && config.assembly.type == "random"
                      ? ", long for a loose gas)\n"
                      : ")\n");
  });
  print_consolidated(std::cerr, "demcal verify: ", "", state.steps, state.wall_time_s,
                     state.from_cache);
  std::cerr << "; loading now\n";
  state.world.set_threads(threads);
  const Tolerances tolerances = default_tolerances(config);
  TriaxialResult run;
  const TriaxialRunner runner(config, state);
  const TrialRun trial = runner.run(up, tolerances, false, 3.0, nullptr, &run);
  const Score& score = trial.score;
  const double total_s = seconds_since(t0);
  const auto& c = score.criteria;
  const std::optional<double> peak_rev = rev_peak(params);
  const double s3 = config.test.lateral_stress;
  nlohmann::json peak{{"stress_zz", c.peak_stress_yy},
                      {"strain_zz", c.peak_strain_yy},
                      {"ratio", -c.peak_stress_yy / s3}};
  if (peak_rev) {
    peak["rev_stress_zz"] = *peak_rev;
    peak["relative_to_rev"] = (c.peak_stress_yy - *peak_rev) / std::abs(*peak_rev);
  }
  const double rate_run = trial.wall_time_s > 0 ? particle_steps / trial.wall_time_s : 0.0;
  nlohmann::json out = verify_head(o, config, n, source, rev, law, up,
                                   sphere_scales(state.world, config.material, up), state);
  out.update({{"dimension", 3},
              {"passed", score.passed},
              {"criteria", to_json(c)},
              {"tolerances", to_json(tolerances)},
              {"diagnosis", to_json(score.diagnosis)},
              {"peak", peak},
              {"diverged", score.diverged},
              {"axial_component", kTriaxialCriteriaNames},
              {"loading",
               {{"steps", up.steps},
                {"particle_steps", particle_steps},
                {"threads", state.world.threads()},
                {"estimated_s", estimate_s},
                {"wall_time_s", trial.wall_time_s},
                {"particle_steps_per_s", rate_run}}},
              {"wall_time_s", total_s},
              {"version", DEMCAL_VERSION}});
  write_verify_files(dir, out, series_csv(verify_metadata(config, run), run.series));
  print_verdict(score.passed, "3D prototype of " + std::to_string(n) + " spheres", up, c,
                tolerances);
  print_peak(std::cout, true, c.peak_stress_yy, std::nullopt, s3);
  std::cout << ")";
  if (peak_rev)
    std::cout << "; the REV's " << *peak_rev << " Pa ("
              << num(100.0 * (c.peak_stress_yy - *peak_rev) / std::abs(*peak_rev), 3) << " %)";
  std::cout << "\n"
            << "  " << score.diagnosis.message << "\n"
            << "  consolidation ";
  print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
  std::cout << ", loading " << trial.wall_time_s << " s (" << rate_run << " particle-steps/s on "
            << state.world.threads() << " thread(s), estimated " << estimate_s << " s), total "
            << total_s << " s\n"
            << "  wrote " << dir << "/verify.json, series.csv\n";
  return score.passed ? 0 : 1;
}
/// The prototype file `proto` mirror-tiled NXxNY (--tile), its source's
/// description and count updated.
Assembly tiled_prototype(const Assembly& proto, const std::string& tile, PrototypeSource& source) {
  int nx = 0, ny = 0;
  char sep = 0, extra = 0;
  if (std::sscanf(tile.c_str(), "%d%c%d%c", &nx, &sep, &ny, &extra) != 3 ||
      (sep != 'x' && sep != 'X') || nx < 1 || ny < 1 || nx * ny > 10000)
    throw InputError("--tile", "", "expected NXxNY, e.g. 2x2, got \"" + tile + "\"");
  if (source.kind != "file")
    throw InputError("--tile", "", "tiles a prototype file: give --prototype FILE");
  Assembly tiled = tile_mirrored(proto, nx, ny);
  source.description += ", mirror-tiled " + std::to_string(nx) + "x" + std::to_string(ny) + " = " +
                        std::to_string(tiled.size()) + " particles";
  source.particles = tiled.size();
  source.tiling = std::to_string(nx) + "x" + std::to_string(ny);
  return tiled;
}

/// 2D verify's engine from the options, checked: "" for demcal's kernel,
/// else the path of lmp (--engine lammps, mpirun too for --np > 1).
std::string engine_2d(const VerifyOptions& o) {
  const bool in_lammps = o.engine == "lammps";
  if (!in_lammps && o.engine != "demcal")
    throw InputError("--engine", "",
                     "must be demcal or lammps, got " + quoted_value(o.engine) +
                         (o.engine == "liggghts"
                              ? " (`demcal export --format liggghts` writes the LIGGGHTS deck)"
                              : ""));
  if (!in_lammps && o.np != 1)
    throw InputError("--np", "",
                     "MPI ranks are for --engine lammps; demcal's verify runs in this process");
  if (o.threads != 0) throw InputError("--threads", "", "3D only (2D verify runs on one thread)");
  if (!in_lammps) return "";
  const std::string lmp = find_on_path("lmp");
  if (lmp.empty())
    throw InputError("--engine", "lammps",
                     "lmp is not on PATH: install LAMMPS (apt-get install lammps)");
  if (o.np > 1 && find_on_path("mpirun").empty())
    throw InputError("--np", "", "mpirun is not on PATH (apt-get install openmpi-bin)");
  return lmp;
}

/// What a 2D verify will run: the prototype's size, the upscaled
/// parameters, the loading's steps in the engine that runs it and its
/// estimated time.
struct Plan2d {
  int64_t n = 0;
  AlgorithmSpec up;
  bool in_lammps = false;
  int64_t run_steps = 0;  ///< LAMMPS runs the deck's Nstep/f (deck_steps)
  double particle_steps = 0.0, estimate_s = 0.0;
  ParticleScales scales;  ///< the prototype's, at the upscaled mass scaling
};

/// The plan's lines on stderr, after its budget check (--max-minutes).
void announce_plan_2d(const VerifyOptions& o, const Plan2d& p, const PrototypeSource& source,
                      const RevParams& rev, const ScalingLaw& law) {
  if (p.estimate_s > 60.0 * o.max_minutes && !o.consolidate_only)
    throw InputError("--max-minutes", "",
                     "the loading of " + std::to_string(p.n) + " particles over " +
                         std::to_string(p.run_steps) + (p.in_lammps ? " LAMMPS" : "") +
                         " steps is estimated at " + num(p.estimate_s / 60.0) +
                         " min, beyond the budget of " + num(o.max_minutes) +
                         " min; raise --max-minutes to run it");
  std::cerr << "demcal verify: prototype " << source.description << "; ";
  if (p.n == rev.particles)
    std::cerr << rev_size_steps_words(p.up.steps, rev.particles, "particles") << "\n";
  else
    std::cerr << p.up.steps << " steps upscaled (" << law.name() << " law, exponent "
              << law.exponent << ") from " << rev.particles << " particles / " << rev.params.steps
              << " steps\n";
  if (o.consolidate_only)
    std::cerr << "demcal verify: --consolidate-only: the consolidation alone, no loading\n";
  else if (p.in_lammps)
    std::cerr << "demcal verify: LAMMPS loading = " << p.run_steps
              << " steps of the deck (Nstep/f), "
              << static_cast<double>(p.n) * static_cast<double>(p.run_steps)
              << " particle-steps, estimated " << p.estimate_s / 60.0 << " min at " << kLammpsSpeed
              << " particle-steps/s a rank plus " << kLammpsStepCost << " s a step"
              << (o.np > 1 ? " on " + std::to_string(o.np) + " ranks (sharing the work from " +
                                 num(kLammpsParticlesPerRank) + " particles a rank) plus " +
                                 num(kLammpsMpiStepCost) + " s a step of exchanges"
                           : std::string())
              << " (plus the consolidation in demcal)\n";
  else
    std::cerr << "demcal verify: loading = " << p.particle_steps << " particle-steps, estimated "
              << p.estimate_s / 60.0 << " min at " << kAssumedSpeed
              << " particle-steps/s (plus the consolidation)\n";
}

/// demcal's loading of the consolidated prototype with the upscaled
/// parameters: verify.json and series.csv in `dir`, the verdict on stdout.
int load_and_report_2d(const VerifyOptions& o, const SceneConfig& config,
                       const ConsolidatedState& state, const Plan2d& p,
                       const PrototypeSource& source, const RevParams& rev, const ScalingLaw& law,
                       const std::string& dir, std::chrono::steady_clock::time_point t0) {
  const AlgorithmSpec& up = p.up;
  LoadingResult run;
  const Tolerances tolerances = default_tolerances(config);
  const TrialRecord trial = run_trial(config, state, up, tolerances, false, 3.0, &run);
  const Score score = score_run(run, config.test.lateral_stress, tolerances);
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  nlohmann::json out = verify_head(o, config, p.n, source, rev, law, up, p.scales, state);
  out["prototype"]["stats"] = to_json(packing_stats(state.world));
  out.update({{"passed", trial.score.passed},
              {"criteria", to_json(trial.score.criteria)},
              {"tolerances", to_json(tolerances)},
              {"diagnosis", to_json(score.diagnosis)},
              {"peak",
               {{"stress_yy", trial.score.criteria.peak_stress_yy},
                {"strain_yy", trial.score.criteria.peak_strain_yy},
                {"ratio", -trial.score.criteria.peak_stress_yy / config.test.lateral_stress}}},
              {"diverged", trial.score.diverged},
              {"loading",
               {{"steps", up.steps},
                {"particle_steps", p.particle_steps},
                {"wall_time_s", trial.wall_time_s},
                {"particle_steps_per_s",
                 trial.wall_time_s > 0 ? p.particle_steps / trial.wall_time_s : 0.0}}},
              {"wall_time_s", total_s},
              {"version", DEMCAL_VERSION}});
  write_verify_files(dir, out, series_csv(verify_metadata(config, run), run.series));

  const auto& c = trial.score.criteria;
  print_verdict(trial.score.passed, "prototype of " + std::to_string(p.n) + " particles", up, c,
                tolerances);
  print_peak(std::cout, false, c.peak_stress_yy, std::nullopt, config.test.lateral_stress);
  std::cout << ")\n"
            << "  " << score.diagnosis.message << "\n"
            << "  consolidation ";
  print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
  std::cout << ", loading " << trial.wall_time_s << " s ("
            << (trial.wall_time_s > 0 ? p.particle_steps / trial.wall_time_s : 0.0)
            << " particle-steps/s), total " << total_s << " s\n"
            << "  wrote " << dir << "/verify.json, series.csv, prototype.csv\n";
  return trial.score.passed ? 0 : 1;
}

int verify_2d(const VerifyOptions& o, const nlohmann::json& params, const RevParams& rev,
              const SceneConfig& config, const ScalingLaw& law) {
  const std::string lmp = engine_2d(o);
  const std::string dir = o.out_dir.empty() ? "demcal-verify-" + config.name : o.out_dir;
  // An unusable -o fails now, before anything is printed, and nothing is
  // made before the consolidation (a failed one leaves no empty folder);
  // made where prototype.csv goes.
  OutputFolder::check(dir);
  auto [file, particles, count_origin] =
      named_prototype(params, o.params, o.prototype, o.particles);
  PrototypeSource source;
  Assembly proto = prototype_assembly(config, particles, file, &source, count_origin);
  if (!o.tile.empty()) proto = tiled_prototype(proto, o.tile, source);
  check_prototype_assembly(config, proto, source);  // the tiles' too, before the consolidation
  Plan2d p;
  p.n = proto.size();
  p.up = upscale(rev.params, rev.particles, p.n, law);
  print_prototype_notes("verify", particles, rev.particles, p.n, law);
  p.particle_steps = static_cast<double>(p.n) * static_cast<double>(p.up.steps);
  p.scales = particle_scales(proto.r, config.material, p.up.mass_scaling);
  // LAMMPS runs the deck's steps (Nstep/f: deck_steps, what the deck
  // writes) at its own speed, its ranks sharing the work only on large
  // prototypes.
  p.in_lammps = !lmp.empty();
  p.run_steps = p.in_lammps ? deck_steps(p.up) : p.up.steps;
  p.estimate_s =
      p.in_lammps ? lammps_estimate_s(p.n, p.run_steps, o.np) : p.particle_steps / kAssumedSpeed;
  announce_plan_2d(o, p, source, rev, law);

  const auto t0 = std::chrono::steady_clock::now();
  // "consolidating ..." only before a consolidation, not before a read
  // from the cache (consolidate_announced); progress lines (--progress).
  const ConsolidationOptions co{.progress = consolidation_progress(o.progress_every_s)};
  const ConsolidatedState state = consolidate_announced(config, proto, co, [&] {
    std::cerr << "demcal verify: consolidating the prototype ("
              << (proto.dense ? "short for a dense packing" : "long for a loose gas") << ")\n";
  });
  // The kernel's speed from the consolidation, not from a cache's reading.
  const double speed =
      state.wall_time_s > 1.0 && !state.from_cache
          ? static_cast<double>(state.steps) * static_cast<double>(p.n) / state.wall_time_s
          : kAssumedSpeed;
  print_consolidated(std::cerr, "demcal verify: ", "", state.steps, state.wall_time_s,
                     state.from_cache);
  if (!o.consolidate_only)
    std::cerr << "; loading now, about "
              << (p.in_lammps ? p.estimate_s : p.particle_steps / speed) / 60.0 << " min";
  std::cerr << "\n";
  // The prototype's state, reusable by `demcal export --prototype` and by
  // later runs (read_particle_file reads it back).
  make_output_dir(dir);
  write_file_atomic(dir + "/prototype.csv", particle_csv(assembly_of(state.world)));
  if (o.consolidate_only) {
    std::cout << "consolidated prototype of " << p.n << " particles: " << state.steps << " steps, ";
    print_consolidation_time(std::cout, state.wall_time_s, state.from_cache);
    std::cout << "; wrote " << dir << "/prototype.csv\n";
    return 0;
  }
  if (p.in_lammps) {
    nlohmann::json head = verify_head(o, config, p.n, source, rev, law, p.up, p.scales, state);
    head["version"] = DEMCAL_VERSION;
    return verify_in_lammps(o, params, config, state, p.up, dir, lmp, p.estimate_s, head);
  }
  return load_and_report_2d(o, config, state, p, source, rev, law, dir, t0);
}

}  // namespace

int cmd_verify(const VerifyOptions& o) {
  const nlohmann::json params = read_params_file(o.params);
  const RevParams rev = rev_params_from_json(params, o.params);
  const SceneConfig config = required_scene(params, o.params, o.config, o.sets);
  const ScalingLaw law = resolve_law(params, o.params, o.law, o.exponent);
  return config.dimension == 3 ? verify_3d(o, params, rev, config, law)
                               : verify_2d(o, params, rev, config, law);
}

}  // namespace demcal::cli
