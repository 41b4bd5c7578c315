#include "marsala/world_server/world_runtime.hpp"

#include <fmt/ranges.h>
#include <sys/resource.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/log_pacing.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/render/timelapse.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/world_server/admission.hpp"
#include "marsala/world_server/completion.hpp"
#include "marsala/world_server/persistence.hpp"
#include "marsala/world_server/run_outputs.hpp"
#include "marsala/world_server/sensing_service.hpp"
#include "marsala/world_server/step.hpp"

namespace marsala::world_server {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// Longest single wait, so that a stop request is seen promptly even when no sample arrives.
constexpr auto kPollInterval = 100ms;
// Between readiness checks once every agent is admitted (matching is not signalled to the world's writers).
constexpr auto kReadyPollInterval = 5ms;
// How long a live agent's request writer may stay not alive before the agent is dropped: a process paused (SIGSTOP,
// a swapped or overloaded machine) for up to 5 s, world or agent, comes back and loses nothing; a dead agent costs
// its team this long once (docs/runtime.md#dropping-agents).
constexpr auto kLivelinessGrace = 6s;
// Between liveliness checks while a step waits for requests. The world wakes once per arriving request; checking
// every agent's writer at each wake-up cost N^2 status queries per step (14,400 at 120 agents: 18 ms of the world's
// CPU per step with Fast DDS), against a grace of seconds.
constexpr auto kLivelinessPoll = 50ms;
// Progress lines at info level every this many steps.
constexpr std::uint64_t kProgressEvery = 500;
// Hellos do not wake the world (a flood of them must not stall the lockstep): they are taken at most this often and
// whenever the world wakes anyway (docs/runtime.md#load-limits).
constexpr auto kHelloInterval = 20ms;
// Each (id, session) is answered at most this often; the legitimate agent says hello every 200 ms.
constexpr auto kAnswerInterval = 150ms;
// Bounds of the per-sender bookkeeping: beyond them, hellos are counted, not remembered.
constexpr std::size_t kMaxAnswerKeys = 4096;
constexpr std::size_t kMaxRefusalKeys = 1024;
// A new session of an admitted agent (a restarted process) gets no answer while the old session's request writer is
// still alive, for up to this long: its liveliness lapses within the 1 s DDS lease when the old process died, and
// the new session then takes the slot over. Still alive after this: refused (two processes with one id).
constexpr auto kTakeoverWait = 3s;
// A session is admitted (first, re-admission, takeover) only on a hello repeated at least this long after its first:
// agents repeat theirs every 200 ms, a flood of random sessions never does. Hellos are remembered for up to two
// generations of kHelloMemory.
constexpr auto kHelloConfirmation = 100ms;
constexpr auto kHelloMemory = 1s;
// Refusals answered per round of hellos (every 20 ms) at most.
constexpr int kMaxRefusalAnswers = 16;
// Requests taken from one partition in one step beyond this many are counted (surplus) and never applied.
constexpr std::size_t kMaxRequestsPerPartition = 8;
// A live agent that has not answered its frame after this long gets the same frame again (its reader may have
// matched late, e.g. after a resume); an agent that receives a frame twice repeats its request, which is ignored.
constexpr auto kResendInterval = 500ms;

/// The q-quantile (nearest rank) of `values`; 0 when empty.
double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}

double elapsed_s(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

/// CPU time of this process so far, every thread's, user and system [s].
double process_cpu_seconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

/// Writes a sample; a failing write is logged, never fatal: one agent's broken link must not stop the world.
template <typename T>
void write_logged(bus::Writer<T>& writer, const T& sample, const char* what) {
  try {
    writer.write(sample);
  } catch (const std::exception& e) {
    spdlog::error("cannot publish {}: {}", what, e.what());
  }
}

}  // namespace

std::string default_run_id(const std::string& scenario_name, int domain_id) {
  return scenario_name + "-d" + std::to_string(domain_id);
}

