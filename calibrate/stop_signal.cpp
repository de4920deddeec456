#include "stop_signal.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstring>

namespace demcal::cli {

namespace {

// Lock-free atomics are async-signal-safe; nothing else is touched in the
// handler but write(2).
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

struct sigaction g_previous_int, g_previous_term;

void on_signal(int signo) {
  g_signal.store(signo);
  g_stop.store(true);
  static const char message[] =
      "\ndemcal: stopping: finishing the trials' current monitoring interval and keeping every "
      "finished trial; signal again to quit at once\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, message, sizeof message - 1);
}

}  // namespace

StopOnSignal::StopOnSignal() {
  g_stop.store(false);
  g_signal.store(0);
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: the second signal gets the default action (terminate).
  // SA_RESTART: file writes in progress are not cut by EINTR.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
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
