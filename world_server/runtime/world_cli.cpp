#include "marsala/world_server/runtime/world_cli.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <optional>
#include <ostream>
#include <thread>
#include <utility>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/cli/command_line.hpp"
#include "marsala/cli/logging.hpp"
#include "marsala/core/error.hpp"
#include "marsala/protocol/end_reason.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/records/output_lock.hpp"
#include "marsala/world_server/records/run_key_file.hpp"
#include "marsala/world_server/records/run_outputs.hpp"
#include "marsala/world_server/runtime/fork_start.hpp"
#include "marsala/world_server/runtime/metrics_server.hpp"
#include "marsala/world_server/runtime/scenario_check.hpp"
#include "marsala/world_server/runtime/step_trace.hpp"
#include "marsala/world_server/runtime/world_runtime.hpp"

namespace marsala::world_server {
namespace {

/// The start of a new run of `scenario_path`: the scenario read, parsed and checked as --check does, the terrain
/// built, a previous run's files removed from --out with --replace. Throws what the world refuses at start.
WorldStart fresh_start(const std::string& scenario_path, RuntimeOptions options, int domain) {
  options.scenario_text = scenario::read_scenario_text(scenario_path);
  if (options.replace) clear_run_files(options.out_dir);
  const scenario::Scenario scenario = scenario::parse_scenario(options.scenario_text, scenario_path, options.overrides);
  return prepare_world_start(scenario, scenario::build_terrain(scenario), std::move(options), domain);
}

/// The options of how long the world waits (--silence-timeout) and what it records besides the run (--snapshot-every,
/// --frames-every).
void add_timing_and_record_options(CLI::App& app, RuntimeOptions& options) {
  app.add_option("--silence-timeout", options.silence_timeout_s,
                 "how long a step is held while no live agent is heard at all (the world's host cut off, or the\n"
                 "whole team) before the drop rules apply [s]; 0: for ever (docs/runtime.md#silence)")
      ->check(cli::seconds_within(0.0, 1e9, " (0: for ever)"))
      ->capture_default_str();
  app.add_option("--snapshot-every", options.snapshot_every, "write snapshot.pb after every N steps (0: never)")
      ->check(CLI::Range(0ull, 1ull << 40))
      ->capture_default_str();
  app.add_option("--frames-every", options.frames_every,
                 "a time-lapse: a PNG frame every K steps and the last into OUT/frames (frame_<step>.png), and\n"
                 "OUT/frames/timelapse.mp4 of them when ffmpeg is on PATH")
      ->check(cli::at_least_one())
      ->type_name("K");
}

/// The --run-key option (docs/runtime.md#who-wrote-it).
void add_run_key_option(CLI::App& app, std::string& run_key) {
  app.add_option("--run-key", run_key,
                 "the run's key (64 hex digits; default: a new one, kept in OUT/run.key and read back by --resume):\n"
                 "agents and monitors given it believe only this run's world (docs/runtime.md#who-wrote-it)")
      ->type_name("FILE");
}

/// The options of the metrics server (docs/runtime.md#metrics): --metrics-port, --metrics-address, --metrics-linger.
void add_metrics_options(CLI::App& app, MetricsOptions& metrics) {
  CLI::Option* port = app.add_option("--metrics-port", metrics.port,
                                     "serve the run's metrics in the Prometheus text format on http://ADDRESS:P/metrics\n"
                                     "(docs/runtime.md#metrics); a port that cannot be listened on exits 2 before anything is written")
                          ->check(CLI::Range(1, 65535))
                          ->type_name("P");
  app.add_option("--metrics-address", metrics.address, "numeric address the metrics server listens on")
      ->needs(port)
      ->capture_default_str();
  app.add_option("--metrics-linger", metrics.linger_s,
                 "after the run's end, keep serving its last values this long, so that the last scrape sees them\n"
                 "(not after a run stopped by a signal) [s]")
      ->needs(port)
      ->check(cli::seconds_within(0.0, 3600.0))
      ->capture_default_str();
}

/// The metrics server when --metrics-port asks for one, bound before the run's folder is touched; exit code 2 (one
/// line naming the port) when it cannot listen.
std::optional<int> start_metrics(std::unique_ptr<MetricsServer>& server, const MetricsOptions& options,
                                 std::ostream& err) {
  if (options.port == 0) return std::nullopt;
  try {
    server = std::make_unique<MetricsServer>(options);
    return std::nullopt;
  } catch (const Error& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return cli::kExitUsage;
  }
}

/// After a run that ended (not by a signal, not in an error), the metrics server keeps serving the last values for
/// --metrics-linger seconds, or until `stop`.
void linger_for_metrics(const MetricsServer* server, const MetricsOptions& options, int code,
                        const std::atomic<bool>& stop) {
  const int signalled = protocol::exit_code(protocol::EndReason::kSignal);
  if (server == nullptr || code == 1 || code == cli::kExitUsage || code == signalled) return;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.linger_s);
  while (!stop && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

/// The step trace when --trace asks for one, its FILE.tmp opened before the run's folder is touched; exit code 2 (one
/// line naming the file) when it cannot be written.
std::optional<int> start_trace(std::unique_ptr<StepTrace>& trace, const std::string& path, std::ostream& err) {
  if (path.empty()) return std::nullopt;
  try {
    trace = std::make_unique<StepTrace>(path, std::chrono::steady_clock::now());
    return std::nullopt;
  } catch (const Error& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return cli::kExitUsage;
  }
}

/// Exit code 2 (one line) when --run-key names no run key: refused before the folder is touched (settle_run_key()
/// reads it again once the folder is the run's).
std::optional<int> refuse_bad_run_key(const std::string& path, std::ostream& err) {
  try {
    if (!path.empty()) protocol::load_run_key(path);
    return std::nullopt;
  } catch (const InvalidArgument& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: --run-key {}", e.what()));
    return cli::kExitUsage;
  }
}

/// The world's DDS participant as the command line asks for it.
bus::BusConfig bus_config(const cli::DdsOptions& dds) {
  return {bus::vendor_from_string(dds.vendor), dds.domain, dds.profile, bus::Role::kWorld,
          bus::Security::of(dds.security, dds.identity, "world"), dds.peers};
}

/// Exit code 2 (one line naming the file, property or value) when the DDS options are ones the participant would refuse
/// (a profile that cannot be read, of the other vendor or with a bad rate limit; a DDS Security folder made for another
/// domain): refused before the folder is touched.
std::optional<int> refuse_bad_dds(const cli::DdsOptions& dds, std::ostream& err) {
  try {
    bus::check_config(bus_config(dds));
    return std::nullopt;
  } catch (const InvalidArgument& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return cli::kExitUsage;
  }
}

/// Locks the run's output folder into `lock` (docs/runtime.md#run-folders); the exit code when it cannot: 2 (one line
/// naming the holder's pid) when another world holds it, 1 when the folder or its lock file cannot be made.
std::optional<int> lock_folder(std::optional<OutputLock>& lock, const std::string& dir, std::ostream& err) {
  try {
    lock.emplace(dir);
    return std::nullopt;
  } catch (const FolderInUse& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return cli::kExitUsage;
  } catch (const Error& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return 1;
  }
}

/// marsala-world --fork DIR --at K (docs/runtime.md#fork); dir empty: no fork.
struct ForkRequest {
  std::string dir;
  std::uint64_t at = 0;  ///< K [steps]
};

/// The --fork DIR and --at K options (docs/runtime.md#fork), excluding `others`; returns --fork.
CLI::Option* add_fork_options(CLI::App& app, ForkRequest& fork, const std::vector<CLI::Option*>& others) {
  CLI::Option* fork_option =
      app.add_option("--fork", fork.dir,
                     "start a new run (in --out) from the run in DIR: its first K steps (--at) replayed with fresh\n"
                     "agents, each request checked against DIR/run.log (exit 8 naming the agent and step when one\n"
                     "differs), then live with --agents (fewer leave at K, more join at K), --max-steps,\n"
                     "--step-deadline, --set of world-only fields (docs/runtime.md#fork)")
          ->type_name("DIR");
  for (CLI::Option* other : others) fork_option->excludes(other);
  app.add_option("--at", fork.at, "with --fork: the step K the fork goes live at (0 .. the parent's steps)")
      ->needs(fork_option)
      ->check(CLI::Range(0ull, 1ull << 40))
      ->type_name("K");
  return fork_option;
}

/// marsala-world --check --fork DIR --at K: whether the fork can be made (prepare_fork() without a folder); 0 and one
/// line saying what it replays when it can, 2 and the reason when not.
int check_fork(const ForkRequest& fork, RuntimeOptions options, int domain, std::ostream& out, std::ostream& err) {
  options.out_dir.clear();
  options.replace = false;
  try {
    const WorldStart start = prepare_fork(fork.dir, fork.at, std::move(options), domain);
    const ForkOrigin& o = start.fork->origin();
    out << fmt::format(
        "fork of {} (run '{}', {} agents): its first {} steps replayed, live from step {} with {} agents; the "
        "parent's terrain sha256 there {}\n",
        o.parent_dir, o.parent_run_id, o.parent_agents, o.at_step, o.at_step, o.agents, o.parent_sha256_at_step);
    return 0;
  } catch (const Error& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return cli::kExitUsage;
  }
}

/// The run, once its folder is locked: the start (fresh or resumed), the run key, the participant, the lockstep and the
/// last line; the exit code (docs/runtime.md#exit-codes), errors as one line.
int run_in_folder(const std::string& scenario_path, const std::string& resume_dir, const ForkRequest& fork,
                  const std::string& run_key, const RuntimeOptions& options, const cli::DdsOptions& dds,
                  MetricsServer* metrics, StepTrace* trace, const std::atomic<bool>& stop, std::ostream& out,
                  std::ostream& err) {
  try {
    WorldStart start;
    if (!resume_dir.empty()) {
      start = prepare_resume(resume_dir, options, dds.domain);
    } else if (!fork.dir.empty()) {
      try {
        start = prepare_fork(fork.dir, fork.at, options, dds.domain);
      } catch (const Error& e) {  // no fork to make: nothing written (docs/runtime.md#fork)
        cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
        return cli::kExitUsage;
      }
    } else {
      try {
        start = fresh_start(scenario_path, options, dds.domain);
      } catch (const Error& e) {  // refused at start, as --check refuses it (docs/runtime.md#exit-codes)
        cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
        return kExitInvalidScenario;
      }
    }
    start.options.run_key = settle_run_key(run_key, start.options.out_dir, !resume_dir.empty());
    const auto participant = bus::make_participant(bus_config(dds));
    WorldRuntime runtime(std::move(start), *participant);
    if (metrics != nullptr) runtime.serve_metrics(*metrics);
    if (trace != nullptr) runtime.trace_steps(*trace);
    const RunResult result = runtime.run(stop);
    out << fmt::format("run {}: {} after {} steps{}, {} agents{}, terrain sha256 {}\n", runtime.run_id(),
                       to_string(result.end_reason), result.steps,
                       result.resumed_at_step ? fmt::format(" (resumed at step {})", *result.resumed_at_step) : "",
                       result.admitted,
                       result.slots_missing > 0
                           ? fmt::format(" ({} of {} slots missing at the end)", result.slots_missing, result.team)
                           : "",
                       result.terrain_sha256);
    if (trace != nullptr) trace->finish();
    return exit_code(result.end_reason, result.slots_missing);
  } catch (const ForkMismatch& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return kExitForkMismatch;
  } catch (const Error& e) {
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return 1;
  } catch (const std::bad_alloc&) {
    cli::write_exit_error(err, "marsala-world: error: out of memory");
    return 1;
  } catch (const std::exception& e) {  // a library's own exception: still one line and exit 1, never an abort
    cli::write_exit_error(err, fmt::format("marsala-world: error: {}", e.what()));
    return 1;
  }
}

}  // namespace

int run_world_cli(int argc, const char* const* argv, const std::atomic<bool>& stop, std::ostream& out,
                  std::ostream& err) {
  CLI::App app{
      "marsala-world: the authoritative world server. Loads a scenario, admits agents over DDS, runs the\n"
      "lockstep (frames, requests, validation in agent-id order) and writes summary.json, terrain_initial.asc,\n"
      "terrain_final.asc, final.png, events.log, final_zoom.png (a close-up of what was built, unless it would\n"
      "cover more than half the terrain) and goal_vector_map.png (when the scenario has one) into --out.\n"
      "The run id (partition prefix) defaults to <scenario name>-d<domain>.\n"
      "marsala-world --check [--json] SCENARIO validates the scenario as the world would at start, without\n"
      "DDS, prints what the run would start from and exits 0 when valid, 2 when not.\n"
      "Every run also writes run.log (every accepted change, checksummed) and snapshot.pb; after a crash,\n"
      "marsala-world --resume DIR continues the run in DIR with its agents (docs/runtime.md#resume).\n"
      "A world holds its folder (DIR/world.lock) while it runs: a second world, --resume or --replace there exits 2.\n"
      "--metrics-port P serves the run's Prometheus metrics on http://127.0.0.1:P/metrics; --trace FILE writes the\n"
      "lockstep as a Chrome trace for Perfetto (docs/runtime.md#metrics, #step-traces).\n"
      "Exit codes: 0 completed, 7 completed with slots missing at the end, 3 max_steps, 4 no_live_agents,\n"
      "5 signal, 6 stalled, 8 a fork's request differed from its parent's before K, 1 error, 2 usage or a scenario\n"
      "the world refuses at start (as --check).",
      "marsala-world"};
  std::string scenario_path, check_path, resume_dir, run_key;
  cli::DdsOptions dds;
  RuntimeOptions options;
  bool quiet = false, check = false, json = false;
  CLI::Option* scenario_option =
      app.add_option("--scenario", scenario_path, "scenario file (protobuf text format); required but with --check");
  CLI::Option* check_option = app.add_flag(
      "--check", check,
      "validate the scenario as the world would at start (scenario, terrain, completion, slots, options) without\n"
      "starting DDS, print what the run would start from and exit: 0 valid, 2 not (one line naming file and field)");
  app.add_flag("--json", json, "with --check: print the report as one JSON object (idl/scenario_check.proto)")
      ->needs(check_option);
  app.add_option("SCENARIO", check_path, "with --check: the scenario file (or give --scenario)")
      ->needs(check_option)
      ->excludes(scenario_option);
  app.add_option("--agents", options.agents, "agents to wait for, ids 1..N (default: every slot of the scenario)")
      ->check(CLI::Range(1u, 100000u));
  cli::add_dds_options(app, dds);
  app.add_option("--out", options.out_dir, "output folder")->capture_default_str();
  app.add_option("--run-id", options.run_id, "run id, the prefix of every agent partition");
  app.add_option("--admit-timeout", options.admit_timeout_s,
                 "seconds to wait for all agents, from the start or the latest admission (five times this at\n"
                 "the most)")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  app.add_option("--max-steps", options.max_steps, "override the scenario's max_steps")
      ->check(CLI::Range(1ull, 1ull << 40));
  app.add_option("--step-deadline", options.step_deadline_s,
                 "override the scenario's step_deadline_s: how long a step waits for a dead or hung agent [s]")
      ->check(CLI::Range(0.001, 3600.0));
  std::uint64_t seed = 0;
  const CLI::Option* seed_option =
      app.add_option("--seed", seed, "override the scenario's seed (start jitter); summary.json reports the seed used");
  app.add_option("--set", options.overrides,
                 "change a field of the scenario, FIELD=VALUE, e.g. robot_type.body.sensing_range_m=5 (repeatable;\n"
                 "every marsala-agent must get the same; recorded in run.log and summary.json)")
      ->type_name("FIELD=VALUE");
  CLI::Option* resume_option =
      app.add_option(
             "--resume", resume_dir,
             "continue the run whose output folder is DIR after a crash of the world: its scenario, options and\n"
             "state come from DIR/run.log (and snapshot.pb); the agents that were running reconnect")
          ->excludes(scenario_option)
          ->excludes(check_option);
  ForkRequest fork;
  CLI::Option* fork_option = add_fork_options(app, fork, {scenario_option, resume_option});
  add_timing_and_record_options(app, options);
  add_run_key_option(app, run_key);
  MetricsOptions metrics_options;
  add_metrics_options(app, metrics_options);
  std::string trace_path;
  app.add_option("--trace", trace_path,
                 "write the lockstep as a Chrome trace (trace-event JSON, for Perfetto) to FILE when the run is over:\n"
                 "each step's frames, wait, application and record, each agent's wait (docs/runtime.md#step-traces)")
      ->type_name("FILE");
  app.add_flag("--replace", options.replace,
               "remove a previous run's files from --out before starting (without it such a folder is refused)")
      ->excludes(resume_option);
  app.add_flag("--quiet", quiet, "log warnings and errors only (--log-level warn)");
  cli::LogOptions log_options;
  cli::add_log_options(app, log_options);
  app.callback([&] {
    // --scenario is required of a run; a check takes its file either way; a resume reads it from the log.
    if (scenario_option->count() == 0 && check_path.empty() && resume_option->count() == 0 && fork_option->count() == 0)
      throw CLI::RequiredError(check ? "SCENARIO (or --scenario)" : "--scenario (or --resume DIR, --fork DIR)");
    if (fork_option->count() > 0 && app.get_option("--at")->count() == 0) throw CLI::RequiredError("--at K");
  });
  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-world", out, err)) return *code;

  if (seed_option->count() > 0) options.seed = seed;
  if (const char* path = std::getenv("PATH")) options.search_path = path;
  if (check) {
    // A metrics port the run could not listen on is refused by the check too (bound and let go at once).
    std::unique_ptr<MetricsServer> metrics;
    if (const auto code = start_metrics(metrics, metrics_options, err)) return *code;
    metrics.reset();
    if (!fork.dir.empty()) return check_fork(fork, options, dds.domain, out, err);
    return run_scenario_check(check_path.empty() ? scenario_path : check_path, options, dds.domain, json, out, err);
  }
  if (quiet && app.get_option("--log-level")->count() == 0) log_options.level = "warn";
  const cli::LoggingScope logging("world", 0, log_options);
  if (const auto code = refuse_bad_run_key(run_key, err)) return *code;
  if (const auto code = refuse_bad_dds(dds, err)) return *code;
  std::unique_ptr<MetricsServer> metrics;
  if (const auto code = start_metrics(metrics, metrics_options, err)) return *code;
  std::unique_ptr<StepTrace> trace;
  if (const auto code = start_trace(trace, trace_path, err)) return *code;
  // The folder is this process's from here to its exit, before --replace clears it or --resume reads it.
  std::optional<OutputLock> lock;
  if (const auto code = lock_folder(lock, resume_dir.empty() ? options.out_dir : resume_dir, err)) return *code;
  const int code =
      run_in_folder(scenario_path, resume_dir, fork, run_key, options, dds, metrics.get(), trace.get(), stop, out, err);
  linger_for_metrics(metrics.get(), metrics_options, code, stop);
  return code;
}

}  // namespace marsala::world_server
