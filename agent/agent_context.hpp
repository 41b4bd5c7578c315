#pragma once
// What one robot knows about itself and its run once admitted: identity, body, the world grid and its target.
// Everything an agent decides flows from this context and its own sensor frames.

#include <cstdint>
#include <optional>
#include <string>

#include "marsala/core/assignment.hpp"
#include "marsala/core/goal_vector_map.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/robot_type.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent {

/// The admitted agent: identity, body, the world's answer and team-wide margins.
struct AgentContext {
  std::uint32_t agent_id = 0;  ///< >= 1
  std::uint64_t session = 0;   ///< echoed in every request
  RobotType type;              ///< body, behaviour, what it builds, pipeline, goal synthesizer
  Assignment assignment;       ///< world grid, tile size, start, target and base station (once admitted)
  /// Depositions stay farther than this from a neighbour's reported centre [m]: the world rejects cells under any
  /// robot, and a neighbour may move before its turn; default = delta/2 + max_step of this body (see
  /// neighbour_keep_out_m()).
  double neighbour_keep_out_m = 0.0;
  std::uint64_t seed = 1;  ///< scenario seed; behaviours that randomise seed from seed + agent_id
  std::optional<GoalVectorMapSpec> goal_vector_map;  ///< the scenario's, for the "goal_vector_map" synthesizer
  /// Builders keep the right-of-way protocol (docs/runtime.md#right-of-way); the agent sets it from the scenario's
  /// `right_of_way` (on by default).
  bool right_of_way = true;
};

/// Keep-out around neighbours for a team whose largest body length is max_delta_m [m] and longest step
/// max_step_m [m]: max_delta_m / 2 + max_step_m + 1e-6 [m].
double neighbour_keep_out_m(double max_delta_m, double max_step_m);

}  // namespace marsala::agent
