#include "support/process.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <sstream>

#include "support/files.hpp"

namespace demcal::test {

const char* const kDemcalBinary = DEMCAL_BINARY;
const char* const kSourceDir = DEMCAL_SOURCE_DIR;

std::string shipped_config(const std::string& name) {
  return std::string(kSourceDir) + "/configs/" + name + ".json";
}

std::string example_params(const std::string& scene) {
  return std::string(kSourceDir) + "/reports/example-" + scene + "/params.json";
}

std::string find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream s(path ? path : "");
  for (std::string dir; std::getline(s, dir, ':');) {
    const fs::path p = fs::path(dir) / name;
    if (fs::exists(p) && ::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

namespace {

/// A new empty file in the temporary directory, for one capture.
fs::path capture_file() {
  std::string pattern = (fs::temp_directory_path() / "demcal_test_capture_XXXXXX").string();
  const int fd = ::mkstemp(pattern.data());
  if (fd >= 0) ::close(fd);
  return pattern;
}

}  // namespace

RunResult run_program(const std::string& program, const std::vector<std::string>& args,
                      const fs::path& cwd) {
  const fs::path out = capture_file(), err = capture_file();
  // Appended piece by piece: `" >" + std::string` chains made GCC 12 warn
  // (-Wrestrict, a false positive inside std::string's insert).
  std::string cmd = "cd ";
  cmd.append(shell_quote(cwd.string())).append(" && ").append(shell_quote(program));
  for (const auto& a : args) cmd.append(" ").append(shell_quote(a));
  cmd.append(" >").append(shell_quote(out.string()));
  cmd.append(" 2>").append(shell_quote(err.string()));
  cmd.append(" </dev/null");
  const int raw = std::system(cmd.c_str());
  RunResult r;
  r.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  std::error_code ec;
  fs::remove(out, ec);
  fs::remove(err, ec);
  return r;
}

RunResult run_demcal(const std::vector<std::string>& args, const fs::path& cwd) {
  return run_program(kDemcalBinary, args, cwd);
}

DeckRun run_deck(const std::string& program, const fs::path& dir, const std::string& deck,
                 const std::map<std::string, std::string>& files,
                 const std::vector<std::string>& options) {
  write_text(dir / "in.deck", deck);
  write_files(dir, files);
  std::vector<std::string> args = options;
  for (const char* a : {"-in", "in.deck", "-log", "log.txt"}) args.emplace_back(a);
  DeckRun run;
  run.status = run_program(program, args, dir).status;
  run.log = read_text(dir / "log.txt");
  return run;
}

pid_t spawn_demcal(const std::vector<std::string>& args) {
  // argv is built before the fork: the child of a threaded process may
  // call only async-signal-safe functions (no allocation) until exec.
  std::vector<std::string> all{kDemcalBinary};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, STDOUT_FILENO);
    ::execv(kDemcalBinary, argv.data());
    ::_exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  wait_exit(pid);
  return pid;
}

}  // namespace demcal::test
