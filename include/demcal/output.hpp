// Writing results: every file goes to a temporary name in the same folder
// and is renamed into place, so a reader never sees half a file.
#pragma once

#include <string>
#include <vector>

#include "demcal/biaxial.hpp"
#include "demcal/world.hpp"

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

/// series.csv: step,strain_yy,b_xx,b_xy,b_yx,b_yy,s_xx,s_xy,s_yx,s_yy,
/// kinetic_energy,unbalanced_force_ratio,lateral_stress_error, then extras.
std::string series_csv(const std::vector<MonitorPoint>& series);
/// Legacy VTK polydata that ParaView opens: particles as vertices (radius,
/// velocity, rotation, angular velocity) and the contact force network as
/// lines (normal and tangential force).
std::string world_vtk(const World& world, const std::string& title);

}  // namespace demcal
