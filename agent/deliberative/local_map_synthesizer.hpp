#pragma once
// Local map synthesizer (paper §III-A): the augmented local map around the robot. A window of the agent's own map
// (the square sensing window [x - r, x + r] x [y - r, y + r] clipped to the grid), its MARS gap and navigability,
// the local origin and the local goal. MARS and navigability are computed on the window alone, which keeps them
// tractable and, by the local MARS bound, consistent with the global one.
//
//   +-------------------------------+   window (local indices, row 0 northmost)
//   |  origin o                     |   o: the occupiable trajectory cell nearest the window boundary
//   |                               |      (the sensing square's, unclipped by the grid)
//   |     \__ trajectory            |   R: the robot's cell
//   |         \__ R ------------- g |   g: where the straight line from R to the target leaves the window
//   +-------------------------------+      (or the target cell when it lies inside)

#include <algorithm>
#include <optional>
#include <utility>
#include <vector>

#include "marsala/agent/deliberative/known_map.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::deliberative {

/// The augmented local map: local heightmap, MARS gap, navigability, robot cell, local origin and local goal.
/// All indices are local (row 0, col 0 = the window's top-left cell); `offset` maps them to the world grid.
struct LocalMap {
  GridGeometry world;               ///< the world grid: positions map to cells through it, as the world maps them
  CellIndex offset;                 ///< world index of the window's top-left cell
  Heightmap heights;                ///< the window [m], placed in the world frame; unknown cells hold the lowest known,
                                    ///< those under the latest scan's rays (overflown) their overflight
  CellMask known;                   ///< 1 where the agent's map knows the cell
  Heightmap gap;                    ///< MARS gap P_kappa[h] - h of the window at the construction kappa [m]; 0 on
                                    ///< unknown cells and on cells held as no surface but a notch's (fill_cap)
  /// How far a cell may be raised whatever the map's noise margin [m]: a bound in a notch (notch_fill()) up to its
  /// notch level, +inf on every other cell. Empty (0 x 0) on a map that holds no bound: no cap.
  Heightmap fill_cap;
  /// 1 on the unknown cells under a ray of the latest scan (KnownMap::overflight): their top lies below the ray, and
  /// their gap is what raises them at most to the MARS height of the known cells (fill_under_rays()). Empty (0 x 0)
  /// on a map without overflights.
  CellMask overflown;
  CellMask blind;                   ///< 1 where the cell's ball holds an unknown cell: it is never occupiable
  CellMask passable;                ///< where a deposition path may run: known cells; on a scanned map known cells
                                    ///< that are not blind, when they reach the local goal
  CellMask occupiable;              ///< occupiable cells; never a blind one
  /// The cells the heights alone make occupiable for `heights_navigability` (NavigabilityProcessor::occupiable()),
  /// 0 on blind cells: `occupiable` before the robot's own and stood-on cells are opened and any caller takes cells
  /// out. Empty (0 x 0) on a map built without it.
  CellMask heights_occupiable;
  NavigabilityParams heights_navigability;  ///< the body heights_occupiable was computed for
  CellMask navigable;               ///< occupiable cells 8-connected to the robot's cell
  CellIndex robot;                  ///< the robot's cell
  std::optional<CellIndex> origin;  ///< the local origin, when some trajectory cell in the window is occupiable
  /// The local goal: local_goal(); for a scanning sensor's map, when it is not reachable through passable cells, the
  /// reachable passable cell nearest to it.
  CellIndex goal;
  bool goal_is_target = false;  ///< true when the local goal is the target's own cell

  /// The window's geometry (world placement, cell size [m]).
  const GridGeometry& geometry() const { return heights.geometry(); }
  int rows() const { return heights.rows(); }
  int cols() const { return heights.cols(); }
  bool contains(CellIndex local) const { return heights.contains(local); }
  CellIndex to_global(CellIndex local) const { return {local.row + offset.row, local.col + offset.col}; }
  CellIndex to_local(CellIndex global) const { return {global.row - offset.row, global.col - offset.col}; }
  /// Centre of a local cell in the world frame [m].
  Position center(CellIndex local) const { return heights.cell_center(local); }
  /// The local cell containing `p` [m] (mapped through the world grid), or nullopt when it is outside the window.
  std::optional<CellIndex> cell_at(Position p) const {
    const auto global = world.cell_at(p);
    if (!global) return std::nullopt;
    const CellIndex local = to_local(*global);
    return contains(local) ? std::optional<CellIndex>(local) : std::nullopt;
  }
};

/// How far `cell` (world index) may be raised when `map` holds it as a bound (faces seen from below, no surface read)
/// [m]: a bound lying below both its neighbours along a grid axis (north-south or east-west), each known as a
/// surface or a bound, is a notch in that line, filled up to its notch level: the higher over the two axes of the
/// lower neighbour of the pair. 0 for any other cell (a bound with no such pair: a wall's foot or side; ground only
/// assumed, unknown or off the grid) (docs/runtime.md#mapping, notches).
double notch_fill(const KnownMap& map, CellIndex cell);

/// How far a cell of the local map (local index) may be raised [m]: its MARS gap less `margin_m` (the map's noise
/// margin), at most its fill cap.
inline double rise_wanted_m(const LocalMap& local, CellIndex cell, double margin_m) {
  const double rise_m = local.gap(cell) - margin_m;
  return local.fill_cap.rows() == local.rows() && local.fill_cap.cols() == local.cols()
             ? std::min(rise_m, local.fill_cap(cell))
             : rise_m;
}

