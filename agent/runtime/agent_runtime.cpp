#include "marsala/agent/runtime/agent_runtime.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <random>
#include <vector>

#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/log_pacing.hpp"

namespace marsala::agent::runtime {
namespace {

using Clock = std::chrono::steady_clock;

/// CPU time of the calling thread so far [ms]: what a decision costs, apart from the other processes' share of the
/// cores while it ran.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// CPU time of this process so far, every thread's (DDS's too) [ms].
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}
/// A frame further ahead of the last step answered is not the world's: no run goes on for a million steps while an
/// agent waits for its next frame.
constexpr std::uint64_t kMaxStepsAhead = 1000000;

/// Empty when a frame addressed to this agent can be trusted to describe the world of `assignment`: a finite pose on
/// the grid, finite height and material, tiles that fit the grid, a scan only for a scanning sensor with points within
/// its reach, finite neighbours; otherwise the problem. A frame
/// with a problem is ignored whole, before any of it reaches the behaviour (which would throw half-way through).
std::string frame_problem(const protocol::SensorFrame& f, const Assignment& assignment, const SensorSpec& sensor) {
  const auto sane = [](double v) { return std::isfinite(v) && std::abs(v) < kMaxMagnitude; };
  if (!sane(f.x_m) || !sane(f.y_m) || !assignment.world.cell_at({f.x_m, f.y_m}))
    return fmt::format("pose ({}, {}) m is not on the grid", f.x_m, f.y_m);
  if (!sane(f.z_m) || !sane(f.material_m3) || f.material_m3 < 0.0)
    return fmt::format("height {} m or material {} m^3 is not a finite amount", f.z_m, f.material_m3);
  for (const TerrainTile& tile : f.tiles) {
    const std::string problem = executive::tile_problem(tile, assignment.world, assignment.tile_size);
    if (!problem.empty()) return problem;
  }
  if (!f.scanned && !f.points.empty()) return fmt::format("{} scan points in a frame without a scan", f.points.size());
  if (f.scanned && !sensor.casts_rays()) return fmt::format("a scan for a robot whose sensor is '{}'", to_string(sensor.kind));
  const std::string scan = executive::scan_problem(f.points, sensor);
  if (!scan.empty()) return scan;
  for (const Neighbour& n : f.neighbours) {
    if (!sane(n.position.x) || !sane(n.position.y) || !sane(n.z_m))
      return fmt::format("neighbour {} at ({}, {}, {}) m is not finite", n.agent_id, n.position.x, n.position.y, n.z_m);
    if (!(n.radius_m >= 0.0 && n.radius_m <= 1e3))
      return fmt::format("neighbour {} has a body radius of {} m, not in [0, 1000] m", n.agent_id, n.radius_m);
  }
  return {};
}

/// The longest a wait lasts before the stop flag is looked at again.
constexpr std::chrono::milliseconds kStopPoll{100};
// How long the world's frame writer may stay not alive before the agent concludes that the world is gone: longer
// than the pauses a world must survive (5 s, docs/runtime.md#dropping-agents), so an agent learns of a dead world
// within about 7 s (the 1 s DDS lease, then this) instead of world_timeout.
constexpr std::chrono::seconds kWorldGrace{6};
// A gap between two turns of the agent's loop this long means the process itself did not run.
constexpr std::chrono::seconds kProcessPause{1};
// How long without a frame before the agent says hello again: the world answers whether it still counts the agent
// in (a pause longer than the world's grace dropped it; docs/runtime.md#re-admission), so a dropped agent learns it
// within about this long after it runs again, and is re-admitted where the rules allow.
constexpr std::chrono::seconds kRehelloAfter{2};

}  // namespace

std::string to_string(RunOutcome outcome) {
  static constexpr EnumName<RunOutcome> kNames[] = {{RunOutcome::kRunOver, "run_over"},
                                                    {RunOutcome::kStopped, "stopped"},
                                                    {RunOutcome::kRefused, "refused"},
                                                    {RunOutcome::kAdmitTimeout, "admit_timeout"},
                                                    {RunOutcome::kWorldTimeout, "world_timeout"},
                                                    {RunOutcome::kWorldGone, "world_gone"}};
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
  if (config_.hello_period.count() <= 0 || config_.admit_timeout.count() <= 0 || config_.world_timeout.count() <= 0)
    throw InvalidArgument("agent " + std::to_string(config_.agent_id) + ": hello period and timeouts must be positive");
  if (config_.session == 0) config_.session = random_session();
  // Made at once, so that an unknown behaviour fails before any traffic; an agent that asks for any slot (agent_id
  // 0) makes it again once its admission names the slot.
  make_behaviour();
}

void AgentRuntime::make_behaviour() {
  if (config_.name.empty() && config_.agent_id != 0)
    config_.name = (config_.type.name.empty() ? "agent" : config_.type.name) + "-" + std::to_string(config_.agent_id);
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
  behaviour_ = reactive::make_robot_behaviour(context);
}

