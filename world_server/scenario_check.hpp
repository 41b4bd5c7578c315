#pragma once
// marsala-world --check: a scenario validated exactly as the world validates it at start (loading, terrain,
// agent slots and start jitter, completion set-up), without DDS, and described for people (text) or scripts (JSON).
// deploy/spawn.sh, demo.sh and sweep.sh read slot counts and names from the JSON instead of parsing the format.

#include <string>

#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/world_state.hpp"

namespace marsala::world_server {

/// A scenario that passed every start-up check, with the world state it starts from (every slot admitted).
struct CheckedScenario {
  scenario::Scenario scenario;
  WorldState state;
};

/// Loads `path` and runs the world's start-up on it; throws the loader's ParseError / InvalidArgument (naming file,
/// line and field) or the world's InvalidArgument for anything the world would refuse to start with.
CheckedScenario check_scenario(const std::string& path);

/// Name, terrain, robot types, slots (start as jittered by the seed, target), completion, limits: one fact a line.
std::string describe_text(const CheckedScenario& checked);

/// The same as one JSON object: {"scenario", "source", "terrain": {...}, "robot_types": [...], "slots": [...],
/// "completion": {"kind", ...}, "max_steps", "step_deadline_s", "seed", "start_jitter_m"}.
std::string describe_json(const CheckedScenario& checked);

}  // namespace marsala::world_server
