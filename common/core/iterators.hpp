#pragma once
// Region iterators over grid cells (grid_map style): construct, then
//   for (SubmapIterator it(geometry, top_left, rows, cols); !it.is_past_end(); ++it) use(*it);
// Every iterator yields only cells that lie on the grid.

#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Offsets (dr, dc) with dr^2 + dc^2 <= radius_cells^2 + 1e-9 [cells], row-major order.
/// This is the ball B_{delta/2} of ARCHITECTURE.md with radius_cells = delta / (2 cs).
std::vector<CellIndex> disc_offsets(double radius_cells);

/// Cells of a rectangular sub-map, row by row, clipped to the grid.
class SubmapIterator {
 public:
  SubmapIterator(const GridGeometry& grid, CellIndex top_left, int rows, int cols);
  CellIndex operator*() const { return current_; }
  SubmapIterator& operator++();
  bool is_past_end() const { return past_end_; }

 private:
  int row_begin_, row_end_, col_begin_, col_end_;
  CellIndex current_;
  bool past_end_;
};

/// Cells whose centres lie within radius_m of a cell's centre (tie tolerance as disc_offsets).
class DiscIterator {
 public:
  DiscIterator(const GridGeometry& grid, CellIndex center, double radius_m);
  CellIndex operator*() const { return current_; }
  DiscIterator& operator++();
  bool is_past_end() const { return index_ >= offsets_.size(); }

 private:
  void skip_off_grid();
  GridGeometry grid_;
  CellIndex center_;
  std::vector<CellIndex> offsets_;
  std::size_t index_ = 0;
  CellIndex current_;
};

/// Cells along the segment from `start` to `end` (Bresenham, 8-connected), both ends included;
/// stops at the first cell that leaves the grid.
class LineIterator {
 public:
  LineIterator(const GridGeometry& grid, CellIndex start, CellIndex end);
  CellIndex operator*() const { return current_; }
  LineIterator& operator++();
  bool is_past_end() const { return past_end_; }

 private:
  GridGeometry grid_;
  CellIndex current_, end_;
  int d_row_, d_col_, step_row_, step_col_, error_;
  bool past_end_;
};

}  // namespace marsala