/// True when a deposition may raise `cell` (local index): it is known, or unknown under the latest scan's rays
/// (LocalMap::overflown).
inline bool may_fill(const LocalMap& local, CellIndex cell) {
  return local.known(cell.row, cell.col) != 0 || (local.overflown.rows() == local.rows() &&
                                                  local.overflown.cols() == local.cols() &&
                                                  local.overflown(cell.row, cell.col) != 0);
}

/// Window of a world grid: top-left cell and size [cells].
struct Window {
  CellIndex top_left;
  int rows = 0;
  int cols = 0;
};

/// The cells whose squares meet [x - r, x + r] x [y - r, y + r] (r = range_m [m]), clipped to the grid; throws
/// InvalidArgument when the robot is off the grid or the range is negative or not finite.
Window sensing_window(const GridGeometry& world, Position robot, double range_m);

/// Builds augmented local maps for one robot.
class LocalMapSynthesizer {
 public:
  /// params: the robot's kappa [m/m], delta [m], eps [m] (occupiable and navigable cells); sensing_range_m:
  /// half-side of its sensing window [m]; construction_kappa: the slope of the MARS whose gap the robot fills [m/m]
  /// (default: params.kappa; a payload's smaller kappa when it builds for one). Throws InvalidArgument on invalid
  /// parameters.
  LocalMapSynthesizer(NavigabilityParams params, double sensing_range_m,
                      std::optional<double> construction_kappa = std::nullopt);

  /// The augmented local map of the agent's map `map` around `robot` [m] heading for `target` [m]; throws
  /// InvalidArgument when the robot is off the grid.
  LocalMap synthesize(const KnownMap& map, Position robot, Position target) const;

  /// The local origin: among trajectory cells (world indices) inside the window, the one nearest the boundary of
  /// the sensing square [x - r, x + r] x [y - r, y + r] around `robot` (r = range_m) that is navigable from the
  /// robot, else the nearest that is occupiable; ties go to the oldest. The square, not the window clipped to the
  /// grid: a world edge is no boundary of what the robot knows.
  /// Under the rays (docs/runtime.md#mapping): each unknown cell of `local` (its heights, known mask and gap already
  /// synthesized) whose column a ray of the latest scan crossed at `overflight` [m] (the world grid's) without striking
  /// it stands below that height, so raising it by P - overflight, P the MARS height at this synthesizer's kappa of the
  /// window's known cells alone, leaves it at most at P, whatever its true height: its gap; its window height becomes
  /// the overflight, and LocalMap::overflown marks it.
  void fill_under_rays(LocalMap& local, const Heightmap& overflight) const;

  static std::optional<CellIndex> local_origin(const LocalMap& local, const std::vector<CellIndex>& trajectory,
                                               Position robot, double range_m);
  /// The local goal: the target's cell when it lies in the window, else the cell where the straight line from the
  /// robot to the target leaves the window (the rectangle of the window's cell centres). Second: goal_is_target.
  static std::pair<CellIndex, bool> local_goal(const LocalMap& local, Position robot, Position target);

  const NavigabilityParams& params() const { return navigability_.params(); }
  double sensing_range_m() const { return sensing_range_m_; }

 private:
  /// The last window's MARS gap and occupiable cells, by the window's placement and heights: both are functions of
  /// the heights alone, so a robot whose window did not change since its last decision (waiting, holding, standing at
  /// the base) reuses them. About 40 % of path_generated's decisions do.
  struct Memo {
    CellIndex offset{-1, -1};
    int rows = 0;
    int cols = 0;
    std::vector<double> heights;
    Heightmap gap;
    CellMask occupiable;
  };
  /// Fills local.gap and local.occupiable from local.heights, from the memo when the window is the last one.
  void gap_and_occupiable(LocalMap& local) const;
  /// NavigabilityProcessor::occupiable() of local.heights, taking from the memo's window every cell whose ball the
  /// windows' edges clip alike and whose ball's bounding square holds the same heights in both: the rule reads only
  /// the ball. The other cells (a moved window's edges, the balls around changed heights) are judged one by one by the
  /// pair rule on the ball, as cell_occupiable_in_ball() judges them, or the whole window again when they are many.
  CellMask occupiable_after_memo(const LocalMap& local) const;
  // The cells of `map.stood` in the window whose balls read as when the robot stood there become occupiable.
  static void open_stood_cells(LocalMap& local, const KnownMap& map);

  MarsProcessor mars_;
  NavigabilityProcessor navigability_;
  double sensing_range_m_;
  mutable Memo memo_;
  mutable double ball_radius_cells_ = -1.0;  // the body ball below is disc_offsets() of this radius [cells]
  mutable std::vector<CellIndex> ball_;
  mutable int ball_reach_ = 0;  // largest |row| or |col| offset of the ball [cells]
  struct BallPair {
    std::size_t a, b;    // indices into ball_
    double threshold_m;  // eps + kappa |a - b| + tolerance [m]
  };
  mutable std::vector<BallPair> ball_pairs_;
};

}  // namespace marsala::agent::deliberative
