#pragma once
// Does the team fit where the scenario starts it (docs/runtime.md#scenario-validation)? The world places robot i at
// its slot's `start` (start jitter moves it only onto occupiable cells, else leaves it there: start_jitter.hpp), so
// the team fits when, at the slots' starts, every body stands on a cell occupiable for it and no two bodies overlap
// (bodies_overlap(): centres closer than (delta_a + delta_b) / 2 - 1e-9 m). A base station too small for the whole
// team at once is no misfit: robots refill there one after another.

#include <cstdint>
#include <string>

#include "marsala/core/heightmap.hpp"
#include "marsala/scenario/scenario.hpp"

namespace marsala::world_server {

/// Why the team of slots 1..agent_count does not fit at its slots' starts on `terrain`, naming the field, e.g.
/// "agent[4] (agent 5).start: (1, 2) m: its body (1 m) overlaps agent 4's, at (1.5, 2) m (0.50 m apart, the bodies
/// need 1 m)"; "" when it fits. The first problem in slot order; an overlap is named at the higher id. Starts must be
/// on the grid (the loader checks it).
std::string team_fit_problem(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count);

}  // namespace marsala::world_server
