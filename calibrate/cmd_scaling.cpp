// `demcal scaling`: the proof of the upscaling law (scaling_study.hpp).
// Writes DIR/scaling.md and DIR/scaling.json; per-size work (trials,
// results) goes to --work (default DIR) and is reused with --resume.
// SIGINT/SIGTERM stop it cleanly, exit status 128 + signal: a size's
// calibration winds down keeping its finished trials, a consolidation, a
// step search or the reference run in progress stops at its next check
// and writes nothing, nothing is written to DIR's report, and the command
// to continue (--resume) is printed. The work folder is locked for the
// study's length (FolderLock): a second study on it is refused, exit 2.
#include <filesystem>
#include <iostream>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "consolidation_progress.hpp"
#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/upscaling/scaling_study.hpp"
#include "output_folder.hpp"
#include "resume_key.hpp"
#include "shell_word.hpp"
#include "stop_signal.hpp"
#include "upscaling_cli.hpp"

namespace demcal::cli {

namespace {

/// The command that continues an interrupted study: the same scene, sizes,
/// budget and folders, with --resume.
std::string resume_command(const ScalingOptions& o, const SceneConfig& config,
                           const std::string& out_dir) {
  std::vector<std::string> args{"demcal", "scaling"};
  if (!o.config.empty()) args.push_back(o.config);
  for (const auto& s : o.sets) args.insert(args.end(), {"--set", s});
  args.insert(args.end(),
              {"--sizes", o.sizes, "--calibrate-max", std::to_string(o.calibrate_max),
               "--max-trials", std::to_string(config.calibration.max_trials), "-o", out_dir});
  if (!o.work_dir.empty()) args.insert(args.end(), {"--work", o.work_dir});
  args.push_back("--resume");
  return shell_command(args);
}

}  // namespace

int cmd_scaling(const ScalingOptions& o) {
  // 2D (disks, biaxial) and 3D (spheres, triaxial) families alike.
  SceneConfig config = load_config(o.config, o.sets);
  if (o.max_trials > 0) config.calibration.max_trials = o.max_trials;
  require_calibration_budget(config);  // --max-trials is checked at parse time
  ScalingStudyOptions so;
  so.sizes = parse_sizes(o.sizes, "--sizes");
  so.sizes_text = o.sizes;
  so.calibrate_max = o.calibrate_max > 0 ? o.calibrate_max : 400;
  so.jobs = o.jobs;
  if (!o.quiet) {
    so.log = [](const std::string& line) { std::cerr << "demcal scaling: " << line << "\n"; };
    so.consolidation_progress = consolidation_progress(o.progress_every_s);
  }
  // Bad sizes (also sizes that make one particle count, or an assembly a
  // size cannot run) fail before any folder is made; the checked
  // assemblies are the ones run.
  CheckedScalingStudy checked = check_scaling_sizes(config, so);
  // Not "reports": run from the repository it overwrote the shipped study.
  const std::string out_dir = o.out_dir.empty() ? "demcal-scaling-" + config.name : o.out_dir;
  // The per-size work beside the report: two studies with different -o do
  // not share (and clear) each other's sizes.
  so.work_dir = o.work_dir.empty() ? out_dir : o.work_dir;
  std::error_code ec;
  // Before --work defaulted to -o, the sizes went to demcal-scaling-NAME
  // whatever -o said: a resume of such a study is pointed there, not run
  // afresh (a missing work folder) or refused for a missing resume.json.
  const std::string old_work = "demcal-scaling-" + config.name;
  if (o.resume && o.work_dir.empty() && so.work_dir != old_work &&
      !std::filesystem::exists(so.work_dir + "/resume.json", ec) &&
      std::filesystem::exists(old_work + "/resume.json", ec))
    throw InputError("--resume", "",
                     "no study's sizes in " + so.work_dir +
                         " (--work defaults to the -o folder), but " + old_work +
                         " holds a study's (the default work folder of earlier demcal builds): "
                         "add --work " +
                         old_work + " to continue it, or leave out --resume to start afresh");
  OutputFolder::check(out_dir);  // an unwritable -o fails now, not after the study
  // What the work folder's results (per size: calibration, fixed-multiplier
  // runs, references, consolidated samples) were made with: --resume reuses
  // them only under the same config (with its --set), particle files'
  // contents, --max-trials and build. A work folder that does not exist yet has nothing to reuse.
  nlohmann::json key{{"schema", "demcal.scaling-resume/1"},
                     {"config_sha256", sha256_hex(config.text)},
                     {"max_trials", config.calibration.max_trials}};
  const FamilyFile family = scaling_family_file(config);
  add_file_digest(key, "family_file_sha256", config, family.key, family.path);
  add_build(key);
  const bool work_exists = std::filesystem::exists(so.work_dir, ec);
  // Held to the end: a second study on this work folder (or a calibration
  // into it) stops here, before it reads or clears anything; a crash or a
  // kill drops it with the process.
  make_output_dir(so.work_dir);
  const FolderLock lock(so.work_dir, "--work");
  const bool reuse = o.resume && work_exists;
  if (reuse)
    require_same_run(so.work_dir, key, "the results in " + so.work_dir,
                     "config, --set, particle files, --max-trials and demcal build",
                     "run the study afresh without --resume (or with another --work)");
  so.resume = reuse;

  if (!reuse) {
    // A fresh start: an earlier study's per-size results would otherwise
    // stay under the new key until overwritten, and a resume after an
    // interruption would take them for this study's.
    for (const auto& e : std::filesystem::directory_iterator(so.work_dir)) {
      const std::string name = e.path().filename().string();
      if (e.is_directory() && name.rfind("size-", 0) == 0 && name.size() > 5 &&
          name.find_first_not_of("0123456789", 5) == std::string::npos)
        std::filesystem::remove_all(e.path());
    }
    write_resume_key(so.work_dir, key);
  }
  // From here on a signal stops cleanly.
  const StopOnSignal stop;
  so.stop = &stop.flag();
  const ScalingStudy st = run_scaling_study(std::move(checked), so);
  if (st.interrupted) {
    std::cerr << "demcal scaling: interrupted; the finished sizes (and a size's finished trials "
                 "and step-search runs) are in "
              << so.work_dir << ", no report was written. Continue with:\n  "
              << resume_command(o, config, out_dir) << "\n";
    return stop.exit_status();
  }
  {
    OutputFolder out(out_dir);  // both files replaced together, or neither
    out.write("scaling.json", to_json(st, config).dump(2) + "\n");
    out.write("scaling.md", scaling_markdown(st, config));
    out.commit();
  }
  std::cout << (st.dimension == 3 ? "3D (spheres): " : "") << "calibrated fit: slope "
            << num(st.lin_cal.slope, 5) << ", intercept " << num(st.lin_cal.intercept, 5) << ", R2 "
            << num(st.lin_cal.r2, 4) << "; fixed multipliers from the REV up: exponent "
            << num(st.measured.exponent, 3) << " (law " << st.chosen.name()
            << "); forward check of the " << law_words(st.candidate) << " law at "
            << st.results.at(st.forward_size).particles << ": "
            << (st.forward_ok ? "passed" : "FAILED") << "\n  wrote " << out_dir << "/scaling.md, "
            << out_dir << "/scaling.json\n";
  if (stop.stopped()) {
    std::cerr << "demcal scaling: interrupted after the last run; every output was written\n";
    return stop.exit_status();
  }
  return st.forward_ok ? 0 : 1;
}

}  // namespace demcal::cli
