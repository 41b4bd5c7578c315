#pragma once
// The world watch: whether the world this agent was admitted to is still there, during the lockstep
// (docs/runtime.md#dropping-agents, #re-admission). Pure: the loop passes the clock in and does the talking.
//
//   sign of life      a frame taken, an answer to a hello, or the world's frame writer alive (DDS liveliness)
//   world silent      the world was seen once, then no sign for kWorldGrace: said once (silent_s); the agent keeps
//                     its state and keeps asking: a paused, cut-off or resumed world finds it again
//   silence limit     no frame taken for world_timeout (0: none)                       -> kWorldTimeout
//   process paused    a turn kProcessPause after the last one: the process itself did not run; the world gets a
//                     fresh grace period and is asked at once whether it still counts this agent in (a hello)
//   no frame          no frame for the run's pace (kRehelloAfter, or kPaceMultiple times the longest of the last
//                     kPaceFrames gaps between frames when longer): a hello every hello_period until a frame comes;
//                     each answer that the world still counts the agent in doubles the gap, up to kStillInRecheck.
//                     The world answers every hello to every agent: 120 agents of a team stepping at 2 s asked after
//                     every step and at 5 Hz while the world admitted (60,000 deliveries a second) and kept it slow.
//   standing          the last request sent stands (docs/runtime.md#standing-answers): the world writes no frame
//                     until one tells something new, so while it stands the silence limit counts from the latest sign
//                     of life and the agent asks whether it is still counted in only kStandingRecheck after its last
//                     frame (a world that dropped it meanwhile says so; one that counts it in writes the next frame)
//   admitting         before the first frame, an admission or answer the world gives another agent of the run is a
//                     sign of life and puts the agent's own question off (kRehelloAfter and the agent's stagger after
//                     it): while the world admits the rest of the team, the team asks about once per quiet spell of
//                     the world's, not each agent every kStillInRecheck (240 agents: 30 questions a second, each
//                     answer delivered to all 240).

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>

namespace marsala::agent::runtime {

/// How long without any sign of the world (its frame writer not alive, no frame, no answer) before the agent says once
/// that the world is silent [s]. Silence never ends the run on the agent's side: only the world's word (run over,
/// refused) or world_timeout does (docs/runtime.md#silence).
inline constexpr std::chrono::seconds kWorldGrace{6};
/// A gap this long between two turns of the agent's loop means the process itself did not run [s].
inline constexpr std::chrono::seconds kProcessPause{1};
/// How long without a frame before the agent says hello again [s]: the world answers whether it still counts the agent
/// in (a pause longer than the world's grace dropped it; docs/runtime.md#re-admission).
inline constexpr std::chrono::seconds kRehelloAfter{2};
/// The longest gap between two hellos of a silence that the world answers [s]: an agent it counts in asks again this
/// often at the least, so one it dropped meanwhile learns it this late at the most (a pause asks at once).
inline constexpr std::chrono::seconds kStillInRecheck{8};
/// While the agent's answer stands, how long after its last frame it asks whether the world still counts it in [s].
inline constexpr std::chrono::seconds kStandingRecheck{30};
/// A world whose steps came this many times as far apart as now is not yet silent [count].
inline constexpr int kPaceMultiple = 3;
/// How many of the latest gaps between frames set the run's pace [count].
inline constexpr std::size_t kPaceFrames = 8;
/// The longest the pace waits before asking [s].
inline constexpr std::chrono::seconds kLongestPace{30};
/// Agents waiting for their first frame put their question off by kRehelloAfter after the world's latest admission or
/// answer to another agent, plus (agent id mod kAdmittingStaggers) x kAdmittingStagger, so that the first to ask after
/// a quiet spell of the world's are few: about one in kAdmittingStaggers.
inline constexpr std::chrono::milliseconds kAdmittingStagger{250};
inline constexpr int kAdmittingStaggers = 16;

/// The stagger of agent `agent_id` (see kAdmittingStagger).
inline std::chrono::milliseconds admitting_stagger(std::uint32_t agent_id) {
  return kAdmittingStagger * static_cast<int>(agent_id % kAdmittingStaggers);
}

/// What the watch concluded on one turn.
enum class WorldState { kWatching, kWorldTimeout };

/// What one turn of the loop must do, and why.
struct WatchTurn {
  WorldState state = WorldState::kWatching;
  std::optional<double> silent_s;    ///< set once per silence, when no sign of the world came for kWorldGrace [s]
  std::optional<double> heard_s;     ///< set when a sign of the world ends a silence said before, that long [s]
  bool hello = false;                ///< say hello now: ask the world whether it still counts this agent in
  std::optional<double> paused_s;    ///< set when the process did not run for this long before this turn [s]
  std::optional<double> no_frame_s;  ///< set when this turn's hello is the first of a silence this long [s]
};

/// Watches the world's signs of life during the lockstep; see the header.
class WorldWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// Starts watching at `now`: the silence limit is world_timeout from now (0: no limit), hellos go every hello_period
  /// once frames stop for kRehelloAfter.
  WorldWatch(Clock::time_point now, std::chrono::milliseconds world_timeout, std::chrono::milliseconds hello_period);

