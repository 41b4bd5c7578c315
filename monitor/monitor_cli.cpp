#include "marsala/monitor/monitor_cli.hpp"

// CLI11 2.1's option conversions trip a false -Wmaybe-uninitialized at -O2; keep our own warnings on.
#include "marsala/cli/command_line.hpp"
#include "marsala/cli/logging.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

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
#include "marsala/monitor/progress.hpp"
#include "marsala/monitor/replay.hpp"
#include "marsala/monitor/run_report.hpp"
#include "marsala/monitor/serve.hpp"

namespace marsala::monitor {
namespace {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

constexpr const char* kTailLegend =
    "Columns: step; live agents/all; mat = material on board of the live agents [m3]; dep = volume deposited\n"
    "in the run [m3]; prog = the run's progress [%] (agents at the goal, share of the payload route's MARS gap\n"
    "filled, or level fraction of the site); then each agent's behaviour state in id order (* at its goal, --\n"
    "dropped, ? no state yet). Beyond what fits the width, live agents are counted per state. Event lines:\n"
    "step > agent kind [volume] detail. The last line gives the progress in words.";

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

  cli::DdsOptions dds;
  auto add_bus_options = [&](CLI::App& cmd) { cli::add_dds_options(cmd, dds); };

  TailOptions tail_options;
  double tail_timeout_s = 0.0;
  auto* tail = app.add_subcommand("tail", "print one line per step (and per event) until the run ends or Ctrl-C");
  add_bus_options(*tail);
  tail->add_option("--run-id", tail_options.run_id, "follow this run only (default: the first run seen)");
  tail->add_flag("--events", tail_options.events, "also print one line per world event");
  auto* tail_timeout = tail->add_option("--timeout", tail_timeout_s,
                                        "exit 1 after this long without a world status [s] (default: wait forever)")
                           ->check(CLI::Range(1e-3, 1e6));
  tail->add_option("--width", tail_options.format.width, "longest line [columns]; 0 = no limit")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  tail->add_option("--every", tail_options.every_steps,
                   "print a step line only when the step passes a multiple of N (and the last one)")
      ->check(cli::at_least_one())
      ->type_name("N");
  double tail_interval_s = 0.0;
  tail->add_option("--interval", tail_interval_s, "print at most one step line every S seconds (and the last one)")
      ->check(CLI::Range(1e-3, 86400.0))
      ->type_name("S");
  tail->footer(kTailLegend);

  ProgressOptions progress_options;
  double progress_interval_s = progress_options.interval.count();
  double progress_timeout_s = 0.0;
  bool progress_in_place = false, progress_lines = false;
  auto* progress = app.add_subcommand(
      "progress", "one line with the step, progress, steps/s and ETA, kept up to date, until the run ends");
  add_bus_options(*progress);
  progress->add_option("--run-id", progress_options.run_id, "follow this run only (default: the first run seen)");
  progress->add_option("--interval", progress_interval_s, "shortest time between two updates [s]")
      ->check(CLI::Range(1e-3, 86400.0))
      ->capture_default_str();
  auto* progress_timeout =
      progress->add_option("--timeout", progress_timeout_s, "exit 1 after this long without a world status [s]")
          ->check(CLI::Range(1e-3, 1e6));
  auto* in_place_flag = progress->add_flag(
      "--in-place", progress_in_place, "rewrite one line in place (the default when stdout is a terminal)");
  progress->add_flag("--lines", progress_lines, "print a new line at each update (the default otherwise)")
      ->excludes(in_place_flag);
  progress->add_option("--width", progress_options.width, "longest line [columns]; 0 = the terminal's width or none")
      ->check(CLI::Range(0, 10000));

  std::string summary_dir;
  auto* summary = app.add_subcommand("summary", "a short account of a finished run, from DIR/summary.json");
  summary->add_option("DIR", summary_dir, "the run's output folder")->required();

  StatusOptions status_options;
  double status_timeout_s = status_options.timeout.count();
  auto* status = app.add_subcommand("status", "print the latest world status as a table, once");
  add_bus_options(*status);
  status->add_option("--timeout", status_timeout_s, "exit 1 when no world status arrives within this long [s]")
      ->check(CLI::Range(1e-3, 1e6))
      ->capture_default_str();

  std::string replay_dir;
  std::uint64_t to_step = 0;
  ReplayOptions replay_options;
  auto* replay = app.add_subcommand("replay", "rebuild a run's terrain from its run.log, without any agent");
  replay->add_option("DIR", replay_dir, "the run's output folder (run.log, terrain_initial.asc)")->required();
  auto* replay_to_step =
      replay
          ->add_option("--to-step", to_step,
                       "stop after N steps (0..N-1): the terrain the world had when it awaited step N")
          ->check(CLI::NonNegativeNumber)
          ->type_name("N");
  auto* replay_frames =
      replay->add_option("--frames-every", replay_options.frames_every, "write a PNG frame every K steps and the last")
          ->check(cli::at_least_one())
          ->type_name("K");
  replay
      ->add_option("--out", replay_options.frames_dir,
                   "the frames' folder (default DIR/replay); one that holds frames is refused")
      ->type_name("FRAMES_DIR")
      ->needs(replay_frames);
  replay->footer(kReplayFooter);

