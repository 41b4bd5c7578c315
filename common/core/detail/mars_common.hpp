#pragma once
// Shared definitions of the MARS processor internals. All geometry is in cell units (row, col);
// heights are metres; kcs = kappa * cell size is the drop per cell of distance [m/cell].

#include <cmath>
#include <limits>

namespace marsala::detail {

/// Side of a source leaf and of a target block [cells]; one 64-bit mask per leaf.
inline constexpr int kBlock = 8;
/// Sources with dr^2 + dc^2 <= this are applied densely to every cell [cells^2].
inline constexpr int kLocalRadius2 = 25;
/// Positive infinity [m].
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// The grid and parameters of one projection.
struct Problem {
  const double* h = nullptr;  ///< row-major heights [m]
  int rows = 0;               ///< grid rows [cells]
  int cols = 0;               ///< grid columns [cells]
  double kcs = 0.0;           ///< kappa * cell size [m/cell]
  double tol = 0.0;           ///< tie tolerance for domination and pruning [m]
};

/// Value of a source of height h_source [m] at squared distance d2 [cells^2]: the one formula
/// used everywhere, so that ties present in the input (a MARS output fed back) are seen bit for bit.
inline double cone_value(double h_source, double kcs, long long d2) {
  return h_source - kcs * std::sqrt(static_cast<double>(d2));
}

/// Row of linear index i in a grid with 1 / cols = inv_cols; exact for any grid below 2^31 cells.
inline int row_of(long long i, double inv_cols) { return static_cast<int>((static_cast<double>(i) + 0.5) * inv_cols); }

}  // namespace marsala::detail
