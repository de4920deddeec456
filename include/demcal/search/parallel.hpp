// Independent runs in parallel (trials, scans, reruns): a small pool that
// takes tasks in order. Results stay deterministic because every task writes
// only its own slot; the thread count never changes what is computed.
#pragma once

#include <functional>
#include <vector>

namespace demcal {

/// `jobs` when > 0, else one per hardware thread (at least 1).
int resolve_jobs(int jobs);

/// f(k) for every k in [0, n), at most `jobs` at once, taken in increasing
/// k (all on the calling thread, in order, when jobs ≤ 1). After an
/// exception no new k starts; the first one is rethrown once the running
/// ones end.
void for_each_parallel(int n, int jobs, const std::function<void(int)>& f);

/// Every task, as for_each_parallel.
void run_parallel(const std::vector<std::function<void()>>& tasks, int jobs);

}  // namespace demcal
