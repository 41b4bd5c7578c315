#pragma once
// A stop request (Ctrl-C) for a running tail or status, and the wake-up their readers share.

#include <atomic>
#include <memory>

#include "marsala/bus/bus.hpp"

namespace marsala::monitor {

/// Asks a running tail or status to stop, and wakes its wait at once. One waiter at a time.
class StopSource {
 public:
  /// Requests the stop; callable from any thread (from a signal, go through SignalWatcher).
  void request_stop() {
    requested_.store(true);
    signal_->notify();
  }
  /// True once request_stop() was called.
  bool stop_requested() const { return requested_.load(); }
  /// The wake-up the monitor's readers notify on data; request_stop() notifies it too.
  const std::shared_ptr<bus::Signal>& signal() const { return signal_; }

 private:
  std::atomic<bool> requested_{false};
  std::shared_ptr<bus::Signal> signal_ = std::make_shared<bus::Signal>();
};

}  // namespace marsala::monitor
