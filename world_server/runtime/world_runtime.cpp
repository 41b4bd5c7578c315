#include "marsala/world_server/runtime/world_runtime.hpp"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "marsala/core/cpu_time.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/log_pacing.hpp"
#include "marsala/core/statistics.hpp"
#include "marsala/protocol/admit_deadline.hpp"
#include "marsala/protocol/world_proof.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/records/run_outputs.hpp"
#include "marsala/world_server/records/run_recorder.hpp"
#include "marsala/world_server/rules/admission.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/sensing_service.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "marsala/world_server/runtime/admission_gate.hpp"
#include "marsala/world_server/runtime/agent_links.hpp"
#include "marsala/world_server/runtime/metrics_server.hpp"
#include "marsala/world_server/runtime/request_collector.hpp"
#include "marsala/world_server/runtime/standing_answers.hpp"
#include "marsala/world_server/runtime/step_trace.hpp"
#include "marsala/world_server/runtime/team_silence.hpp"

namespace marsala::world_server {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// Between readiness checks once every agent is admitted (matching is not signalled to the world's writers).
constexpr auto kReadyPollInterval = 5ms;
// Progress lines at info level every this many steps.
constexpr std::uint64_t kProgressEvery = 500;
// Hellos do not wake the world (a flood of them must not stall the lockstep): they are taken at most this often and
// whenever the world wakes anyway (docs/runtime.md#load-limits).
constexpr auto kHelloInterval = 20ms;
// How often the world says it is admitting before its run starts.
constexpr auto kAdmittingStatusInterval = 500ms;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

double elapsed_s(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

double milliseconds(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

/// The status of `state`'s run for WorldStatus: progress and every admitted agent.
protocol::WorldStatus world_status(const WorldState& state, bool running, bool completed, double wall_seconds) {
  protocol::WorldStatus s;
  s.step = state.step;
  s.wall_seconds = wall_seconds;
  s.deposited_volume_m3 = state.deposited_volume_m3;
  s.progress = progress(state);
  s.progress_detail = progress_detail(state);
  s.running = running;
  s.completed = completed;
  s.team_size = static_cast<std::uint32_t>(state.agents.size());
  for (const AgentRecord& a : state.agents) {
    if (!a.admitted) continue;
    protocol::AgentStatus as;
    as.agent_id = a.id;
    as.name = a.name;
    as.state = a.state;
    as.x_m = a.position.x;
    as.y_m = a.position.y;
    as.z_m = a.z_m;
    as.material_m3 = a.material_m3;
    as.deposited_m3 = a.deposited_m3;
    as.accepted = a.accepted;
    as.rejected = a.rejected;
    as.missed = a.missed;
    as.alive = a.alive;
    as.at_goal = a.alive && at_goal(state, a);
    as.waiting_for = a.waiting_for;
    s.agents.push_back(std::move(as));
  }
  return s;
}

/// One line on how the run completes and where its terrain check stands at the start.
void log_completion(const scenario::Scenario& scenario, const WorldState& state) {
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal: spdlog::info("completion: agents_at_goal"); break;
    case scenario::CompletionKind::kPayloadPath:
      spdlog::info("completion: payload_path from {} to {}, checked every {} steps: {}", state.payload_path.from,
                   state.payload_path.to, state.payload_path.check_every_steps,
                   state.check.met ? "already navigable" : "not navigable yet");
      spdlog::info("completion: the target's cell ({} m) may end at most {} m (one cube layer) higher",
                   state.check.target_initial_m, state.check.max_target_rise_m);
      break;
    case scenario::CompletionKind::kLevelSite:
      spdlog::info("completion: level_site, checked every {} steps: level fraction {:.4f} of {:.4f} needed",
                   state.site.check_every_steps, state.check.level_fraction, state.site.min_fraction);
      break;
  }
  if (scenario.start_jitter_m > 0.0)
    spdlog::info("starts jittered by up to {} m with seed {}", scenario.start_jitter_m, scenario.seed);
}

/// The cells the accepted request of `agent` set in this step (for its deposition in events.log).
const std::vector<Deposition>& deposited_cells(const std::vector<Submission>& submissions, const StepOutcome& outcome,
                                               std::uint32_t agent) {
  static const std::vector<Deposition> none;
  for (std::size_t i = 0; i < submissions.size(); ++i)
    if (outcome.accepted_submissions[i] && submissions[i].channel_id == agent) return outcome.raised_cells[i];
  return none;
}

RecorderSetup recorder_setup(const RuntimeOptions& options, const std::optional<ResumeInfo>& resume) {
  RecorderSetup setup;
  setup.out_dir = options.out_dir;
  setup.run_id = options.run_id;
  setup.snapshot_every = options.snapshot_every;
  setup.frames_every = options.frames_every;
  if (resume) setup.resume_good_bytes = resume->good_bytes;
  return setup;
}

/// What a resume says about itself, in the log and in events.log.
std::string resume_note(const ResumeInfo& resume) {
  return fmt::format(
      "resumed: {} records replayed{}{}", resume.records,
      resume.snapshot_step > 0 ? fmt::format(" after the snapshot of step {}", resume.snapshot_step) : std::string(),
      resume.tail_problem.empty() ? std::string() : fmt::format("; cut {}", resume.tail_problem));
}

}  // namespace

struct WorldRuntime::Impl {
  Impl(WorldStart start, bus::Participant& p)
      : scenario(std::move(start.scenario)),
        options(std::move(start.options)),
        participant(p),
        state(std::move(start.state)),
        resume(std::move(start.resume)),
        resume_step(state.step),
        fork(std::move(start.fork)),
        recorder(recorder_setup(options, resume)),
        silence(std::chrono::milliseconds(static_cast<long long>(options.silence_timeout_s * 1000.0))),
        standing(state.agents.size(), scenario.standing_answers) {
    sensing.emplace(state);
    last_rejection.resize(state.agents.size());
  }

