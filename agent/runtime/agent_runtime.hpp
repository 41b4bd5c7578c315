#pragma once
// The agent's edge (ARCHITECTURE.md): the bus participant, admission, and one ActionRequest per SensorFrame.
//
//   hello every hello_period on the default partition  ──▶  world
//   admission (this id and session)                    ◀──  world      (refused: kRefused; none: kAdmitTimeout)
//   frames on partition_for(run, id, session)          ◀──  world      (none for world_timeout -> kWorldTimeout; a
//                                                                       silent world is waited for, never given up)
//   one request per frame, same step                   ──▶  world      (run_over frame -> kRunOver; the frame of
//                                                                       the step already answered: the same request)
//   no frame for 2 s: hello again                      ──▶  world      (refused, e.g. dropped for good: kRefused;
//                                                                       accepted: still in, or re-admitted)
//
// Threads: admission and the world watch run on the caller's thread; a frame is taken, decided and answered on the
// bus's thread that received it (bus::EndpointOptions::on_data), under the lockstep's lock, so that a step wakes one
// thread of the process, not two; what the behaviour throws there is thrown by run(). Frames that came before the
// lockstep was ready are taken by the caller's thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/bus/bus.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::runtime {

class AgentRuntime;
struct RunResult;

/// Who the agent is and how patient it is.
struct RuntimeConfig {
  std::uint32_t agent_id = 0;                        ///< the scenario slot; 0: any free slot of `type` (--id auto)
  std::string name;                                  ///< human-readable, e.g. "husky-3"
  RobotType type;                                    ///< its slot's robot type; the hello declares its body
  std::uint64_t session = 0;                         ///< 0: a random one (random_session())
  double neighbour_keep_out_m = 0.0;                 ///< 0: delta/2 + max_step of this body [m]
  std::uint64_t seed = 1;                            ///< scenario seed
  std::optional<GoalVectorMapSpec> goal_vector_map;  ///< the scenario's, for the "goal_vector_map" synthesizer
  bool right_of_way = true;                          ///< the scenario's: keep the right-of-way protocol
  std::chrono::milliseconds hello_period{200};       ///< between hellos until admitted
  std::chrono::milliseconds admit_timeout{60000};    ///< give up when not admitted by then, counted from the latest
                                                     ///< agent the world admitted (protocol::AdmitDeadline)
  std::chrono::milliseconds world_timeout{600000};   ///< give up when no frame comes for this long; 0: never
  /// The run's public key (protocol::world_key_of() of --run-key): only a world that proves it is believed. Empty:
  /// the key of the first world that proves itself is pinned (docs/runtime.md#who-wrote-it).
  std::string world_key;
  std::function<void(std::uint32_t)> on_assigned;    ///< called with the slot an --id auto agent was given (logging)
  /// Called once admitted, with the run's id: a non-empty answer refuses the run on the agent's side (kOutputRefused,
  /// the answer as message; e.g. a --dump-map folder holding another run's maps).
  std::function<std::string(const std::string& run_id)> on_admitted;
  /// Called once when an admitted run ends, whatever ended it (`failed`: an error is about to be thrown), with the
  /// agent (its config and behaviour as they stand) and the result so far (e.g. --dump-map writes the robot's map).
  std::function<void(const AgentRuntime&, const RunResult&, bool failed)> on_end;
};

/// Why run() returned.
enum class RunOutcome { kRunOver, kStopped, kRefused, kAdmitTimeout, kWorldTimeout, kOutputRefused };
/// "run_over", "stopped", "refused", "admit_timeout", "world_timeout", "output_refused".
std::string to_string(RunOutcome outcome);

/// What happened in a run.
struct RunResult {
  RunOutcome outcome = RunOutcome::kStopped;
  std::string message;               ///< one line for the operator
  std::string run_id;                ///< from the admission
  std::uint64_t frames = 0;          ///< frames received [count]
  std::uint64_t requests = 0;        ///< requests sent [count]
  std::uint64_t rejected = 0;        ///< frames reporting the previous request rejected [count]
  std::uint64_t last_step = 0;       ///< step of the last frame
  std::uint64_t last_answered = 0;   ///< step of the last new decision sent
  std::uint64_t repeated_past = 0;   ///< requests repeated for steps before last_answered (the world went back) [count]
  std::uint64_t ignored_frames = 0;  ///< frames not from the world it was admitted to, or inconsistent [count]
  std::uint64_t ignored_admissions = 0;  ///< admissions of this agent not proven by the run's world [count]
  std::string final_state;           ///< the behaviour's state at the end
  double decision_cpu_median_ms = 0.0;  ///< median CPU time of the behaviour's decision of one step [ms]
  double cpu_ms_per_step = 0.0;  ///< the process's CPU time (all threads, DDS's too) from its first decision to the
                                 ///< run-over frame, per step of the run since (or per decision when more) [ms]
};

/// A non-zero random session id (std::random_device): tells a restarted agent process apart.
std::uint64_t random_session();

/// One agent process: admission, then the lockstep loop.
class AgentRuntime {
 public:
  /// Makes the behaviour at once, so an unknown name fails before any traffic (InvalidArgument listing the valid
  /// names). Throws InvalidArgument when the hello period or admit timeout is not positive or the world timeout is
  /// negative.
  AgentRuntime(bus::Participant& participant, RuntimeConfig config);
  ~AgentRuntime();

  /// Runs until the run is over, the world refuses, a timeout passes, or `stop` becomes true (checked at least
  /// every 100 ms). Throws when the behaviour meets a broken contract (a malformed frame or admission) or the
  /// bus fails.
  RunResult run(const std::atomic<bool>& stop);

  const RuntimeConfig& config() const { return config_; }
  /// The robot's behaviour (made anew when an --id auto agent is given its slot).
  const reactive::Behaviour& behaviour() const { return *behaviour_; }

 private:
  bool admit(const std::atomic<bool>& stop, RunResult& result, protocol::Admission& admission);
  /// True when admission `a`, written by participant `from`, comes from the run's world: signed for `from` with the
  /// run's key (config world_key, or the key pinned at admission); otherwise counted and logged (1st, 10th, ...).
  bool from_world(const protocol::Admission& a, const bus::WriterId& from, RunResult& result) const;
  void end_admitted(const RunResult& result, bool failed) const;
  void make_behaviour();
  class Lockstep;  // the loop after admission, in agent_runtime.cpp

  bus::Participant& participant_;
  RuntimeConfig config_;
  protocol::AgentHello hello_;
  std::shared_ptr<bus::Signal> admission_signal_;
  std::unique_ptr<bus::Writer<protocol::AgentHello>> hellos_;
  std::unique_ptr<bus::Reader<protocol::Admission>> admissions_;
  bus::WriterId
      world_;  ///< the participant whose admission let this agent in (the lockstep's frame gate takes frames from it)
  std::string world_key_;  ///< the run's public key: configured, or pinned from the admission that let it in
  Assignment assignment_;
  std::unique_ptr<reactive::Behaviour> behaviour_;
};

}  // namespace marsala::agent::runtime
