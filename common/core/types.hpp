#pragma once
// Vocabulary types shared by every layer, in the paper's language.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace marsala {

/// A cell of a row-major grid: row 0 is the northmost row, col 0 the westmost column.
struct CellIndex {
  int row = 0;
  int col = 0;
  friend bool operator==(CellIndex a, CellIndex b) { return a.row == b.row && a.col == b.col; }
  friend bool operator!=(CellIndex a, CellIndex b) { return !(a == b); }
  /// Row-major order (north to south, then west to east): the order of the grid's storage.
  friend bool operator<(CellIndex a, CellIndex b) { return a.row < b.row || (a.row == b.row && a.col < b.col); }
};

/// A rectangle of grid cells: rows [first.row, first.row + rows) x cols [first.col, first.col + cols).
struct CellRect {
  CellIndex first;  ///< top-left (north-west) cell
  int rows = 0;     ///< [cells]
  int cols = 0;     ///< [cells]

  bool empty() const { return rows <= 0 || cols <= 0; }
  long long size() const { return empty() ? 0 : static_cast<long long>(rows) * cols; }
  bool contains(CellIndex c) const {
    return c.row >= first.row && c.row < first.row + rows && c.col >= first.col && c.col < first.col + cols;
  }
};

/// A point in the world frame [m]: x grows east, y grows north.
struct Position {
  double x = 0.0;
  double y = 0.0;
  friend bool operator==(Position a, Position b) { return a.x == b.x && a.y == b.y; }
  friend bool operator!=(Position a, Position b) { return !(a == b); }
};

/// The planar (Euclidean) distance between two positions [m].
inline double distance(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

/// std::hypot(dx, dy) <= r, the same answer for less work where many offsets lie far: hypot() rounds the true length to
/// a neighbouring double, so it is never below the larger of |dx| and |dy|, and when that exceeds r so does the length.
inline bool within(double dx, double dy, double r) {
  return std::max(std::abs(dx), std::abs(dy)) <= r && std::hypot(dx, dy) <= r;
}

/// An axis-aligned rectangle of the world frame [m]: [x0, x1] x [y0, y1] (x0 <= x1 and y0 <= y1 once validated).
struct Rect {
  double x0 = 0.0;
  double y0 = 0.0;
  double x1 = 0.0;
  double y1 = 0.0;
  friend bool operator==(const Rect& a, const Rect& b) {
    return a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1;
  }
  friend bool operator!=(const Rect& a, const Rect& b) { return !(a == b); }
};

/// Motion parameters of a robot (paper eq. 1).
struct NavigabilityParams {
  double kappa = 0.3;    ///< maximum climbable slope, rise over run [m/m]
  double delta_m = 1.0;  ///< body length: diameter of the ball B_{delta/2} [m]
  double eps_m = 0.05;   ///< largest discontinuity driven over per body length [m]
  friend bool operator==(const NavigabilityParams& a, const NavigabilityParams& b) {
    return a.kappa == b.kappa && a.delta_m == b.delta_m && a.eps_m == b.eps_m;
  }
  friend bool operator!=(const NavigabilityParams& a, const NavigabilityParams& b) { return !(a == b); }
};

/// A tile of the authoritative terrain, as a robot's terrain sensing delivers it: heights of cells [tile_row *
/// tile_size, ...) x [tile_col * tile_size, ...).
struct TerrainTile {
  std::int32_t tile_row = 0;
  std::int32_t tile_col = 0;
  std::int32_t rows = 0;  ///< cells in this tile (tile_size, or fewer at the grid edge)
  std::int32_t cols = 0;
  std::vector<double> heights;  ///< rows * cols heights [m], row-major, row 0 northmost
};

/// Another robot within proximity range, as proximity sensing reports it.
struct Neighbour {
  std::uint32_t agent_id = 0;
  Position position;  ///< its centre [m]
  double z_m = 0.0;   ///< terrain height under its centre [m]
  double radius_m = 0.0;  ///< half its body length delta: proximity sensing sees the body's extent [m]
};

/// Raise one cell by `height_m` (> 0): additive construction only.
struct Deposition {
  std::int32_t row = 0;
  std::int32_t col = 0;
  double height_m = 0.0;
};

/// Deposit `volume_m3` of material with its centre at (x_m, y_m) in the world frame: the robot's depositor gives it
/// its physical shape (common/core/deposit_shapes.hpp: a column of cubes, a cone of granular material).
struct Deposit {
  Position centre;  ///< [m]
  double volume_m3 = 0.0;
};

/// Fixed tolerances every implementation shares (ARCHITECTURE.md, grid conventions; docs/runtime.md#tolerances).
namespace tolerance {
/// Added to (delta / (2 cs))^2 when deciding whether an offset lies in the ball [cells^2].
inline constexpr double kBallCells2 = 1e-9;
/// Added to eps + kappa * distance when deciding whether a pair of heights passes [m].
inline constexpr double kHeightM = 1e-9;
/// Added to length limits (step, reach, base radius, proximity, clearance) [m].
inline constexpr double kLengthM = 1e-9;
/// Added to volume limits [m^3].
inline constexpr double kVolumeM3 = 1e-12;
/// Largest |h/q - round(h/q)| of a height h that counts as a whole number of cube layers q.
inline constexpr double kCubeMultiple = 1e-6;
}  // namespace tolerance

}  // namespace marsala
