#include "demcal/io/files.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace demcal {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTempPrefix = ".demcal-tmp-";

/// What a non-regular file is, for the message.
std::string kind_of(const fs::file_status& s) {
  switch (s.type()) {
    case fs::file_type::directory:
      return "a folder";
    case fs::file_type::character:
    case fs::file_type::block:
      return "a device node";
    case fs::file_type::fifo:
      return "a fifo";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

/// `path`: the system's reason for errno (ENOSPC: "No space left on device").
[[noreturn]] void fail_errno(const std::string& path, const std::string& doing) {
  throw std::runtime_error(path + ": " + doing + " failed: " + std::strerror(errno));
}

/// Create `tmp` (it must not exist), write all of `content`, fsync, close.
/// On failure the partial temporary is removed and the error names `shown`.
void write_new_file(const std::string& tmp, const std::string& content, const std::string& shown) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) fail_errno(shown, "creating the temporary " + tmp);
  const char* p = content.data();
  size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int saved = errno ? errno : EIO;
      ::close(fd);
      ::unlink(tmp.c_str());
      errno = saved;
      fail_errno(shown, "write");
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  // Delayed allocation can report a full disk only here: check both.
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    fail_errno(shown, "write");
  }
}

/// The PID of a name .demcal-tmp-PID-…, or -1.
pid_t temporary_owner(const std::string& name) {
  const size_t prefix = std::strlen(kTempPrefix);
  if (name.compare(0, prefix, kTempPrefix) != 0) return -1;
  const size_t dash = name.find('-', prefix);
  if (dash == std::string::npos || dash == prefix || dash - prefix > 9) return -1;
  const std::string digits = name.substr(prefix, dash - prefix);
  if (digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return static_cast<pid_t>(std::stol(digits));
}

bool process_alive(pid_t pid) {
  // Not ours to signal (EPERM) still means alive.
  return pid == ::getpid() || ::kill(pid, 0) == 0 || errno == EPERM;
}

}  // namespace

std::string temporary_name(const std::string& name, pid_t pid) {
  // NAME_MAX is 255 bytes: a long name is cut (O_EXCL still refuses a clash).
  return kTempPrefix + std::to_string(pid) + "-" + name.substr(0, 200);
}

std::string temporary_name(const std::string& name) { return temporary_name(name, ::getpid()); }

void require_regular_file_target(const std::string& path) {
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);
  if (s.type() == fs::file_type::not_found || s.type() == fs::file_type::regular) return;
  if (ec && s.type() == fs::file_type::none)
    throw InputError(path, "", "cannot be written (" + ec.message() + ")");
  throw InputError(path, "", "exists and is " + kind_of(s) + "; demcal writes only regular files");
}

void require_readable_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);
  if (s.type() == fs::file_type::not_found) throw InputError(path, "", "no such file");
  if (ec) throw InputError(path, "", "cannot open (" + ec.message() + ")");  // ELOOP, EACCES
  if (s.type() != fs::file_type::regular)
    throw InputError(path, "", "is " + kind_of(s) + ", not a file");
}

std::string read_text_file(const std::string& path) {
  require_readable_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open (") + std::strerror(errno) + ")");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw InputError(path, "", "cannot read file");
  return s.str();
}

void drop_utf8_bom(std::string& text) {
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
}

void write_file_atomic(const std::string& path, const std::string& content) {
  require_regular_file_target(path);
  const fs::path target(path);
  const fs::path tmp = target.parent_path() / temporary_name(target.filename().string());
  write_new_file(tmp.string(), content, path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    fail_errno(path, "renaming the temporary into place");
  }
}

void append_line_durable(const std::string& path, const std::string& line) {
  require_regular_file_target(path);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) fail_errno(path, "opening for appending");
  const std::string data = line + "\n";
  const ssize_t written = ::write(fd, data.data(), data.size());
  const bool ok = written == static_cast<ssize_t>(data.size()) && ::fsync(fd) == 0;
  const int saved = errno;
  ::close(fd);
  errno = saved ? saved : EIO;
  if (!ok) fail_errno(path, "append");
}

void make_output_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  // The folder is the user's -o: failing to make it is bad input (exit 2).
  if (ec || !fs::is_directory(dir, ec))
    throw InputError(
        dir, "", "cannot create output folder" + (ec ? " (" + ec.message() + ")" : std::string()));
}

