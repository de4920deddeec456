// Writing results. Three rules hold for every file demcal writes:
//  - only regular files: a target that exists as anything else (a device
//    node, a folder, a fifo, a socket) is refused with an InputError
//    (exit 2), never replaced;
//  - a reader never sees half a file: content goes to a temporary in the
//    same folder, named .demcal-tmp-PID-NAME so that it cannot collide with
//    a user's file, and is renamed into place;
//  - the outputs of one command change together or not at all
//    (OutputTransaction).
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"

namespace demcal {

/// The temporary that process `pid` writes for `name`: ".demcal-tmp-PID-NAME".
/// Only names of this form are ever removed as stale (see
/// remove_stale_temporaries).
std::string temporary_name(const std::string& name, pid_t pid);
/// The same for this process.
std::string temporary_name(const std::string& name);

/// Refuse a path that exists and is not a regular file (following
/// symlinks): InputError naming the path and what it is, exit 2.
void require_regular_file_target(const std::string& path);

/// Refuse an input path that cannot be read as a regular file: missing, a
/// folder, a device node or fifo (/dev/zero would never end), a symlink
/// loop. One InputError naming the path and the reason, exit 2.
void require_readable_file(const std::string& path);
/// The whole of a regular file (require_readable_file first).
std::string read_text_file(const std::string& path);
/// Drop the UTF-8 byte order mark an editor may put at the start of a text
/// file (`text`: the file, or its first line); the readers of text files
/// (particle files, `demcal score`'s series) take the file without it.
void drop_utf8_bom(std::string& text);

/// Write `content` to `path` atomically (temporary + fsync + rename). A
/// non-regular target is an InputError; a failed write throws
/// std::runtime_error naming the path and the system's reason ("No space
/// left on device") and leaves neither the temporary nor a changed target.
void write_file_atomic(const std::string& path, const std::string& content);
/// Append one line and flush it to disk before returning (trials.jsonl).
void append_line_durable(const std::string& path, const std::string& line);
/// Create an output folder (and parents). Throws naming the path.
void make_output_dir(const std::string& dir);
/// Remove the temporaries (files and staging folders) that killed processes
/// left in `dir`: only names .demcal-tmp-PID-… whose PID is not running.
void remove_stale_temporaries(const std::string& dir);

/// All the files of one command's output, replaced together or not at all.
/// add() writes each file into a staging folder inside `dir`
/// (.demcal-tmp-PID-stageK: same file system, so the renames cannot fail
/// for space); commit() moves the files they replace aside, renames the new
/// ones into place and only then deletes the old ones, undoing every rename
/// if one fails. Without commit() (an exception, a failed computation) the
/// destructor removes the staging folder: the folder is as it was.
class OutputTransaction {
 public:
  /// `dir` must exist (see make_output_dir).
  explicit OutputTransaction(std::string dir);
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();

  /// Stage `content` for dir/`name` (`name` may hold subfolders,
  /// "series/a.csv"; never "..").
  void add(const std::string& name, const std::string& content);
  /// dir/`name`, if it exists, is removed by commit(): a file of an earlier
  /// run that this one does not write (so the folder holds one run).
  void retire(const std::string& name);
  /// Put every staged file in place at once (see the class comment).
  void commit();

  const std::string& dir() const { return dir_; }

 private:
  std::string target(const std::string& name) const;
  void discard() noexcept;

  std::string dir_, stage_;
  std::vector<std::string> names_, retired_;
  bool done_ = false;
};

}  // namespace demcal
