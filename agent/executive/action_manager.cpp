#include "marsala/agent/executive/action_manager.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/segment_cells.hpp"

namespace marsala::agent::executive {
namespace {

/// Below this a robot counts as standing on its cell's centre [m].
constexpr double kCentredM = 1e-9;

/// True when every cell the straight motion from `from` to `to` passes through, other than the one it leaves, is in
/// the map and set in `mask`: the world accepts a motion only when each of them is occupiable
/// (docs/runtime.md#rule-2-motion), and the mask holds no cell the agent does not believe occupiable.
bool sweep_clear(const deliberative::LocalMap& map, const CellMask& mask, Position from, Position to) {
  const std::vector<CellIndex> cells = cells_on_segment(map.world, from, to);
  for (std::size_t i = 1; i < cells.size(); ++i) {
    if (cells[i] == cells.front()) continue;
    const CellIndex local = map.to_local(cells[i]);
    if (!map.contains(local) || mask(local.row, local.col) == 0) return false;
  }
  return true;
}

}  // namespace

ActionManager::ActionManager(double max_step_m) : max_step_m_(max_step_m) {
  if (!(max_step_m > 0.0) || !std::isfinite(max_step_m))
    throw InvalidArgument(fmt::format("action manager: max step must be finite and > 0 m, got {}", max_step_m));
}

const CellMask& ActionManager::moves_mask(const deliberative::LocalMap& map) const {
  return map.navigable(map.robot.row, map.robot.col) != 0 ? map.navigable : map.occupiable;
}

std::optional<Motion> ActionManager::advance(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                             Position robot, const std::vector<BodyClearance>& others) const {
  if (path.empty()) return std::nullopt;
  const CellMask& mask = moves_mask(map);
  const Position own = map.center(path[0]);
  const double d_own = distance(own, robot);
  const bool can_centre =
      mask(path[0].row, path[0].col) != 0 && d_own > kCentredM && d_own <= max_step_m_ && clear_of(others, robot, own);
  // A path that ends on the robot's own cell: arrive on its centre (a partial diagonal move leaves a robot off it).
  if (path.size() == 1) return can_centre ? std::optional<Motion>(Motion{path[0], own, 0, d_own}) : std::nullopt;
  std::optional<Motion> best;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const CellIndex cell = path[i];
    if (!map.contains(cell) || mask(cell.row, cell.col) == 0) break;
    const Position centre = map.center(cell);
    const double d = distance(centre, robot);
    if (d <= max_step_m_ && sweep_clear(map, mask, robot, centre) && clear_of(others, robot, centre))
      best = Motion{cell, centre, i, d};
  }
  if (best) return best;
  // The next cell is navigable but out of range from where the robot stands: first step onto its own centre.
  const CellIndex next = path[1];
  if (!map.contains(next) || mask(next.row, next.col) == 0) return std::nullopt;
  if (can_centre) return Motion{path[0], own, 0, d_own};
  // Centred, and the next cell's centre is farther than a step (a diagonal move when the step is shorter than a
  // cell's diagonal): go max_step of the way towards it, provided that point lies in another cell it can move to.
  const Position aim = map.center(next);
  const double d_next = distance(aim, robot);
  const double f = max_step_m_ * (1.0 - 1e-9) / d_next;
  const Position partial{robot.x + (aim.x - robot.x) * f, robot.y + (aim.y - robot.y) * f};
  const auto cell = map.cell_at(partial);
  if (!cell || *cell == path[0] || mask(cell->row, cell->col) == 0 || !sweep_clear(map, mask, robot, partial) ||
      !clear_of(others, robot, partial))
    return std::nullopt;  // a new cell it may reach, or no motion
  return Motion{*cell, partial, *cell == next ? std::size_t{1} : std::size_t{0}, distance(partial, robot)};
}

}  // namespace marsala::agent::executive
