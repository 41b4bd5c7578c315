#include "common/processing/deposition.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"
#include "common/grid/iterators.hpp"

namespace marsala::processing {
namespace {

std::string describe(CellIndex i) { return "(" + std::to_string(i.row) + ", " + std::to_string(i.col) + ")"; }

double checked_gap(const grid::Heightmap& gap, CellIndex i) {
  if (!gap.contains(i)) throw InvalidArgument("deposition target cell " + describe(i) + " is off the grid");
  const double g = gap(i);
  if (!(g >= 0.0) || !std::isfinite(g))
    throw InvalidArgument("MARS gap at cell " + describe(i) + " is " + std::to_string(g) +
                          "; a gap is finite and >= 0");
  return g;
}

}  // namespace

double deposition_target_volume(const grid::Heightmap& gap, const std::vector<CellIndex>& cells) {
  grid::CellMask footprint = grid::CellMask::Zero(gap.rows(), gap.cols());
  for (const CellIndex i : cells) {
    checked_gap(gap, i);
    footprint(i.row, i.col) = 1;
  }
  return deposition_target_volume(gap, footprint);
}

double deposition_target_volume(const grid::Heightmap& gap, const grid::CellMask& footprint) {
  if (footprint.rows() != gap.rows() || footprint.cols() != gap.cols())
    throw InvalidArgument("footprint mask is " + std::to_string(footprint.rows()) + " x " +
                          std::to_string(footprint.cols()) + " but the gap grid is " + std::to_string(gap.rows()) +
                          " x " + std::to_string(gap.cols()));
  double sum_m = 0.0;
  for (grid::SubmapIterator it(gap.geometry(), {0, 0}, gap.rows(), gap.cols()); !it.is_past_end(); ++it)
    if (footprint((*it).row, (*it).col) != 0) sum_m += checked_gap(gap, *it);
  return sum_m * gap.cell_size_m() * gap.cell_size_m();
}

double deposition_target_volume(const grid::Heightmap& gap) {
  return deposition_target_volume(gap, grid::CellMask::Ones(gap.rows(), gap.cols()));
}

grid::CellMask path_footprint(const grid::GridGeometry& grid, const std::vector<CellIndex>& path, double delta_m) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m))
    throw InvalidArgument("body length delta must be finite and > 0, got " + std::to_string(delta_m));
  grid::CellMask footprint = grid::CellMask::Zero(grid.rows, grid.cols);
  for (const CellIndex p : path) {
    if (!grid.contains(p)) throw InvalidArgument("path cell " + describe(p) + " is off the grid");
    for (grid::DiscIterator it(grid, p, delta_m / 2.0); !it.is_past_end(); ++it) footprint((*it).row, (*it).col) = 1;
  }
  return footprint;
}

}  // namespace marsala::processing
