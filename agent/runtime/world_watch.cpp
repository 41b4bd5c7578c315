#include "marsala/agent/runtime/world_watch.hpp"

#include <algorithm>

namespace marsala::agent::runtime {
namespace {

double seconds(WorldWatch::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// The silence limit from `now`: world_timeout later, or never for 0.
WorldWatch::Clock::time_point limit_from(WorldWatch::Clock::time_point now, std::chrono::milliseconds world_timeout) {
  return world_timeout.count() == 0 ? WorldWatch::Clock::time_point::max() : now + world_timeout;
}

}  // namespace

WorldWatch::WorldWatch(Clock::time_point now, std::chrono::milliseconds world_timeout,
                       std::chrono::milliseconds hello_period)
    : world_timeout_(world_timeout),
      hello_period_(hello_period),
      hello_gap_(hello_period),
      deadline_(limit_from(now, world_timeout)),
      last_frame_at_(now),
      next_hello_(now + kRehelloAfter),
      last_sign_(now),
      last_turn_(now) {}

WatchTurn WorldWatch::turn(Clock::time_point now, const std::function<bool()>& writer_alive) {
  WatchTurn turn;
  // A turn takes at most the loop's stop poll: a much longer gap means this process was not running (stopped,
  // starved), and what it could not see is no sign that the world is gone; its DDS readers may still hold the world's
  // writer as not alive until the next lease renewal, so the world gets a fresh grace period. The agent also asks the
  // world at once whether it still counts it in: frames queued before the pause may still arrive and look fresh,
  // while the world may have dropped it meanwhile (docs/runtime.md#re-admission).
  const bool was_paused = now - last_turn_ >= kProcessPause;
  if (was_paused) last_sign_ = now;
  if (sign_since_turn_ || writer_alive()) {
    if (silence_said_) turn.heard_s = seconds(now - last_sign_);
    silence_said_ = false;
    sign_since_turn_ = false;
    world_seen_ = true;
    last_sign_ = now;
    if (standing_) deadline_ = limit_from(now, world_timeout_);  // the frames held back would tell nothing new
  } else if (world_seen_ && !silence_said_ && now - last_sign_ >= kWorldGrace) {
    // Said once; the agent keeps its state and keeps asking (docs/runtime.md#silence).
    turn.silent_s = seconds(now - last_sign_);
    silence_said_ = true;
  }
  if (now >= deadline_) {
    turn.state = WorldState::kWorldTimeout;
    return turn;
  }
  if (was_paused) {
    turn.paused_s = seconds(now - last_turn_);
    turn.hello = true;
    asked_ = true;
    hello_gap_ = hello_period_;
    next_hello_ = now + hello_period_;
  }
  last_turn_ = now;
  if (now - last_frame_at_ >= quiet_limit() && now >= next_hello_) {
    if (!asked_) turn.no_frame_s = seconds(now - last_frame_at_);
    turn.hello = true;
    asked_ = true;
    next_hello_ = now + hello_gap_;
  }
  return turn;
}

bool WorldWatch::frame(Clock::time_point now) {
  sign_since_turn_ = true;
  if (framed_ && !standing_) gaps_[gap_count_++ % kPaceFrames] = now - last_frame_at_;  // a held-back gap sets no pace
  framed_ = true;
  last_frame_at_ = now;
  deadline_ = limit_from(now, world_timeout_);
  const bool was_asking = asked_;
  asked_ = false;
  hello_gap_ = hello_period_;
  next_hello_ = now;  // the next silence asks after quiet_limit()
  return was_asking;
}

void WorldWatch::answered() {
  sign_since_turn_ = true;
  hello_gap_ = std::max<std::chrono::milliseconds>(hello_period_,
                                                  std::min<std::chrono::milliseconds>(hello_gap_ * 2, kStillInRecheck));
}

void WorldWatch::answered_another(Clock::time_point now, Clock::duration stagger) {
  sign_since_turn_ = true;
  if (!framed_) next_hello_ = std::max(next_hello_, now + kRehelloAfter + stagger);
}

WorldWatch::Clock::duration WorldWatch::quiet_limit() const {
  if (standing_) return kStandingRecheck;
  Clock::duration longest{0};
  for (std::size_t i = 0; i < std::min(gap_count_, kPaceFrames); ++i) longest = std::max(longest, gaps_[i]);
  return std::clamp<Clock::duration>(kPaceMultiple * longest, kRehelloAfter, kLongestPace);
}

WorldWatch::Clock::time_point WorldWatch::wake_by() const {
  return asked_ ? std::min(deadline_, next_hello_) : deadline_;
}

}  // namespace marsala::agent::runtime
