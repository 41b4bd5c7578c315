#pragma once
// The robot body (paper §II, §V-A): the motion parameters of eq. 1 composed with the kinematics and capabilities
// the world checks every request against. Scenarios declare it, agents plan with it, the wire carries it; this is
// its one definition.

#include <string>

#include "marsala/core/types.hpp"

namespace marsala {

/// A robot's body, kinematics and capabilities.
struct RobotBody {
  NavigabilityParams navigability;    ///< kappa [m/m], delta_m [m], eps_m [m] of eq. 1
  double max_step_m = 0.2;            ///< distance threshold: longest motion in one step [m]
  double max_deposit_m3 = 0.01;       ///< deposition threshold: most material placed in one step [m^3]
  double material_capacity_m3 = 2.0;  ///< material carried when full [m^3]
  double reach_m = 1.2;               ///< manipulator reach from the robot's centre [m]
  double sensing_range_m = 3.0;       ///< half-side of the square terrain window it senses [m]
  double proximity_range_m = 3.0;     ///< neighbours within this distance are reported [m]
  double cube_size_m = 0.05;          ///< smallest deposition: a cube of this side [m]

  /// Equal field by field, bit for bit (both sides read the same scenario file).
  friend bool operator==(const RobotBody& a, const RobotBody& b);
  friend bool operator!=(const RobotBody& a, const RobotBody& b) { return !(a == b); }
};

/// Largest magnitude any length, volume or slope may have [m, m^3, m/m]; beyond it a value is absurd.
inline constexpr double kMaxMagnitude = 1e6;

/// Empty when every field of `body` is finite, below kMaxMagnitude in magnitude and in its range (kappa, delta_m,
/// max_step_m, max_deposit_m3, cube_size_m > 0; the other fields >= 0) and max_step_m <= delta_m / 2 (+1e-9 m);
/// otherwise the first problem, e.g. "kappa = nan: must be finite, > 0 and < 1e6 [m/m]". Scenario validation and the world's admission both use it.
std::string body_problem(const RobotBody& body);

/// Height of one cube spread over a cell, q = cube^3 / cs^2 [m]: depositions are whole multiples of it. Agent and
/// world compute it here, so they agree bit for bit. Throws InvalidArgument unless both sizes are finite and > 0.
double cube_layer_m(double cube_size_m, double cell_size_m);

}  // namespace marsala
