#include "marsala/agent/executive/lane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "marsala/core/iterators.hpp"
#include "marsala/core/mars_processor.hpp"

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

/// The unit vector to the right of `path` at its cell i, its direction taken from path[i - k] to path[i + k] (k =
/// kLaneDirectionSpan, clipped to the path); nullopt when those are the same cell.
std::optional<Position> right_at(const deliberative::LocalMap& local, const std::vector<CellIndex>& path, int i) {
  const int n = static_cast<int>(path.size());
  const Position from = local.center(path[static_cast<std::size_t>(std::max(0, i - kLaneDirectionSpan))]);
  const Position to = local.center(path[static_cast<std::size_t>(std::min(n - 1, i + kLaneDirectionSpan))]);
  const double dx = to.x - from.x, dy = to.y - from.y, length = std::hypot(dx, dy);
  if (!(length > 0.0)) return std::nullopt;
  return Position{dy / length, -dx / length};  // right of (dx, dy): x east, y north
}

/// Per path cell: the unit vector to the right of the path there, and the offset from the cell of the point
/// offset_m right of the corridor's centre across it (NaN where the path is not in a corridor of kMinCorridorCells
/// path cells in a row), for path cells from `first` on.
struct Across {
  std::vector<Position> right;
  std::vector<double> wanted;
};

Across across(const deliberative::LocalMap& local, const CellMask& corridor, const std::vector<CellIndex>& path,
              double offset_m, double corridor_width_m, int first) {
  const int n = static_cast<int>(path.size());
  const double none = std::numeric_limits<double>::quiet_NaN();
  Across a{std::vector<Position>(path.size(), Position{0.0, 0.0}), std::vector<double>(path.size(), none)};
  for (int i = first; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const CellIndex cell = path[k];
    const auto right = right_at(local, path, i);
    if (!right || corridor(cell.row, cell.col) == 0) continue;
    a.right[k] = *right;
    const Position centre = local.center(cell);
    const auto to_right = extent(local, corridor, centre, a.right[k], corridor_width_m);
    const auto to_left = extent(local, corridor, centre, {-a.right[k].x, -a.right[k].y}, corridor_width_m);
    if (to_right && to_left) a.wanted[k] = std::clamp(0.5 * (*to_right - *to_left) + offset_m, -*to_left, *to_right);
  }
  // A corridor is a stretch of at least kMinCorridorCells path cells: a narrow spot between obstacles is not a band.
  for (int i = first; i < n;) {
    int j = i;
    while (j < n && !std::isnan(a.wanted[static_cast<std::size_t>(j)])) ++j;
    if (j - i < kMinCorridorCells)
      for (int k = i; k < j; ++k) a.wanted[static_cast<std::size_t>(k)] = none;
    i = j + 1;
  }
  return a;
}

/// Where the structure lies across a path cell off it, on one side: from the first structure cell, at most
/// `limit` [m] away, to the end of the structure's run from there (up to twice the limit) [m].
struct SideRun {
  double from_m = 0.0;
  double to_m = 0.0;
};
std::optional<SideRun> side_run(const deliberative::LocalMap& local, const CellMask& structure, Position from,
                                Position unit, double limit) {
  const double sample = 0.5 * local.geometry().cell_size_m;
  const auto in_structure = [&](double t) {
    const auto cell = local.cell_at({from.x + t * unit.x, from.y + t * unit.y});
    return cell && structure(cell->row, cell->col) != 0;
  };
  double t = sample;
  while (t <= limit + 1e-9 && !in_structure(t)) t += sample;
  if (t > limit + 1e-9) return std::nullopt;
  SideRun run{t, t};
  while (run.to_m + sample <= 2.0 * limit + 1e-9 && in_structure(run.to_m + sample)) run.to_m += sample;
  return run;
}

/// Per path cell: true when the path runs beside `structure` there: the cell is off it, and across the path on
/// either side the structure begins within width_m [m] and its far edge lies more than width_m / 2 from the cell (a
/// band width_m wide centred on the cell would not hold it: filling around the cell widens the structure, it does
/// not complete it); for at least kMinCorridorCells path cells in a row (a path that runs beside the structure, not
/// one that leaves its ragged tip).
std::vector<bool> beside(const deliberative::LocalMap& local, const CellMask& structure,
                         const std::vector<CellIndex>& path, double width_m) {
  const int n = static_cast<int>(path.size());
  std::vector<bool> out(path.size(), false);
  for (int i = 0; i < n; ++i) {
    const CellIndex cell = path[static_cast<std::size_t>(i)];
    const auto right = right_at(local, path, i);
    if (!right || structure(cell.row, cell.col) != 0) continue;
    const Position centre = local.center(cell);
    const auto to_right = side_run(local, structure, centre, *right, width_m);
    const auto to_left = side_run(local, structure, centre, {-right->x, -right->y}, width_m);
    out[static_cast<std::size_t>(i)] =
        (to_right && to_right->to_m > 0.5 * width_m) || (to_left && to_left->to_m > 0.5 * width_m);
  }
  for (int i = 0; i < n;) {
    int j = i;
    while (j < n && out[static_cast<std::size_t>(j)]) ++j;
    if (j - i < kMinCorridorCells)
      for (int k = i; k < j; ++k) out[static_cast<std::size_t>(k)] = false;
    i = j + 1;
  }
  return out;
}

}  // namespace

