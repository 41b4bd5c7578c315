#pragma once
// Heightmap: a row-major grid of double heights [m] with its place in the world frame.
//
//   y (north)
//   ^
//   |  row 0       +-------+-------+-------+   <- northmost row (first data line of an .asc file)
//   |              | (0,0) | (0,1) | (0,2) |
//   |  row 1       +-------+-------+-------+
//   |              | (1,0) | (1,1) | (1,2) |
//   |  yll ------> +-------+-------+-------+
//   |              ^ xll    <- cs ->
//   +------------------------------------------> x (east)
//
// Cell (r, c) has its centre at x = xll + (c + 0.5) * cs, y = yll + (nrows - r - 0.5) * cs.
// Index (CellIndex: row, col) and Position (x, y in metres) never mix implicitly.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "marsala/core/types.hpp"

namespace marsala {

/// Row-major storage of heights [m].
using HeightMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// Row-major per-cell flags (1 = true, 0 = false), e.g. occupiable or navigable cells.
using CellMask = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Size and placement of a grid: rows, cols, lower-left corner [m], cell size [m/cell].
struct GridGeometry {
  int rows = 0;
  int cols = 0;
  double xll_m = 0.0;
  double yll_m = 0.0;
  double cell_size_m = 1.0;

  /// True when (row, col) lies on the grid.
  bool contains(CellIndex i) const { return i.row >= 0 && i.row < rows && i.col >= 0 && i.col < cols; }
  /// Centre of a cell in the world frame [m]; defined for any index (off-grid too).
  Position cell_center(CellIndex i) const {
    return {xll_m + (i.col + 0.5) * cell_size_m, yll_m + (rows - i.row - 0.5) * cell_size_m};
  }
  /// The cell whose square contains p, or nullopt when p is off the grid.
  std::optional<CellIndex> cell_at(Position p) const;
  /// Number of cells.
  long long size() const { return static_cast<long long>(rows) * cols; }
  friend bool operator==(const GridGeometry& a, const GridGeometry& b) {
    return a.rows == b.rows && a.cols == b.cols && a.xll_m == b.xll_m && a.yll_m == b.yll_m &&
           a.cell_size_m == b.cell_size_m;
  }
};

/// The cells of `grid` whose centres lie in `area` [m] (edges included, within tolerance::kLengthM), as a rectangle;
/// empty when no centre does. The cells a site or a goal vector map covers, for the world and the agents alike.
CellRect cells_centred_in(const GridGeometry& grid, const Rect& area);

/// A grid of heights [m] placed in the world frame.
class Heightmap {
 public:
  Heightmap() = default;
  /// A rows x cols grid of `fill` metres; throws InvalidArgument on non-positive sizes.
  Heightmap(GridGeometry geometry, double fill = 0.0);
  /// Wraps existing heights; the geometry's rows/cols are taken from the matrix.
  Heightmap(GridGeometry geometry, HeightMatrix heights);

  int rows() const { return geometry_.rows; }
  int cols() const { return geometry_.cols; }
  long long size() const { return geometry_.size(); }
  double cell_size_m() const { return geometry_.cell_size_m; }
  const GridGeometry& geometry() const { return geometry_; }

  /// Unchecked access [m].
  double operator()(int row, int col) const { return heights_(row, col); }
  double& operator()(int row, int col) { return heights_(row, col); }
  double operator()(CellIndex i) const { return heights_(i.row, i.col); }
  double& operator()(CellIndex i) { return heights_(i.row, i.col); }
  /// Checked access [m]; throws InvalidArgument naming the index when off the grid.
  double at(CellIndex i) const;
  double& at(CellIndex i);

  bool contains(CellIndex i) const { return geometry_.contains(i); }
  Position cell_center(CellIndex i) const { return geometry_.cell_center(i); }
  std::optional<CellIndex> cell_at(Position p) const { return geometry_.cell_at(p); }

  /// Row-major contiguous heights: element (r, c) is data()[r * cols() + c].
  const double* data() const { return heights_.data(); }
  double* data() { return heights_.data(); }
  const HeightMatrix& heights() const { return heights_; }
  HeightMatrix& heights() { return heights_; }

  /// Copy of the sub-map with top-left cell `top_left` and the given size, placed so that
  /// its cells keep their world positions; throws InvalidArgument when it leaves the grid.
  Heightmap window(CellIndex top_left, int rows, int cols) const;

  /// Smallest and largest height [m].
  double min_height() const { return heights_.minCoeff(); }
  double max_height() const { return heights_.maxCoeff(); }

 private:
  GridGeometry geometry_;
  HeightMatrix heights_;
};

}  // namespace marsala