  ServeOptions serve_options;
  auto* serve = app.add_subcommand("serve", "serve a live view of the run to browsers (HTTP, loopback by default)");
  add_bus_options(*serve);
  serve->add_option("--port", serve_options.port, "TCP port to listen on")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  serve->add_option("--bind", serve_options.bind_address, "numeric address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  auto* serve_run_dir =
      serve
          ->add_option("--run-dir", serve_options.run_dir,
                       "the run's --out folder: its run.log, followed as it grows, gives the terrain and deposits")
          ->type_name("DIR");
  auto* serve_replay =
      serve->add_option("--replay", serve_options.replay_dir, "play this run folder back instead of following DDS")
          ->type_name("DIR")
          ->excludes(serve_run_dir);
  serve->add_option("--speed", serve_options.replay_steps_per_s, "replay pace [steps/s]")
      ->check(CLI::Range(1e-3, 1e9))
      ->needs(serve_replay)
      ->capture_default_str();
  serve
      ->add_option("--terrain-every", serve_options.terrain_interval_s,
                   "shortest time between two terrain pictures [s]")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  serve->footer(kServeFooter);

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

  if (*serve) {
    try {
      // Bound first: a bad port or address is a usage error, found before anything joins DDS.
      LiveServer server(serve_options);
      std::unique_ptr<bus::Participant> participant;
      if (serve_options.replay_dir.empty())
        participant =
            bus::make_participant({bus::vendor_from_string(dds.vendor), dds.domain, dds.profile, bus::Role::kServer,
                                   bus::Security::of(dds.security, dds.identity, "monitor")});
      return server.run(participant.get(), stop, out);
    } catch (const ListenError& e) {
      err << "marsala-monitor: serve: " << e.what() << "\n";
      return kExitUsage;
    } catch (const InvalidArgument& e) {
      err << "marsala-monitor: serve: " << e.what() << "\n";
      return kExitUsage;
    } catch (const Error& e) {
      err << "marsala-monitor: serve: " << e.what() << "\n";
      return kExitError;
    } catch (const std::exception& e) {
      err << "marsala-monitor: serve: unexpected error: " << e.what() << "\n";
      return kExitError;
    }
  }

  try {
    if (*summary) {
      out << run_report(summary_dir);
      return 0;
    }
    if (*replay) {
      if (replay_to_step->count() > 0) replay_options.to_step = to_step;
      if (const char* path = std::getenv("PATH")) replay_options.search_path = path;
      const ReplayReport report = replay_run(replay_dir, replay_options);
      if (!report.tail_problem.empty())
        err << "marsala-monitor: replayed the " << report.steps << " good steps; " << report.tail_problem << "\n";
      out << format_replay_report(report);
      return 0;
    }
    auto participant =
        bus::make_participant({bus::vendor_from_string(dds.vendor), dds.domain, dds.profile, bus::Role::kServer,
                               bus::Security::of(dds.security, dds.identity, "monitor")});
    if (*tail) {
      if (tail_timeout->count() > 0) tail_options.timeout = std::chrono::duration<double>(tail_timeout_s);
      tail_options.interval = std::chrono::duration<double>(tail_interval_s);
      return run_tail(*participant, tail_options, stop, out, err);
    }
    if (*progress) {
      // In place only on a terminal (or when asked): anything else, a file or a pipe, gets whole lines.
      const bool terminal = &out == &std::cout && isatty(STDOUT_FILENO) == 1;
      progress_options.in_place = progress_in_place || (terminal && !progress_lines);
      if (progress_options.width == 0 && terminal) progress_options.width = terminal_columns() - 1;
      progress_options.interval = std::chrono::duration<double>(progress_interval_s);
      if (progress_timeout->count() > 0) progress_options.timeout = std::chrono::duration<double>(progress_timeout_s);
      return run_progress(*participant, progress_options, stop, out, err);
    }
    status_options.timeout = std::chrono::duration<double>(status_timeout_s);
    return run_status(*participant, status_options, stop, out, err);
  } catch (const Error& e) {
    err << "marsala-monitor: " << e.what() << "\n";
  } catch (const std::bad_alloc&) {
    err << "marsala-monitor: out of memory\n";
  } catch (const std::exception& e) {
    err << "marsala-monitor: unexpected error: " << e.what() << "\n";
  }
  return kExitError;
}

}  // namespace marsala::monitor
