// SIGINT/SIGTERM as a clean stop: while a StopOnSignal lives, the first
// signal only sets a flag (the calibration polls it and winds down, keeping
// every finished trial); both handlers are then reset, so a second signal
// of either kind ends the process at once.
#pragma once

#include <atomic>

namespace demcal::cli {

class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();  ///< restores the previous handlers
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

  const std::atomic<bool>& flag() const;
  bool stopped() const { return flag().load(); }
  /// The signal that asked to stop (0: none), and the conventional exit
  /// status for it, 128 + signal (130 for SIGINT, 143 for SIGTERM).
  int signal_number() const;
  int exit_status() const { return 128 + signal_number(); }
};

}  // namespace demcal::cli
