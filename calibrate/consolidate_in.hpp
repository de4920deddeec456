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
/// and, at 10 000, had done under 5 % of demcal's steps in 90 % of demcal's
/// whole CPU time (reports/engines.md §27), so it pays only on many more MPI ranks than
/// demcal's threads, which `--consolidate-in deck` asks for.
bool consolidate_in_deck(const std::string& choice, const std::string& format, bool no_consolidate,
                         int particles);

}  // namespace demcal::cli
