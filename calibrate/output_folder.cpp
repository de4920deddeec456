#include "output_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "demcal/io/input_error.hpp"

namespace demcal::cli {

namespace fs = std::filesystem;

OutputFolder::~OutputFolder() {
  if (committed_) return;
  files_.reset();  // removes the staged files
  remove_created();
}

void OutputFolder::remove_created() noexcept {
  std::error_code ec;
  // fs::remove leaves a folder that is not empty (someone else wrote there).
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
  created_.clear();
}

void OutputFolder::write(const std::string& name, const std::string& content) {
  files_->add(name, content);
}

void OutputFolder::retire(const std::string& name) { files_->retire(name); }

void OutputFolder::commit() {
  files_->commit();
  committed_ = true;
}

OutputFolder::OutputFolder(const std::string& dir, bool probe_only) : name_(dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();  // "out/" → "out"
  dir_ = p;
  std::vector<fs::path> missing;  // deepest first
  std::error_code ec;
  fs::path q = p;
  while (!q.empty() && fs::symlink_status(q, ec).type() == fs::file_type::not_found) {
    missing.push_back(q);
    q = q.parent_path();
  }
  if (!q.empty() && !fs::is_directory(q, ec))
    fail(q == p ? "exists and is not a folder" : q.string() + " is not a folder");
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!fs::create_directory(*it, ec))
      fail("cannot create folder " + it->string() + (ec ? " (" + ec.message() + ")" : ""));
    created_.push_back(*it);
  }
  // A folder that exists may still refuse files (permissions, read-only):
  // making the staging folder proves it can be written.
  // What a killed earlier command left here (its staging folder): only
  // .demcal-tmp-PID-… of processes that are gone.
  if (!probe_only) remove_stale_temporaries(dir_.string());
  try {
    files_ = std::make_unique<OutputTransaction>(dir_.string());
  } catch (const InputError&) {
    fail("cannot write files in this folder");
  } catch (const std::exception& e) {
    fail(e.what());
  }
  if (probe_only) {
    files_.reset();
    remove_created();
    committed_ = true;
  }
}

void OutputFolder::fail(const std::string& what) {
  files_.reset();
  remove_created();
  committed_ = true;
  throw InputError(name_, "", "output folder unusable: " + what);
}

namespace {

fs::path folder_of(const fs::path& file) {
  return file.has_parent_path() ? file.parent_path() : fs::path(".");
}

}  // namespace

void check_output_file(const std::string& path) {
  std::error_code ec;
  const fs::path file(path);
  if (!file.has_filename() || fs::is_directory(file, ec))
    throw InputError(path, "", "is a folder; give a file name");
  OutputFolder::check(folder_of(file).string());
}

void write_output_file(const std::string& path, const std::string& content) {
  const fs::path file(path);
  if (!file.has_filename()) throw InputError(path, "", "is a folder; give a file name");
  OutputFolder out(folder_of(file).string());
  out.write(file.filename().string(), content);
  out.commit();
}

FolderLock::FolderLock(const std::string& dir, const std::string& option) {
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    throw InputError(dir, "",
                     std::string("cannot open the output folder (") + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int saved = errno;
    ::close(fd_);
    fd_ = -1;
    if (saved == EWOULDBLOCK)
      throw InputError(dir, "",
                       "another demcal command is writing into this folder; wait for it to end "
                       "or give another " +
                           option);
    throw InputError(dir, "",
                     std::string("cannot lock the output folder (") + std::strerror(saved) + ")");
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing drops the lock
}

}  // namespace demcal::cli
