// An output folder written all or nothing (the CLI's commands that write
// several files). check() proves, before any computation, that the folder
// can be made and written, and leaves no trace (bad path: InputError, exit
// 2). The constructor makes the missing folders; write() adds files
// atomically; unless commit() is called, the destructor removes the files
// written and the folders made, so a failure half-way leaves no partial
// output.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace demcal::cli {

class OutputFolder {
 public:
  static void check(const std::string& dir) { OutputFolder probe(dir, true); }

  explicit OutputFolder(const std::string& dir) : OutputFolder(dir, false) {}
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  void write(const std::string& name, const std::string& content);
  void commit() { committed_ = true; }

 private:
  OutputFolder(const std::string& dir, bool probe_only);
  [[noreturn]] void fail(const std::string& what);
  void discard();  // remove the files written, then the folders made

  std::string name_;
  std::filesystem::path dir_;
  std::vector<std::filesystem::path> created_, written_;
  bool committed_ = false;
};

}  // namespace demcal::cli
