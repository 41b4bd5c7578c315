#include "marsala/core/heightmap.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

void check_geometry(const GridGeometry& g) {
  if (g.rows <= 0 || g.cols <= 0)
    throw InvalidArgument(fmt::format("grid size must be positive, got {} x {}", g.rows, g.cols));
  if (!(g.cell_size_m > 0.0) || !std::isfinite(g.cell_size_m))
    throw InvalidArgument(fmt::format("cell size must be a positive finite number of metres, got {}", g.cell_size_m));
  if (!std::isfinite(g.xll_m) || !std::isfinite(g.yll_m)) throw InvalidArgument("grid corner must be finite");
}

}  // namespace

std::optional<CellIndex> GridGeometry::cell_at(Position p) const {
  const double col = std::floor((p.x - xll_m) / cell_size_m);
  const double row_from_south = std::floor((p.y - yll_m) / cell_size_m);
  if (!(col >= 0 && col < cols && row_from_south >= 0 && row_from_south < rows)) return std::nullopt;
  return CellIndex{rows - 1 - static_cast<int>(row_from_south), static_cast<int>(col)};
}

CellRect cells_centred_in(const GridGeometry& grid, const Rect& area) {
  constexpr double tol = tolerance::kLengthM;
  // Scanning every row and column decides each centre exactly as the definition says, with no rounding shortcut.
  int r0 = grid.rows, r1 = -1, c0 = grid.cols, c1 = -1;
  for (int r = 0; r < grid.rows; ++r) {
    const double y = grid.cell_center({r, 0}).y;
    if (y >= area.y0 - tol && y <= area.y1 + tol) r0 = std::min(r0, r), r1 = std::max(r1, r);
  }
  for (int c = 0; c < grid.cols; ++c) {
    const double x = grid.cell_center({0, c}).x;
    if (x >= area.x0 - tol && x <= area.x1 + tol) c0 = std::min(c0, c), c1 = std::max(c1, c);
  }
  if (r1 < 0 || c1 < 0) return {};
  return {{r0, c0}, r1 - r0 + 1, c1 - c0 + 1};
}

Heightmap::Heightmap(GridGeometry geometry, double fill) : geometry_(geometry) {
  check_geometry(geometry_);
  heights_.setConstant(geometry_.rows, geometry_.cols, fill);
}

Heightmap::Heightmap(GridGeometry geometry, HeightMatrix heights) : geometry_(geometry), heights_(std::move(heights)) {
  geometry_.rows = static_cast<int>(heights_.rows());
  geometry_.cols = static_cast<int>(heights_.cols());
  check_geometry(geometry_);
}

double Heightmap::at(CellIndex i) const {
  if (!contains(i)) throw InvalidArgument(fmt::format("cell {} is off the {} x {} grid", i, rows(), cols()));
  return heights_(i.row, i.col);
}

double& Heightmap::at(CellIndex i) {
  if (!contains(i)) throw InvalidArgument(fmt::format("cell {} is off the {} x {} grid", i, rows(), cols()));
  return heights_(i.row, i.col);
}

Heightmap Heightmap::window(CellIndex top_left, int rows, int cols) const {
  const CellIndex bottom_right{top_left.row + rows - 1, top_left.col + cols - 1};
  if (rows <= 0 || cols <= 0 || !contains(top_left) || !contains(bottom_right))
    throw InvalidArgument(
        fmt::format("window {} x {} at {} leaves the {} x {} grid", rows, cols, top_left, this->rows(), this->cols()));
  GridGeometry g = geometry_;
  g.rows = rows;
  g.cols = cols;
  g.xll_m = geometry_.xll_m + top_left.col * geometry_.cell_size_m;
  g.yll_m = geometry_.yll_m + (geometry_.rows - 1 - bottom_right.row) * geometry_.cell_size_m;
  return Heightmap(g, HeightMatrix(heights_.block(top_left.row, top_left.col, rows, cols)));
}

}  // namespace marsala
