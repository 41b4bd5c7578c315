#pragma once
// The request collector: one step's wait for the live agents' requests (docs/runtime.md#lockstep). It reads every
// partition, selects with RequestSelection (the owner's answer always, others up to kMaxRequestsPerPartition, the
// rest surplus), looks every kResendLook at the agents that have not answered (their frame written again when the
// resend rule says so, resend_policy.hpp; the deadline stopped while a frame is still being delivered), and returns
// when every live agent has answered, the step deadline passes or the run is stopped.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "marsala/world_server/rules/world_state.hpp"
#include "marsala/world_server/runtime/agent_links.hpp"
#include "marsala/world_server/runtime/request_selection.hpp"
#include "marsala/world_server/runtime/step_trace.hpp"

namespace marsala::world_server {

/// How often the agents that have not answered are looked at: resends (resend_policy.hpp; an agent that receives a
/// frame twice repeats its request, which is ignored) and frames still in flight.
inline constexpr std::chrono::milliseconds kResendLook{100};
/// At most this much of one step's wait is not counted against its deadline because a frame was still in flight
/// (a slow link delivering it) [ms]; beyond it the deadline runs as usual.
inline constexpr std::chrono::milliseconds kMaxDeliveryStretch{120000};
/// Between liveliness checks while a step waits. The world wakes once per arriving request; checking every agent's
/// writer at each wake-up cost N^2 status queries per step (14,400 at 120 agents: 18 ms of the world's CPU per step
/// with Fast DDS), against a grace of seconds.
inline constexpr std::chrono::milliseconds kLivelinessPoll{50};
/// Longest single wait, so that a stop request is seen promptly even when no sample arrives.
inline constexpr std::chrono::milliseconds kPollInterval{100};
/// A gap this long between two wake-ups of a step's wait means the world's process did not run (SIGSTOP, a starved
/// machine): the gap does not count against the step deadline, so a paused world charges no agent a miss.
inline constexpr std::chrono::seconds kWorldPause{1};

/// What the runtime does while a step waits; the state it changes (admissions, drops) is the one being collected for.
struct CollectDuties {
  std::function<void()> on_wake;                  ///< at every wake-up: hellos (taken at their own pace)
  std::function<void()> check_liveliness;         ///< every kLivelinessPoll
  std::function<void(std::uint32_t)> send_frame;  ///< an agent without a frame of this step gets its first
  /// True while the step is held (no live agent heard: docs/runtime.md#silence): the deadline does not run meanwhile.
  std::function<bool()> held;
};

/// What one step collected.
struct Collected {
  std::vector<Submission> submissions;           ///< in the order read, partition by partition
  std::uint32_t surplus = 0;                     ///< requests beyond a partition's limit, never applied
  std::chrono::steady_clock::duration waited{};  ///< time spent waiting for requests
  /// Each agent whose answer was taken, when it was read and its reported decision time (the step trace).
  std::vector<AgentAnswer> answered_at;
  /// Where in `submissions` each answer read this step lies. Standing answers are not among them: a question during the
  /// step ends an agent's standing answer (StandingAnswers::end()), and taking its held answer again would undo that.
  std::vector<std::size_t> answers;
};

/// Collects the requests of each step from the agents' links.
class RequestCollector {
 public:
  using Clock = std::chrono::steady_clock;  ///< the wall clock of the step deadline

  /// Reads from `links`; waits on `signal`, which their request readers notify.
  RequestCollector(AgentLinks& links, std::shared_ptr<bus::Signal> signal)
      : links_(links), signal_(std::move(signal)) {}

  /// The requests of state.step's live agents until all answered, `deadline_s` passes, or `stop`; the time the
  /// world's process did not run (kWorldPause), the time the step is held and the time a frame of an agent that has
  /// not answered is in flight (up to kMaxDeliveryStretch) are not counted. Requests of a dropped
  /// agent's partition are read and discarded. `standing` holds the answers that stand for this step
  /// (standing_answers.hpp): their agents count as answered from the start.
  Collected collect(const WorldState& state, double deadline_s, const std::atomic<bool>& stop,
                    const CollectDuties& duties, std::vector<Submission> standing = {});

 private:
  /// Reads every partition once into `into`.
  void read_partitions(const WorldState& state, RequestSelection& selection, Collected& into);
  /// Looks at the live agents that have not answered at `now`: resends, first frames; true when a frame of one of
  /// them is in flight.
  bool look(const WorldState& state, const RequestSelection& selection, const CollectDuties& duties,
            Clock::time_point now);

  AgentLinks& links_;
  std::shared_ptr<bus::Signal> signal_;
  Clock::time_point next_liveliness_check_{};  ///< liveliness is checked from then on (kept across steps)
};

}  // namespace marsala::world_server
