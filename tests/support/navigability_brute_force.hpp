#pragma once
// Brute-force references for NavigabilityProcessor, written straight from ARCHITECTURE.md (grid conventions):
// every pair of every ball is checked (O(r^4) per cell), the ball from cell centres, the flood fill a plain BFS.
// For small grids only: tests and the benchmark's baseline.

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::testing {

/// 1 where the cell is occupiable (paper eq. 1), from the definition: every pair of cells whose centres lie
/// within delta/2 of the cell's centre passes |h(r) - h(q)| <= eps + kappa |r - q| + 1e-9 m.
inline CellMask occupiable_brute_force(const Heightmap& h, NavigabilityParams params) {
  const GridGeometry& g = h.geometry();
  const double cs = g.cell_size_m;
  const double radius_cells = params.delta_m / (2.0 * cs);
  const double ball_limit = radius_cells * radius_cells + tolerance::kBallCells2;  // [cells^2]
  const double reach = std::min(std::ceil(radius_cells) + 1.0, static_cast<double>(h.rows() + h.cols()));
  const int search = static_cast<int>(reach);
  CellMask out(h.rows(), h.cols());
  std::vector<CellIndex> ball;
  for (int pr = 0; pr < h.rows(); ++pr)
    for (int pc = 0; pc < h.cols(); ++pc) {
      const Position centre = g.cell_center({pr, pc});
      ball.clear();
      // Cells off the grid are ignored: scan the ball's bounding square clipped to the grid.
      for (int r = std::max(0, pr - search); r <= std::min(h.rows() - 1, pr + search); ++r)
        for (int c = std::max(0, pc - search); c <= std::min(h.cols() - 1, pc + search); ++c) {
          const Position x = g.cell_center({r, c});
          const double dx = (x.x - centre.x) / cs, dy = (x.y - centre.y) / cs;
          if (dx * dx + dy * dy <= ball_limit) ball.push_back({r, c});
        }
      bool occupiable = true;
      for (std::size_t a = 0; a < ball.size() && occupiable; ++a)
        for (std::size_t b = a + 1; b < ball.size(); ++b) {
          const Position pa = g.cell_center(ball[a]), pb = g.cell_center(ball[b]);
          const double distance_m = std::sqrt((pa.x - pb.x) * (pa.x - pb.x) + (pa.y - pb.y) * (pa.y - pb.y));
          if (!(std::abs(h(ball[a]) - h(ball[b])) <= params.eps_m + params.kappa * distance_m + tolerance::kHeightM)) {
            occupiable = false;
            break;
          }
        }
      out(pr, pc) = occupiable ? 1 : 0;
    }
  return out;
}

/// 1 where the cell is 8-connected to `origin` through occupiable cells (all 0 when the origin is not
/// occupiable); `origin` must lie on the grid.
inline CellMask navigable_brute_force(const Heightmap& h, NavigabilityParams params, CellIndex origin) {
  const CellMask occupiable = occupiable_brute_force(h, params);
  CellMask out = CellMask::Zero(h.rows(), h.cols());
  if (occupiable(origin.row, origin.col) == 0) return out;
  std::queue<CellIndex> queue;
  queue.push(origin);
  out(origin.row, origin.col) = 1;
  while (!queue.empty()) {
    const CellIndex cell = queue.front();
    queue.pop();
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const CellIndex next{cell.row + dr, cell.col + dc};
        if (!h.contains(next) || occupiable(next.row, next.col) == 0 || out(next.row, next.col) != 0) continue;
        out(next.row, next.col) = 1;
        queue.push(next);
      }
  }
  return out;
}

}  // namespace marsala::testing
