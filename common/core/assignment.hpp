#pragma once
// Where the world places an agent for a run: the world grid, how its terrain arrives, where the robot starts, its
// target and the base station. The world makes it from the scenario's slot at admission, the Admission message
// carries it, and the agent's layers read it from their context.

#include <string>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// An agent's place in a run.
struct Assignment {
  GridGeometry world;          ///< the world grid (rows, cols, lower-left corner [m], cell size [m/cell])
  int tile_size = 16;          ///< the terrain arrives in tiles of tile_size x tile_size cells (fewer at the edge)
  Position start;              ///< where the robot starts [m]
  Position target;             ///< the scenario's goal for this agent [m]
  Position base;               ///< base station centre: material is refilled only near it [m]
  double base_radius_m = 0.0;  ///< [m]
};

/// Empty when the grid has rows, columns and a finite, positive cell size, a finite corner, and tile_size >= 1;
/// otherwise the problem, e.g. "world grid 0 x 12 with cell size 1 m is not a valid grid".
std::string assignment_problem(const Assignment& assignment);

}  // namespace marsala
