#include "marsala/agent/runtime/agent_runtime.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include "marsala/agent/runtime/frame_gate.hpp"
#include "marsala/agent/runtime/world_watch.hpp"
#include "marsala/core/cpu_time.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/log_pacing.hpp"
#include "marsala/core/statistics.hpp"
#include "marsala/protocol/admit_deadline.hpp"
#include "marsala/protocol/world_proof.hpp"

namespace marsala::agent::runtime {
namespace {

using Clock = std::chrono::steady_clock;

/// The longest a wait lasts before the stop flag is looked at again.
constexpr std::chrono::milliseconds kStopPoll{100};

/// What the behaviour's decisions cost: each decision's CPU time on this thread (apart from the other processes' share
/// of the cores while it ran), and the process's CPU time, every thread's (DDS's too), from the first decision on.
class DecisionCosts {
 public:
  /// Runs `decide`, records its cost and tells it in the request (decision_us, decision_cpu_us: the step trace).
  template <typename Decide>
  protocol::ActionRequest measure(Decide decide) {
    if (!process_at_first_ms_) process_at_first_ms_ = process_cpu_ms();
    const Clock::time_point wall = Clock::now();
    const double began = thread_cpu_ms();
    protocol::ActionRequest request = decide();
    const double cpu_ms = thread_cpu_ms() - began;
    decision_ms_.push_back(cpu_ms);
    request.decision_us = to_us(std::chrono::duration<double, std::milli>(Clock::now() - wall).count());
    request.decision_cpu_us = to_us(cpu_ms);
    return request;
  }
  /// The median decision [ms]; 0 before the first.
  double median_ms() const { return median(decision_ms_); }
  /// The process's CPU time since the first decision, per step of the run since [ms]; 0 before any.
  double process_ms_per(std::uint64_t steps) const {
    if (steps == 0 || !process_at_first_ms_) return 0.0;
    return (process_cpu_ms() - *process_at_first_ms_) / static_cast<double>(steps);
  }

 private:
  static std::uint32_t to_us(double ms) {
    return static_cast<std::uint32_t>(std::clamp(std::lround(ms * 1000.0), 0L, 4294967295L));
  }

