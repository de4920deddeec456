// Test support: starting the demcal program (or another one, such as LAMMPS)
// the two ways the tests need: run to completion with the output captured,
// or start in the background and keep the pid (to signal or kill it).
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace demcal::test {

/// The demcal program built with the tests, and the source tree (configs/).
/// Plain character constants, not std::string: other translation units use
/// them while initialising their own globals (`const std::string kHex5 =
/// shipped_config("hex_5x5")`), and a std::string global of another file may
/// not be constructed yet then (the order follows the link order).
extern const char* const kDemcalBinary;
extern const char* const kSourceDir;
/// A shipped scene config, e.g. shipped_config("hex_5x5").
std::string shipped_config(const std::string& name);
/// A shipped example calibration's params.json, e.g.
/// example_params("hex_10x10") (REV 100 disks, 88140 steps) or
/// example_params("fcc_4x4x4") (REV 256 spheres): reports/example-SCENE/.
std::string example_params(const std::string& scene);

/// The first executable `name` on PATH (lmp, liggghts), or "" when there is
/// none: the tests that need another engine skip without it.
std::string find_on_path(const std::string& name);

/// `s` single-quoted for /bin/sh.
std::string shell_quote(const std::string& s);

struct RunResult {
  int status = -1;  ///< exit status; -1 when the program did not exit normally
  std::string out, err;
};

/// Run `program ARGS` in `cwd` to completion, stdout and stderr captured.
/// The capture files live in the temporary directory and are removed
/// afterwards, so `cwd` holds only what the program itself wrote.
RunResult run_program(const std::string& program, const std::vector<std::string>& args,
                      const std::filesystem::path& cwd);
/// run_program for demcal.
RunResult run_demcal(const std::vector<std::string>& args, const std::filesystem::path& cwd);

/// An input deck run by another engine (LAMMPS, LIGGGHTS).
struct DeckRun {
  int status = -1;  ///< the engine's exit status
  std::string log;  ///< its log file
};
/// Write `deck` as `dir`/in.deck and `files` beside it, then run
/// `program OPTIONS -in in.deck -log log.txt` in `dir`.
DeckRun run_deck(const std::string& program, const std::filesystem::path& dir,
                 const std::string& deck, const std::map<std::string, std::string>& files,
                 const std::vector<std::string>& options = {"-screen", "none"});

/// Start `demcal ARGS` in the background, stdout to /dev/null; returns the pid.
pid_t spawn_demcal(const std::vector<std::string>& args);
/// Wait for `pid`; its exit status, -1 when it was killed by a signal.
int wait_exit(pid_t pid);

/// A pid that is certainly not running: a child that has exited and been
/// reaped (for code that must tell a live process from a gone one).
pid_t dead_pid();

}  // namespace demcal::test
