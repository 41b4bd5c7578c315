#include "marsala/world_server/runtime/liveliness.hpp"

namespace marsala::world_server {

LivelinessVerdict LivelinessWatch::observe(bool alive, Clock::time_point now) {
  if (alive) {
    const bool back = not_alive_since_.has_value();
    seen_ = true;
    not_alive_since_.reset();
    return back ? LivelinessVerdict::kBack : LivelinessVerdict::kSteady;
  }
  if (!seen_) return LivelinessVerdict::kSteady;
  if (!not_alive_since_) {
    not_alive_since_ = now;
    return LivelinessVerdict::kLost;
  }
  return now - *not_alive_since_ >= kLivelinessGrace ? LivelinessVerdict::kDrop : LivelinessVerdict::kSteady;
}

}  // namespace marsala::world_server