  std::vector<double> decision_ms_;            // [ms]
  std::optional<double> process_at_first_ms_;  // [ms]
};

}  // namespace

std::string to_string(RunOutcome outcome) {
  static constexpr EnumName<RunOutcome> kNames[] = {{RunOutcome::kRunOver, "run_over"},
                                                    {RunOutcome::kStopped, "stopped"},
                                                    {RunOutcome::kRefused, "refused"},
                                                    {RunOutcome::kAdmitTimeout, "admit_timeout"},
                                                    {RunOutcome::kWorldTimeout, "world_timeout"},
                                                    {RunOutcome::kOutputRefused, "output_refused"}};
  return enum_to_string(kNames, outcome);
}

std::uint64_t random_session() {
  std::random_device device;
  std::uint64_t session = 0;
  while (session == 0) session = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  return session;
}

AgentRuntime::AgentRuntime(bus::Participant& participant, RuntimeConfig config)
    : participant_(participant), config_(std::move(config)) {
  if (config_.hello_period.count() <= 0 || config_.admit_timeout.count() <= 0 || config_.world_timeout.count() < 0)
    throw InvalidArgument(
        fmt::format("agent {}: the hello period and admit timeout must be positive, the world timeout not negative",
                    config_.agent_id));
  if (config_.session == 0) config_.session = random_session();
  world_key_ = config_.world_key;
  // Made at once, so that an unknown behaviour fails before any traffic; an agent that asks for any slot (agent_id
  // 0) makes it again once its admission names the slot.
  make_behaviour();
}

void AgentRuntime::make_behaviour() {
  if (config_.name.empty() && config_.agent_id != 0)
    config_.name = fmt::format("{}-{}", config_.type.name.empty() ? "agent" : config_.type.name, config_.agent_id);
  AgentContext context;
  context.agent_id = config_.agent_id;
  context.session = config_.session;
  context.type = config_.type;
  context.neighbour_keep_out_m =
      config_.neighbour_keep_out_m > 0.0
          ? config_.neighbour_keep_out_m
          : neighbour_keep_out_m(config_.type.body.navigability.delta_m, config_.type.body.max_step_m);
  context.seed = config_.seed;
  context.goal_vector_map = config_.goal_vector_map;
  context.right_of_way = config_.right_of_way;
  behaviour_ = reactive::make_robot_behaviour(context);
}

AgentRuntime::~AgentRuntime() = default;

bool AgentRuntime::admit(const std::atomic<bool>& stop, RunResult& result, protocol::Admission& admission) {
  admission_signal_ = std::make_shared<bus::Signal>();
  hellos_ = participant_.create_writer<protocol::AgentHello>({"", nullptr, bus::Durability::kVolatile, 64});
  admissions_ =
      participant_.create_reader<protocol::Admission>({"", admission_signal_, bus::Durability::kVolatile, 64});
  const auto& signal = admission_signal_;
  const auto& hellos = hellos_;
  const auto& admissions = admissions_;
  protocol::AgentHello& hello = hello_;
  hello.agent_id = config_.agent_id;
  hello.session = config_.session;
  hello.name = config_.agent_id != 0  ? config_.name
               : config_.name.empty() ? fmt::format("{}-any", config_.type.name)
                                      : config_.name;
  hello.behaviour = config_.type.behaviour;
  hello.body = config_.type.body;
  spdlog::info("agent {} ({}, {}): saying hello, session {:016x}", config_.agent_id, config_.name,
               config_.type.behaviour, config_.session);

  // The admit timeout counts from the latest agent the world admitted for the first time (protocol::AdmitDeadline).
  const Clock::time_point started = Clock::now();
  protocol::AdmitDeadline wait(started, config_.admit_timeout);
  std::set<std::uint32_t> others_admitted;
  Clock::time_point next_hello = Clock::now();
  while (!stop.load()) {
    const Clock::time_point now = Clock::now();
    if (now >= wait.deadline()) {
      result.outcome = RunOutcome::kAdmitTimeout;
      result.message =
          others_admitted.empty()
              ? fmt::format("not admitted within {} s (is marsala-world running on this DDS domain?)",
                            config_.admit_timeout.count() / 1000.0)
              : fmt::format("not admitted within {} s, while the world admitted {} other agents (the last more than "
                            "{} s ago)",
                            std::chrono::duration<double>(now - started).count(), others_admitted.size(),
                            config_.admit_timeout.count() / 1000.0);
      return false;
    }
    if (now >= next_hello) {
      hellos->write(hello);
      next_hello = now + config_.hello_period;
    }
    signal->wait_until(std::min({next_hello, wait.deadline(), now + kStopPoll}));
    for (const bus::Received<protocol::Admission>& received : admissions->take_received()) {
      const protocol::Admission& a = received.sample;
      const bool any_slot = config_.agent_id == 0;
      if (a.session != config_.session || (!any_slot && a.agent_id != config_.agent_id)) {  // not ours
        if (a.accepted && a.agent_id != config_.agent_id && others_admitted.insert(a.agent_id).second)
          wait.progress(Clock::now());
        continue;
      }
      if (!from_world(a, received.from, result)) continue;
      if (!a.accepted) {
        result.outcome = RunOutcome::kRefused;
        result.message = fmt::format("refused by the world: {}", a.reason);
        return false;
      }
      if (any_slot) {
        if (a.agent_id == 0) throw Error("an admission for any slot names no slot (agent_id 0)");
        config_.agent_id = a.agent_id;
        make_behaviour();
        hello.agent_id = a.agent_id;  // later hellos speak for the slot, under the name the world gave it
        hello.name = config_.name;
        if (config_.on_assigned) config_.on_assigned(a.agent_id);
        spdlog::info("agent: assigned slot {} ({})", a.agent_id, config_.name);
      }
      admission = a;
      world_ = received.from;
      world_key_ = a.world_key;
      assignment_ = a.assignment;
      result.run_id = a.run_id;
      behaviour_->on_admission(a);
      spdlog::info("agent {}: admitted to run '{}' ({} x {} cells of {} m) by the world at participant {}",
                   config_.agent_id, a.run_id, a.assignment.world.rows, a.assignment.world.cols,
                   a.assignment.world.cell_size_m, world_.to_string());
      return true;
    }
  }
  result.outcome = RunOutcome::kStopped;
  result.message = "stopped before admission";
  return false;
}

bool AgentRuntime::from_world(const protocol::Admission& a, const bus::WriterId& from, RunResult& result) const {
  const char* problem = nullptr;
  if (!world_key_.empty() && a.world_key != world_key_)
    problem = "not signed with this run's key";
  else if (!protocol::world_proven(a.world_key, a.world_proof, a.run_id, from.prefix))
    problem = "its proof does not hold for that participant";
  if (problem == nullptr) return true;
  if (power_of_ten(++result.ignored_admissions))
    spdlog::warn("agent {}: ignoring an admission ({}) from participant {} ({} so far): {}", config_.agent_id,
                 a.accepted ? "accepted" : "refused", from.to_string(), result.ignored_admissions, problem);
  return false;
}

/// One admitted run's lockstep (docs/runtime.md#lockstep): the agent's partition, whether the world is still there
/// (the world watch), which frame is taken (the frame gate), and one decision per new step.
class AgentRuntime::Lockstep {
 public:
  Lockstep(AgentRuntime& agent, const protocol::Admission& admission, RunResult& result)
      : agent_(agent),
        admission_(admission),
        result_(result),
        partition_(protocol::partition_for(admission.run_id, agent.config_.agent_id, agent.config_.session)),
        signal_(std::make_shared<bus::Signal>()),
        requests_(agent.participant_.create_writer<protocol::ActionRequest>(
            {partition_, nullptr, bus::Durability::kVolatile, 64})),
        gate_(agent.config_.agent_id, agent.assignment_, agent.config_.type.sensor, agent.world_),
        watch_(Clock::now(), agent.config_.world_timeout, agent.config_.hello_period),
        frames_(agent.participant_.create_reader<protocol::SensorFrame>(
            {partition_, signal_, bus::Durability::kVolatile, 64, [this] { on_frames(); }})) {
    // Frames that came while the reader was being made wait in its queue for run()'s first turn.
    std::lock_guard<std::mutex> lock(mutex_);
    armed_ = true;
  }

