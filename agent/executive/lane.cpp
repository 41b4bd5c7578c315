#include "marsala/agent/executive/lane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace marsala::agent::executive {
namespace {

/// How far the corridor through `from` reaches along `unit` (half-cell samples up to `limit`) [m]; nullopt when it
/// does not end within the limit (open ground).
std::optional<double> extent(const deliberative::LocalMap& local, const CellMask& corridor, Position from,
                             Position unit, double limit) {
  const double sample = 0.5 * local.geometry().cell_size_m;
  double reached = 0.0;
  for (double t = sample; t <= limit + 1e-9; t += sample) {
    const auto cell = local.cell_at({from.x + t * unit.x, from.y + t * unit.y});
    if (!cell || corridor(cell->row, cell->col) == 0) return reached;
    reached = t;
  }
  return std::nullopt;
}

}  // namespace

std::vector<CellIndex> lane_path(const deliberative::LocalMap& local, const CellMask& corridor,
                                 const std::vector<CellIndex>& path, double offset_m, double corridor_width_m) {
  if (!(offset_m > 0.0) || path.size() < 2) return path;
  const int n = static_cast<int>(path.size());
  // Per path cell: the unit vector to the right of the path there, and the lane's offset from the cell (NaN where
  // the path is not in a corridor).
  const double none = std::numeric_limits<double>::quiet_NaN();
  std::vector<Position> right(path.size(), Position{0.0, 0.0});
  std::vector<double> wanted(path.size(), none);
  for (int i = 1; i < n; ++i) {
    const CellIndex cell = path[static_cast<std::size_t>(i)];
    const Position a = local.center(path[static_cast<std::size_t>(std::max(0, i - kLaneDirectionSpan))]);
    const Position b = local.center(path[static_cast<std::size_t>(std::min(n - 1, i + kLaneDirectionSpan))]);
    const double dx = b.x - a.x, dy = b.y - a.y, length = std::hypot(dx, dy);
    if (!(length > 0.0) || corridor(cell.row, cell.col) == 0) continue;
    right[static_cast<std::size_t>(i)] = {dy / length, -dx / length};  // right of (dx, dy): x east, y north
    const Position centre = local.center(cell);
    const auto to_right = extent(local, corridor, centre, right[static_cast<std::size_t>(i)], corridor_width_m);
    const Position left{-right[static_cast<std::size_t>(i)].x, -right[static_cast<std::size_t>(i)].y};
    const auto to_left = extent(local, corridor, centre, left, corridor_width_m);
    if (to_right && to_left)
      wanted[static_cast<std::size_t>(i)] = std::clamp(0.5 * (*to_right - *to_left) + offset_m, -*to_left, *to_right);
  }
  // A corridor is a stretch of at least kMinCorridorCells path cells: a narrow spot between obstacles is not a band.
  for (int i = 1; i < n;) {
    int j = i;
    while (j < n && !std::isnan(wanted[static_cast<std::size_t>(j)])) ++j;
    if (j - i < kMinCorridorCells)
      for (int k = i; k < j; ++k) wanted[static_cast<std::size_t>(k)] = none;
    i = j + 1;
  }
  // The offset changes by at most the distance between consecutive path cells (a lane is entered and left at 45
  // degrees at most), from 0 at the robot.
  std::vector<CellIndex> lane{path.front()};
  lane.reserve(path.size());
  double t = 0.0;
  for (int i = 1; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const double ds = std::hypot(local.center(path[k]).x - local.center(path[k - 1]).x,
                                 local.center(path[k]).y - local.center(path[k - 1]).y);
    const double goal = std::isnan(wanted[k]) ? 0.0 : wanted[k];
    t = std::clamp(goal, t - ds, t + ds);
    CellIndex cell = path[k];
    if (t != 0.0 && (right[k].x != 0.0 || right[k].y != 0.0)) {
      const Position centre = local.center(cell);
      const auto shifted = local.cell_at({centre.x + t * right[k].x, centre.y + t * right[k].y});
      if (shifted && local.navigable(shifted->row, shifted->col) != 0) cell = *shifted;
    }
    if (cell != lane.back()) lane.push_back(cell);
  }
  return lane;
}

}  // namespace marsala::agent::executive
