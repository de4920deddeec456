// Test support: a reader of the legacy-VTK polydata `demcal run` writes
// (src/scene/run_output.cpp, the same layout in 2D and 3D), for the CLI
// tests of both dimensions.
#pragma once

#include <set>
#include <string>

namespace demcal::test {

/// Checks every count of `text` against the data that follows (points
/// finite, `particles` vertices, contacts as lines between distinct
/// particles, at least one with `contacts`, point and cell data blocks of
/// the right length) as GoogleTest failures; returns the names of the data
/// arrays read.
std::set<std::string> check_vtk_polydata(const std::string& text, long particles,
                                         bool contacts = true);

}  // namespace demcal::test
