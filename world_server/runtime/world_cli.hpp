#pragma once
// The marsala-world command line as a callable function, so tests can drive it in-process.

#include <atomic>
#include <iosfwd>

namespace marsala::world_server {

/// Runs marsala-world with argv until the run ends or `stop` becomes true; returns the exit code: 0 when the run
/// finished (completed or not), 1 on errors (bad scenario: one line naming file and line; no agent admitted), 2 on
/// usage errors. Help goes to `out`, errors to `err` as one line "marsala-world: error: <reason>".
/// With --check [--json] SCENARIO: run_scenario_check() (scenario_check.hpp): the report on `out`, 0 when the world
/// would start from the scenario, 2 when not.
int run_world_cli(int argc, const char* const* argv, const std::atomic<bool>& stop, std::ostream& out,
                  std::ostream& err);

}  // namespace marsala::world_server
