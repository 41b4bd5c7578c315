#include "marsala/monitor/monitor_cli.hpp"

// CLI11 2.1's option conversions trip a false -Wmaybe-uninitialized at -O2; keep our own warnings on.
#include "marsala/cli/command_line.hpp"

#include <exception>
#include <new>
#include <ostream>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"
#include "marsala/monitor/follow.hpp"

namespace marsala::monitor {
namespace {

constexpr int kExitError = 1;

constexpr const char* kTailLegend =
    "Columns: step; live agents/all; mat = material on board of the live agents [m3]; dep = volume deposited\n"
    "in the run [m3]; goal = agents at their goal [%]; then each agent's behaviour state in id order\n"
    "(* at its goal, -- dropped, ? no state yet). Beyond what fits the width, live agents are counted per\n"
    "state. Event lines: step > agent kind [volume] detail.";

}  // namespace

int run_monitor_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err, const StopSource& stop) {
  CLI::App app{
      "marsala-monitor: watch a running MARSala system (world status, agents, events). It only reads:\n"
      "it joins and leaves a running system without disturbing it.",
      "marsala-monitor"};
  app.require_subcommand(1);

  std::string dds = "cyclone";
  int domain = 0;
  auto add_bus_options = [&](CLI::App& cmd) {
    cmd.add_option("--dds", dds, "DDS vendor: cyclone, fastdds, or inprocess (tests only)")
        ->check(CLI::IsMember({"cyclone", "fastdds", "inprocess"}))
        ->capture_default_str();
    cmd.add_option("--domain", domain, "DDS domain id")->check(CLI::Range(0, 232))->capture_default_str();
  };

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
  tail->footer(kTailLegend);

  StatusOptions status_options;
  double status_timeout_s = status_options.timeout.count();
  auto* status = app.add_subcommand("status", "print the latest world status as a table, once");
  add_bus_options(*status);
  status->add_option("--timeout", status_timeout_s, "exit 1 when no world status arrives within this long [s]")
      ->check(CLI::Range(1e-3, 1e6))
      ->capture_default_str();

  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-monitor", out, err)) return *code;

  try {
    auto participant = bus::make_participant({bus::vendor_from_string(dds), domain});
    if (*tail) {
      if (tail_timeout->count() > 0) tail_options.timeout = std::chrono::duration<double>(tail_timeout_s);
      return run_tail(*participant, tail_options, stop, out, err);
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
