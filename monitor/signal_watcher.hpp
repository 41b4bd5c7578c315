#pragma once
// Turns SIGINT and SIGTERM into a StopSource request, without a signal handler: the signals are blocked
// and one thread takes them with sigwait(), so the stop runs as ordinary code (locks, notify) and a
// Ctrl-C ends marsala-monitor cleanly with exit code 0.

#include <atomic>
#include <thread>

#include "marsala/monitor/stop_source.hpp"

namespace marsala::monitor {

/// Owns the thread that waits for SIGINT/SIGTERM. Construct it first in main, before any other thread
/// exists: it blocks both signals in the calling thread, and threads started later (the DDS backends')
/// inherit the mask. They stay blocked for the rest of the process. Throws Error when it cannot.
class SignalWatcher {
 public:
  explicit SignalWatcher(StopSource& stop);
  ~SignalWatcher();
  SignalWatcher(const SignalWatcher&) = delete;
  SignalWatcher& operator=(const SignalWatcher&) = delete;

 private:
  std::atomic<bool> closing_{false};
  std::thread thread_;
};

}  // namespace marsala::monitor
