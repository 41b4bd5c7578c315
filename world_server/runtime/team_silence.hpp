#pragma once
// The team-silence rule (docs/runtime.md#silence), pure and with the clock passed in: when no live agent is heard at
// all (not one request writer alive), the one cut off is the world (its host's network, a pause of its own), or the
// whole team at once; the world then holds the step, with no deadline and no liveliness drop, until an agent is heard
// again, so the run goes on as if nothing happened. After `limit` of it the hold ends and the drop rules apply.

#include <chrono>
#include <optional>

namespace marsala::world_server {

/// What one observation of the team means.
enum class SilenceVerdict {
  kHeard,    ///< some live agent is heard, as before
  kStarted,  ///< no live agent heard, for the first time: the hold starts
  kHeld,     ///< still none heard, within the limit: the step stays held
  kEnded,    ///< an agent heard again after a silence (held or given up)
  kGivenUp,  ///< none heard for the limit: the hold ends, the drop rules apply (said once)
  kUnheld,   ///< still none heard after the limit
};

/// The observations of the team's silence during the lockstep.
class TeamSilence {
 public:
  using Clock = std::chrono::steady_clock;  ///< the observations' clock

  /// `limit`: how long a silence is held [ms]; 0: for ever.
  explicit TeamSilence(std::chrono::milliseconds limit) : limit_(limit) {}

  /// Takes one observation at `now`: `heard` = some live agent's request writer is alive (or no agent is live).
  SilenceVerdict observe(bool heard, Clock::time_point now);
  /// True while the step is held: a silence within the limit.
  bool held() const { return since_.has_value() && !given_up_; }
  /// How long the current silence has lasted at `now` [s]; 0 when none.
  double silent_s(Clock::time_point now) const;

 private:
  std::chrono::milliseconds limit_;
  std::optional<Clock::time_point> since_;  // the silence's start
  bool given_up_ = false;                   // the silence outlasted the limit
};

}  // namespace marsala::world_server
