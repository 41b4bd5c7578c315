#pragma once
// The liveliness grace rule (docs/runtime.md#dropping-agents), pure and with the clock passed in: an agent is dropped
// only when its request writer, once seen alive, has not been alive again for kLivelinessGrace. A process paused for
// up to 5 s (SIGSTOP, a swapped or overloaded machine), world or agent, comes back and loses nothing; a dead agent
// costs its team this long once.

#include <chrono>
#include <optional>

namespace marsala::world_server {

/// How long a live agent's request writer may stay not alive before the agent is dropped.
inline constexpr std::chrono::seconds kLivelinessGrace{6};

/// What one observation of an agent's request writer means.
enum class LivelinessVerdict {
  kSteady,  ///< nothing new: alive as before, never seen alive yet, or not alive for less than the grace
  kBack,    ///< alive again after it was found not alive
  kLost,    ///< found not alive for the first time after it was seen alive: the grace starts
  kDrop,    ///< not alive for kLivelinessGrace: drop the agent
};

/// The observations of one agent session's request writer.
class LivelinessWatch {
 public:
  using Clock = std::chrono::steady_clock;  ///< the observations' clock

  /// Takes one observation at `now`: `alive` = the request writer is alive.
  LivelinessVerdict observe(bool alive, Clock::time_point now);
  /// Forgets a running grace (the agent was just admitted again); whether it was ever seen alive is kept.
  void forgive() { not_alive_since_.reset(); }
  /// True once the writer has been seen alive.
  bool seen() const { return seen_; }

 private:
  bool seen_ = false;
  std::optional<Clock::time_point> not_alive_since_;
};

}  // namespace marsala::world_server
