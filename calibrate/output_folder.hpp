// The output folder of a CLI command, written all or nothing. check()
// proves, before any computation, that the folder can be made and written,
// and leaves no trace (bad path: InputError, exit 2). The constructor makes
// the missing folders; write() stages files (OutputTransaction in
// demcal/io/files.hpp); commit() puts them all in place at once, replacing
// the files of an earlier run together. Without commit() the destructor
// removes the staged files and the folders it made: a failure half-way
// leaves the folder as it was, and no empty folder behind.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "demcal/io/files.hpp"

namespace demcal::cli {

class OutputFolder {
 public:
  static void check(const std::string& dir) { OutputFolder probe(dir, true); }

  explicit OutputFolder(const std::string& dir) : OutputFolder(dir, false) {}
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  /// Stage dir/`name` (may hold subfolders: "series/a.csv").
  void write(const std::string& name, const std::string& content);
  /// dir/`name` of an earlier run that this one does not write: removed at
  /// commit, so the folder holds one run.
  void retire(const std::string& name);
  void commit();
  const std::string& path() const { return name_; }

 private:
  OutputFolder(const std::string& dir, bool probe_only);
  [[noreturn]] void fail(const std::string& what);
  void remove_created() noexcept;  // the folders made, deepest first, if empty

  std::string name_;
  std::filesystem::path dir_;
  std::vector<std::filesystem::path> created_;
  std::unique_ptr<OutputTransaction> files_;
  bool committed_ = false;
};

/// Before the work: the file `path` can be written as write_output_file
/// writes it (not a folder; its folder can be made and written; nothing
/// left behind). Else an InputError naming it (exit 2).
void check_output_file(const std::string& path);
/// One output file (-o FILE) written as the commands write their folders:
/// the missing folders made, the file put in place at once (OutputFolder).
void write_output_file(const std::string& path, const std::string& content);

/// An exclusive lock on an existing output folder (flock on the folder
/// itself), held until destruction: two commands writing into one folder
/// (two calibrations interleaving their trials.jsonl) cannot run at once.
/// A folder already locked: InputError naming it (exit 2) and `option`,
/// the flag that names another folder. The kernel drops the lock when the
/// process dies, so a killed run leaves none behind.
class FolderLock {
 public:
  explicit FolderLock(const std::string& dir, const std::string& option = "-o");
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

 private:
  int fd_ = -1;
};

}  // namespace demcal::cli
