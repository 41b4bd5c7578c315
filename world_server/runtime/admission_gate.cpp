#include "marsala/world_server/runtime/admission_gate.hpp"

#include <algorithm>
#include <utility>

#include "marsala/core/log_pacing.hpp"

namespace marsala::world_server {

bool AdmissionGate::persistent(SenderKey sender, Clock::time_point now) {
  if (now - seen_rotated_ >= kHelloMemory) {
    seen_previous_ = std::move(seen_current_);
    seen_current_.clear();
    seen_rotated_ = now;
  }
  Clock::time_point first = now;
  if (const auto it = seen_previous_.find(sender); it != seen_previous_.end()) first = it->second;
  const auto [it, fresh] = seen_current_.try_emplace(sender, first);
  if (!fresh) first = std::min(first, it->second);
  return now - first >= kHelloConfirmation;
}

TakeoverWait AdmissionGate::takeover(SenderKey sender, bool held, Clock::time_point now) {
  if (!held) return TakeoverWait::kNone;
  if (!persistent(sender, now)) return TakeoverWait::kWaiting;  // a sender that said hello once (a flood): no notice
  if (takeover_since_.size() >= kMaxRefusalKeys) takeover_since_.clear();
  const auto [it, first] = takeover_since_.try_emplace(sender, now);
  if (now - it->second >= kTakeoverWait) return TakeoverWait::kNone;
  return first ? TakeoverWait::kStarted : TakeoverWait::kWaiting;
}

bool AdmissionGate::may_answer(SenderKey sender, Clock::time_point now) {
  const auto it = answered_at_.find(sender);
  if (it != answered_at_.end() && now - it->second < kAnswerInterval) return false;
  if (answered_at_.size() >= kMaxAnswerKeys) answered_at_.clear();
  answered_at_[sender] = now;
  return true;
}

bool AdmissionGate::report_refusal(SenderKey sender) {
  ++refusals_;
  return refused_.size() < kMaxRefusalKeys ? refused_.insert(sender).second : power_of_ten(refusals_);
}

std::size_t AdmissionGate::remembered() const {
  return seen_current_.size() + seen_previous_.size() + takeover_since_.size() + answered_at_.size() + refused_.size();
}

}  // namespace marsala::world_server
