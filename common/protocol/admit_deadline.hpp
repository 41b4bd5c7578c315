#pragma once
// How long either side of the admission waits (docs/runtime.md#start-of-the-run, #admission): the admit timeout,
// counted again from each sign that admission progresses (the world: an agent admitted; an agent: another agent seen
// admitted for the first time), kAdmitProgressCap timeouts from the start at the most. A crowd admitted one by one is
// still coming: Fast DDS admitted 82 of 120 agents in the first 60 s on two cores under load.
//
//   AdmitDeadline wait(Clock::now(), timeout);
//   if (admitted_one) wait.progress(Clock::now());
//   if (Clock::now() >= wait.deadline()) ...

#include <algorithm>
#include <chrono>

namespace marsala::protocol {

/// The admit timeout restarts at each sign of progress, up to this many times its length from the start [count].
inline constexpr int kAdmitProgressCap = 5;

/// When to stop waiting for admission.
class AdmitDeadline {
 public:
  using Clock = std::chrono::steady_clock;

  AdmitDeadline(Clock::time_point start, Clock::duration timeout)
      : timeout_(timeout), latest_(start + kAdmitProgressCap * timeout), deadline_(start + timeout) {}

  /// Admission progressed at `now`: the deadline is a timeout from now, kAdmitProgressCap timeouts from the start at
  /// the most, never earlier than it was.
  void progress(Clock::time_point now) { deadline_ = std::min(latest_, std::max(deadline_, now + timeout_)); }
  Clock::time_point deadline() const { return deadline_; }

 private:
  Clock::duration timeout_;
  Clock::time_point latest_;
  Clock::time_point deadline_;
};

}  // namespace marsala::protocol
