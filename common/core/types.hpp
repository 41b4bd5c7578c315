#pragma once
// Vocabulary types shared by every layer, in the paper's language.

#include <cstdint>

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

/// Fixed tolerances every implementation shares (ARCHITECTURE.md, grid conventions).
namespace tolerance {
/// Added to (delta / (2 cs))^2 when deciding whether an offset lies in the ball [cells^2].
inline constexpr double kBallCells2 = 1e-9;
/// Added to eps + kappa * distance when deciding whether a pair of heights passes [m].
inline constexpr double kHeightM = 1e-9;
}  // namespace tolerance

}  // namespace marsala