  /// Until the run is over, the world is silent for world_timeout or no longer counts this agent in, or `stop`.
  /// Frames are taken where they arrive (on_frames()); this thread keeps the world watch and takes what came before.
  void run(const std::atomic<bool>& stop) {
    Closing closing{*this};  // whichever way this returns, the bus's thread takes no frame afterwards
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop.load() && !over_) {
      // Asked before the lock: a backend calls on_frames() holding its reader's locks, which this query takes.
      lock.unlock();
      const bool writer_alive = frames_->alive_writers() >= 1;
      lock.lock();
      if (over_) break;
      const Clock::time_point now = Clock::now();
      if (!world_still_there(now, writer_alive) || !still_counted_in(now) || take_frames()) return;
      const Clock::time_point wake_by = std::min(watch_.wake_by(), now + kStopPoll);
      lock.unlock();
      signal_->wait_until(wake_by);
      lock.lock();
    }
    if (failure_) std::rethrow_exception(failure_);
    if (over_) return;  // the run-over frame, taken on the bus's thread
    result_.outcome = RunOutcome::kStopped;
    result_.message = fmt::format("stopped at step {}", result_.last_step);
  }

 private:
  std::uint32_t id() const { return agent_.config_.agent_id; }

  /// The world watch's turn: false (and the outcome) at the silence limit; says a silence once, and hello when it asks.
  bool world_still_there(Clock::time_point now, bool writer_alive) {
    const WatchTurn turn = watch_.turn(now, [writer_alive] { return writer_alive; });
    if (turn.state == WorldState::kWorldTimeout) {
      result_.outcome = RunOutcome::kWorldTimeout;
      result_.message = fmt::format("no sensor frame for {} s (last step {}; --world-timeout)",
                                    agent_.config_.world_timeout.count() / 1000.0, result_.last_step);
      return false;
    }
    if (turn.silent_s)
      spdlog::warn(
          "agent {}: the world is silent: no frame, no answer and its frame writer not alive for {} s (last step {}); "
          "keeping this robot's state and asking until {}",
          id(), *turn.silent_s, result_.last_step,
          agent_.config_.world_timeout.count() == 0
              ? std::string("the world answers (--world-timeout 0)")
              : fmt::format("{} s without a frame (--world-timeout)", agent_.config_.world_timeout.count() / 1000.0));
    if (turn.heard_s) spdlog::info("agent {}: the world is heard again after {} s of silence", id(), *turn.heard_s);
    if (turn.paused_s)
      spdlog::info(
          "agent {}: this process did not run for {} s; asking the world whether it still counts this agent in", id(),
          *turn.paused_s);
    if (turn.no_frame_s)
      spdlog::info("agent {}: no frame for {} s; asking the world whether it still counts this agent in", id(),
                   *turn.no_frame_s);
    if (turn.hello) agent_.hellos_->write(agent_.hello_);
    return true;
  }