AgentRuntime::~AgentRuntime() = default;

RunResult AgentRuntime::run(const std::atomic<bool>& stop) {
  RunResult result;
  protocol::Admission admission;
  if (admit(stop, result, admission)) lockstep(stop, admission, result);
  result.final_state = behaviour_->state_name();
  return result;
}

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
  hello.name = config_.agent_id != 0 ? config_.name : config_.name.empty() ? config_.type.name + "-any" : config_.name;
  hello.behaviour = config_.type.behaviour;
  hello.body = config_.type.body;
  spdlog::info("agent {} ({}, {}): saying hello, session {:016x}", config_.agent_id, config_.name,
               config_.type.behaviour, config_.session);

  const Clock::time_point deadline = Clock::now() + config_.admit_timeout;
  Clock::time_point next_hello = Clock::now();
  while (!stop.load()) {
    const Clock::time_point now = Clock::now();
    if (now >= deadline) {
      result.outcome = RunOutcome::kAdmitTimeout;
      result.message = fmt::format("not admitted within {} s (is marsala-world running on this DDS domain?)",
                                   config_.admit_timeout.count() / 1000.0);
      return false;
    }
    if (now >= next_hello) {
      hellos->write(hello);
      next_hello = now + config_.hello_period;
    }
    signal->wait_until(std::min({next_hello, deadline, now + kStopPoll}));
    for (const bus::Received<protocol::Admission>& received : admissions->take_received()) {
      const protocol::Admission& a = received.sample;
      const bool any_slot = config_.agent_id == 0;
      if (a.session != config_.session || (!any_slot && a.agent_id != config_.agent_id)) continue;  // not ours
      if (!a.accepted) {
        result.outcome = RunOutcome::kRefused;
        result.message = "refused by the world: " + a.reason;
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

void AgentRuntime::lockstep(const std::atomic<bool>& stop, const protocol::Admission& admission, RunResult& result) {
  const std::string partition = protocol::partition_for(admission.run_id, config_.agent_id, config_.session);
  auto signal = std::make_shared<bus::Signal>();
  auto frames = participant_.create_reader<protocol::SensorFrame>({partition, signal, bus::Durability::kVolatile, 64});
  auto requests =
      participant_.create_writer<protocol::ActionRequest>({partition, nullptr, bus::Durability::kVolatile, 64});
  bool answered_any = false;
  std::uint64_t last_answered = 0;
  protocol::ActionRequest last_request;  // repeated when the world sends the frame of its step again
  Clock::time_point last_frame_at = Clock::now();
  Clock::time_point next_hello = last_frame_at + kRehelloAfter;
  bool asked = false;  // a hello went out since the last frame
  Clock::time_point deadline = Clock::now() + config_.world_timeout;
  // Signs that the world lives: a frame, an answer to a hello (the world answers while it waits for a slow agent,
  // whose step can last the whole deadline) or its frame writer's DDS liveliness. A frame or an answer spares the
  // DDS status query on the per-step path.
  bool world_seen = false;
  bool sign_since_check = false;
  std::vector<double> decision_cpu_ms;  // CPU time of each decision [ms]
  double cpu_at_first_frame = 0.0;      // process CPU time when the first decision began [ms]
  Clock::time_point last_sign = Clock::now();
  Clock::time_point last_turn = last_sign;
  while (!stop.load()) {
    const Clock::time_point now = Clock::now();
    // A turn of this loop takes at most kStopPoll: a much longer gap means this process was not running (stopped,
    // starved), and what it could not see is no sign that the world is gone; its DDS readers may still hold the
    // world's writer as not alive until the next lease renewal, so the world gets a fresh grace period.
    // It also asks the world at once whether it still counts this agent in: frames queued before the pause may still
    // arrive and look fresh, while the world may have dropped it meanwhile (docs/runtime.md#re-admission).
    const bool was_paused = now - last_turn >= kProcessPause;
    if (was_paused) last_sign = now;
    if (sign_since_check || frames->alive_writers() >= 1) {
      sign_since_check = false;
      world_seen = true;
      last_sign = now;
    } else if (world_seen && now - last_sign >= kWorldGrace) {
      result.outcome = RunOutcome::kWorldGone;
      result.message =
          fmt::format("the world is gone: no frame, no answer and its frame writer not alive for {} s (last step {})",
                      std::chrono::duration<double>(now - last_sign).count(), result.last_step);
      return;
    }
    if (now >= deadline) {
      result.outcome = RunOutcome::kWorldTimeout;
      result.message = fmt::format("no sensor frame for {} s (last step {})", config_.world_timeout.count() / 1000.0,
                                   result.last_step);
      return;
    }
    if (was_paused) {
      spdlog::info("agent {}: this process did not run for {} s; asking the world whether it still counts this agent in",
                   config_.agent_id, std::chrono::duration<double>(now - last_turn).count());
      hellos_->write(hello_);
      asked = true;
      next_hello = now + config_.hello_period;
    }
    last_turn = now;
    if (now - last_frame_at >= kRehelloAfter && now >= next_hello) {
      if (!asked)
        spdlog::info("agent {}: no frame for {} s; asking the world whether it still counts this agent in",
                     config_.agent_id, std::chrono::duration<double>(now - last_frame_at).count());
      hellos_->write(hello_);
      asked = true;
      next_hello = now + config_.hello_period;
    }
    for (const bus::Received<protocol::Admission>& received : admissions_->take_received()) {
      const protocol::Admission& a = received.sample;
      if (a.agent_id != config_.agent_id || a.session != config_.session || !asked) continue;
      // Another participant answering: the world was restarted from its log (docs/runtime.md#resume), and frames now
      // come from it; or a stranger, which only a stop of the world's frames lets in (asked), and only for this run.
      if (received.from != world_) {
        if (!a.accepted || a.run_id != admission.run_id) continue;
        spdlog::info("agent {}: the world of run '{}' answers from participant {} now (was {})", config_.agent_id,
                     a.run_id, received.from.to_string(), world_.to_string());
        world_ = received.from;
      }
      sign_since_check = true;
      if (!a.accepted) {
        result.outcome = RunOutcome::kRefused;
        result.message = "the world no longer counts this agent in: " + a.reason;
        return;
      }
    }
    signal->wait_until(std::min({deadline, now + kStopPoll, asked ? next_hello : now + kStopPoll}));
    for (const bus::Received<protocol::SensorFrame>& received : frames->take_received()) {
      const protocol::SensorFrame& frame = received.sample;
      // Only the world that admitted this agent speaks for the run; what it sends must make sense.
      std::string why;
      if (received.from != world_)
        why = "written by participant " + received.from.to_string() + ", not by the world this agent was admitted "
              "to (" + world_.to_string() + ")";
      else if (frame.agent_id != config_.agent_id)
        why = "addressed to agent " + std::to_string(frame.agent_id);
      else if (answered_any && frame.step > last_answered && frame.step - last_answered > kMaxStepsAhead)
        why = fmt::format("step {} is more than {} steps ahead of the last one answered ({})", frame.step,
                          kMaxStepsAhead, last_answered);
      else
        why = frame_problem(frame, assignment_, config_.type.sensor);
      if (!why.empty()) {
        if (power_of_ten(++result.ignored_frames))
          spdlog::warn("agent {}: ignoring a frame ({} so far): {}", config_.agent_id, result.ignored_frames, why);
        continue;
      }
      ++result.frames;
      sign_since_check = true;
      last_frame_at = Clock::now();
      if (asked) spdlog::info("agent {}: frames again at step {}", config_.agent_id, frame.step);
      asked = false;
      result.last_step = frame.step;
      deadline = Clock::now() + config_.world_timeout;
      if (frame.last_result == protocol::ActionResult::kRejected) {
        ++result.rejected;
        spdlog::warn("agent {}: request before step {} rejected: {}", config_.agent_id, frame.step, frame.last_reason);
      }
      if (frame.run_over) {
        behaviour_->decide(frame);
        result.outcome = RunOutcome::kRunOver;
        result.message = "run over at step " + std::to_string(frame.step);
        result.decision_cpu_median_ms = median(decision_cpu_ms);
        if (result.requests > 0)
          result.cpu_ms_per_step = (process_cpu_ms() - cpu_at_first_frame) / static_cast<double>(result.requests);
        spdlog::info("agent {}: {} ({} requests, {} rejected, {} frames ignored; decision CPU median {:.3f} ms, "
                     "process CPU {:.3f} ms per step)",
                     config_.agent_id, result.message, result.requests, result.rejected, result.ignored_frames,
                     result.decision_cpu_median_ms, result.cpu_ms_per_step);
        return;
      }
      if (answered_any && frame.step == last_answered) {
        // The world did not get (or not yet) the answer: the same request again, never a second decision.
        spdlog::debug("agent {}: the frame of step {} again; repeating its request", config_.agent_id, frame.step);
        requests->write(last_request);
        continue;
      }
      if (answered_any && frame.step < last_answered) {
        spdlog::warn("agent {}: ignoring a stale frame for step {}", config_.agent_id, frame.step);
        continue;
      }
      const std::string before = behaviour_->state_name();
      if (!answered_any) cpu_at_first_frame = process_cpu_ms();
      const double decision_began = thread_cpu_ms();
      last_request = behaviour_->decide(frame);
      decision_cpu_ms.push_back(thread_cpu_ms() - decision_began);
      requests->write(last_request);
      ++result.requests;
      answered_any = true;
      last_answered = frame.step;
      if (behaviour_->state_name() != before)
        spdlog::debug("agent {}: step {}: {} -> {}", config_.agent_id, frame.step, before, behaviour_->state_name());
    }
  }
  result.outcome = RunOutcome::kStopped;
  result.message = "stopped at step " + std::to_string(result.last_step);
}

}  // namespace marsala::agent::runtime
