// Writing results: every file goes to a temporary name in the same folder
// and is renamed into place, so a reader never sees half a file.
#pragma once

#include <string>
#include <vector>

#include "demcal/io/input_error.hpp"

namespace demcal {

/// Write `content` to `path` atomically (temp file + rename). Throws
/// std::runtime_error naming the path on failure.
void write_file_atomic(const std::string& path, const std::string& content);
/// Append one line and flush it to disk before returning (trials.jsonl).
void append_line_durable(const std::string& path, const std::string& line);
/// Create an output folder (and parents). Throws naming the path.
void make_output_dir(const std::string& dir);
/// Remove temporary files write_file_atomic left in `dir` when a process
/// was killed mid-write (NAME.tmp.PID with PID no longer running).
void remove_stale_temporaries(const std::string& dir);

}  // namespace demcal
