#include "stop_signal.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace demcal::cli {

namespace {

// Lock-free atomics are async-signal-safe; besides them the handler only
// calls sigaction(2) and write(2), both async-signal-safe.
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

struct sigaction g_previous_int, g_previous_term;

void on_signal(int signo) {
  const int saved_errno = errno;
  // The next SIGINT or SIGTERM, whichever, gets the default action (quit).
  struct sigaction dfl;
  std::memset(&dfl, 0, sizeof dfl);
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(SIGINT, &dfl, nullptr);
  sigaction(SIGTERM, &dfl, nullptr);
  int none = 0;
  g_signal.compare_exchange_strong(none, signo);  // the first signal decides the status
  g_stop.store(true);
  static const char message[] =
      "\ndemcal: stopping at the next safe point, keeping every finished trial; signal again to "
      "quit at once\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, message, sizeof message - 1);
  errno = saved_errno;
}

}  // namespace

StopOnSignal::StopOnSignal() {
  g_stop.store(false);
  g_signal.store(0);
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  // Both signals blocked while the handler runs; SA_RESTART: file writes in
  // progress are not cut by EINTR.
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

StopOnSignal::~StopOnSignal() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

const std::atomic<bool>& StopOnSignal::flag() const { return g_stop; }
int StopOnSignal::signal_number() const { return g_signal.load(); }

}  // namespace demcal::cli
