#pragma once
// Body clearance (docs/runtime.md#collisions): the other robots a frame's proximity sensing shows, as the discs this
// robot's centre must keep out of. The world rejects a motion whose end overlaps another live robot's body, judging
// the requests of a step in ascending agent id: a neighbour with a higher id is where the frame shows it when this
// robot's request is judged, one with a lower id may already have moved up to a step closer. So the disc around a
// neighbour has radius (own radius + its radius), plus this robot's max_step when the neighbour's id is lower (its
// step is not known; a robot of another type may step farther, and then the world rejects the motion and the robot
// stands still for a step).
//
// The same rule as the world's: a position is clear when it lies outside every disc, or when the robot already
// stands inside a disc and the position is not nearer that disc's centre (overlapping bodies may move apart).

#include <cstdint>
#include <vector>

#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// Another robot's body: this robot's centre must stay at least min_distance_m from `centre`.
struct BodyClearance {
  std::uint32_t agent_id = 0;
  Position centre;             ///< the neighbour's position [m]
  double min_distance_m = 0.0;  ///< own radius + its radius (+ max_step for a lower id) [m]
};

/// The discs of `neighbours` for robot `self_id` with body radius `radius_m` and step `max_step_m` [m]; neighbours with
/// a non-finite position or radius are skipped (the runtime refuses such frames before).
std::vector<BodyClearance> body_clearances(const std::vector<Neighbour>& neighbours, std::uint32_t self_id,
                                           double radius_m, double max_step_m);

/// True when a motion from `from` to `to` [m] ends clear of every disc (see the header).
bool clear_of(const std::vector<BodyClearance>& others, Position from, Position to);

/// Takes the cells whose centres are not clear (from the robot's position) out of the local map's occupiable and
/// navigable masks, the robot's own cell excepted, and recomputes navigable as the occupiable cells 8-connected to
/// the robot's cell: routes and motions then go around the other robots, or wait. Returns the number of cells taken
/// out.
long long keep_clear(deliberative::LocalMap& local, Position robot, const std::vector<BodyClearance>& others);

/// Takes the world cells `cells` that lie in the window out of the local map's occupiable and navigable masks, the
/// robot's own cell excepted, and recomputes navigable as keep_clear does: cells this robot must not step onto though
/// its map holds them occupiable (a motion target the world refused). Returns the number of cells taken out.
long long keep_off(deliberative::LocalMap& local, const std::vector<CellIndex>& cells);

}  // namespace marsala::agent::executive
