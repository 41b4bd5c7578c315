// marsala-monitor: tail a running system (tail, status), replay a run's log (replay), export it as MCAP (export).
// Reads only; Ctrl-C ends it cleanly.
#include <fmt/format.h>

#include <exception>
#include <iostream>

#include "marsala/monitor/monitor_cli.hpp"
#include "marsala/monitor/signal_watcher.hpp"

int main(int argc, char** argv) {
  try {
    marsala::monitor::StopSource stop;
    // First, before any thread exists: SIGINT/SIGTERM become stop requests in every thread started later.
    marsala::monitor::SignalWatcher watcher(stop);
    return marsala::monitor::run_monitor_cli(argc, argv, std::cout, std::cerr, stop);
  } catch (const std::exception& e) {
    std::cerr << fmt::format("marsala-monitor: {}\n", e.what());
    return 1;
  }
}
