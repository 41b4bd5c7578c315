#include "marsala/world_server/runtime/team_silence.hpp"

namespace marsala::world_server {

SilenceVerdict TeamSilence::observe(bool heard, Clock::time_point now) {
  if (heard) {
    const bool ended = since_.has_value();
    since_.reset();
    given_up_ = false;
    return ended ? SilenceVerdict::kEnded : SilenceVerdict::kHeard;
  }
  if (!since_) {
    since_ = now;
    return SilenceVerdict::kStarted;
  }
  if (given_up_) return SilenceVerdict::kUnheld;
  if (limit_.count() > 0 && now - *since_ >= limit_) {
    given_up_ = true;
    return SilenceVerdict::kGivenUp;
  }
  return SilenceVerdict::kHeld;
}

double TeamSilence::silent_s(Clock::time_point now) const {
  return since_ ? std::chrono::duration<double>(now - *since_).count() : 0.0;
}

}  // namespace marsala::world_server
