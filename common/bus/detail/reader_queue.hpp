#pragma once
// The part of a reader every backend shares: samples delivered on the vendor's listener thread (the writer's thread
// in process) are queued here until take(); the endpoint's on_data handler is called on that thread when samples come
// (else its Signal is notified), and its Signal on writer liveliness or match changes.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "marsala/bus/bus.hpp"

namespace marsala::bus::detail {

/// Keeps a volatile reader volatile on transient-local writers (topics.hpp): passes only samples whose source
/// timestamp [ns since the epoch, the writer's wall clock] is not before the reader's creation. Transient-local
/// readers pass everything. Across hosts, a writer whose clock lags by d loses what it writes within d of the
/// reader's creation: keep clocks synchronised. A sample without a source timestamp (<= 0) passes: its age is
/// unknown, and a genuine sample arrives so when Fast DDS reassembles it from fragments whose first arrived without a
/// timestamp (Cyclone puts one only in the first datagram of a fragmented sample; the rest of a sample lost in part is
/// repaired without one), docs/runtime.md#foreign-types.
class VolatileFilter {
 public:
  explicit VolatileFilter(Durability durability)
      : volatile_(durability == Durability::kVolatile),
        created_ns_(
            std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
                .count()) {}
  /// Whether a sample with this source timestamp [ns since the epoch] is delivered.
  bool passes(std::int64_t source_timestamp_ns) const {
    return !volatile_ || source_timestamp_ns <= 0 || source_timestamp_ns >= created_ns_;
  }

 private:
  bool volatile_;
  std::int64_t created_ns_;
};

/// Thread-safe FIFO of received samples plus the reader's wake-up.
template <typename T>
class ReaderQueue {
 public:
  explicit ReaderQueue(std::shared_ptr<Signal> signal, std::function<void()> on_data = {})
      : signal_(std::move(signal)), on_data_(std::move(on_data)) {}

  /// Appends samples in arrival order, then calls the on_data handler, or else wakes the waiter (nothing to append =
  /// neither). The queue is not locked while the handler runs: it may take().
  void push(std::vector<Received<T>>&& samples) {
    if (samples.empty()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.empty()) {
        queue_ = std::move(samples);
      } else {
        for (Received<T>& s : samples) queue_.push_back(std::move(s));
      }
    }
    if (on_data_)
      on_data_();
    else
      notify();
  }
  /// Everything queued since the last take.
  std::vector<Received<T>> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Received<T>> out;
    out.swap(queue_);
    return out;
  }
  /// Wakes the waiter (a writer came, went or changed liveliness).
  void notify() const {
    if (signal_) signal_->notify();
  }

 private:
  std::shared_ptr<Signal> signal_;
  std::function<void()> on_data_;
  std::mutex mutex_;
  std::vector<Received<T>> queue_;
};

}  // namespace marsala::bus::detail
