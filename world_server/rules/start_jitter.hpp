#pragma once
// Start jitter (Scenario.start_jitter_m): the world moves each agent's start by a seeded random offset, so that runs
// of one scenario with different seeds start differently, while one seed always gives the same starts.

#include <cstdint>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/scenario/scenario.hpp"

namespace marsala::world_server {

/// Where agent slot.id starts: the slot's start moved by an offset uniform in the disc of radius jitter_m, drawn
/// with splitmix64 seeded from (seed, slot.id) by rejection in the square (no standard distributions, no libm), so
/// every platform draws the same points. A draw is kept when its cell is on the grid and occupiable for `body`
/// (cell_occupiable); after 64 rejected draws, or when jitter_m is 0, the slot's start. Throws InvalidArgument
/// when jitter_m is negative or not finite.
Position jittered_start(const Heightmap& terrain, const scenario::AgentSlot& slot, const RobotBody& body,
                        double jitter_m, std::uint64_t seed);

/// Draws per agent before falling back to the slot's start.
inline constexpr int kMaxJitterDraws = 64;

}  // namespace marsala::world_server
