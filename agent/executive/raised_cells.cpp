#include "marsala/agent/executive/raised_cells.hpp"

#include <fmt/format.h>

#include <cmath>
#include <algorithm>
#include <limits>

#include "marsala/agent/executive/lane.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::executive {

RaisedCells::RaisedCells(int rows, int cols) : rows_(rows), cols_(cols) {
  if (rows <= 0 || cols <= 0)
    throw InvalidArgument(fmt::format("raised cells: a grid of {} x {} cells (both must be positive)", rows, cols));
  first_m_.assign(static_cast<std::size_t>(rows) * cols, std::numeric_limits<double>::quiet_NaN());
}

void RaisedCells::observe(const deliberative::LocalMap& local) {
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const CellIndex g = local.to_global({r, c});
      if (local.known(r, c) == 0 || !on_grid(g)) continue;
      double& first = first_m_[index(g)];
      if (std::isnan(first)) first = local.heights(r, c);
    }
}

CellMask RaisedCells::raised(const deliberative::LocalMap& local, double tolerance_m) const {
  CellMask out = CellMask::Zero(local.rows(), local.cols());
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const CellIndex g = local.to_global({r, c});
      if (local.known(r, c) == 0 || !on_grid(g)) continue;
      const double first = first_m_[index(g)];
      if (!std::isnan(first) && local.heights(r, c) > first + tolerance_m) out(r, c) = 1;
    }
  return out;
}

double RaisedCells::first_height_m(CellIndex cell) const {
  return on_grid(cell) ? first_m_[index(cell)] : std::numeric_limits<double>::quiet_NaN();
}

Heightmap first_seen_heights(const deliberative::LocalMap& local, const RaisedCells& raised) {
  Heightmap first = local.heights;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const double seen = raised.first_height_m(local.to_global({r, c}));
      if (!std::isnan(seen)) first(r, c) = seen;
    }
  return first;
}

Heightmap first_seen_gap(const deliberative::LocalMap& local, const RaisedCells& raised, double kappa) {
  return gap_below_bound_of(local, first_seen_heights(local, raised), kappa);
}

}  // namespace marsala::agent::executive
