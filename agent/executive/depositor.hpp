#pragma once
// Depositors (docs/runtime.md#depositors): the executive layer's small actuator interface that turns the deposition
// manager's wish (cells and their MARS gaps along the path) into what the request carries. Chosen by name from the
// robot type (scenario field depositor), through make_depositor():
//   "layer": the manager's whole cube layers per cell (Deposition), as always;
//   "cube":  columns of cubes of side s centred on wanted cells, in path order (contour crafting), each column as
//            tall as every cell of its footprint still wants (never above the MARS height);
//   "cone":  piles of granular material: among dump points on wanted cells within reach and a few volumes (the
//            largest pile that fits among them), the pile (predicted with the world's own cone_pile_shape on the
//            local map) that puts most volume under the MARS height on the path's footprint, with no cell above the
//            MARS height of the local map (kConeRoundingM for rounding) and no cell it may not raise (checked on a
//            pile 1e-6 bigger, so that rounding in the world's frame cannot reach one); up to kMaxConesPerStep piles
//            a step. Under the local MARS height is under the world's deposit bound, the MARS of the initial terrain
//            (docs/runtime.md#deposit-bound): filled only up to it, the terrain never lifts its own bound.
// Every depositor keeps the manager's way-back check (the longest prefix of its deposits that keeps it).
// The behaviours see only DepositionPlan.

#include <memory>
#include <string>
#include <vector>

#include "marsala/agent/executive/deposition_manager.hpp"
#include "marsala/core/robot_type.hpp"

namespace marsala::agent::executive {

/// A cone pile may rise above the local map's MARS height by at most this much: rounding only, never an overshoot
/// that would lift the bound of the cells around it [m].
inline constexpr double kConeRoundingM = 1e-9;
/// Most piles a cone depositor places in one step.
inline constexpr int kMaxConesPerStep = 8;
/// Dump points tried per pile: the first wanted cells within reach, in path order.
inline constexpr int kConeDumpPoints = 12;

/// Turns the deposition manager's wish into this step's depositions or deposits.
class Depositor {
 public:
  virtual ~Depositor() = default;
  /// "layer", "cube" or "cone".
  virtual std::string name() const = 0;
  /// What to deposit from `robot` [m] (after this step's motion) with `material_m3` on board, along `path` (local
  /// indices, from where the robot will stand), within every rule the world checks.
  virtual DepositionPlan plan(const DepositionManager& manager, const deliberative::LocalMap& map,
                              const std::vector<CellIndex>& path, Position robot, double material_m3,
                              const Neighbourhood& neighbours) const = 0;
};

/// The depositor of a robot type: its depositor spec and (for a cube without its own side) the body's cube size.
/// Throws InvalidArgument listing the valid names when the name is unknown.
std::unique_ptr<Depositor> make_depositor(const RobotType& type);

}  // namespace marsala::agent::executive