void check_run_id(const std::string& run_id) {
  const bool ok = !run_id.empty() && std::all_of(run_id.begin(), run_id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (!ok) throw InvalidArgument("run id '" + run_id + "' must be non-empty letters, digits, '_', '-', '.'");
}

/// The endpoints of one admitted agent (process): its session's partition.
struct AgentLink {
  std::uint64_t session = 0;  ///< the session whose partition the endpoints use
  std::unique_ptr<bus::Writer<protocol::SensorFrame>> frames;
  std::unique_ptr<bus::Reader<protocol::ActionRequest>> requests;
  bool writer_seen = false;                          ///< its request writer has been alive at least once
  std::optional<Clock::time_point> not_alive_since;  ///< when its seen writer was last found not alive
  std::optional<protocol::SensorFrame> frame;        ///< the current step's frame, for resends
};

WorldStart prepare_world_start(const scenario::Scenario& s, Heightmap terrain, RuntimeOptions options, int domain_id) {
  WorldStart start{s, std::move(options), {}, std::nullopt};
  RuntimeOptions& o = start.options;
  if (o.seed) start.scenario.seed = *o.seed;
  const std::uint32_t agents = o.agents == 0 ? static_cast<std::uint32_t>(s.slots.size()) : o.agents;
  if (agents > s.slots.size())
    throw InvalidArgument("--agents " + std::to_string(agents) + " exceeds the " + std::to_string(s.slots.size()) +
                          " agent slots of scenario '" + s.name + "'");
  o.agents = agents;
  if (o.run_id.empty()) o.run_id = default_run_id(s.name, domain_id);
  check_run_id(o.run_id);
  if (!(o.admit_timeout_s >= 0.0) || !std::isfinite(o.admit_timeout_s))
    throw InvalidArgument("admit timeout must be finite and >= 0 s");
  if (o.max_steps == 0) o.max_steps = s.max_steps;
  if (o.step_deadline_s == 0.0) o.step_deadline_s = s.step_deadline_s;
  if (!(o.step_deadline_s > 0.0) || !std::isfinite(o.step_deadline_s))
    throw InvalidArgument("step deadline must be finite and > 0 s");
  // Every builder computes MARS at its construction kappa on windows of this terrain, whose heights grow as it is
  // built, up to the world's height limit (kMaxMagnitude): refuse combinations that doubles cannot compute there
  // (docs/runtime.md#scenario-validation) instead of letting an agent's processor fail mid-run.
  const double height_limit_m = kMaxMagnitude;
  for (std::uint32_t id = 1; id <= agents; ++id) {
    const RobotType& type = s.robot_for(id);
    const std::string problem = mars_problem(construction_params(type).kappa, terrain.cell_size_m(), height_limit_m,
                                             terrain.rows(), terrain.cols());
    if (!problem.empty())
      throw InvalidArgument(
          fmt::format("scenario {}: robot type '{}': construction kappa: {}", s.source_path, type.name, problem));
  }
  if (!o.out_dir.empty() && !o.replace) check_fresh_output_dir(o.out_dir);
  start.state = make_world_state(start.scenario, std::move(terrain), agents);
  return start;
}

WorldStart prepare_resume(const std::string& dir, RuntimeOptions options, int domain_id) {
  namespace fs = std::filesystem;
  const Clock::time_point began = Clock::now();
  const std::string log_path = (fs::path(dir) / kRunLogFile).string();
  if (!fs::exists(log_path))
    throw Error("--resume " + dir + ": no " + kRunLogFile + " there (only runs of this version can be resumed)");
  runlog::RunLogReader reader(log_path);
  const proto::LogHeader& h = reader.header();
  if (h.scenario_text().empty())
    throw Error(log_path + ": the header holds no scenario text (the run was started without a scenario file)");
  const std::vector<std::string> overrides(h.overrides().begin(), h.overrides().end());
  const scenario::Scenario scenario = scenario::parse_scenario(h.scenario_text(), h.scenario_file(), overrides);
  const std::string terrain_path = (fs::path(dir) / "terrain_initial.asc").string();
  Heightmap terrain = terrain::read_asc(terrain_path);
  if (terrain.rows() != h.rows() || terrain.cols() != h.cols() || terrain.cell_size_m() != h.cell_size_m() ||
      runlog::terrain_sha256(terrain) != h.initial_terrain_sha256())
    throw ParseError(terrain_path, 0,
                     "it is not the initial terrain run.log was written from (grid or SHA-256 differs)");
  options.agents = h.agents();
  options.run_id = h.run_id();
  options.seed = h.seed();
  if (options.max_steps == 0) options.max_steps = h.max_steps();
  options.step_deadline_s = h.step_deadline_s();
  options.scenario_text = h.scenario_text();
  options.overrides = overrides;
  const std::string out_dir = dir;
  options.out_dir.clear();  // the folder holds this run's files: no freshness check
  WorldStart start = prepare_world_start(scenario, std::move(terrain), std::move(options), domain_id);
  start.options.out_dir = out_dir;
  RebuiltState rebuilt = rebuild_state(dir, std::move(start.state), reader);
  if (rebuilt.ended)
    throw Error("--resume " + dir + ": the run ended (" + rebuilt.end_reason + ") after " +
                std::to_string(rebuilt.state.step) + " steps; there is nothing to resume");
  for (const char* name : {"summary.json", "terrain_final.asc"})
    if (fs::exists(fs::path(dir) / name))
      throw Error("--resume " + dir + ": " + name + " exists, so the run ended; there is nothing to resume");
  start.state = std::move(rebuilt.state);
  ResumeInfo info;
  info.good_bytes = rebuilt.good_bytes;
  info.snapshot_step = rebuilt.snapshot_step;
  info.records = rebuilt.records;
  info.tail_problem = rebuilt.tail_problem;
  info.snapshot_problem = rebuilt.snapshot_problem;
  info.rebuild_seconds = elapsed_s(began);
  start.resume = info;
  return start;
}

struct WorldRuntime::Impl {
  Impl(WorldStart start, bus::Participant& p)
      : scenario(std::move(start.scenario)),
        options(std::move(start.options)),
        participant(p),
        state(std::move(start.state)),
        resume(std::move(start.resume)),
        resume_step(state.step) {
    // make_world_state() keeps the terrain as given: the state's terrain is still the initial one, unless resumed.
    if (scenario.has_goal_vector_map || state.completion == scenario::CompletionKind::kPayloadPath)
      initial_terrain =
          resume ? terrain::read_asc((std::filesystem::path(options.out_dir) / "terrain_initial.asc").string())
                 : state.terrain;
    sensing.emplace(state);
    links.resize(state.agents.size());
    last_rejection.resize(state.agents.size());
  }

  void open_endpoints() {
    signal = std::make_shared<bus::Signal>();
    hellos = participant.create_reader<protocol::AgentHello>({"", nullptr, bus::Durability::kVolatile, 64});
    admissions = participant.create_writer<protocol::Admission>({"", nullptr, bus::Durability::kVolatile, 64});
    status = participant.create_writer<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
    events = participant.create_writer<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256});
    statuses = participant.create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 16});
    std::random_device device;
    while (world_id == 0) world_id = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }

  void emit(const protocol::WorldEvent& e, const std::vector<Deposition>& cells = {}) {
    write_logged(*events, e, "a world event");
    if (event_log) event_log->append(e, cells);
  }

  void note(const std::string& text) {
    spdlog::info("step {}: {}", state.step, text);
    if (event_log) event_log->note(state.step, text);
  }

  protocol::WorldEvent make_event(std::uint32_t agent, protocol::EventKind kind, std::string detail) const {
    protocol::WorldEvent e;
    e.step = state.step;
    e.agent_id = agent;
    e.kind = kind;
    e.detail = std::move(detail);
    return e;
  }

  /// Appends a record to run.log (IoError ends the run: nothing the world does goes unrecorded).
  void record(const proto::LogRecord& r) { run_log->append(r); }

  /// Opens the partition endpoints of agent `id`'s admitted session (replacing another session's).
  void open_link(std::uint32_t id) {
    const AgentRecord& a = state.agent(id);
    AgentLink& link = links[id - 1];
    if (link.requests && link.session == a.session) return;
    const std::string partition = protocol::partition_for(options.run_id, id, a.session);
    link = AgentLink{};
    link.session = a.session;
    link.frames =
        participant.create_writer<protocol::SensorFrame>({partition, nullptr, bus::Durability::kVolatile, 64});
    link.requests =
        participant.create_reader<protocol::ActionRequest>({partition, signal, bus::Durability::kVolatile, 64});
    spdlog::info("agent {} '{}' ({}) on partition {}", id, a.name, a.type.name, partition);
  }

  /// True when the request writer of the slot's admitted session is alive.
  bool holder_connected(std::uint32_t id) const {
    if (!state.has_agent(id)) return false;
    const AgentLink& link = links[id - 1];
    return link.requests && link.requests->alive_writers() >= 1;
  }

  /// True when `hello` is a new session of a live agent whose session is still connected, seen for less than
  /// kTakeoverWait: it is not answered yet (see kTakeoverWait).
  bool waits_for_takeover(const protocol::AgentHello& hello, Clock::time_point now) {
    if (!state.has_agent(hello.agent_id)) return false;
    const AgentRecord& a = state.agent(hello.agent_id);
    if (!a.alive || a.session == hello.session || !holder_connected(hello.agent_id)) return false;
    if (!persistent(hello, now)) return true;  // a sender that said hello once (a flood) is not even logged
    if (takeover_since.size() >= kMaxRefusalKeys) takeover_since.clear();
    const auto [it, first] = takeover_since.try_emplace({hello.agent_id, hello.session}, now);
    if (first)
      spdlog::info(
          "agent {}: session {:016x} says hello while session {:016x} is still connected; waiting up to {} s "
          "for it to go",
          hello.agent_id, hello.session, a.session,
          std::chrono::duration_cast<std::chrono::seconds>(kTakeoverWait).count());
    return now - it->second < kTakeoverWait;
  }

  /// True when (id, session) said hello before, at least kHelloConfirmation ago (and within the last two generations of
  /// kHelloMemory). A real agent repeats its hello every 200 ms until answered; a flood of random sessions never does,
  /// so it never takes a slot. Bounded: a generation holds at most the hellos taken in kHelloMemory (64 per 20 ms).
  bool persistent(const protocol::AgentHello& hello, Clock::time_point now) {
    if (now - seen_rotated >= kHelloMemory) {
      seen_previous = std::move(seen_current);
      seen_current.clear();
      seen_rotated = now;
    }
    const auto key = std::make_pair(hello.agent_id, hello.session);
    Clock::time_point first = now;
    if (const auto it = seen_previous.find(key); it != seen_previous.end()) first = it->second;
    const auto [it, fresh] = seen_current.try_emplace(key, first);
    if (!fresh) first = std::min(first, it->second);
    return now - first >= kHelloConfirmation;
  }

  /// True when (id, session) may be answered now: each at most every kAnswerInterval (bounded bookkeeping).
  bool may_answer(const protocol::AgentHello& hello, Clock::time_point now) {
    const auto key = std::make_pair(hello.agent_id, hello.session);
    const auto it = answered_at.find(key);
    if (it != answered_at.end() && now - it->second < kAnswerInterval) return false;
    if (answered_at.size() >= kMaxAnswerKeys) answered_at.clear();
    answered_at[key] = now;
    return true;
  }

  /// Takes the pending hellos (at most every kHelloInterval unless `now_please`) and answers them; carries out accepted
  /// admissions (first, re-admission, takeover), records them in run.log and opens the session's endpoints.
  void service_hellos(bool now_please = false) {
    const Clock::time_point now = Clock::now();
    if (!now_please && now < next_hello_service) return;
    next_hello_service = now + kHelloInterval;
    check_other_worlds();
    if (!run_started && now >= next_admitting_status) {
      publish_status(true, false, 0.0);
      next_admitting_status = now + 500ms;
    }
    int refusal_answers = 0;
    for (const protocol::AgentHello& hello : hellos->take()) {
      if (waits_for_takeover(hello, now)) continue;
      const AdmissionDecision decision = decide_admission(state, hello, run_started, holder_connected(hello.agent_id));
      if (decision.accepted && decision.kind != AdmissionKind::kRepeat) {
        const protocol::AgentHello slot = slot_hello(state, hello, decision);  // "any slot": the one assigned
        if (!persistent(hello, now)) continue;                                 // answered when it says hello again
        const std::uint64_t previous = state.agent(slot.agent_id).session;
        if (admit(state, slot, decision.kind)) {
          record(admitted_record(state, slot.agent_id, decision.kind));
          AgentRecord& a = state.agent(slot.agent_id);
          if (decision.kind != AdmissionKind::kFirst && a.session != previous) sensing->forget(slot.agent_id);
          open_link(slot.agent_id);
          links[slot.agent_id - 1].not_alive_since.reset();
          std::string detail = a.name;
          if (decision.kind == AdmissionKind::kReadmission)
            detail += fmt::format(" (re-admitted, {} of {})", a.readmissions, kMaxReadmissions);
          if (decision.kind == AdmissionKind::kTakeover)
            detail += fmt::format(" (session {:016x} takes over from {:016x})", a.session, previous);
          spdlog::info("admitted agent {}: {}", slot.agent_id, detail);
          emit(make_event(slot.agent_id, protocol::EventKind::kAdmitted, detail));
        }
      } else if (!decision.accepted) {
        ++refusals;
        // Agents repeat their hello: each (id, session) is logged and published once (while the bounded memory of
        // them lasts; then every 1st, 10th, 100th ... refusal), answered every time it may be.
        const bool fresh = refused.size() < kMaxRefusalKeys ? refused.insert({hello.agent_id, hello.session}).second
                                                            : power_of_ten(refusals);
        if (fresh) {
          spdlog::warn("refused agent {}: {} ({} refusals so far)", hello.agent_id, decision.reason, refusals);
          emit(make_event(hello.agent_id, protocol::EventKind::kRefused, decision.reason));
        }
      }
      // Refusals are answered at most kMaxRefusalAnswers per round: a flood of hellos must not become a flood of
      // admissions.
      if (!decision.accepted && ++refusal_answers > kMaxRefusalAnswers) continue;
      if (may_answer(hello, now))
        write_logged(*admissions, admission_message(state, hello, decision, options.run_id), "an admission");
    }
  }

  /// Drops every live agent whose request writer was alive and has not been alive again for kLivelinessGrace.
  void check_liveliness() {
    const Clock::time_point now = Clock::now();
    for (std::uint32_t id : state.live_ids()) {
      AgentLink& link = links[id - 1];
      if (link.requests->alive_writers() >= 1) {
        if (link.not_alive_since) spdlog::info("agent {}: its request writer is alive again", id);
        link.writer_seen = true;
        link.not_alive_since.reset();
      } else if (link.writer_seen) {
        if (!link.not_alive_since) {
          link.not_alive_since = now;
          spdlog::info("agent {}: its request writer lost liveliness; dropped unless it is back within {} s", id,
                       std::chrono::duration_cast<std::chrono::seconds>(kLivelinessGrace).count());
        } else if (now - *link.not_alive_since >= kLivelinessGrace) {
          spdlog::warn("agent {} dropped: its request writer lost liveliness", id);
          record(dropped_record(state, id, "request writer lost liveliness"));
          emit(drop_agent(state, id, "request writer lost liveliness"));
        }
      }
    }
  }

  bool ready(std::uint32_t id) const {
    const AgentLink& link = links[id - 1];
    return link.frames->matched_readers() >= 1 && link.requests->alive_writers() >= 1;
  }

  void admit_agents(const std::atomic<bool>& stop) {
    const Clock::time_point deadline = Clock::now() + seconds(options.admit_timeout_s);
    const std::size_t expected = state.agents.size();
    for (;;) {
      service_hellos(true);
      check_liveliness();
      std::size_t admitted = 0;
      bool all_ready = true;
      for (const AgentRecord& a : state.agents) {
        admitted += a.admitted ? 1 : 0;
        if (a.alive && !ready(a.id)) all_ready = false;
      }
      if (admitted == expected && all_ready) return;
      const Clock::time_point now = Clock::now();
      if (stop || now >= deadline) break;
      signal->wait_until(std::min(
          deadline, now + (admitted == expected ? kReadyPollInterval
                                                : std::chrono::duration_cast<Clock::duration>(kHelloInterval))));
    }
    std::size_t admitted = 0, ready_count = 0;
    for (const AgentRecord& a : state.agents) {
      admitted += a.admitted ? 1 : 0;
      ready_count += a.alive && ready(a.id) ? 1 : 0;
    }
    if (admitted == 0)
      throw Error(stop ? "stopped before any agent was admitted"
                       : "no agent admitted within the admit timeout of " + format_seconds(options.admit_timeout_s) +
                             " (expected " + std::to_string(expected) + " on run '" + options.run_id + "')");
    spdlog::warn("starting with {} of {} agents admitted, {} of them connected ({})", admitted, expected, ready_count,
                 stop ? "stopped during admission" : "admit timeout");
  }

  void send_frame(std::uint32_t id, bool run_over) {
    AgentLink& link = links[id - 1];
    link.frame = sensing->frame_for(state, id, run_over);
    write_logged(*link.frames, *link.frame, "a sensor frame");
  }

  /// Requests of the current step's live agents until all answered, the deadline passes, or stop. At most
  /// kMaxRequestsPerPartition are taken from one partition in a step; the rest are counted in `surplus`. An agent
  /// that has not answered after kResendInterval gets its frame again.
  std::vector<Submission> collect(const std::atomic<bool>& stop, std::uint32_t& surplus) {
    const Clock::time_point deadline = Clock::now() + seconds(options.step_deadline_s);
    Clock::time_point next_resend = Clock::now() + kResendInterval;
    std::vector<Submission> submissions;
    std::vector<bool> answered(state.agents.size(), false);
    std::vector<std::size_t> taken(state.agents.size(), 0);
    surplus = 0;
    for (;;) {
      service_hellos();
      for (const AgentRecord& a : state.agents) {
        if (!links[a.id - 1].requests) continue;
        std::vector<protocol::ActionRequest> received = links[a.id - 1].requests->take();
        if (!a.alive) continue;  // a dropped agent's requests are read only to be discarded
        for (protocol::ActionRequest& r : received) {
          // The owner's answer for this step is always taken; the limit applies to everything else, so a flood on
          // an agent's partition never displaces its own request.
          const bool answer = !answered[a.id - 1] && r.step == state.step && carries_identity_of(a, r);
          if (!answer && taken[a.id - 1] >= kMaxRequestsPerPartition) {
            ++surplus;
            continue;
          }
          if (answer)
            answered[a.id - 1] = true;
          else
            ++taken[a.id - 1];
          submissions.push_back({a.id, std::move(r)});
        }
      }
      const Clock::time_point now = Clock::now();
      if (now >= next_liveliness_check) {
        check_liveliness();
        next_liveliness_check = now + kLivelinessPoll;
      }
      const std::vector<std::uint32_t> live = state.live_ids();
      if (std::all_of(live.begin(), live.end(), [&](std::uint32_t id) { return answered[id - 1]; })) break;
      if (stop || now >= deadline) break;
      if (now >= next_resend) {
        for (std::uint32_t id : live) {
          if (answered[id - 1]) continue;
          AgentLink& link = links[id - 1];
          if (link.frame && link.frame->step == state.step)
            write_logged(*link.frames, *link.frame, "a sensor frame");
          else
            send_frame(id, false);  // admitted during this step (re-admission, takeover): its first frame of it
        }
        next_resend = now + kResendInterval;
      }
      signal->wait_until(std::min({deadline, next_resend, now + kPollInterval}));
      step_waited += Clock::now() - now;
    }
    return submissions;
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
      throw Error(
          fmt::format("another marsala-world runs on DDS domain {} (run '{}', scenario '{}', {}): one world per "
                      "domain; give this one another --domain",
                      participant.domain_id(), other.run_id, other.scenario,
                      other.admitting ? "admitting its agents" : "at step " + std::to_string(other.step)));
    }
  }

  void publish_status(bool running, bool completed, double wall_seconds) {
    protocol::WorldStatus s;
    s.world_id = world_id;
    s.admitting = running && !run_started;
    s.run_id = options.run_id;
    s.scenario = scenario.name;
    s.step = state.step;
    s.wall_seconds = wall_seconds;
    s.deposited_volume_m3 = state.deposited_volume_m3;
    s.progress = progress(state);
    s.progress_detail = progress_detail(state);
    s.running = running;
    s.completed = completed;
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
      s.agents.push_back(std::move(as));
    }
    write_logged(*status, s, "the world status");
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

  /// The cells the accepted request of `agent` set in this step (for its deposition in events.log).
  static const std::vector<Deposition>& deposited_cells(const std::vector<Submission>& submissions,
                                                        const StepOutcome& outcome, std::uint32_t agent) {
    static const std::vector<Deposition> none;
    for (std::size_t i = 0; i < submissions.size(); ++i)
      if (outcome.accepted_submissions[i] && submissions[i].channel_id == agent) return outcome.raised_cells[i];
    return none;
  }

  /// Runs steps until an end condition; returns the end reason.
  protocol::EndReason lockstep(const std::atomic<bool>& stop, Clock::time_point start) {
    for (;;) {
      if (frames) frames->maybe_write(state.step, false, [this] { return frame_picture(false); });
      if (stop) return protocol::EndReason::kSignal;
      if (is_completed(state)) return protocol::EndReason::kCompleted;
      if (state.step >= options.max_steps) return protocol::EndReason::kMaxSteps;
      const std::vector<std::uint32_t> live = state.live_ids();
      if (live.empty()) return protocol::EndReason::kNoLiveAgents;
      const Clock::time_point step_start = Clock::now();
      step_waited = Clock::duration::zero();
      for (std::uint32_t id : live) send_frame(id, false);
      std::uint32_t surplus = 0;
      std::vector<Submission> submissions = collect(stop, surplus);
      if (stop) return protocol::EndReason::kSignal;  // the interrupted step is not applied
      const StepOutcome outcome = apply_step(state, submissions);
      state.surplus_requests += surplus;
      // Recorded before anything of the step is published: a crash never loses a step an agent has seen applied.
      record(step_record(submissions, outcome, state, surplus));
      if (surplus > 0)
        note(fmt::format("{} requests beyond {} per partition ignored", surplus, kMaxRequestsPerPartition));
      if (options.snapshot_every > 0 && state.step % options.snapshot_every == 0) take_snapshot();
      const Clock::duration step_took = Clock::now() - step_start;
      step_ms.push_back(std::chrono::duration<double, std::milli>(step_took).count());
      step_world_ms.push_back(std::chrono::duration<double, std::milli>(step_took - step_waited).count());
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
      // An agent dropped for missing its deadlines may only be slow or hung: tell it the run is over for it.
      for (std::uint32_t id : outcome.dropped) send_frame(id, true);
      publish_status(true, outcome.completed, elapsed_s(start));
      if (state.step % kProgressEvery == 0)
        spdlog::info("step {}: {} live agents, {:.6f} m3 deposited, progress {:.3f}: {}", state.step,
                     state.live_ids().size(), state.deposited_volume_m3, progress(state), progress_detail(state));
    }
  }

  /// One line on how the run completes and where its terrain check stands at the start.
  void log_completion() const {
    switch (state.completion) {
      case scenario::CompletionKind::kAgentsAtGoal: spdlog::info("completion: agents_at_goal"); break;
      case scenario::CompletionKind::kPayloadPath:
        spdlog::info("completion: payload_path from ({}, {}) to ({}, {}), checked every {} steps: {}",
                     state.payload_path.from.x, state.payload_path.from.y, state.payload_path.to.x,
                     state.payload_path.to.y, state.payload_path.check_every_steps,
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

  /// Waits until every agent told that the run is over has closed its request writer, or the linger time passes.
  void linger(const std::vector<std::uint32_t>& ids) {
    const Clock::time_point deadline = Clock::now() + seconds(options.linger_s);
    for (;;) {
      const bool gone = std::all_of(ids.begin(), ids.end(),
                                    [&](std::uint32_t id) { return links[id - 1].requests->alive_writers() == 0; });
      const Clock::time_point now = Clock::now();
      if (gone || now >= deadline) return;
      signal->wait_until(std::min(deadline, now + kPollInterval));
    }
  }

  /// snapshot.pb of the state after the step just recorded; run.log is synced first, so that the snapshot never
  /// points past what a crash of the machine keeps.
  void take_snapshot() {
    run_log->sync();
    write_snapshot((std::filesystem::path(options.out_dir) / kSnapshotFile).string(),
                   make_snapshot(state, options.run_id, run_log->bytes()));
  }

  /// Opens run.log: a new one with its header, or (resumed) the existing one cut after its last good record.
  void open_run_log() {
    const std::string path = (std::filesystem::path(options.out_dir) / kRunLogFile).string();
    if (!resume) {
      LogStart start;
      start.scenario_text = options.scenario_text;
      start.run_id = options.run_id;
      start.agents = static_cast<std::uint32_t>(state.agents.size());
      start.max_steps = options.max_steps;
      start.step_deadline_s = options.step_deadline_s;
      run_log = runlog::RunLogWriter::create(path, log_header(scenario, start, state.terrain));
      return;
    }
    run_log = runlog::RunLogWriter::continue_at(path, resume->good_bytes);
    proto::LogRecord r;
    r.mutable_resumed()->set_step(state.step);
    r.mutable_resumed()->set_snapshot_step(resume->snapshot_step);
    record(r);
    ++state.resumes;
  }

  /// A resumed run: reopens the endpoints of the agents that were live and waits (answering hellos) until each is
  /// ready again, or the admit timeout; agents that do not come back miss their steps and are dropped by the rules.
  void reconnect_agents(const std::atomic<bool>& stop) {
    for (const AgentRecord& a : state.agents)
      if (a.alive) open_link(a.id);
    const Clock::time_point deadline = Clock::now() + seconds(options.admit_timeout_s);
    for (;;) {
      service_hellos(true);
      const std::vector<std::uint32_t> live = state.live_ids();
      if (std::all_of(live.begin(), live.end(), [&](std::uint32_t id) { return ready(id); })) return;
      const Clock::time_point now = Clock::now();
      if (stop || now >= deadline) break;
      signal->wait_until(std::min(deadline, now + std::chrono::duration_cast<Clock::duration>(kHelloInterval)));
    }
    std::vector<std::uint32_t> missing;
    for (std::uint32_t id : state.live_ids())
      if (!ready(id)) missing.push_back(id);
    spdlog::warn("resuming without {} of {} live agents reconnected: {}", missing.size(), state.live_ids().size(),
                 fmt::join(missing, ", "));
  }

  /// A time-lapse frame: the terrain now, drawn like final_zoom.png (depositors' colours, agents, base, target; no
  /// route, which would cost a payload plan per frame) on the window fixed at the start, or like final.png without one.
  render::Image frame_picture(bool last) const {
    RunInfo info;
    info.scenario = fmt::format("{}, step {}", scenario.name, state.step);  // the close-up's title names no step
    info.completed = last && is_completed(state);
    if (!frame_window) return render::render_terrain(state.terrain, final_picture_options(state, info, std::nullopt));
    const CellRect& w = *frame_window;
    return render::render_terrain(state.terrain.window(w.first, w.rows, w.cols),
                                  final_picture_options(state, info, std::nullopt, w));
  }

  /// The last frame and timelapse.mp4 (ffmpeg); a time-lapse that cannot be finished is an error of the run.
  void finish_frames() {
    if (!frames) return;
    frames->maybe_write(state.step, true, [this] { return frame_picture(true); });
    const render::TimelapseResult video = frames->finish(options.search_path);
    spdlog::info("time-lapse: {} frames in {} ({:.3f} s drawing){}", frames->names().size(), frames->dir(),
                 frames->seconds(),
                 video.path.empty() ? "; " + video.note : fmt::format(", {} ({:.3f} s)", video.path, video.seconds));
  }

  RunResult run(const std::atomic<bool>& stop) {
    const Clock::time_point admit_start = Clock::now();
    if (resume) {
      event_log.emplace((std::filesystem::path(options.out_dir) / "events.log").string(), true);
    } else {
      write_initial_outputs(options.out_dir, state.terrain);
      event_log.emplace((std::filesystem::path(options.out_dir) / "events.log").string());
    }
    if (options.frames_every > 0) {
      // A resumed run goes on adding frames to its folder; a fresh one never mixes its frames with another's.
      const std::string dir = (std::filesystem::path(options.out_dir) / "frames").string();
      if (!resume) render::check_fresh_frames_dir(dir, "another run's time-lapse");
      frames.emplace(dir, options.frames_every);
      // One window for every frame, so that the time-lapse does not jump: the close-up of the base and the payload
      // ends or the site (and what was built before a resume), as final_zoom.png frames them.
      frame_window = zoom_window(state, std::nullopt);
    }
    open_run_log();
    open_endpoints();
    if (resume) {
      run_started = true;
      spdlog::info("run '{}' resumed at step {}: {} records replayed{} in {:.3f} s", options.run_id, state.step,
                   resume->records,
                   resume->snapshot_step > 0 ? fmt::format(" after the snapshot of step {}", resume->snapshot_step)
                                             : std::string(),
                   resume->rebuild_seconds);
      if (!resume->tail_problem.empty()) spdlog::warn("cut run.log's damaged tail: {}", resume->tail_problem);
      if (!resume->snapshot_problem.empty())
        spdlog::warn("snapshot not used ({}); replayed run.log from its start", resume->snapshot_problem);
      note(fmt::format("resumed: {} records replayed{}{}", resume->records,
                       resume->snapshot_step > 0 ? fmt::format(" after the snapshot of step {}", resume->snapshot_step)
                                                 : std::string(),
                       resume->tail_problem.empty() ? std::string() : "; cut " + resume->tail_problem));
      log_completion();
      reconnect_agents(stop);
    } else {
      spdlog::info("run '{}': scenario '{}', {} x {} cells of {} m, waiting for {} agents (admit timeout {} s)",
                   options.run_id, scenario.name, state.terrain.rows(), state.terrain.cols(),
                   state.terrain.cell_size_m(), state.agents.size(), options.admit_timeout_s);
      log_completion();
      admit_agents(stop);
    }
    const double admit_seconds = elapsed_s(admit_start);
    std::uint32_t connected = 0;
    for (const AgentRecord& a : state.agents) connected += a.alive && ready(a.id) ? 1 : 0;
    run_started = true;
    const Clock::time_point start = Clock::now();
    const double cpu_before = process_cpu_seconds();
    publish_status(true, false, 0.0);
    const protocol::EndReason end_reason = lockstep(stop, start);
    const double cpu_steps = process_cpu_seconds() - cpu_before;

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
    record(end);
    run_log->sync();
    for (std::uint32_t id : live) send_frame(id, true);
    emit(make_event(0, protocol::EventKind::kRunOver, to_string(end_reason)));
    publish_status(false, result.completed, result.wall_seconds);

    RunInfo info;
    info.scenario = scenario.name;
    info.scenario_file = scenario.source_path;
    info.overrides = scenario.overrides;
    info.run_id = options.run_id;
    info.dds = bus::to_string(participant.vendor());
    info.seed = scenario.seed;
    info.start_jitter_m = scenario.start_jitter_m;
    if (scenario.has_goal_vector_map) info.goal_vector_map = scenario.goal_vector_map;
    info.initial_terrain = std::move(initial_terrain);
    info.completed = result.completed;
    info.end_reason = end_reason;
    info.wall_seconds = result.wall_seconds;
    info.step_wall_median_ms = percentile(step_ms, 0.5);
    info.step_wall_p90_ms = percentile(step_ms, 0.9);
    info.step_world_median_ms = percentile(step_world_ms, 0.5);
    info.step_world_p90_ms = percentile(step_world_ms, 0.9);
    info.world_cpu_ms_per_step = step_ms.empty() ? 0.0 : 1000.0 * cpu_steps / static_cast<double>(step_ms.size());
    info.admit_seconds = admit_seconds;
    info.connected = connected;
    write_final_outputs(options.out_dir, state, info);
    finish_frames();
    for (const AgentRecord& a : state.agents) result.admitted += a.admitted ? 1 : 0;
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
  std::optional<SensingService> sensing;
  std::vector<AgentLink> links;  ///< [id - 1]
  std::shared_ptr<bus::Signal> signal;
  std::vector<double> step_ms;  ///< wall time of each lockstep step [ms]
  std::vector<double> step_world_ms;  ///< the world's own part of each step: its wall time less its waits [ms]
  Clock::duration step_waited{};      ///< time the current step spent waiting for requests
  Clock::time_point next_liveliness_check{};  ///< collect() checks the agents' liveliness from then on
  Heightmap initial_terrain;    ///< kept for goal_vector_map.png and payload_path's construction sites
  std::unique_ptr<bus::Reader<protocol::AgentHello>> hellos;
  std::unique_ptr<bus::Writer<protocol::Admission>> admissions;
  std::unique_ptr<bus::Writer<protocol::WorldStatus>> status;
  std::unique_ptr<bus::Writer<protocol::WorldEvent>> events;
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> statuses;  ///< other worlds' status on this domain
  std::uint64_t world_id = 0;                                    ///< random, this process's
  Clock::time_point next_admitting_status{};
  std::optional<EventLog> event_log;
  std::optional<render::FrameWriter> frames;  ///< --frames-every
  std::optional<CellRect> frame_window;       ///< the frames' close-up; none = the whole terrain
  std::vector<std::string> last_rejection;  ///< [id - 1]: the rejection reason last logged at info level
  std::set<std::pair<std::uint32_t, std::uint64_t>> refused;  ///< (id, session) already reported as refused
  std::map<std::pair<std::uint32_t, std::uint64_t>, Clock::time_point> answered_at;  ///< last answer per sender
  std::map<std::pair<std::uint32_t, std::uint64_t>, Clock::time_point>
      takeover_since;  ///< first hello of a new session
  std::map<std::pair<std::uint32_t, std::uint64_t>, Clock::time_point> seen_current, seen_previous;  ///< persistent()
  Clock::time_point seen_rotated{};
  std::uint64_t refusals = 0;
  Clock::time_point next_hello_service{};
  bool run_started = false;
  std::optional<ResumeInfo> resume;
  std::uint64_t resume_step = 0;  ///< the step a resumed run continued at
  std::optional<runlog::RunLogWriter> run_log;
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

const WorldState& WorldRuntime::state() const { return impl_->state; }

const std::string& WorldRuntime::run_id() const { return impl_->options.run_id; }

}  // namespace marsala::world_server