  /// The world's answers to this agent's hellos: false (and the outcome) when it no longer counts the agent in. Its
  /// admissions and answers to other agents of the run are signs of life (WorldWatch::answered_another()).
  bool still_counted_in(Clock::time_point now) {
    const RuntimeConfig& config = agent_.config_;
    for (const bus::Received<protocol::Admission>& received : agent_.admissions_->take_received()) {
      const protocol::Admission& a = received.sample;
      if (a.agent_id != config.agent_id && a.accepted && a.run_id == admission_.run_id &&
          received.from == gate_.world()) {
        watch_.answered_another(now, admitting_stagger(config.agent_id));
        continue;
      }
      if (a.agent_id != config.agent_id || a.session != config.session || !watch_.asked()) continue;
      // Another participant answering: the world was restarted from its log (docs/runtime.md#resume) and proves the
      // run's key; frames now come from it. A stranger cannot prove it (docs/runtime.md#who-wrote-it).
      if (received.from != gate_.world()) {
        if (!a.accepted || a.run_id != admission_.run_id || !agent_.from_world(a, received.from, result_)) continue;
        spdlog::info("agent {}: the world of run '{}' answers from participant {} now (was {})", id(), a.run_id,
                     received.from.to_string(), gate_.world().to_string());
        gate_.set_world(received.from);
      }
      watch_.answered();
      if (!a.accepted) {
        result_.outcome = RunOutcome::kRefused;
        result_.message = fmt::format("the world no longer counts this agent in: {}", a.reason);
        return false;
      }
    }
    return true;
  }