void remove_stale_temporaries(const std::string& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const pid_t pid = temporary_owner(entry.path().filename().string());
    if (pid <= 0 || process_alive(pid)) continue;
    std::error_code rm;
    fs::remove_all(entry.path(), rm);  // a file, or a dead transaction's staging folder
  }
}

// ---- OutputTransaction -----------------------------------------------------

OutputTransaction::OutputTransaction(std::string dir) : dir_(std::move(dir)) {
  static std::atomic<int> counter{0};
  stage_ = (fs::path(dir_) / temporary_name("stage" + std::to_string(++counter))).string();
  if (::mkdir(stage_.c_str(), 0755) != 0) {
    if (errno == EACCES || errno == EROFS || errno == ENOTDIR || errno == ENOENT)
      throw InputError(
          dir_, "",
          std::string("cannot write files in this folder (") + std::strerror(errno) + ")");
    fail_errno(dir_, "creating a staging folder");
  }
}

OutputTransaction::~OutputTransaction() {
  if (!done_) discard();
}

void OutputTransaction::discard() noexcept {
  std::error_code ec;
  fs::remove_all(stage_, ec);
  done_ = true;
}

std::string OutputTransaction::target(const std::string& name) const {
  const fs::path rel = fs::path(name).lexically_normal();
  if (name.empty() || rel.is_absolute() || rel.empty() || *rel.begin() == "..")
    throw std::logic_error("OutputTransaction: not a name inside the folder: " + name);
  return (fs::path(dir_) / rel).string();
}

void OutputTransaction::add(const std::string& name, const std::string& content) {
  if (done_) throw std::logic_error("OutputTransaction::add after commit");
  const std::string final_path = target(name);
  require_regular_file_target(final_path);
  const fs::path staged = fs::path(stage_) / fs::path(name).lexically_normal();
  std::error_code ec;
  fs::create_directories(staged.parent_path(), ec);
  if (ec) throw std::runtime_error(final_path + ": cannot stage (" + ec.message() + ")");
  write_new_file(staged.string(), content, final_path);
  names_.push_back(fs::path(name).lexically_normal().string());
}

void OutputTransaction::retire(const std::string& name) {
  retired_.push_back(fs::path(target(name)).lexically_relative(dir_).string());
}

void OutputTransaction::commit() {
  if (done_) throw std::logic_error("OutputTransaction::commit twice");
  const fs::path dir(dir_), stage(stage_), old = fs::path(stage_) / ".old";
  std::error_code ec;
  fs::create_directory(old, ec);
  // Journal of what was done, to undo it in reverse if a step fails.
  struct Move {
    fs::path from, to;
  };
  std::vector<Move> done;
  std::vector<fs::path> made;  // subfolders created in dir
  auto undo = [&]() {
    for (auto it = done.rbegin(); it != done.rend(); ++it)
      std::rename(it->to.c_str(), it->from.c_str());
    for (auto it = made.rbegin(); it != made.rend(); ++it) fs::remove(*it, ec);
  };
  auto move = [&](const fs::path& from, const fs::path& to) {
    fs::create_directories(to.parent_path(), ec);
    if (std::rename(from.c_str(), to.c_str()) != 0) {
      const int saved = errno;
      undo();
      discard();
      errno = saved;
      fail_errno(to.string(), "replacing the earlier output");
    }
    done.push_back({from, to});
  };
  std::vector<std::string> aside = names_;
  aside.insert(aside.end(), retired_.begin(), retired_.end());
  // 1. The files being replaced or retired go into the staging folder.
  for (const auto& name : aside) {
    if (fs::symlink_status(dir / name, ec).type() == fs::file_type::not_found) continue;
    move(dir / name, old / name);
  }
  // 2. The new files go into place (subfolders made as needed).
  for (const auto& name : names_) {
    for (fs::path p = fs::path(name).parent_path(); !p.empty(); p = p.parent_path())
      if (!fs::exists(dir / p, ec)) made.insert(made.begin(), dir / p);
    move(stage / name, dir / name);
  }
  // 3. Only now the old files go (with the staging folder).
  discard();
}

}  // namespace demcal
