#include "output_folder.hpp"

#include <unistd.h>

#include <fstream>

#include "demcal/scene/config.hpp"
#include "demcal/io/files.hpp"
#include "demcal/scene/run_output.hpp"

namespace demcal::cli {

namespace fs = std::filesystem;

OutputFolder::~OutputFolder() {
  if (!committed_) discard();
}

void OutputFolder::discard() {
  std::error_code ec;
  for (auto it = written_.rbegin(); it != written_.rend(); ++it) fs::remove(*it, ec);
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
  written_.clear();
  created_.clear();
}

void OutputFolder::write(const std::string& name, const std::string& content) {
  const std::string path = (dir_ / name).string();
  write_file_atomic(path, content);  // on failure it leaves nothing behind itself
  written_.push_back(path);
}

OutputFolder::OutputFolder(const std::string& dir, bool probe_only) : name_(dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();  // "out/" → "out"
  dir_ = p;
  std::vector<fs::path> missing;  // deepest first
  std::error_code ec;
  fs::path q = p;
  while (!q.empty() && !fs::exists(q, ec)) {
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
  // A folder that exists may still refuse files (permissions, read-only).
  const fs::path probe = p / (".demcal-probe-" + std::to_string(::getpid()));
  {
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot write files in this folder");
    written_.push_back(probe);
  }
  fs::remove(probe, ec);
  written_.pop_back();
  if (probe_only) {
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
    created_.clear();
    committed_ = true;
  }
}

void OutputFolder::fail(const std::string& what) {
  discard();
  committed_ = true;
  throw InputError(name_, "", "output folder unusable: " + what);
}

}  // namespace demcal::cli