  /// Frames as they arrive, on the bus's thread (bus::EndpointOptions::on_data): the gate, the decision and the
  /// request are done there, so a step wakes one thread of this process, not the bus's and then the loop's (README
  /// "Idle robots up to 120"). A failure is handed to the loop, which throws it.
  void on_frames() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!armed_ || over_) return;
    try {
      if (!take_frames()) return;
    } catch (...) {
      failure_ = std::current_exception();
    }
    over_ = true;
    signal_->notify();
  }

  /// Every frame received so far through the gate, in order; true when the run is over. Called with mutex_ held.
  bool take_frames() {
    for (const bus::Received<protocol::SensorFrame>& received : frames_->take_received())
      if (take(received)) return true;
    return false;
  }

  /// Ends the bus thread's part when run() returns, whichever way: it takes no frame after that.
  struct Closing {
    Lockstep& lockstep;
    ~Closing() {
      std::lock_guard<std::mutex> lock(lockstep.mutex_);
      lockstep.over_ = true;
    }
  };

  /// One received frame through the gate; true when the run is over.
  bool take(const bus::Received<protocol::SensorFrame>& received) {
    const protocol::SensorFrame& frame = received.sample;
    const FrameJudgement judgement = gate_.judge(frame, received.from);
    if (judgement.call == FrameCall::kIgnored) {
      if (power_of_ten(++result_.ignored_frames))
        spdlog::warn("agent {}: ignoring a frame ({} so far): {}", id(), result_.ignored_frames, judgement.problem);
      return false;
    }
    ++result_.frames;
    if (watch_.frame(Clock::now())) spdlog::info("agent {}: frames again at step {}", id(), frame.step);
    result_.last_step = frame.step;
    if (frame.last_result == protocol::ActionResult::kRejected) {
      ++result_.rejected;
      spdlog::warn("agent {}: request before step {} rejected: {}", id(), frame.step, frame.last_reason);
    }
    switch (judgement.call) {
      case FrameCall::kRunOver: run_over(frame); return true;
      case FrameCall::kRepeat:
        // The world did not get (or not yet) the answer, or went back to a step this agent answered (a resume cut
        // its log's damaged tail): the same request again, never a second decision.
        if (frame.step < result_.last_answered && power_of_ten(++result_.repeated_past))
          spdlog::warn(
              "agent {}: the world went back to step {} (this agent answered up to {}); repeating its "
              "requests from there ({} so far)",
              id(), frame.step, result_.last_answered, result_.repeated_past);
        requests_->write(*gate_.request_for(frame.step));
        return false;
      case FrameCall::kStale:
        spdlog::debug("agent {}: ignoring a late copy of the frame of step {}", id(), frame.step);
        return false;
      default: decide(frame); return false;
    }
  }

  /// A new step: the behaviour's decision, sent.
  void decide(const protocol::SensorFrame& frame) {
    reactive::Behaviour& behaviour = *agent_.behaviour_;
    const std::string before = behaviour.state_name();
    protocol::ActionRequest request = costs_.measure([&] { return behaviour.decide(frame); });
    request.standing = behaviour.answer_stands();
    watch_.standing(request.standing);
    requests_->write(request);
    ++result_.requests;
    if (!first_decided_) first_decided_ = frame.step;
    result_.last_answered = frame.step;
    gate_.answered(frame.step, std::move(request));
    if (behaviour.state_name() != before)
      spdlog::debug("agent {}: step {}: {} -> {}", id(), frame.step, before, behaviour.state_name());
  }

  /// The run-over frame: the behaviour sees it, the run's costs are reported.
  void run_over(const protocol::SensorFrame& frame) {
    agent_.behaviour_->decide(frame);
    result_.outcome = RunOutcome::kRunOver;
    result_.message = fmt::format("run over at step {}", frame.step);
    result_.decision_cpu_median_ms = costs_.median_ms();
    // Per step of the run, not per request: while its answer stands the agent sends none (docs/runtime.md#standing-
    // answers), and its process still runs.
    const std::uint64_t steps = first_decided_ && frame.step > *first_decided_ ? frame.step - *first_decided_ : 0;
    result_.cpu_ms_per_step = costs_.process_ms_per(std::max(steps, result_.requests));
    spdlog::info(
        "agent {}: {} ({} requests, {} rejected, {} frames ignored, {} admissions ignored; decision CPU median "
        "{:.3f} ms, process CPU {:.3f} ms per step)",
        id(), result_.message, result_.requests, result_.rejected, result_.ignored_frames, result_.ignored_admissions,
        result_.decision_cpu_median_ms, result_.cpu_ms_per_step);
  }

  AgentRuntime& agent_;
  const protocol::Admission& admission_;
  RunResult& result_;
  std::string partition_;
  std::shared_ptr<bus::Signal> signal_;
  std::mutex mutex_;  // the lockstep's state below, shared by the loop and the bus's thread (on_frames())
  bool armed_ = false;  // the reader is made: on_frames() may take frames
  bool over_ = false;   // the run is over (or failed, or run() returned): frames are no longer taken
  std::exception_ptr failure_;  // what on_frames() met, thrown by run()
  std::unique_ptr<bus::Writer<protocol::ActionRequest>> requests_;
  FrameGate gate_;
  WorldWatch watch_;
  DecisionCosts costs_;
  std::optional<std::uint64_t> first_decided_;  // the step of the first decision
  // Last: made once everything on_frames() uses exists, and gone (its callbacks over) before any of it goes.
  std::unique_ptr<bus::Reader<protocol::SensorFrame>> frames_;
};

void AgentRuntime::end_admitted(const RunResult& result, bool failed) const {
  if (config_.on_end) config_.on_end(*this, result, failed);
}

RunResult AgentRuntime::run(const std::atomic<bool>& stop) {
  RunResult result;
  protocol::Admission admission;
  if (admit(stop, result, admission)) {
    const std::string refusal = config_.on_admitted ? config_.on_admitted(result.run_id) : std::string();
    if (!refusal.empty()) {
      result.outcome = RunOutcome::kOutputRefused;
      result.message = refusal;
      result.final_state = behaviour_->state_name();
      return result;
    }
    try {
      Lockstep(*this, admission, result).run(stop);
    } catch (...) {
      try {
        end_admitted(result, true);
      } catch (const std::exception& e) {
        spdlog::error("agent {}: at the end of a failed run: {}", config_.agent_id, e.what());
      }
      throw;
    }
    end_admitted(result, false);
  }
  result.final_state = behaviour_->state_name();
  return result;
}

}  // namespace marsala::agent::runtime
