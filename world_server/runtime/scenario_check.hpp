#pragma once
// marsala-world --check: a scenario validated exactly as the world validates it at start, without the bus. The check
// runs the world's own start-up path (load_scenario(), build_terrain(), prepare_world_start(): the completion check
// set up on the terrain, slots and base on the grid, the options against the slots) and reports what the run would
// start from: name, terrain, robot types, slots, completion and its parameters, max_steps, seed. Scripts read the
// JSON form (idl/scenario_check.proto) instead of parsing the scenario format themselves.

#include <iosfwd>
#include <string>

#include "marsala/world_server/runtime/world_start.hpp"

namespace marsala::world_server {

/// Exit code of --check for a scenario the world would reject at start.
inline constexpr int kExitInvalidScenario = 2;

/// The start marsala-world would make from `scenario_path` with `options` on `domain_id`, bus aside. Throws what the
/// world throws at start: ParseError (file, line), IoError (missing scenario or terrain file), InvalidArgument
/// (scenario and field).
WorldStart check_scenario(const std::string& scenario_path, const RuntimeOptions& options, int domain_id);

/// The report of a checked start as text lines: scenario, terrain, robot types, slots, completion, base, max_steps
/// and seed. Numbers print in their shortest form that reads back exactly.
std::string scenario_check_text(const WorldStart& start);

/// The report as one JSON object (proto::ScenarioCheck, proto field names, every field printed) and a newline.
std::string scenario_check_json(const WorldStart& start);

/// Checks `scenario_path` and prints the report to `out` (JSON when `json`). Returns 0 when the world would start
/// from it; kExitInvalidScenario with one line "marsala-world: error: <reason naming file and field>" on `err` when
/// not; 1 when out of memory.
int run_scenario_check(const std::string& scenario_path, const RuntimeOptions& options, int domain_id, bool json,
                       std::ostream& out, std::ostream& err);

}  // namespace marsala::world_server
