#include "marsala/core/assignment.hpp"

#include <cmath>

#include "marsala/core/format.hpp"

namespace marsala {

std::string assignment_problem(const Assignment& a) {
  const GridGeometry& g = a.world;
  if (g.rows <= 0 || g.cols <= 0 || !(g.cell_size_m > 0.0) || !std::isfinite(g.cell_size_m) ||
      !std::isfinite(g.xll_m) || !std::isfinite(g.yll_m))
    return fmt::format("world grid {} x {} with cell size {} m is not a valid grid", g.rows, g.cols, g.cell_size_m);
  if (a.tile_size < 1) return fmt::format("tile size must be >= 1, got {}", a.tile_size);
  return {};
}

}  // namespace marsala