  /// One turn of the loop at `now`. `writer_alive` (the world's frame writer's DDS liveliness) is asked only when no
  /// frame or answer came since the last turn: it spares the status query on the per-step path.
  WatchTurn turn(Clock::time_point now, const std::function<bool()>& writer_alive);
  /// True when a hello went out since the last frame: only then may an answer speak for the world.
  bool asked() const { return asked_; }
  /// The world answered a hello: a sign of life; the next hellos of this silence go twice as far apart.
  void answered();
  /// The world admitted or answered another agent of the run at `now`: a sign of life; before the first frame the
  /// next hello waits until kRehelloAfter + `stagger` after it (the world is admitting the rest of the team).
  void answered_another(Clock::time_point now, Clock::duration stagger);
  /// A frame was taken at `now`: a sign of life, the silence limit starts again. True when a hello had gone out since
  /// the last frame (frames are back).
  bool frame(Clock::time_point now);
  /// Whether the request just sent stands: while it does, the world holds its frames back (see the header).
  void standing(bool stands) { standing_ = stands; }
  /// The latest time the loop may wait until before its next turn: the silence limit, or the next hello while asking.
  Clock::time_point wake_by() const;
  /// How long without a frame before asking: kRehelloAfter, or kPaceMultiple times the longest recent gap between
  /// frames when longer, kLongestPace at the most; kStandingRecheck while the last answer stands.
  Clock::duration quiet_limit() const;

 private:
  std::chrono::milliseconds world_timeout_;
  std::chrono::milliseconds hello_period_;
  std::chrono::milliseconds hello_gap_;  // between two hellos of this silence: hello_period_, doubled per answer
  Clock::time_point deadline_;       // no frame by then: kWorldTimeout (max(): never)
  Clock::time_point last_frame_at_;  // the last frame taken
  Clock::time_point next_hello_;     // no hello before then
  Clock::time_point last_sign_;      // the last sign of life (or the end of a pause of this process)
  Clock::time_point last_turn_;      // the previous turn
  bool asked_ = false;               // a hello went out since the last frame
  bool framed_ = false;              // a frame was taken once
  std::array<Clock::duration, kPaceFrames> gaps_{};  // the latest gaps between two frames, a ring
  std::size_t gap_count_ = 0;                       // gaps seen so far (the ring's next slot: modulo kPaceFrames)
  bool world_seen_ = false;          // some sign of life came once
  bool sign_since_turn_ = false;     // a frame or an answer came since the last turn
  bool silence_said_ = false;        // the current silence was said (silent_s)
  bool standing_ = false;            // the last request sent stands
};

}  // namespace marsala::agent::runtime
