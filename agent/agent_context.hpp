#pragma once
// What one robot knows about itself and its run once admitted: identity, body, the world grid and its target.
// Everything an agent decides flows from this context and its own sensor frames.

#include <cstdint>
#include <optional>
#include <string>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/goal_vector_map.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent {

/// What the robot builds and how it works with the team (scenario robot type; defaults: build for its own body).
struct Task {
  std::optional<double> construction_kappa;    ///< slope the structure must keep [m/m]; default body kappa
  std::optional<double> construction_eps_m;    ///< discontinuity it may keep [m]; default body eps
  std::optional<double> construction_width_m;  ///< diameter of the band filled along the path [m]; default delta
  double separation_m = 2.0;                   ///< pipeline: distance kept behind the front neighbour [m]
  double lane_offset_m = 0.5;                  ///< pipeline: lanes this far right of the way [m]
  std::string goal_synthesizer = "fixed_target";                  ///< by name
  std::optional<GoalVectorMapSpec> goal_vector_map;   ///< for "goal_vector_map"
};

/// Where the world placed this agent, read from its admission by the reactive layer (assignment_from): the layers
/// below never see the wire message.
struct Assignment {
  GridGeometry world;           ///< the world grid (rows, cols, lower-left corner [m], cell size [m/cell])
  int tile_size = 16;           ///< the terrain arrives in tiles of tile_size x tile_size cells
  Position start;               ///< where the robot starts [m]
  Position target;              ///< the scenario's goal for this agent [m]
  Position base;                ///< base station centre: material is refilled only near it [m]
  double base_radius_m = 0.0;   ///< [m]
};

/// The admitted agent: identity, body, the world's answer and team-wide margins.
struct AgentContext {
  std::uint32_t agent_id = 0;       ///< >= 1
  std::uint64_t session = 0;        ///< echoed in every request
  RobotBody body;                   ///< this robot's body, kinematics and capabilities
  Assignment assignment;            ///< world grid, tile size, start, target and base station (once admitted)
  /// Depositions stay farther than this from a neighbour's reported centre [m]: the world rejects cells under any
  /// robot, and a neighbour may move before its turn; default = delta/2 + max_step of this body (see
  /// neighbour_keep_out_m()).
  double neighbour_keep_out_m = 0.0;
  std::uint64_t seed = 1;           ///< scenario seed; behaviours that randomise seed from seed + agent_id
  Task task;                        ///< what it builds, with whom, towards which goals
};

/// The construction parameters of a context: the task's, falling back to the body's (kappa, width as delta, eps).
NavigabilityParams construction_params(const AgentContext& context);

/// Keep-out around neighbours for a team whose largest body length is max_delta_m [m] and longest step
/// max_step_m [m]: max_delta_m / 2 + max_step_m + 1e-6 [m].
double neighbour_keep_out_m(double max_delta_m, double max_step_m);

}  // namespace marsala::agent
