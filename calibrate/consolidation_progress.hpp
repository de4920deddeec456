// Consolidation progress on stderr, for every command that consolidates
// (2D and 3D): a consolidation never runs for minutes silently.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/consolidation_progress.hpp"
#include "demcal/scene/triaxial.hpp"

namespace demcal::cli {

/// From this many particles a prototype's consolidation (`export`, `rev`)
/// and 3D `verify`'s loading step on every core: the kernels' two
/// threads break even near 10^4 disks (reports/performance.md, "Threads":
/// 1.78x at 10^4 on an idle machine) and lose below, more so on a loaded
/// machine, where a worker spinning at a barrier is preempted (a 256-sphere
/// prototype ran 10-28x slower on two threads than on one).
constexpr int kThreadsFrom = 10000;

/// ConsolidationOptions::threads for a prototype of `particles` (disks or
/// spheres): 0 (every core) from kThreadsFrom, else 1. The state is the
/// same bit for bit on any count.
int prototype_consolidation_threads(int64_t particles);

/// How a consolidation on `threads` (ConsolidationOptions::threads, 0:
/// every core) runs, for a command's "consolidating ..." line:
/// "single-threaded" or "on N threads".
std::string consolidation_threads_words(int threads);

/// Seconds between progress lines by default: a consolidation that ends
/// sooner prints none.
inline constexpr double kProgressEverySeconds = 2.0;

/// A callback that prints one line on stderr (phase, step, criteria, time
/// so far and the estimate) when at least `every_s` seconds have passed
/// since the start or the last line; 0 prints at every check. One callback
/// may serve consolidations one after another (not at once).
ConsolidationCallback consolidation_progress(double every_s = kProgressEverySeconds);

/// A consolidated state's wall time on `out` with three significant digits,
/// whole seconds from 1000 s on (the stream's format is left as it was), as
/// every command prints it: "0.0249 s", "4012 s"; for a state read from the consolidation
/// cache, whose wall_time_s is the reading's (the consolidation's own is
/// not kept), "read from the cache in 0.0265 s".
void print_consolidation_time(std::ostream& out, double wall_time_s, bool from_cache);

/// What stability, rev, verify and export say on stderr once a
/// consolidation is done: "<prefix>consolidated <what> in N steps, <time>"
/// (print_consolidation_time; `what` may be empty), left open for the
/// caller's ending.
void print_consolidated(std::ostream& out, std::string_view prefix, std::string_view what,
                        int64_t steps, double wall_time_s, bool from_cache);

/// consolidate() (disks) or consolidate_triaxial() (spheres) through the
/// consolidation cache of the environment, the same state, with
/// `announce()` called first only when it consolidates afresh: a command's
/// "consolidating ..." line is never printed before a cache read.
ConsolidatedState consolidate_announced(const SceneConfig& config, const Assembly& assembly,
                                        const ConsolidationOptions& options,
                                        const std::function<void()>& announce);
TriaxialState consolidate_announced(const SceneConfig& config, const SphereAssembly& assembly,
                                    const ConsolidationOptions& options,
                                    const std::function<void()>& announce);

}  // namespace demcal::cli
