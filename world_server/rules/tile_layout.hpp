#pragma once
// Terrain tiles: the grid cut into tile_size x tile_size blocks (smaller at the south and east edges), the unit
// in which sensor frames carry terrain and the world tracks changes.
//
//   tile (0, 0) = cells rows [0, T) x cols [0, T)      T = tile_size; tile (tr, tc) = rows [tr T, min((tr+1) T, rows))
//   +------+------+---+                                                          x cols [tc T, min((tc+1) T, cols))
//   | 0,0  | 0,1  |0,2|   <- row 0 (north)
//   +------+------+---+
//   | 1,0  | 1,1  |1,2|   <- the last tile row/column is cut by the grid edge
//   +------+------+---+

#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::world_server {

/// A tile: its place in the tile grid and the cells it covers.
struct Tile {
  int tile_row = 0;
  int tile_col = 0;
  CellIndex first_cell;  ///< top-left (north-west) cell
  int rows = 0;          ///< [cells]
  int cols = 0;          ///< [cells]
};

/// How a grid is cut into tiles; pure geometry.
class TileLayout {
 public:
  /// Throws InvalidArgument for an empty grid or tile_size < 1.
  TileLayout(const GridGeometry& grid, int tile_size);

  int tile_size() const { return tile_size_; }
  int tile_rows() const { return tile_rows_; }
  int tile_cols() const { return tile_cols_; }
  int tile_count() const { return tile_rows_ * tile_cols_; }
  /// Row-major index of tile (tile_row, tile_col).
  int index(int tile_row, int tile_col) const { return tile_row * tile_cols_ + tile_col; }
  /// Index of the tile holding an on-grid cell.
  int index_of(CellIndex cell) const { return index(cell.row / tile_size_, cell.col / tile_size_); }
  /// The tile with row-major index `index`.
  Tile tile(int index) const;
  /// Indices (ascending) of the tiles whose world-frame squares meet the closed square [x - r, x + r] x
  /// [y - r, y + r] [m]; empty when it misses the grid.
  std::vector<int> tiles_in_square(Position centre, double half_side_m) const;

 private:
  GridGeometry grid_;
  int tile_size_;
  int tile_rows_;
  int tile_cols_;
};

}  // namespace marsala::world_server
