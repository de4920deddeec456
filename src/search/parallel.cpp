#include "demcal/search/parallel.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>

namespace demcal {

int resolve_jobs(int jobs) {
  if (jobs > 0) return jobs;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void for_each_parallel(int n, int jobs, const std::function<void(int)>& f) {
  if (jobs <= 1 || n <= 1) {
    for (int k = 0; k < n; ++k) f(k);
    return;
  }
  std::mutex m;
  int next = 0;
  std::exception_ptr error;
  auto worker = [&] {
    for (;;) {
      int k;
      {
        std::lock_guard<std::mutex> lock(m);
        if (next >= n || error) return;
        k = next++;
      }
      try {
        f(k);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < std::min(jobs, n); ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

void run_parallel(const std::vector<std::function<void()>>& tasks, int jobs) {
  for_each_parallel(static_cast<int>(tasks.size()), jobs, [&](int k) { tasks[k](); });
}

}  // namespace demcal
