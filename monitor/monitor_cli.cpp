#include "marsala/monitor/monitor_cli.hpp"

// CLI11 2.1's option conversions trip a false -Wmaybe-uninitialized at -O2; keep our own warnings on.
#include "marsala/cli/command_line.hpp"
#include "marsala/cli/logging.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <exception>
#include <memory>
#include <new>
#include <optional>
#include <ostream>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"
#include "marsala/monitor/follow.hpp"
#include "marsala/monitor/mcap_export.hpp"
#include "marsala/monitor/progress.hpp"
#include "marsala/monitor/replay.hpp"
#include "marsala/monitor/world_gate.hpp"
#include "marsala/monitor/run_report.hpp"
#include "marsala/monitor/serve.hpp"

namespace marsala::monitor {
namespace {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

constexpr const char* kTailLegend =
    "Columns: step; live agents/team slots; mat = material on board of the live agents [m3]; dep = volume deposited\n"
    "in the run [m3]; prog = the run's progress [%] (agents at the goal, share of the payload route's MARS gap\n"
    "filled, or level fraction of the site); then each agent's behaviour state in id order (* at its goal, --\n"
    "dropped, ? no state yet). Beyond what fits the width, live agents are counted per state. Event lines:\n"
    "step > agent kind [volume] detail. The last line gives the progress in words, and the team's slots missing.\n"
    "Exit 0 the run ended (or Ctrl-C), 1 no status for --timeout, 2 a bad option, 3 the world is gone (no live\n"
    "world status writer for --gone-after).";

constexpr const char* kReplayFooter =
    "Rebuilds the terrain from DIR/run.log on DIR/terrain_initial.asc (its SHA-256 must match the log's header),\n"
    "applying the accepted depositions step by step and checking each step's number and deposited volume and the\n"
    "run end's terrain SHA-256 against the replay. A damaged tail (a crash of the world) is reported on stderr and\n"
    "not applied. Prints a summary; the last line is \"terrain_sha256 <hex>\". Exit 0 ok, 1 the log and the replay\n"
    "disagree or a file is missing or bad, 2 usage. With ffmpeg on PATH the frames also become timelapse.mp4.";

constexpr const char* kServeFooter =
    "Serves a page that shows the run as it goes: the terrain (from --run-dir's run.log) with every raised cell\n"
    "tinted by the robot that deposited it, the robots coloured by role (active, following, returning, done,\n"
    "dropped), the base, targets, goal, site or payload, and a side panel with step, steps/s, progress and the\n"
    "agents' table. Live data comes from the world's WorldStatus and WorldEvent over DDS (read only); --replay DIR\n"
    "plays a run folder back instead, without DDS. Many browsers may watch: each gets the newest state when it asks.\n"
    "Exit 0 on Ctrl-C, 2 for a bad option or a port that cannot be listened on.";

/// Columns of the terminal on stdout, 80 when it does not say.
int terminal_columns() {
  winsize size{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

/// The monitor's DDS participant as the command line asks for it.
bus::BusConfig bus_config(const cli::DdsOptions& dds) {
  return {bus::vendor_from_string(dds.vendor), dds.domain, dds.profile, bus::Role::kServer,
          bus::Security::of(dds.security, dds.identity, "monitor"), dds.peers};
}

/// Joins the DDS domain of the command line, read only.
std::unique_ptr<bus::Participant> join_domain(const cli::DdsOptions& dds) { return bus::make_participant(bus_config(dds)); }

/// The tail subcommand: its options (define_tail binds them) and its CLI11 subcommand.
struct TailCommand {
  CLI::App* cmd = nullptr;
  TailOptions options;
  double timeout_s = 0.0;
  CLI::Option* timeout = nullptr;
  double interval_s = 0.0;
  double gone_after_s = 10.0;
};

void define_tail(CLI::App& app, TailCommand& c, cli::DdsOptions& dds) {
  c.cmd = app.add_subcommand("tail", "print one line per step (and per event) until the run ends or Ctrl-C");
  cli::add_dds_options(*c.cmd, dds);
  c.cmd->add_option("--run-id", c.options.run_id, "follow this run only (default: the first run seen)");
  c.cmd->add_flag("--events", c.options.events, "also print one line per world event");
  c.timeout = c.cmd->add_option("--timeout", c.timeout_s,
                                "exit 1 after this long without a world status [s] (default: wait forever)")
                  ->check(cli::seconds_within(1e-3, 1e6));
  c.cmd->add_option("--width", c.options.format.width, "longest line [columns]; 0 = no limit")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  c.cmd->add_option("--every", c.options.every_steps,
                    "print a step line only when the step passes a multiple of N (and the last one)")
      ->check(cli::at_least_one())
      ->type_name("N");
  c.cmd->add_option("--interval", c.interval_s, "print at most one step line every S seconds (and the last one)")
      ->check(cli::seconds_within(1e-3, 86400.0))
      ->type_name("S");
  c.cmd->add_option("--gone-after", c.gone_after_s,
                    "once the run was seen, exit 3 when no world status writer has been alive for this long [s]; "
                    "0 = never")
      ->check(cli::seconds_within(0.0, 1e6, " (0: never)"))
      ->capture_default_str();
  c.cmd->footer(kTailLegend);
}

int run_tail_command(TailCommand& c, bus::Participant& participant, const StopSource& stop, std::ostream& out,
                     std::ostream& err) {
  if (c.timeout->count() > 0) c.options.timeout = std::chrono::duration<double>(c.timeout_s);
  c.options.interval = std::chrono::duration<double>(c.interval_s);
  c.options.gone_after = std::chrono::duration<double>(c.gone_after_s);
  return run_tail(participant, c.options, stop, out, err);
}

/// The progress subcommand: its options (define_progress binds them) and its CLI11 subcommand.
struct ProgressCommand {
  CLI::App* cmd = nullptr;
  ProgressOptions options;
  double interval_s = options.interval.count();
  double timeout_s = 0.0;
  CLI::Option* timeout = nullptr;
  bool in_place = false;
  bool lines = false;
};

void define_progress(CLI::App& app, ProgressCommand& c, cli::DdsOptions& dds) {
  c.cmd = app.add_subcommand(
      "progress", "one line with the step, progress, steps/s and ETA, kept up to date, until the run ends");
  cli::add_dds_options(*c.cmd, dds);
  c.cmd->add_option("--run-id", c.options.run_id, "follow this run only (default: the first run seen)");
  c.cmd->add_option("--interval", c.interval_s, "shortest time between two updates [s]")
      ->check(cli::seconds_within(1e-3, 86400.0))
      ->capture_default_str();
  c.timeout = c.cmd->add_option("--timeout", c.timeout_s, "exit 1 after this long without a world status [s]")
                  ->check(cli::seconds_within(1e-3, 1e6));
  auto* in_place_flag = c.cmd->add_flag("--in-place", c.in_place,
                                        "rewrite one line in place (the default when stdout is a terminal)");
  c.cmd->add_flag("--lines", c.lines, "print a new line at each update (the default otherwise)")->excludes(in_place_flag);
  c.cmd->add_option("--width", c.options.width, "longest line [columns]; 0 = the terminal's width or none")
      ->check(CLI::Range(0, 10000));
}

int run_progress_command(ProgressCommand& c, bus::Participant& participant, const StopSource& stop, std::ostream& out,
                         std::ostream& err) {
  // In place only on a terminal (or when asked): anything else, a file or a pipe, gets whole lines.
  const bool terminal = &out == &std::cout && isatty(STDOUT_FILENO) == 1;
  c.options.in_place = c.in_place || (terminal && !c.lines);
  if (c.options.width == 0 && terminal) c.options.width = terminal_columns() - 1;
  c.options.interval = std::chrono::duration<double>(c.interval_s);
  if (c.timeout->count() > 0) c.options.timeout = std::chrono::duration<double>(c.timeout_s);
  return run_progress(participant, c.options, stop, out, err);
}

/// The summary subcommand: its options (define_summary binds them) and its CLI11 subcommand.
struct SummaryCommand {
  CLI::App* cmd = nullptr;
  std::string dir;
};

void define_summary(CLI::App& app, SummaryCommand& c) {
  c.cmd = app.add_subcommand("summary", "a short account of a finished run, from DIR/summary.json");
  c.cmd->add_option("DIR", c.dir, "the run's output folder")->required();
}

/// The status subcommand: its options (define_status binds them) and its CLI11 subcommand.
struct StatusCommand {
  CLI::App* cmd = nullptr;
  StatusOptions options;
  double timeout_s = options.timeout.count();
  double listen_s = options.listen.count();
};

void define_status(CLI::App& app, StatusCommand& c, cli::DdsOptions& dds) {
  c.cmd = app.add_subcommand("status", "print the latest world status as a table, once");
  cli::add_dds_options(*c.cmd, dds);
  c.cmd->add_option("--timeout", c.timeout_s, "exit 1 when no world status arrives within this long [s]")
      ->check(cli::seconds_within(1e-3, 1e6))
      ->capture_default_str();
  c.cmd->add_option("--listen", c.listen_s,
                    "after the first status it believes, listen this long more, naming any other publisher of the "
                    "run's statuses on stderr, then print the newest [s]")
      ->check(cli::seconds_within(0.0, 60.0))
      ->capture_default_str();
}

int run_status_command(StatusCommand& c, bus::Participant& participant, const StopSource& stop, std::ostream& out,
                       std::ostream& err) {
  c.options.timeout = std::chrono::duration<double>(c.timeout_s);
  c.options.listen = std::chrono::duration<double>(c.listen_s);
  return run_status(participant, c.options, stop, out, err);
}

/// The replay subcommand: its options (define_replay binds them) and its CLI11 subcommand.
struct ReplayCommand {
  CLI::App* cmd = nullptr;
  std::string dir;
  std::uint64_t to_step = 0;
  CLI::Option* to_step_option = nullptr;
  ReplayOptions options;
};

void define_replay(CLI::App& app, ReplayCommand& c) {
  c.cmd = app.add_subcommand("replay", "rebuild a run's terrain from its run.log, without any agent");
  c.cmd->add_option("DIR", c.dir, "the run's output folder (run.log, terrain_initial.asc)")->required();
  c.to_step_option = c.cmd
                         ->add_option("--to-step", c.to_step,
                                      "stop after N steps (0..N-1): the terrain the world had when it awaited step N")
                         ->check(CLI::NonNegativeNumber)
                         ->type_name("N");
  auto* frames =
      c.cmd->add_option("--frames-every", c.options.frames_every, "write a PNG frame every K steps and the last")
          ->check(cli::at_least_one())
          ->type_name("K");
  c.cmd
      ->add_option("--out", c.options.frames_dir,
                   "the frames' folder (default DIR/replay); one that holds frames is refused")
      ->type_name("FRAMES_DIR")
      ->needs(frames);
  c.cmd->footer(kReplayFooter);
}

int run_replay_command(ReplayCommand& c, std::ostream& out, std::ostream& err) {
  if (c.to_step_option->count() > 0) c.options.to_step = c.to_step;
  if (const char* path = std::getenv("PATH")) c.options.search_path = path;
  const ReplayReport report = replay_run(c.dir, c.options);
  if (!report.tail_problem.empty())
    err << fmt::format("marsala-monitor: replayed the {} good steps; {}\n", report.steps, report.tail_problem);
  out << format_replay_report(report);
  return 0;
}

constexpr const char* kExportFooter =
    "Writes the run folder DIR as one MCAP file for Foxglove or Lichtblick (docs/runtime.md#mcap-export): /terrain\n"
    "(foxglove.Grid, heights as float32 \"height\") at the start, every K steps and at the end; /robots\n"
    "(foxglove.SceneUpdate: pose, heading, state, material of each robot) at the start and after every step; /events\n"
    "(foxglove.Log) from events.log. JSON encoding with JSON Schemas; chunked, indexed, uncompressed. The log is\n"
    "replayed with every check of replay; a damaged log is refused. Exit 0 ok, 2 bad input (FILE exists, no run\n"
    "folder, a log that fails its checksums), 1 another error; nothing is left under FILE unless it succeeded.";

/// The export subcommand: its options (define_export binds them) and its CLI11 subcommand.
struct ExportCommand {
  CLI::App* cmd = nullptr;
  std::string dir;
  std::string mcap;
  McapExportOptions options;
  double step_ms = 100.0;
};

void define_export(CLI::App& app, ExportCommand& c) {
  c.cmd = app.add_subcommand("export", "write a finished run's folder as an MCAP file (Foxglove, Lichtblick)");
  c.cmd->add_option("DIR", c.dir, "the run's output folder (run.log, terrain_initial.asc, events.log)")->required();
  c.cmd->add_option("--mcap", c.mcap, "the MCAP file to write; must not exist")->required()->type_name("FILE");
  c.cmd->add_option("--every", c.options.terrain_every, "a terrain every K steps (and at the start and end)")
      ->check(cli::at_least_one())
      ->type_name("K")
      ->capture_default_str();
  c.cmd->add_option("--step-ms", c.step_ms, "the time of one step in the file [ms]")
      ->check(cli::number_within(1e-3, 3.6e6, "a step time in ms"))
      ->capture_default_str();
  c.cmd->footer(kExportFooter);
}

/// Bad input (a missing folder, an existing target, a damaged or inconsistent log) exits 2.
int run_export_command(ExportCommand& c, std::ostream& out, std::ostream& err) {
  c.options.step_ns = static_cast<std::uint64_t>(std::llround(c.step_ms * 1e6));
  try {
    out << format_export_report(export_mcap(c.dir, c.mcap, c.options));
    return 0;
  } catch (const InvalidArgument& e) {
    err << fmt::format("marsala-monitor: export: {}\n", e.what());
  } catch (const ParseError& e) {
    err << fmt::format("marsala-monitor: export: {}\n", e.what());
  }
  return kExitUsage;
}

/// The serve subcommand: its options (define_serve binds them) and its CLI11 subcommand.
struct ServeCommand {
  CLI::App* cmd = nullptr;
  ServeOptions options;
};

void define_serve(CLI::App& app, ServeCommand& c, cli::DdsOptions& dds) {
  c.cmd = app.add_subcommand("serve", "serve a live view of the run to browsers (HTTP, loopback by default)");
  cli::add_dds_options(*c.cmd, dds);
  c.cmd->add_option("--port", c.options.port, "TCP port to listen on")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  c.cmd->add_option("--bind", c.options.bind_address, "numeric address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  auto* run_dir =
      c.cmd
          ->add_option("--run-dir", c.options.run_dir,
                       "the run's --out folder: its run.log, followed as it grows, gives the terrain and deposits")
          ->type_name("DIR");
  auto* replay =
      c.cmd->add_option("--replay", c.options.replay_dir, "play this run folder back instead of following DDS")
          ->type_name("DIR")
          ->excludes(run_dir);
  c.cmd->add_option("--speed", c.options.replay_steps_per_s, "replay pace [steps/s]")
      ->check(cli::number_within(1e-3, 1e9, "a pace in steps/s"))
      ->needs(replay)
      ->capture_default_str();
  c.cmd
      ->add_option("--terrain-every", c.options.terrain_interval_s,
                   "shortest time between two terrain pictures [s]")
      ->check(cli::seconds_within(0.0, 3600.0))
      ->capture_default_str();
  c.cmd->footer(kServeFooter);
}

/// serve has its own exit codes: a port or address it cannot listen on is a usage error (2).
int run_serve_command(const ServeCommand& c, const cli::DdsOptions& dds, const StopSource& stop, std::ostream& out,
                      std::ostream& err) {
  try {
    // Bound first: a bad port or address is a usage error, found before anything joins DDS.
    LiveServer server(c.options);
    std::unique_ptr<bus::Participant> participant;
    if (c.options.replay_dir.empty()) participant = join_domain(dds);
    return server.run(participant.get(), stop, out);
  } catch (const ListenError& e) {
    err << fmt::format("marsala-monitor: serve: {}\n", e.what());
    return kExitUsage;
  } catch (const InvalidArgument& e) {
    err << fmt::format("marsala-monitor: serve: {}\n", e.what());
    return kExitUsage;
  } catch (const Error& e) {
    err << fmt::format("marsala-monitor: serve: {}\n", e.what());
    return kExitError;
  } catch (const std::exception& e) {
    err << fmt::format("marsala-monitor: serve: unexpected error: {}\n", e.what());
    return kExitError;
  }
}

/// Every subcommand, defined on one CLI::App (which keeps pointers into this struct: it must not move).
struct MonitorCommands {
  cli::DdsOptions dds;  ///< shared by the subcommands that join DDS (only one runs)
  TailCommand tail;
  ProgressCommand progress;
  SummaryCommand summary;
  StatusCommand status;
  ReplayCommand replay;
  ServeCommand serve;
  ExportCommand export_;
};

/// Runs the chosen subcommand other than serve; errors become one line on `err` and exit code 1.
int run_chosen(MonitorCommands& c, const StopSource& stop, std::ostream& out, std::ostream& err) {
  try {
    if (*c.summary.cmd) {
      out << run_report(c.summary.dir);
      return 0;
    }
    if (*c.replay.cmd) return run_replay_command(c.replay, out, err);
    if (*c.export_.cmd) return run_export_command(c.export_, out, err);
    try {
      WorldGate::world_key_from_environment();  // a bad run key file is bad input: exit 2 before any traffic
      bus::check_config(bus_config(c.dds));     // so are a bad profile and an identity folder of another domain
    } catch (const InvalidArgument& e) {
      err << fmt::format("marsala-monitor: {}\n", e.what());
      return cli::kExitUsage;
    }
    const std::unique_ptr<bus::Participant> participant = join_domain(c.dds);
    if (*c.tail.cmd) return run_tail_command(c.tail, *participant, stop, out, err);
    if (*c.progress.cmd) return run_progress_command(c.progress, *participant, stop, out, err);
    return run_status_command(c.status, *participant, stop, out, err);
  } catch (const Error& e) {
    err << fmt::format("marsala-monitor: {}\n", e.what());
  } catch (const std::bad_alloc&) {
    err << "marsala-monitor: out of memory\n";
  } catch (const std::exception& e) {
    err << fmt::format("marsala-monitor: unexpected error: {}\n", e.what());
  }
  return kExitError;
}

}  // namespace

int run_monitor_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& usage_err,
                    const StopSource& stop) {
  CLI::App app{
      "marsala-monitor: watch a running MARSala system (world status, agents, events), or replay a run from its\n"
      "output folder. It only reads: it joins and leaves a running system without disturbing it.",
      "marsala-monitor"};
  app.require_subcommand(1);
  cli::LogOptions log_options;
  cli::add_log_options(app, log_options);
  app.fallthrough();  // before the subcommands, which inherit it: --log-format and --log-level also after one
  MonitorCommands commands;
  define_tail(app, commands.tail, commands.dds);
  define_progress(app, commands.progress, commands.dds);
  define_summary(app, commands.summary);
  define_status(app, commands.status, commands.dds);
  define_replay(app, commands.replay);
  define_serve(app, commands.serve, commands.dds);
  define_export(app, commands.export_);
  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-monitor", out, usage_err)) return *code;

  // The monitor's diagnostics are lines on a stream; in json each becomes one log record (common/cli/logging.hpp).
  const cli::LoggingScope logging("monitor", 0, log_options, &usage_err);
  std::optional<cli::LogLineStream> json_err;
  if (cli::log_format() == cli::LogFormat::kJson)
    json_err.emplace("marsala-monitor: ", [](const std::string& line) {
      // Everything the monitor says on stderr is why it fails, except a replay's note on a damaged tail it skipped.
      return line.rfind("replayed the ", 0) == 0 ? "warn" : "error";
    });
  std::ostream& err = json_err ? static_cast<std::ostream&>(*json_err) : usage_err;
  if (*commands.serve.cmd) return run_serve_command(commands.serve, commands.dds, stop, out, err);
  return run_chosen(commands, stop, out, err);
}

}  // namespace marsala::monitor
