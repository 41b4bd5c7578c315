#include "marsala/world_server/rules/tile_layout.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala::world_server {

TileLayout::TileLayout(const GridGeometry& grid, int tile_size) : grid_(grid), tile_size_(tile_size) {
  if (grid.rows <= 0 || grid.cols <= 0) throw InvalidArgument("tile layout: the grid is empty");
  if (tile_size < 1) throw InvalidArgument(fmt::format("tile layout: tile_size must be >= 1, got {}", tile_size));
  tile_rows_ = (grid.rows + tile_size - 1) / tile_size;
  tile_cols_ = (grid.cols + tile_size - 1) / tile_size;
}

Tile TileLayout::tile(int index) const {
  Tile t;
  t.tile_row = index / tile_cols_;
  t.tile_col = index % tile_cols_;
  t.first_cell = {t.tile_row * tile_size_, t.tile_col * tile_size_};
  t.rows = std::min(tile_size_, grid_.rows - t.first_cell.row);
  t.cols = std::min(tile_size_, grid_.cols - t.first_cell.col);
  return t;
}

std::vector<int> TileLayout::tiles_in_square(Position centre, double half_side_m) const {
  std::vector<int> out;
  if (!(half_side_m >= 0.0) || !std::isfinite(centre.x) || !std::isfinite(centre.y)) return out;
  const double cs = grid_.cell_size_m;
  const double x_lo = centre.x - half_side_m, x_hi = centre.x + half_side_m;
  const double y_lo = centre.y - half_side_m, y_hi = centre.y + half_side_m;
  // Tile column tc spans x in [xll + tc T cs, xll + min((tc + 1) T, cols) cs]; tile row tr spans
  // y in [yll + (rows - min((tr + 1) T, rows)) cs, yll + (rows - tr T) cs]. Closed intervals: touching counts.
  const auto col_meets = [&](int tc) {
    const double a = grid_.xll_m + static_cast<double>(tc * tile_size_) * cs;
    const double b = grid_.xll_m + static_cast<double>(std::min((tc + 1) * tile_size_, grid_.cols)) * cs;
    return a <= x_hi && b >= x_lo;
  };
  const auto row_meets = [&](int tr) {
    const double a = grid_.yll_m + static_cast<double>(grid_.rows - std::min((tr + 1) * tile_size_, grid_.rows)) * cs;
    const double b = grid_.yll_m + static_cast<double>(grid_.rows - tr * tile_size_) * cs;
    return a <= y_hi && b >= y_lo;
  };
  // A first guess from the arithmetic, widened by one tile, then settled by the exact predicates above.
  const double tile_m = tile_size_ * cs;
  const auto clamp_index = [](double v, int n) {
    return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(n - 1)));
  };
  const int c0 = clamp_index(std::floor((x_lo - grid_.xll_m) / tile_m) - 1.0, tile_cols_);
  const int c1 = clamp_index(std::floor((x_hi - grid_.xll_m) / tile_m) + 1.0, tile_cols_);
  const double top_y = grid_.yll_m + grid_.rows * cs;
  const int r0 = clamp_index(std::floor((top_y - y_hi) / tile_m) - 1.0, tile_rows_);
  const int r1 = clamp_index(std::floor((top_y - y_lo) / tile_m) + 1.0, tile_rows_);
  for (int tr = r0; tr <= r1; ++tr) {
    if (!row_meets(tr)) continue;
    for (int tc = c0; tc <= c1; ++tc)
      if (col_meets(tc)) out.push_back(index(tr, tc));
  }
  return out;
}

}  // namespace marsala::world_server
