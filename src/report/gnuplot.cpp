// Running gnuplot without a shell, in a private temporary folder.
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "demcal/report/report.hpp"

namespace demcal {

namespace fs = std::filesystem;

std::string find_program(const std::string& name) {
  if (name.empty()) return "";
  auto executable = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
  };
  if (name.find('/') != std::string::npos) return executable(name) ? name : "";
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
  std::stringstream s(dirs);
  std::string dir;
  while (std::getline(s, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/" + name;
    if (executable(candidate)) return candidate;
  }
  return "";
}

std::map<std::string, std::string> run_gnuplot(const std::string& program,
                                               const std::string& script,
                                               const std::map<std::string, std::string>& files,
                                               const std::vector<std::string>& outputs,
                                               std::string* error) {
  std::map<std::string, std::string> out;
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return out;
  };
  const std::string exe = find_program(program);
  if (exe.empty()) return fail(program + " not found");
  std::string tmpl = (fs::temp_directory_path() / "demcal-report-XXXXXX").string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data())) return fail("cannot create a temporary folder");
  const fs::path dir(buf.data());
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{dir};
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream f(dir / name, std::ios::binary);
    f << content;
    return static_cast<bool>(f);
  };
  for (const auto& [name, content] : files) {
    if (name.find('/') != std::string::npos || !write(name, content))
      return fail("cannot write " + name);
  }
  if (!write("plots.gp", script)) return fail("cannot write the gnuplot script");

  // Everything the child needs is prepared before fork(): it only calls
  // async-signal-safe functions.
  const std::string dir_s = dir.string(), log_s = (dir / "gnuplot.log").string();
  std::vector<std::string> env_s{"HOME=" + dir_s, "LC_ALL=C.UTF-8", "LANG=C.UTF-8"};
  if (const char* path = std::getenv("PATH")) env_s.push_back(std::string("PATH=") + path);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string arg0 = "gnuplot", arg1 = "plots.gp";
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  const pid_t pid = ::fork();
  if (pid < 0) return fail("cannot start gnuplot (fork failed)");
  if (pid == 0) {
    if (::chdir(dir_s.c_str()) != 0) _exit(126);
    const int null_fd = ::open("/dev/null", O_RDONLY);
    const int log_fd = ::open(log_s.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (null_fd >= 0) ::dup2(null_fd, 0);
    if (log_fd >= 0) {
      ::dup2(log_fd, 1);
      ::dup2(log_fd, 2);
    }
    ::execve(exe.c_str(), argv, envp.data());
    _exit(127);
  }
  int status = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0) return fail("lost track of gnuplot");
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(30)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return fail("gnuplot did not finish in 30 s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (const auto& name : outputs) {
    std::ifstream f(dir / name, std::ios::binary);
    if (!f) continue;
    std::ostringstream s;
    s << f.rdbuf();
    if (s.str().find("</svg>") == std::string::npos) continue;  // cut short by an error
    out[name] = s.str();
  }
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) && error) {
    std::ifstream f(log_s);
    std::ostringstream s;
    s << f.rdbuf();
    std::string log;
    for (char c : s.str()) {
      const bool space = c == '\n' || c == '\r' || c == '\t' || c == ' ';
      if (space && (log.empty() || log.back() == ' ')) continue;
      log += space ? ' ' : c;
    }
    if (log.size() > 600) log = log.substr(0, 600) + "...";
    *error = "gnuplot failed: " + log;
  }
  return out;
}

}  // namespace demcal
