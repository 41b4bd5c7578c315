#include "marsala/core/segment_cells.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

/// The cell of `p` by GridGeometry::cell_at's arithmetic, without its on-grid check.
CellIndex cell_of(const GridGeometry& g, Position p) {
  const double col = std::floor((p.x - g.xll_m) / g.cell_size_m);
  const double row_from_south = std::floor((p.y - g.yll_m) / g.cell_size_m);
  return {g.rows - 1 - static_cast<int>(row_from_south), static_cast<int>(col)};
}

/// Appends to `ts` every t in (0, 1) where from + t (to - from) crosses an integer (a grid line, in cells).
void add_crossings(double from, double to, std::vector<double>& ts) {
  if (from == to) return;
  const double lo = std::min(from, to), hi = std::max(from, to);
  for (double k = std::floor(lo) + 1.0; k < hi; k += 1.0) ts.push_back((k - from) / (to - from));
}

}  // namespace

std::vector<CellIndex> cells_on_segment(const GridGeometry& grid, Position a, Position b) {
  if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y))
    throw InvalidArgument(fmt::format("cells_on_segment: segment ({}, {}) -> ({}, {}) is not finite", a.x, a.y, b.x,
                                      b.y));
  const double cs = grid.cell_size_m;
  std::vector<CellIndex> cells{cell_of(grid, a)};
  const auto add = [&](CellIndex c) {
    if (!(c == cells.back())) cells.push_back(c);
  };
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  if (length > 0.0) {
    // Parameters where the segment crosses a grid line; between two consecutive ones it lies in one cell (or on one
    // boundary), which its midpoint names.
    std::vector<double> ts{0.0, 1.0};
    add_crossings((a.x - grid.xll_m) / cs, (b.x - grid.xll_m) / cs, ts);
    add_crossings((a.y - grid.yll_m) / cs, (b.y - grid.yll_m) / cs, ts);
    std::sort(ts.begin(), ts.end());
    for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
      if ((ts[i + 1] - ts[i]) * length < kSweepMinLengthM) continue;  // a corner, or a graze
      const double t = 0.5 * (ts[i] + ts[i + 1]);
      add(cell_of(grid, {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}));
    }
  }
  add(cell_of(grid, b));
  return cells;
}

}  // namespace marsala