  // ---- endpoints and what the world publishes

  void open_endpoints() {
    signal = std::make_shared<bus::Signal>();
    hellos = participant.create_reader<protocol::AgentHello>({"", nullptr, bus::Durability::kVolatile, 64});
    admissions = participant.create_writer<protocol::Admission>({"", nullptr, bus::Durability::kVolatile, 64});
    status = participant.create_writer<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
    events = participant.create_writer<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256});
    statuses = participant.create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 16});
    links.emplace(participant, signal, options.run_id, state.agents.size());
    collector.emplace(*links, signal);
    std::random_device device;
    while (world_id == 0) world_id = (static_cast<std::uint64_t>(device()) << 32) ^ device();
    // Who this world is, for agents and monitors (docs/runtime.md#who-wrote-it): the run key's public half and its
    // signature of (run, this participant), once per process.
    const protocol::RunKey key = options.run_key ? *options.run_key : protocol::make_run_key();
    world_key = protocol::world_key_of(key);
    world_proof = protocol::prove_world(key, options.run_id, participant.id().prefix);
  }

  void emit(const protocol::WorldEvent& e, const std::vector<Deposition>& cells = {}) {
    write_logged(*events, e, "a world event");
    recorder.event(e, cells);
  }

  void note(const std::string& text) {
    spdlog::info("step {}: {}", state.step, text);
    recorder.note(state.step, text);
  }

  protocol::WorldEvent make_event(std::uint32_t agent, protocol::EventKind kind, std::string detail) const {
    protocol::WorldEvent e;
    e.step = state.step;
    e.agent_id = agent;
    e.kind = kind;
    e.detail = std::move(detail);
    return e;
  }

  void publish_status(bool running, bool completed, double wall_seconds) {
    protocol::WorldStatus s = world_status(state, running, completed, wall_seconds);
    s.world_id = world_id;
    s.world_key = world_key;
    s.world_proof = world_proof;
    s.admitting = running && !run_started;
    s.run_id = options.run_id;
    s.scenario = scenario.name;
    write_logged(*status, s, "the world status");
    publish_metrics();
  }

  /// The metrics snapshot of now to the metrics server, when there is one (docs/runtime.md#metrics).
  void publish_metrics() {
    if (metrics_server == nullptr) return;
    std::vector<bool> connected(state.agents.size(), false);
    for (const AgentRecord& a : state.agents) connected[a.id - 1] = links && links->has(a.id) && links->connected(a.id);
    take_state(metrics, state, connected);
    metrics.phase = ended ? RunPhase::kOver : run_started ? RunPhase::kRunning : RunPhase::kAdmitting;
    metrics.end_reason = ended;
    metrics_server->publish(std::make_shared<const MetricsSnapshot>(metrics));
  }

  /// A step's times and rejections into the metrics, when served.
  void observe_step_metrics(const StepOutcome& outcome, Clock::duration step_took, Clock::duration world_part) {
    if (metrics_server == nullptr) return;
    metrics.step_seconds.observe(std::chrono::duration<double>(step_took).count());
    metrics.step_world_seconds.observe(std::chrono::duration<double>(world_part).count());
    for (std::size_t i = 0; i < kRejectionReasons; ++i) metrics.rejections_by_reason[i] += outcome.rejected_by_reason[i];
  }

  /// Refuses to go on beside another world on this domain (docs/runtime.md#one-world-per-domain): every world
  /// publishes its status from the start, with a random world_id; of two that meet, the one still admitting yields
  /// to one past admission, and of two admitting, the larger world_id yields. Throws Error naming the other run.
  void check_other_worlds() {
    for (const protocol::WorldStatus& other : statuses->take()) {
      if (other.world_id == world_id || other.world_id == 0 || (!other.running && !other.admitting)) continue;
      const bool me_admitting = !run_started;
      const bool yield = me_admitting && (!other.admitting || other.world_id < world_id);
      if (!yield) continue;
      throw Error(fmt::format(
          "another marsala-world runs on DDS domain {} (run '{}', scenario '{}', {}): one world per domain; give this "
          "one another --domain",
          participant.domain_id(), other.run_id, other.scenario,
          other.admitting ? std::string("admitting its agents") : fmt::format("at step {}", other.step)));
    }
  }

  // ---- admission

  /// True when the request writer of the slot's admitted session is alive.
  bool holder_connected(std::uint32_t id) const { return state.has_agent(id) && links->connected(id); }

  /// False when `hello` names a slot's admitted session but `from` is not the participant that session belongs to
  /// (a copy: ignored, counted, never answered; AgentLinks::bind()).
  bool owned_session(const protocol::AgentHello& hello, const bus::WriterId& from) {
    if (!state.has_agent(hello.agent_id) || !links->has(hello.agent_id)) return true;
    const AgentRecord& a = state.agent(hello.agent_id);
    return !a.admitted || a.session != hello.session || links->bind(hello.agent_id, from);
  }

  /// The answer to `hello`, with this world's proof.
  protocol::Admission signed_admission(const protocol::AgentHello& hello, const AdmissionDecision& decision) const {
    protocol::Admission a = admission_message(state, hello, decision, options.run_id);
    a.world_key = world_key;
    a.world_proof = world_proof;
    return a;
  }

  /// True when `hello` must wait for a live slot's connected session to go (AdmissionGate::takeover()).
  bool waits_for_takeover(const protocol::AgentHello& hello, const SenderKey& sender, Clock::time_point now) {
    const bool held = state.has_agent(hello.agent_id) && state.agent(hello.agent_id).alive &&
                      state.agent(hello.agent_id).session != hello.session && holder_connected(hello.agent_id);
    const TakeoverWait wait = gate.takeover(sender, held, now);
    if (wait == TakeoverWait::kStarted)
      spdlog::info(
          "agent {}: session {:016x} says hello while session {:016x} is still connected; waiting up to {} s "
          "for it to go",
          hello.agent_id, hello.session, state.agent(hello.agent_id).session,
          std::chrono::duration_cast<std::chrono::seconds>(kTakeoverWait).count());
    return wait != TakeoverWait::kNone;
  }

  /// Carries out an accepted admission of a persistent sender, participant `from`: records it in run.log and opens
  /// its endpoints, the session bound to `from`.
  void carry_out(const protocol::AgentHello& slot, AdmissionKind kind, const bus::WriterId& from) {
    const std::uint64_t previous = state.agent(slot.agent_id).session;
    if (!admit(state, slot, kind)) return;
    recorder.record(admitted_record(state, slot.agent_id, kind));
    const AgentRecord& a = state.agent(slot.agent_id);
    if (kind != AdmissionKind::kFirst && a.session != previous) sensing->forget(slot.agent_id);
    standing.end(slot.agent_id);
    links->open(a, from);
    links->forgive(slot.agent_id);
    std::string detail = a.name;
    if (kind == AdmissionKind::kReadmission)
      detail += fmt::format(" (re-admitted, {} of {})", a.readmissions, kMaxReadmissions);
    if (kind == AdmissionKind::kTakeover)
      detail += fmt::format(" (session {:016x} takes over from {:016x})", a.session, previous);
    spdlog::info("admitted agent {}: {}", slot.agent_id, detail);
    emit(make_event(slot.agent_id, protocol::EventKind::kAdmitted, detail));
  }

  /// Takes the pending hellos (at most every kHelloInterval unless `now_please`) and answers them; carries out accepted
  /// admissions (first, re-admission, takeover) of senders that repeat their hello.
  void service_hellos(bool now_please = false) {
    const Clock::time_point now = Clock::now();
    if (!now_please && now < next_hello_service) return;
    next_hello_service = now + kHelloInterval;
    check_other_worlds();
    if (!run_started && now >= next_admitting_status) {
      publish_status(true, false, 0.0);
      next_admitting_status = now + kAdmittingStatusInterval;
    }
    gate.begin_round();
    for (const bus::Received<protocol::AgentHello>& received : hellos->take_received()) {
      const protocol::AgentHello& hello = received.sample;
      const SenderKey sender = sender_of(hello, received.from.prefix);
      if (!owned_session(hello, received.from) || waits_for_takeover(hello, sender, now)) continue;
      const bool started = run_started && !(admitting_late && late_slot(hello.agent_id));
      const AdmissionDecision decision = decide_admission(state, hello, started, holder_connected(hello.agent_id));
      if (late_slot(decision.agent_id) && !fork_live) continue;  // a fork's late slot: answered at K, not before
      // A live agent asking again holds no frame it takes: a negative acknowledgement (docs/runtime.md#resends). Once
      // this process has answered its session with an admission (so the agent takes this world's frames: not so
      // after a resume), its frame again, on its own partition, is the answer: an admission goes to every agent of
      // the team, and a crowd asking during slow steps kept the world sending those instead of taking requests.
      if (decision.accepted && decision.kind == AdmissionKind::kRepeat && run_started) {
        const std::uint32_t id = slot_hello(state, hello, decision).agent_id;  // "any slot": the one it holds
        // An agent whose answer stood: its frame of the next step goes out and answers (standing_answers.hpp).
        if (state.has_agent(id) && state.agent(id).alive && standing.end(id)) continue;
        if (state.has_agent(id) && links->has(id) && state.agent(id).alive && links->answers_with_frame(id)) {
          if (gate.may_answer(sender, now)) links->answer_with_frame(id, now);
          continue;
        }
        if (state.has_agent(id) && links->has(id)) links->asked(id);
      }
      if (decision.accepted && decision.kind != AdmissionKind::kRepeat) {
        const protocol::AgentHello slot = slot_hello(state, hello, decision);  // "any slot": the one assigned
        if (!gate.persistent(sender, now)) continue;                           // answered when it says hello again
        carry_out(slot, decision.kind, received.from);
      } else if (!decision.accepted && gate.report_refusal(sender)) {
        spdlog::warn("refused agent {}: {} ({} refusals so far)", hello.agent_id, decision.reason, gate.refusals());
        emit(make_event(hello.agent_id, protocol::EventKind::kRefused, decision.reason));
      }
      if (!decision.accepted && !gate.may_answer_refusal()) continue;
      if (gate.may_answer(sender, now)) {
        write_logged(*admissions, signed_admission(hello, decision), "an admission");
        if (decision.accepted) links->accepted(slot_hello(state, hello, decision).agent_id, hello.session);
      }
    }
  }

  /// The team-silence rule (team_silence.hpp, docs/runtime.md#silence): true while the step is held because no live
  /// agent is heard; each live agent's liveliness grace then starts afresh when the hold ends.
  bool hold_for_silence(Clock::time_point now) {
    const std::vector<std::uint32_t> live = state.live_ids();
    const bool heard = !run_started || live.empty() ||
                       std::any_of(live.begin(), live.end(), [&](std::uint32_t id) { return links->connected(id); });
    const double silent_s = silence.silent_s(now);
    switch (silence.observe(heard, now)) {
      case SilenceVerdict::kStarted:
        note(fmt::format(
            "no live agent heard (not one request writer alive): step {} held until one is, for up to {}", state.step,
            options.silence_timeout_s > 0 ? fmt::format("{} s (--silence-timeout)", options.silence_timeout_s)
                                          : std::string("ever (--silence-timeout 0)")));
        break;
      case SilenceVerdict::kEnded: note(fmt::format("agents heard again after {:.1f} s of silence", silent_s)); break;
      case SilenceVerdict::kGivenUp:
        note(fmt::format("no live agent heard for {} s (--silence-timeout): the drop rules apply", silent_s));
        break;
      default: break;
    }
    if (!silence.held()) return false;
    for (std::uint32_t id : live) links->forgive(id);
    return true;
  }

  /// Drops every live agent whose request writer was alive and has not been alive again for kLivelinessGrace, unless
  /// the whole team is silent (hold_for_silence()).
  void check_liveliness() {
    const Clock::time_point now = Clock::now();
    if (hold_for_silence(now)) return;
    for (std::uint32_t id : state.live_ids()) {
      switch (links->observe(id, now)) {
        case LivelinessVerdict::kSteady: break;
        case LivelinessVerdict::kBack: spdlog::info("agent {}: its request writer is alive again", id); break;
        case LivelinessVerdict::kLost:
          spdlog::info("agent {}: its request writer lost liveliness; dropped unless it is back within {} s", id,
                       kLivelinessGrace.count());
          break;
        case LivelinessVerdict::kDrop:
          spdlog::warn("agent {} dropped: its request writer lost liveliness", id);
          recorder.record(dropped_record(state, id, "request writer lost liveliness"));
          emit(drop_agent(state, id, "request writer lost liveliness"));
          break;
      }
    }
  }

  /// Waits for the expected agents: until all are admitted and ready, the admit timeout or `stop`. Throws Error when
  /// none was admitted.
  void admit_agents(const std::atomic<bool>& stop) {
    // The timeout counts from the latest admission (protocol::AdmitDeadline).
    protocol::AdmitDeadline wait(Clock::now(), seconds(options.admit_timeout_s));
    std::size_t admitted_before = 0;
    const std::size_t expected = state.agents.size() - late_slots().size();
    for (;;) {
      service_hellos(true);
      check_liveliness();
      std::size_t admitted = 0;
      bool all_ready = true;
      for (const AgentRecord& a : state.agents) {
        if (late_slot(a.id)) continue;
        admitted += a.admitted ? 1 : 0;
        if (a.alive && !links->ready(a.id)) all_ready = false;
      }
      if (admitted == expected && all_ready) return;
      const Clock::time_point now = Clock::now();
      if (admitted > admitted_before) wait.progress(now);
      admitted_before = admitted;
      if (stop || now >= wait.deadline()) break;
      signal->wait_until(std::min(
          wait.deadline(), now + (admitted == expected ? kReadyPollInterval
                                                : std::chrono::duration_cast<Clock::duration>(kHelloInterval))));
    }
    std::size_t admitted = 0, ready_count = 0;
    for (const AgentRecord& a : state.agents) {
      admitted += a.admitted ? 1 : 0;
      ready_count += a.alive && links->ready(a.id) ? 1 : 0;
    }
    if (admitted == 0)
      throw Error(stop ? std::string("stopped before any agent was admitted")
                       : fmt::format("no agent admitted within the admit timeout of {} s (expected {} on run '{}')",
                                     options.admit_timeout_s, expected, options.run_id));
    spdlog::warn("starting with {} of {} agents admitted, {} of them connected ({})", admitted, expected, ready_count,
                 stop ? "stopped during admission" : "admit timeout");
  }

  /// A resumed run: reopens the endpoints of the agents that were live and waits (answering hellos) until each is
  /// ready again, or the admit timeout; agents that do not come back miss their steps and are dropped by the rules.
  void reconnect_agents(const std::atomic<bool>& stop) {
    for (const AgentRecord& a : state.agents)
      if (a.alive) links->open(a);
    const Clock::time_point deadline = Clock::now() + seconds(options.admit_timeout_s);
    const auto all_ready = [&] {
      const std::vector<std::uint32_t> live = state.live_ids();
      return std::all_of(live.begin(), live.end(), [&](std::uint32_t id) { return links->ready(id); });
    };
    for (;;) {
      service_hellos(true);
      if (all_ready()) return;
      const Clock::time_point now = Clock::now();
      if (stop || now >= deadline) break;
      signal->wait_until(std::min(deadline, now + std::chrono::duration_cast<Clock::duration>(kHelloInterval)));
    }
    std::vector<std::uint32_t> missing;
    for (std::uint32_t id : state.live_ids())
      if (!links->ready(id)) missing.push_back(id);
    spdlog::warn("resuming without {} of {} live agents reconnected: {}", missing.size(), state.live_ids().size(),
                 fmt::join(missing, ", "));
  }

  // ---- the lockstep

  /// Writes agent `id` its frame of this step.
  void send_frame(std::uint32_t id, bool run_over) { tell(sensing->frame_for(state, id, run_over)); }

  /// Writes `frame` to its agent; what the agent was told ends its standing answer (standing_answers.hpp).
  void tell(protocol::SensorFrame frame) {
    standing.end(frame.agent_id);
    links->send(frame.agent_id, std::move(frame));
  }

  /// Logs a rejection at info level, or at debug level when it repeats the agent's previous one (a stuck agent would
  /// otherwise fill the log; events.log keeps every one).
  void log_rejection(const protocol::WorldEvent& e) {
    if (e.agent_id == 0) {  // forged: bounded, whoever sends them
      if (power_of_ten(state.unattributed_rejections))
        spdlog::warn("step {}: {} requests without an admitted identity rejected so far, e.g.: {}", e.step,
                     state.unattributed_rejections, e.detail);
      return;
    }
    std::string& last = last_rejection[e.agent_id - 1];
    if (e.detail == last) {
      spdlog::debug("step {}: agent {} rejected again: {}", e.step, e.agent_id, e.detail);
      return;
    }
    spdlog::info("step {}: agent {} rejected: {}", e.step, e.agent_id, e.detail);
    last = e.detail;
  }

  /// What a step applied, told: notes and events to the log, events.log and the bus.
  void report_step(const std::vector<Submission>& submissions, const StepOutcome& outcome) {
    if (outcome.completion_checked)
      spdlog::debug("step {}: {} check: {} (level fraction {:.4f})", outcome.step,
                    scenario::to_string(state.completion), state.check.met ? "met" : "not met",
                    state.check.level_fraction);
    for (const std::string& text : outcome.notes) note(text);
    for (const protocol::WorldEvent& e : outcome.events) {
      if (e.kind == protocol::EventKind::kRejected)
        log_rejection(e);
      else if (e.kind == protocol::EventKind::kMissed || e.kind == protocol::EventKind::kDropped)
        spdlog::warn("step {}: agent {} {}: {}", e.step, e.agent_id, protocol::to_string(e.kind), e.detail);
      else if (e.kind == protocol::EventKind::kAtGoal)
        spdlog::info("step {}: agent {} reached the goal", e.step, e.agent_id);
      emit(e, e.kind == protocol::EventKind::kDeposited ? deposited_cells(submissions, outcome, e.agent_id)
                                                        : std::vector<Deposition>{});
    }
    for (const AgentRecord& a : state.agents)
      if (a.last_result != protocol::ActionResult::kRejected) last_rejection[a.id - 1].clear();
  }

  /// Why the lockstep ends before the next step, if it does.
  std::optional<protocol::EndReason> end_before_step(const std::atomic<bool>& stop) const {
    if (stop) return protocol::EndReason::kSignal;
    if (is_completed(state)) return protocol::EndReason::kCompleted;
    if (state.step >= options.max_steps) return protocol::EndReason::kMaxSteps;
    if (state.live_ids().empty()) return protocol::EndReason::kNoLiveAgents;
    if (stalled(state.stall, state.step, state.stall_steps)) return protocol::EndReason::kStalled;
    return std::nullopt;
  }

  /// Frames: each live agent's frame of this step, unless its answer stands (the frame tells it nothing new): those
  /// answers, for the collector.
  std::vector<Submission> send_frames() {
    std::vector<Submission> stood;
    for (std::uint32_t id : state.live_ids()) {
      protocol::SensorFrame frame = sensing->frame_for(state, id, false);
      if (std::optional<protocol::ActionRequest> answer = standing.stands_for(id, frame, links->last_frame(id)))
        stood.push_back({id, std::move(*answer)});
      else
        tell(std::move(frame));
    }
    return stood;
  }

  /// The answers read this step that were applied: each stands from now on when it says so and may (standing_answers
  /// .hpp); one that says so but asks for something is taken for its step only, and the operator is told.
  void keep_standing_answers(const Collected& collected, const StepOutcome& outcome) {
    for (std::size_t i : collected.answers) {
      const Submission& s = collected.submissions[i];
      if (!outcome.accepted_submissions[i]) continue;  // its frame, written this step, ended any standing answer
      if (!standing.answered(s.channel_id, s.request) && power_of_ten(++unstandable_answers))
        spdlog::warn(
            "step {}: agent {} said its request stands, but it asks for something (a motion, deposition or refill): "
            "taken for this step only ({} so far)",
            outcome.step, s.channel_id, unstandable_answers);
    }
  }

  /// Record: the step in run.log before anything of it is published (a crash never loses a step an agent has seen
  /// applied), then the surplus note and the snapshot when due.
  void record_step(const Collected& collected, const StepOutcome& outcome) {
    recorder.record(step_record(collected.submissions, outcome, state, collected.surplus));
    if (collected.surplus > 0)
      note(fmt::format("{} requests beyond {} per partition ignored", collected.surplus, kMaxRequestsPerPartition));
    recorder.after_step(state);
  }

  /// Status: the step's notes and events, run_over frames to agents the step dropped (one dropped for missing its
  /// deadlines may only be slow or hung), WorldStatus and the progress line.
  void publish_step(const Collected& collected, const StepOutcome& outcome, Clock::time_point start) {
    report_step(collected.submissions, outcome);
    for (std::uint32_t id : outcome.dropped) send_frame(id, true);
    publish_status(true, outcome.completed, elapsed_s(start));
    if (state.step % kProgressEvery == 0)
      spdlog::info("step {}: {} live agents, {:.6f} m3 deposited, progress {:.3f}: {}", state.step,
                   state.live_ids().size(), state.deposited_volume_m3, progress(state), progress_detail(state));
  }

  /// Runs steps until an end condition; returns the end reason. A step: frames -> collect -> apply -> record ->
  /// status.
  protocol::EndReason lockstep(const std::atomic<bool>& stop, Clock::time_point start) {
    const CollectDuties duties{[this] { service_hellos(); }, [this] { check_liveliness(); },
                               [this](std::uint32_t id) { send_frame(id, false); }, [this] { return silence.held(); }};
    for (;;) {
      if (fork && state.step == fork->origin().at_step && !fork_live) go_live(stop);
      recorder.frame(state, scenario.name, false);
      if (const auto end = end_before_step(stop)) return *end;
      StepTimes times;  // the phases' ends, for the step time and the trace
      times.step = state.step;
      times.start = Clock::now();
      std::vector<Submission> stood = send_frames();
      times.frames_out = Clock::now();
      Collected collected = collector->collect(state, options.step_deadline_s, stop, duties, std::move(stood));
      if (stop) return protocol::EndReason::kSignal;  // the interrupted step is not applied
      if (fork && fork->replaying(state.step)) replay_fork_step(collected);
      times.collected = Clock::now();
      const StepOutcome outcome = apply_step(state, collected.submissions);
      keep_standing_answers(collected, outcome);
      times.applied = Clock::now();
      state.surplus_requests += collected.surplus;
      record_step(collected, outcome);
      times.recorded = Clock::now();
      const Clock::duration step_took = times.recorded - times.start;
      step_ms.push_back(milliseconds(step_took));
      step_world_ms.push_back(milliseconds(step_took - collected.waited));
      observe_step_metrics(outcome, step_took, step_took - collected.waited);
      publish_step(collected, outcome, start);
      trace_step(times, collected, outcome);
    }
  }

  /// A fork's step before K (docs/runtime.md#fork): the live requests must be the parent's, and the recorded ones
  /// are applied. Throws ForkMismatch naming the agent and the step.
  void replay_fork_step(Collected& collected) {
    if (const std::string problem = fork->mismatch(state.step, collected.submissions); !problem.empty())
      throw ForkMismatch(fmt::format("fork of {} at step {}: {}", fork->origin().parent_dir, fork->origin().at_step,
                                     problem));
    collected.submissions = fork->recorded(state.step, state);
    collected.answers.clear();  // they named the live submissions; no answer stands while the parent's steps replay
  }

  /// True for a fork's late slot (above the parent's team, docs/runtime.md#fork): not admitted before K.
  bool late_slot(std::uint32_t id) const { return fork && id > fork->origin().parent_agents && state.has_agent(id); }

  /// A fork's late slots, in order (none for a run that is no fork, or a fork without a larger team).
  std::vector<std::uint32_t> late_slots() const {
    std::vector<std::uint32_t> ids;
    for (const AgentRecord& a : state.agents)
      if (late_slot(a.id)) ids.push_back(a.id);
    return ids;
  }

  /// A fork's late slots join at K (docs/runtime.md#fork): first admissions at their scenario starts with full
  /// material, waited for (answering hellos) up to the admit timeout before step K's frames go out; a slot that has
  /// not joined by then stays out of the run (refused later, missing at its end).
  void admit_late_slots(const std::atomic<bool>& stop) {
    const std::vector<std::uint32_t> late = late_slots();
    if (late.empty()) return;
    admitting_late = true;
    const Clock::time_point deadline = Clock::now() + seconds(options.admit_timeout_s);
    const auto joined = [&](std::uint32_t id) { return state.agent(id).alive && links->ready(id); };
    for (;;) {
      service_hellos(true);
      if (std::all_of(late.begin(), late.end(), joined)) break;
      const Clock::time_point now = Clock::now();
      if (stop || now >= deadline) break;
      signal->wait_until(std::min(deadline, now + std::chrono::duration_cast<Clock::duration>(kHelloInterval)));
    }
    admitting_late = false;
    std::vector<std::uint32_t> absent;
    for (std::uint32_t id : late)
      if (!joined(id)) absent.push_back(id);
    note(fmt::format("fork: {} of {} late slots joined at step {}{}", late.size() - absent.size(), late.size(),
                     state.step,
                     absent.empty() ? std::string()
                                    : fmt::format(" (not within the admit timeout of {} s: {})",
                                                  options.admit_timeout_s, fmt::join(absent, ", "))));
  }

  /// A fork at step K: checks the terrain against the parent's at K, then lets the slots above the fork's team leave
  /// or, for a larger team, admits the late slots.
  void go_live(const std::atomic<bool>& stop) {
    fork_live = true;
    const ForkOrigin& o = fork->origin();
    const std::string sha = runlog::terrain_sha256(state.terrain);
    if (sha != o.parent_sha256_at_step)
      throw ForkMismatch(fmt::format("fork of {}: the terrain at step {} is {}, the parent's was {}", o.parent_dir,
                                     o.at_step, sha, o.parent_sha256_at_step));
    note(fmt::format("fork of {} (run '{}') live from step {} with {} agents (the parent's team: {}): terrain sha256 {} "
                     "as the parent's",
                     o.parent_dir, o.parent_run_id, o.at_step, o.agents, o.parent_agents, sha));
    for (std::uint32_t id = o.agents + 1; id <= o.parent_agents; ++id) {
      if (!state.has_agent(id) || !state.agent(id).alive) continue;
      const std::string reason = fmt::format("not in the fork's team of {}", o.agents);
      recorder.record(dropped_record(state, id, reason));
      emit(drop_agent(state, id, reason));
      send_frame(id, true);
    }
    admit_late_slots(stop);
  }

  /// A step's spans into the trace, when one is written (docs/runtime.md#step-traces).
  void trace_step(StepTimes& times, Collected& collected, const StepOutcome& outcome) {
    if (trace == nullptr) return;
    times.published = Clock::now();
    times.answers = std::move(collected.answered_at);
    for (const protocol::WorldEvent& e : outcome.events)
      if (e.kind == protocol::EventKind::kMissed) times.missed.push_back(e.agent_id);
    trace->step(times);
  }

  // ---- the run

  /// Waits until every agent told that the run is over has closed its request writer, or the linger time passes.
  void linger(const std::vector<std::uint32_t>& ids) {
    const Clock::time_point deadline = Clock::now() + seconds(options.linger_s);
    for (;;) {
      const bool gone = std::all_of(ids.begin(), ids.end(), [&](std::uint32_t id) { return links->gone(id); });
      const Clock::time_point now = Clock::now();
      if (gone || now >= deadline) return;
      signal->wait_until(std::min(deadline, now + Clock::duration(kPollInterval)));
    }
  }

  /// Opens the run's files and endpoints, then admits the agents (a resumed run: reconnects them).
  void start(const std::atomic<bool>& stop) {
    LogStart log_start;
    log_start.scenario_text = options.scenario_text;
    log_start.run_id = options.run_id;
    log_start.agents = static_cast<std::uint32_t>(state.agents.size());
    log_start.max_steps = options.max_steps;
    log_start.step_deadline_s = options.step_deadline_s;
    if (fork) log_start.fork = &fork->origin();
    recorder.open(scenario, log_start, state);
    if (resume) {
      proto::LogRecord r;
      r.mutable_resumed()->set_step(state.step);
      r.mutable_resumed()->set_snapshot_step(resume->snapshot_step);
      recorder.record(r);
      ++state.resumes;
    }
    open_endpoints();
    if (!resume) {
      spdlog::info("run '{}': scenario '{}', {} x {} cells of {} m, waiting for {} agents (admit timeout {} s)",
                   options.run_id, scenario.name, state.terrain.rows(), state.terrain.cols(),
                   state.terrain.cell_size_m(), state.agents.size(), options.admit_timeout_s);
      log_completion(scenario, state);
      admit_agents(stop);
      return;
    }
    run_started = true;
    spdlog::info("run '{}' resumed at step {}: {} records replayed{} in {:.3f} s", options.run_id, state.step,
                 resume->records,
                 resume->snapshot_step > 0 ? fmt::format(" after the snapshot of step {}", resume->snapshot_step)
                                           : std::string(),
                 resume->rebuild_seconds);
    if (!resume->tail_problem.empty()) spdlog::warn("cut run.log's damaged tail: {}", resume->tail_problem);
    if (!resume->snapshot_problem.empty())
      spdlog::warn("snapshot not used ({}); replayed run.log from its start", resume->snapshot_problem);
    note(resume_note(*resume));
    log_completion(scenario, state);
    reconnect_agents(stop);
  }

  /// A stalled run: why, in the log and events.log, with one line per live robot (docs/runtime.md#stall).
  void report_stall() {
    note(fmt::format("stalled: no rise of the progress ({:.4f}) and no terrain change for {} steps, since step {}",
                     state.stall.best_progress, quiet_steps(state.stall, state.step), state.stall.quiet_since));
    for (const AgentRecord& a : state.agents)
      if (a.alive)
        note(fmt::format("stalled: agent {} {} with {:.3f} m3 at {}, waiting for: {}", a.id,
                         a.state.empty() ? std::string("(no state)") : a.state, a.material_m3, a.position,
                         a.waiting_for.empty() ? std::string("(nothing said)") : a.waiting_for));
  }

  /// What summary.json reports besides the state.
  RunInfo run_info(protocol::EndReason end_reason, double wall_seconds, double cpu_ms) const {
    RunInfo info;
    info.scenario = scenario.name;
    info.scenario_file = scenario.source_path;
    info.overrides = scenario.overrides;
    info.run_id = options.run_id;
    info.dds = bus::to_string(participant.vendor());
    info.seed = scenario.seed;
    info.start_jitter_m = scenario.start_jitter_m;
    if (scenario.has_goal_vector_map) info.goal_vector_map = scenario.goal_vector_map;
    info.completed = end_reason == protocol::EndReason::kCompleted;
    info.end_reason = end_reason;
    info.wall_seconds = wall_seconds;
    info.step_wall_median_ms = median(step_ms);
    info.step_wall_p90_ms = percentile(step_ms, 0.9);
    info.step_world_median_ms = median(step_world_ms);
    info.step_world_p90_ms = percentile(step_world_ms, 0.9);
    info.world_cpu_ms_per_step = step_ms.empty() ? 0.0 : cpu_ms / static_cast<double>(step_ms.size());
    if (fork) info.fork = fork->origin();
    return info;
  }

  RunResult run(const std::atomic<bool>& stop) {
    const Clock::time_point admit_start = Clock::now();
    start(stop);
    const double admit_seconds = elapsed_s(admit_start);
    std::uint32_t connected = 0;
    for (const AgentRecord& a : state.agents) connected += a.alive && links->ready(a.id) ? 1 : 0;
    run_started = true;
    const Clock::time_point start = Clock::now();
    const double cpu_before_ms = process_cpu_ms();
    publish_status(true, false, 0.0);
    const protocol::EndReason end_reason = lockstep(stop, start);
    const double cpu_steps_ms = process_cpu_ms() - cpu_before_ms;
    if (end_reason == protocol::EndReason::kStalled) report_stall();

    RunResult result;
    result.end_reason = end_reason;
    result.completed = end_reason == protocol::EndReason::kCompleted;
    result.steps = state.step;
    result.wall_seconds = elapsed_s(start);
    const std::vector<std::uint32_t> live = state.live_ids();
    proto::LogRecord end;
    end.mutable_end()->set_steps(state.step);
    end.mutable_end()->set_end_reason(to_string(end_reason));
    end.mutable_end()->set_terrain_sha256(runlog::terrain_sha256(state.terrain));
    recorder.record(end);
    recorder.sync();
    for (std::uint32_t id : live) send_frame(id, true);
    emit(make_event(0, protocol::EventKind::kRunOver, to_string(end_reason)));
    ended = end_reason;
    publish_status(false, result.completed, result.wall_seconds);

    RunInfo info = run_info(end_reason, result.wall_seconds, cpu_steps_ms);
    info.admit_seconds = admit_seconds;
    info.connected = connected;
    recorder.finish(state, std::move(info), options.search_path);
    for (const AgentRecord& a : state.agents) result.admitted += a.admitted ? 1 : 0;
    result.team = static_cast<std::uint32_t>(state.agents.size());
    result.slots_missing =
        static_cast<std::uint32_t>(missing_slots(state, fork ? &fork->origin() : nullptr).size());
    result.terrain_sha256 = runlog::terrain_sha256(state.terrain);
    if (resume) result.resumed_at_step = resume_step;
    spdlog::info("run over ({}): {} steps in {:.3f} s, {:.6f} m3 deposited, terrain sha256 {}", to_string(end_reason),
                 result.steps, result.wall_seconds, state.deposited_volume_m3, result.terrain_sha256);
    linger(live);
    return result;
  }

  scenario::Scenario scenario;  ///< with the seed in use
  RuntimeOptions options;
  bus::Participant& participant;
  WorldState state;
  std::optional<ResumeInfo> resume;
  std::uint64_t resume_step = 0;  ///< the step a resumed run continued at
  std::optional<ForkReplay> fork;  ///< a fork's replay of its parent's first K steps (docs/runtime.md#fork)
  bool fork_live = false;          ///< the fork has reached K
  bool admitting_late = false;     ///< a fork's late slots may take their first admission (admit_late_slots())
  RunRecorder recorder;           ///< run.log, snapshots, events.log, frames, final outputs
  TeamSilence silence;            ///< whether the step is held for a silent team
  std::optional<SensingService> sensing;
  StandingAnswers standing;               ///< the agents' standing answers
  std::uint64_t unstandable_answers = 0;  ///< answers that said they stand but asked for something [count]
  AdmissionGate gate;
  std::shared_ptr<bus::Signal> signal;
  std::optional<AgentLinks> links;
  std::optional<RequestCollector> collector;
  std::unique_ptr<bus::Reader<protocol::AgentHello>> hellos;
  std::unique_ptr<bus::Writer<protocol::Admission>> admissions;
  std::unique_ptr<bus::Writer<protocol::WorldStatus>> status;
  std::unique_ptr<bus::Writer<protocol::WorldEvent>> events;
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> statuses;  ///< other worlds' status on this domain
  std::uint64_t world_id = 0;                                    ///< random, this process's
  std::string world_key, world_proof;  ///< the run key's public half, its signature of (run, this participant)
  Clock::time_point next_admitting_status{};
  Clock::time_point next_hello_service{};
  bool run_started = false;
  std::vector<std::string> last_rejection;  ///< [id - 1]: the rejection reason last logged at info level
  std::vector<double> step_ms;              ///< wall time of each lockstep step [ms]
  std::vector<double> step_world_ms;        ///< the world's own part of each step: its wall time less its waits [ms]
  MetricsServer* metrics_server = nullptr;  ///< where publish_metrics() goes; none: no metrics
  MetricsSnapshot metrics;                  ///< the metrics, kept up to date while served
  std::optional<protocol::EndReason> ended;  ///< set when the lockstep is over
  StepTrace* trace = nullptr;                ///< where trace_step() goes; none: no trace
};

