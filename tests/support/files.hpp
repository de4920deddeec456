// Test support: scratch folders and whole-file reads and writes, shared by
// the tests and the benchmarks so that each test says only what it checks.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace demcal::test {

namespace fs = std::filesystem;

/// A fresh, empty folder under the system's temporary directory, named after
/// `tag`, the process id and the running test (so parallel ctest processes
/// and tests of one fixture never share one), removed when it goes out of
/// scope. Removal ignores errors: a test that left a read-only file behind
/// must still report its own failure, not a teardown exception.
class TempDir {
 public:
  explicit TempDir(const std::string& tag);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  fs::path operator/(const fs::path& name) const { return path_ / name; }
  std::string str() const { return path_.string(); }

 private:
  fs::path path_;
};

/// The unique scratch path TempDir would use, removed but not created (for
/// a program that must create its own output folder).
fs::path fresh_path(const std::string& tag);

/// The whole file as bytes; "" when it cannot be opened.
std::string read_text(const fs::path& path);
/// Write `content` to `path` (binary, replacing it), creating the parent
/// folders; returns the path as a string, for command lines.
std::string write_text(const fs::path& path, const std::string& content);
/// Write each (name, content) of `files` into `dir` (an exported deck's
/// data and wall files, for instance).
void write_files(const fs::path& dir, const std::map<std::string, std::string>& files);
nlohmann::json read_json(const fs::path& path);
/// The lines of a text, without their newlines.
std::vector<std::string> lines_of(const std::string& text);
/// File names directly in `dir`.
std::set<std::string> names_in(const fs::path& dir);
/// Every file and folder under `dir` (recursively), relative to it: what a
/// command wrote there.
std::set<std::string> paths_under(const fs::path& dir);

}  // namespace demcal::test
