#pragma once
// Completion (runtime_spec.md): every live agent (at least one) stands inside the goal rectangle at a terrain height
// of at least the goal's min_height_m, checked on the authoritative terrain.

#include "world_server/world_state.hpp"

namespace marsala::world_server {

/// True when `agent`'s centre lies in the goal rectangle (closed, +1e-9 m) and the height under it is at least
/// goal.min_height_m - 1e-9 m.
bool at_goal(const WorldState& state, const AgentRecord& agent);

/// True when at least one agent is live and every live agent is at the goal.
bool is_completed(const WorldState& state);

/// Fraction of the live agents at the goal [0, 1]; 0 when none is live.
double progress(const WorldState& state);

}  // namespace marsala::world_server
