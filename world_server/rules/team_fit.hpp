#pragma once
// Does the team fit on its base (docs/runtime.md#team-fit)? Every robot starts at its slot's `start` and comes back
// to the base station to refill, so the team must be able to stand there at once: N disjoint bodies (discs of
// delta_m of each slot's robot type; touching allowed, as bodies_overlap() judges), each centred on a cell occupiable
// for its body, in the start area: the disc round the base's centre of radius max(base radius, the farthest start's
// distance from it). The world does not need the starts themselves to be disjoint (starts jittered or placed into
// each other separate under rule 2.5), so the team fits when
//   - the slots' starts are such a placement (each start occupiable for its body, no two bodies overlapping), or
//   - a greedy placement finds one: robots in slot order, each on the first cell of the start area, farthest from the
//     base's centre first (a disc fills best from its rim; ties in row-major order), that is occupiable for its body
//     and keeps clear of the bodies placed.
// A greedy placement can miss a packing that exists; a scenario whose own starts are disjoint and occupiable is
// never refused.

#include <cstdint>
#include <string>

#include "marsala/core/heightmap.hpp"
#include "marsala/scenario/scenario.hpp"

namespace marsala::world_server {

/// Why the team of slots 1..agent_count does not fit on its base (see the header), naming the field, e.g. "agent
/// (12 robots): only 9 bodies of 1 m find room on the cells occupiable for them within 2 m of the base's centre
/// (the start area; the slots' starts do not do: agent[1] (agent 2).start: (1, 2) m: its body (1 m) overlaps agent
/// 1's, at (1.5, 2) m (0.50 m apart, the bodies need 1 m))"; "" when it fits.
std::string team_fit_problem(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count);

/// Why the slots' starts 1..agent_count are no placement of the team (the first problem in slot order, an overlap
/// named at the higher id), e.g. "agent[1] (agent 2).start: (1, 2) m: cell (3, 4) is not occupiable for its body
/// (kappa 0.3, delta 1 m, eps 0.05 m)"; "" when they are one.
std::string start_placement_problem(const scenario::Scenario& scenario, const Heightmap& terrain,
                                    std::uint32_t agent_count);

/// How many robots of slots 1..agent_count the greedy placement of the header finds room for in the start area of
/// radius `radius_m` round the base's centre (agent_count when the whole team fits).
std::uint32_t greedy_placed(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count,
                            double radius_m);

}  // namespace marsala::world_server
