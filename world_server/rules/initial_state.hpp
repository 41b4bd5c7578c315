#pragma once
// The world's initial state as a run starts it: the starts of the slots (start jitter) and the completion check set
// up on the terrain, above world_state so that the plain state never reaches up into the rules that use it.

#include <cstdint>

#include "marsala/core/heightmap.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// The initial state: world_state_at() with slots 1..agent_count, each start moved by jittered_start() when the
/// scenario's start_jitter_m > 0 (seeded by scenario.seed), and for kPayloadPath and kLevelSite the completion check
/// set up and evaluated once (start_completion_check()), so a scenario complete from the start ends at once. Throws
/// InvalidArgument when agent_count is 0 or exceeds the scenario's slots, when the payload's `from` or `to` is off
/// the grid, or when the site holds no cell of the grid.
WorldState make_world_state(const scenario::Scenario& scenario, Heightmap terrain, std::uint32_t agent_count);

}  // namespace marsala::world_server
