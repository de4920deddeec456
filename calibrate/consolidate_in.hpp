// Where `demcal export --consolidate-in demcal|deck|auto` consolidates the
// prototype: the rule, in one place (its own file so that the tests link it).
#pragma once

#include <string>

namespace demcal::cli {

/// Checks --consolidate-in (`choice`) against `format` and --no-consolidate
/// (InputError, exit 2) and says whether the LAMMPS deck's stage 1
/// consolidates the prototype of `particles` particles: only when asked
/// (`deck`). `auto` is demcal's kernel at every size, 2D and 3D: on one
/// core the deck's stage 1 took 19x demcal's CPU time at 2 500 random disks
/// and costs ~2.8x demcal's per particle-step at 10 000 (some 5x in all, with
/// its 1.7x the steps; reports/engines.md §27, §28), so it pays only on more
/// MPI ranks than that, which `--consolidate-in deck` asks for.
bool consolidate_in_deck(const std::string& choice, const std::string& format, bool no_consolidate,
                         int particles);

}  // namespace demcal::cli
