#pragma once
// The marsala-monitor command line as a callable function, so tests can drive it in-process.

#include <iosfwd>

#include "marsala/monitor/stop_source.hpp"

namespace marsala::monitor {

/// Runs marsala-monitor with argv (subcommands tail, progress, summary, status, replay, serve, export); returns the exit code (0 ok, 1 error, 2 usage).
/// `stop` ends a running tail or status (main.cpp wires it to SIGINT/SIGTERM). Errors go to `err` as
/// "marsala-monitor: <reason>".
int run_monitor_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err, const StopSource& stop);

}  // namespace marsala::monitor
