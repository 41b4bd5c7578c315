#pragma once
// Action manager (paper §III, executive layer): the motion of one step. It advances along a planned path to the
// farthest path cell that is navigable now (on the local map before this step's depositions: the world applies
// the motion first) and within the distance threshold, whose straight way from the robot passes through navigable
// cells only, and targets that cell's centre, so the world (which checks the distance and that every cell the
// motion passes through is occupiable: cells_on_segment) never has a reason to reject it. Every target also ends
// clear of the other robots' bodies (body_clearance.hpp: the world's rule 2.5).

#include <optional>
#include <vector>

#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/agent/executive/body_clearance.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// One step's motion.
struct Motion {
  CellIndex cell;              ///< the target cell (local index)
  Position target;             ///< its centre [m]
  std::size_t path_index = 0;  ///< index of the target cell on the path it follows (0 when not on a path)
  double distance_m = 0.0;     ///< from the robot's position to the target [m]
};

/// Chooses motions within the distance threshold.
class ActionManager {
 public:
  /// max_step_m: the longest motion in one step [m]; throws InvalidArgument unless finite and > 0.
  explicit ActionManager(double max_step_m);
  double max_step_m() const { return max_step_m_; }

  /// The farthest cell of `path` (path[0] = the robot's cell) reachable along the path through cells navigable
  /// now, with its centre within max_step of `robot` [m] and every cell on the straight way there (but the robot's
  /// own) navigable; when the robot's own cell is not occupiable, occupiable cells stand in for navigable ones (a
  /// way out). If the path is the robot's own cell alone, or only that cell's centre is in range, and the robot is
  /// off the centre, the motion centres the robot; if the robot is centred and the next cell's centre is beyond a
  /// step (a diagonal when the step is shorter than a cell's diagonal), it goes a step's length towards that centre,
  /// when the point it reaches lies in another cell it may move to along a clear way. Targets not clear_of `others`
  /// are never chosen. nullopt when no progress is possible.
  std::optional<Motion> advance(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                Position robot, const std::vector<BodyClearance>& others = {}) const;

 private:
  const CellMask& moves_mask(const deliberative::LocalMap& map) const;
  double max_step_m_;
};

}  // namespace marsala::agent::executive