std::vector<CellIndex> lane_path(const deliberative::LocalMap& local, const CellMask& corridor,
                                 const std::vector<CellIndex>& path, double offset_m, double corridor_width_m) {
  if (!(offset_m > 0.0) || path.size() < 2) return path;
  const int n = static_cast<int>(path.size());
  const auto [right, wanted] = across(local, corridor, path, offset_m, corridor_width_m, 1);
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

std::vector<CellIndex> band_centre_path(const deliberative::LocalMap& local, const CellMask& corridor,
                                        const std::vector<CellIndex>& path, double corridor_width_m,
                                        double max_shift_m, const CellMask* structure) {
  if (path.size() < 2 || !(max_shift_m > 0.0)) return path;
  const int n = static_cast<int>(path.size());
  const Across a = across(local, corridor, path, 0.0, corridor_width_m, 0);
  // A path that runs beside the structure is no part of it: nothing is built along it.
  std::vector<bool> off(path.size(), false);
  if (structure && structure->rows() == local.rows() && structure->cols() == local.cols())
    off = beside(local, *structure, path, corridor_width_m);
  std::vector<CellIndex> out;
  out.reserve(path.size());
  double shift = 0.0;  // the shift towards the centre line at the last path cell in a corridor [m]
  bool seen = false;
  for (int i = 0; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    if (off[k]) continue;
    const double w = a.wanted[k];
    if (!std::isnan(w)) shift = std::clamp(w, -max_shift_m, max_shift_m), seen = true;
    CellIndex cell = path[k];
    // Past the corridor (the structure's end) the centre line goes on at the last shift, across the path's own
    // direction there.
    const auto right = seen && shift != 0.0 ? right_at(local, path, i) : std::nullopt;
    if (right) {
      const Position c = local.center(cell);
      if (const auto moved = local.cell_at({c.x + shift * right->x, c.y + shift * right->y})) cell = *moved;
    }
    if (out.empty() || cell != out.back()) out.push_back(cell);
  }
  return out;
}

CellMask band_mask(const deliberative::LocalMap& local, const std::vector<std::vector<CellIndex>>& paths,
                   double half_width_m) {
  CellMask out = CellMask::Zero(local.rows(), local.cols());
  const std::vector<CellIndex> disc = disc_offsets(half_width_m / local.geometry().cell_size_m);
  for (const auto& path : paths)
    for (const CellIndex p : path)
      for (const CellIndex d : disc) {
        const CellIndex q{p.row + d.row, p.col + d.col};
        if (local.contains(q)) out(q.row, q.col) = 1;
      }
  return out;
}

Heightmap band_sources(const deliberative::LocalMap& local, const CellMask& band) {
  // The lowest height of the window is no source: every cone from it lies under every cell.
  Heightmap sources = local.heights;
  const double low = local.heights.heights().minCoeff();
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (band(r, c) == 0) sources(r, c) = low;
  return sources;
}

Heightmap band_fill_gap(const deliberative::LocalMap& local, const CellMask& band, double kappa) {
  return gap_below_bound_of(local, band_sources(local, band), kappa);
}

Heightmap way_fill_gap(const deliberative::LocalMap& local, const std::vector<CellIndex>& path, double radius_m,
                       double kappa) {
  return gap_below_bound_of(local, way_sources(local, path, radius_m), kappa);
}

Heightmap way_sources(const deliberative::LocalMap& local, const std::vector<CellIndex>& path, double radius_m) {
  return band_sources(local, band_mask(local, {path}, radius_m));
}

Heightmap gap_below_bound_of(const deliberative::LocalMap& local, const Heightmap& sources, double kappa) {
  return gap_below(local, MarsProcessor(kappa).project(sources, gap_cells(local)));
}

CellMask gap_cells(const deliberative::LocalMap& local) {
  CellMask cells(local.rows(), local.cols());
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) cells(r, c) = !(local.gap(r, c) <= 0.0);
  return cells;
}

Heightmap gap_below(const deliberative::LocalMap& local, const Heightmap& target) {
  Heightmap gap = local.gap;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      gap(r, c) = std::min(gap(r, c), std::max(0.0, target(r, c) - local.heights(r, c)));
  return gap;
}

}  // namespace marsala::agent::executive
