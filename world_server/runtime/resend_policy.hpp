#pragma once
// When the world writes a step's frame to an agent again (docs/runtime.md#resends), pure and with the clock passed in.
// DDS delivers every copy it has accepted (reliable writers repair their own losses), so another copy helps only an
// agent whose reader never got one: a reader that matched after the copy was written (after a resume, a
// re-admission, a partition), or one that acknowledged the copy and lost it (a flooded reader). A copy is therefore
// written again only when none is in flight, at most once per step as a repair, with an interval that backs off; and
// at once to a reader that matched since the last copy. Resending while a copy is in flight is what collapsed a slow
// link: every copy queued behind the last, and the agents were dropped before any arrived.

#include <chrono>
#include <cstdint>

namespace marsala::world_server {

/// The first repair of an unanswered, delivered frame comes this long after the copy was written [ms].
inline constexpr std::chrono::milliseconds kFirstRepairInterval{500};
/// The repair interval doubles after every repair up to this [ms] (below the default 10 s step deadline).
inline constexpr std::chrono::milliseconds kMaxRepairInterval{4000};
/// After this many steps in a row without a repair the interval halves again (down to kFirstRepairInterval) [steps].
inline constexpr std::uint32_t kRepairDecaySteps = 16;

/// What an agent's frame writer says about the copies written so far, at one look.
struct CopyState {
  int readers = 0;           ///< readers matched now [count]
  bool acknowledged = true;  ///< every matched reader acknowledged every copy (nothing left to deliver)
};

/// True when a copy is still on its way: a matched reader has not acknowledged it (DDS is delivering it).
inline bool in_flight(const CopyState& copy) { return copy.readers >= 1 && !copy.acknowledged; }

/// What to do about an unanswered frame at one look.
enum class Resend {
  kNone,        ///< nothing: answered, a copy in flight, no reader, or not due
  kLateReader,  ///< a reader matched since the last copy was written: it has none, write one now
  kRepair,      ///< the copy was delivered, no answer within the interval: write it once more (once per step)
  kAsked,       ///< the agent said hello again since the last copy: it holds no frame it takes, write one now
};

/// The resend rule of one agent link: per step, from the frame's first copy to the step's end.
class ResendPolicy {
 public:
  using Clock = std::chrono::steady_clock;  ///< the looks' clock

  /// The step's first copy was written at `now` to `readers` matched readers.
  void first_copy(Clock::time_point now, int readers);
  /// What to do at `now` about the step's frame, not answered yet, given its writer's `copy` state; a reader that
  /// left since the last copy is forgotten, so one that matches again counts as late.
  Resend look(Clock::time_point now, const CopyState& copy);
  /// The agent said hello again while its frame is unanswered (it asks whether the world still counts it in, having
  /// taken no frame for a while, e.g. one written before it trusted this world): a negative acknowledgement, so the
  /// next look writes one copy unless one is in flight (the agent asks only after 2 s without a frame).
  void asked() { asked_ = true; }
  /// Records that `what` (kLateReader, kRepair or kAsked) was written at `now` to `readers` matched readers.
  void copied(Resend what, Clock::time_point now, int readers);
  /// The current repair interval [ms]: kFirstRepairInterval, doubled after each repair, halved after
  /// kRepairDecaySteps steps without one.
  std::chrono::milliseconds interval() const { return interval_; }
  /// Copies written in this step besides the first [count].
  std::uint32_t resends() const { return resends_; }

 private:
  std::chrono::milliseconds interval_ = kFirstRepairInterval;
  Clock::time_point last_copy_{};  // when the latest copy was written
  int readers_at_last_copy_ = 0;   // fewest readers matched since it was written
  bool repaired_ = false;          // this step's repair was written
  bool asked_ = false;             // the agent asked since the latest copy
  std::uint32_t resends_ = 0;      // copies this step besides the first
  std::uint32_t quiet_steps_ = 0;  // steps in a row without a repair
};

}  // namespace marsala::world_server
