#pragma once
// Vocabulary types shared by every layer, in the paper's language.

#include <cstdint>
#include <vector>

namespace marsala {

/// A cell of a row-major grid: row 0 is the northmost row, col 0 the westmost column.
struct CellIndex {
  int row = 0;
  int col = 0;
  friend bool operator==(CellIndex a, CellIndex b) { return a.row == b.row && a.col == b.col; }
  friend bool operator!=(CellIndex a, CellIndex b) { return !(a == b); }
};

/// A point in the world frame [m]: x grows east, y grows north.
struct Position {
  double x = 0.0;
  double y = 0.0;
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
  double x_m = 0.0;
  double y_m = 0.0;
  double z_m = 0.0;
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
  double x_m = 0.0;
  double y_m = 0.0;
  double volume_m3 = 0.0;
};

/// Fixed tolerances every implementation shares (ARCHITECTURE.md, grid conventions).
namespace tolerance {
/// Added to (delta / (2 cs))^2 when deciding whether an offset lies in the ball [cells^2].
inline constexpr double kBallCells2 = 1e-9;
/// Added to eps + kappa * distance when deciding whether a pair of heights passes [m].
inline constexpr double kHeightM = 1e-9;
}  // namespace tolerance

}  // namespace marsala
