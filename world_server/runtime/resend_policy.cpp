#include "marsala/world_server/runtime/resend_policy.hpp"

#include <algorithm>

namespace marsala::world_server {

void ResendPolicy::first_copy(Clock::time_point now, int readers) {
  // The back-off outlives the step: an agent that keeps answering late is not repaired every step.
  if (repaired_) {
    quiet_steps_ = 0;
  } else if (++quiet_steps_ >= kRepairDecaySteps) {
    interval_ = std::max(kFirstRepairInterval, interval_ / 2);
    quiet_steps_ = 0;
  }
  last_copy_ = now;
  readers_at_last_copy_ = readers;
  repaired_ = false;
  asked_ = false;
  resends_ = 0;
}

Resend ResendPolicy::look(Clock::time_point now, const CopyState& copy) {
  readers_at_last_copy_ = std::min(readers_at_last_copy_, copy.readers);
  // Nobody to write to, or DDS still delivering a copy: another copy would only queue behind it.
  if (copy.readers < 1 || in_flight(copy)) return Resend::kNone;
  if (copy.readers > readers_at_last_copy_) return Resend::kLateReader;
  if (asked_) return Resend::kAsked;
  if (!repaired_ && now - last_copy_ >= interval_) return Resend::kRepair;
  return Resend::kNone;
}

void ResendPolicy::copied(Resend what, Clock::time_point now, int readers) {
  if (what == Resend::kNone) return;
  if (what == Resend::kRepair) {
    repaired_ = true;
    interval_ = std::min(kMaxRepairInterval, interval_ * 2);
  }
  last_copy_ = now;
  readers_at_last_copy_ = readers;
  asked_ = false;
  ++resends_;
}

}  // namespace marsala::world_server
