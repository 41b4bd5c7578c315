#pragma once
// A kind of robot (paper §IV, §V): its body, the reactive behaviour that drives it, what it builds and how it works
// in the construction pipeline. Scenarios declare robot types; each agent process runs one; this is their one
// definition, so the facts are not copied from struct to struct on the way.

#include <optional>
#include <string>
#include <vector>

#include "marsala/core/robot_body.hpp"
#include "marsala/core/sensor_spec.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// The construction pipeline of the "path_builder" behaviour (paper §V-A, Fig. 4).
struct Pipeline {
  double separation_m = 2.0;   ///< a follower keeps at least this far behind its front neighbour [m]
  /// Each robot keeps this far right of a corridor's centre line in the direction it drives (agent/executive/lane.hpp);
  /// 0: no lanes [m].
  double lane_offset_m = 0.75;
};

/// Localisation error (docs/runtime.md#localisation-error): the robot believes its pose off the true one by an error
/// e_k per axis, e_k = a e_(k-1) + sqrt(1 - a^2) sd n_k with a = exp(-1 / correlation_steps), n_k standard normal.
struct Localisation {
  double noise_sd_m = 0.0;           ///< standard deviation of the error per axis; 0: exact [m]
  double correlation_steps = 50.0;   ///< steps over which the error decorrelates to 1/e [steps]
};

/// The depositor kinds, named in scenarios "layer", "cube", "cone".
enum class DepositorKind { kLayer, kCube, kCone };
/// "layer", "cube", "cone".
std::string to_string(DepositorKind kind);
/// The kind named `name`; throws InvalidArgument "unknown depositor 'x'; valid: cone, cube, layer".
DepositorKind depositor_kind(const std::string& name);
/// The valid depositor names, sorted.
std::vector<std::string> depositor_names();

/// What a robot's depositor does with material (docs/runtime.md#depositors): "layer" (the default) raises whole
/// cells by whole cube layers (Deposition), "cube" places columns of cubes and "cone" dumps granular material that
/// settles at its angle of repose, both at a position (Deposit; common/core/deposit_shapes.hpp).
struct DepositorSpec {
  DepositorKind kind = DepositorKind::kLayer;
  /// cube: side of one cube [m]; unset: the body's cube_size_m. Must be >= the grid's cell size (the world refuses
  /// to start otherwise): a narrower cube has no footprint of its own on the heightmap.
  std::optional<double> cube_size_m;
  double repose_deg = 34.0;  ///< cone: angle of repose of the material, in (0, 90) [deg]
};

/// A kind of robot.
struct RobotType {
  std::string name;                        ///< e.g. "husky"
  std::string behaviour = "ramp_builder";  ///< reactive behaviour by name (agent registry)
  RobotBody body;
  /// What it builds: a structure navigable for kappa and eps_m over a band delta_m wide along its path; unset: for
  /// its own body (construction_params()).
  std::optional<NavigabilityParams> construction;
  Pipeline pipeline;
  std::string goal_synthesizer = "fixed_target";  ///< goal synthesizer by name (agent registry)
  Localisation localisation;                      ///< how wrong the robot's own pose estimate is
  SensorSpec sensor;  ///< what it senses the terrain with (default ground truth tiles)
  DepositorSpec depositor;                        ///< how it deposits (scenario field 8)
};

/// The cube side of a "cube" depositor: its own, else the body's cube_size_m [m].
inline double depositor_cube_size_m(const RobotType& type) {
  return type.depositor.cube_size_m.value_or(type.body.cube_size_m);
}

/// What `type` builds: its construction, or its own body's kappa, delta (as the band width) and eps.
inline NavigabilityParams construction_params(const RobotType& type) {
  return type.construction.value_or(type.body.navigability);
}

}  // namespace marsala