WorldRuntime::WorldRuntime(const scenario::Scenario& scenario, Heightmap terrain, RuntimeOptions options,
                           bus::Participant& participant)
    : impl_(std::make_unique<Impl>(
          prepare_world_start(scenario, std::move(terrain), std::move(options), participant.domain_id()),
          participant)) {}

WorldRuntime::WorldRuntime(WorldStart start, bus::Participant& participant)
    : impl_(std::make_unique<Impl>(std::move(start), participant)) {}

WorldRuntime::~WorldRuntime() = default;

RunResult WorldRuntime::run(const std::atomic<bool>& stop) { return impl_->run(stop); }

void WorldRuntime::trace_steps(StepTrace& trace) {
  impl_->trace = &trace;
  trace.name_tracks(static_cast<std::uint32_t>(impl_->state.agents.size()));
}

void WorldRuntime::serve_metrics(MetricsServer& server) {
  impl_->metrics_server = &server;
  impl_->metrics.run_id = impl_->options.run_id;
  impl_->metrics.scenario = impl_->scenario.name;
  impl_->metrics.dds = bus::to_string(impl_->participant.vendor());
}

const WorldState& WorldRuntime::state() const { return impl_->state; }

const std::string& WorldRuntime::run_id() const { return impl_->options.run_id; }

}  // namespace marsala::world_server
