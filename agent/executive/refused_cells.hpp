#pragma once
// Refused cells (docs/runtime.md#refused-requests): what the world's refusals taught the robot. A motion the world
// refused because a cell is not occupiable for the body (rules 2.3 and 2.4) says the robot's map is wrong around that
// cell: the cell stays out of the robot's local map until the map around it changes (a scan reads its ball
// differently, the robot or another builds there), so the same request is never sent again on the same map. A motion
// refused for another reason (a neighbour's body, rule 2.5) depends on where the others stand: it is held out for a
// number of steps only. A deposition refused on a named cell (under a robot, out of reach) is no deposition target
// for as long.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// The cell (world index) a refusal reason names ("... cell (r, c) ..."), if any.
std::optional<CellIndex> cell_named(const std::string& reason);

/// The drop a terrain refusal names, as the body found it (": cell (r, c) at h m lies too far below cell (r, c) at h
/// m"): the lower cell and its height, then the higher (world indices, m); nullopt when it names none.
struct DropRefusal {
  CellIndex low;
  double low_m = 0.0;
  CellIndex high;
  double high_m = 0.0;
};
std::optional<DropRefusal> drop_named(const std::string& reason);
/// Every drop a terrain refusal names, the worst first (drop_named()), then each "; cell (r, c) at h m lies too far
/// below cell (r, c) at h m" that follows it: the other cells of the ball that break the rule
/// (docs/runtime.md#refused-requests). A malformed or non-finite entry ends the list there; empty when the reason names
/// no drop.
std::vector<DropRefusal> drops_named(const std::string& reason);

/// What a refusal for the deposit bound says (docs/runtime.md#deposit-bound, rules 3.5b and 3d.10): the cell and the
/// height the request would have left it at ("... would leave cell (r, c) at h m, ... above the deposit bound ...")
/// [world index, m]; nullopt for any other reason.
struct BoundRefusal {
  CellIndex cell;
  double height_m = 0.0;
};
std::optional<BoundRefusal> bound_named(const std::string& reason);

/// Where the pile stood that a refusal for a robot's body names (rule 3d.8: "deposit at (x, y) m raises cell (r, c),
/// under agent N") [m]; nullopt for any other reason.
std::optional<Position> pile_under_robot_named(const std::string& reason);

/// True when the reason says a cell is not occupiable for the body (rules 2.3, 2.4): the terrain there, not the
/// neighbours.
bool refused_for_terrain(const std::string& reason);

/// The cells a robot must not ask for again, and why.
class RefusedCells {
 public:
  /// ball_radius_cells: the body's ball (delta / (2 cs)) [cells], whose cells decide occupancy; change_m: the least
  /// change of a known height in the ball that counts as new information [m] (a scanned map's noise margin; > 0);
  /// hold_steps: how long a refusal that does not depend on the terrain holds [steps]. Throws InvalidArgument on a
  /// negative radius, a change that is not finite and > 0, or hold_steps 0.
  RefusedCells(double ball_radius_cells, double change_m, std::uint64_t hold_steps);

  /// The world refused a motion into `cell` (world index, as the map registers it) for the terrain: remembered with
  /// the map's heights and known mask of its ball, until they change (update()). Each earlier terrain refusal of the
  /// same cell doubles the change that counts (a noisy map that flickers there earns no new try each time).
  /// `drop_low`: the lower cell of the drop the world named, when it did (world index): its height is then a fact the
  /// map keeps against scans (MappingSystem::record_drop()), and any rise of it (the robot's own construction there)
  /// releases the refusal too, however small.
  void refuse_terrain(CellIndex cell, const Heightmap& heights, const CellMask& known,
                      std::optional<CellIndex> drop_low = std::nullopt);
  /// The world refused a request for a reason that does not depend on the terrain: `cell` held out until `step` +
  /// hold_steps.
  void refuse_for_now(CellIndex cell, std::uint64_t step);
  /// Forgets the terrain refusals whose ball the map now reads differently (a known height moved by more than
  /// change_m, or a cell became known or unknown) or whose named drop's lower cell rose, and the others once their
  /// hold has passed at `step`.
  void update(const Heightmap& heights, const CellMask& known, std::uint64_t step);

  /// True when no cell is held out.
  bool empty() const { return cells_.empty(); }
  /// True when `cell` (world index) is held out.
  bool contains(CellIndex cell) const { return cells_.count(cell) != 0; }
  /// The held-out cells, ascending (world indices).
  std::vector<CellIndex> cells() const;
  /// How many refusals were recorded so far [count].
  long long refusals() const { return refusals_; }

 private:
  struct Entry {
    std::uint64_t until_step = 0;  ///< a hold for a reason other than the terrain; 0 for a terrain refusal
    std::vector<double> ball;      ///< a terrain refusal: the ball's heights when refused, NaN where unknown [m]
    double change_m = 0.0;         ///< a terrain refusal: the change of a height that releases it [m]
    std::optional<CellIndex> drop_low;  ///< a terrain refusal that named its drop: the lower cell
    double drop_low_m = 0.0;            ///< and its height when refused [m]
  };
  std::vector<double> ball(CellIndex cell, const Heightmap& heights, const CellMask& known) const;
  static bool changed(const std::vector<double>& before, const std::vector<double>& now, double change_m);

  std::vector<CellIndex> offsets_;
  double change_m_;
  std::uint64_t hold_steps_;
  std::map<CellIndex, Entry> cells_;
  std::map<CellIndex, int> terrain_refusals_;  ///< terrain refusals per cell so far [count]
  long long refusals_ = 0;
};

}  // namespace marsala::agent::executive
