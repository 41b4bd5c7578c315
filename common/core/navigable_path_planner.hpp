#pragma once
// Navigable path planner (paper §III-A, eq. 4-5): an informed search on the augmented local map for a deposition
// path to the local goal. A* over 8-connected cells with
//   f(n) = g(n) + alpha * c(n) + beta * l(n)
// g: path length [m]; c: construction cost, the MARS gap summed over the robot's footprint (cells within delta/2)
// at every path cell after the start [m] (eq. 5); l: straight-line distance to the goal [m].
// The path need not be navigable now: filling the MARS gap over its footprint makes it so (paper §II).
// A footprint cut by the map edge is priced at its mean gap times the full ball's cell count, so that the edge of
// the window (or of the world) is not a cheap corridor.

#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Weights of eq. 4 and the footprint size of eq. 5.
struct PlannerParams {
  double alpha = 0.00123;  ///< weight of the construction cost c [m of travel per m of accumulated gap]
  double beta = 1.0;       ///< weight of the heuristic l [-]; 1 keeps the search optimal (l is consistent)
  double delta_m = 1.0;    ///< body length: c sums the gap within delta/2 of each path cell [m]
};

/// Defaults for a body on a grid of cell_size_m [m]: alpha = cs / N, N the number of cells in the ball
/// B_{delta/2} (81 for delta 1 m at 0.1 m cells). Then alpha * c = sum over path cells of (mean footprint gap * cs):
/// the area [m^2] of the gap's vertical section along the path, so a detour is taken only when it saves more of
/// that area than its extra length [m]: around a wall through a nearby opening, but not around the robot's own
/// half-built ramp (whose target lies beyond the window). beta = 1: on windows of ~10^4 cells the optimal search
/// is cheap and its result exact.
/// Throws InvalidArgument unless delta_m and cell_size_m are finite and > 0.
PlannerParams default_planner_params(double delta_m, double cell_size_m);

/// What the planner found.
struct PlannerResult {
  bool found = false;             ///< false: no path through allowed cells (an expected outcome)
  std::vector<CellIndex> path;    ///< start ... goal, 8-connected (local indices)
  double length_m = 0.0;          ///< g at the goal [m]
  double gap_cost_m = 0.0;        ///< c at the goal [m]
  double target_volume_m3 = 0.0;  ///< deposition target volume: the MARS gap over the path's footprint [m^3]
  int expanded = 0;               ///< nodes expanded [count]
};

/// A* with the cost of eq. 4-5. The agent plans deposition paths with it on its augmented local map; the world, with
/// alpha = 0 on a zero gap, finds the payload's shortest route (the same search, so both agree on what a path is).
class NavigablePathPlanner {
 public:
  /// Throws InvalidArgument unless alpha >= 0, beta >= 0 and delta_m > 0, all finite.
  explicit NavigablePathPlanner(PlannerParams params);
  const PlannerParams& params() const { return params_; }

  /// A path through the cells where `allowed` is non-zero, priced by `gap` [m]; throws InvalidArgument when the
  /// mask and the gap differ in size, a gap value is negative or not finite, or start or goal is off the grid.
  PlannerResult plan(const Heightmap& gap, const CellMask& allowed, CellIndex start, CellIndex goal) const;

 private:
  PlannerParams params_;
};

}  // namespace marsala
