#include "marsala/core/deposition.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala {
namespace {

double checked_gap(const Heightmap& gap, CellIndex i) {
  if (!gap.contains(i)) throw InvalidArgument(fmt::format("deposition target cell {} is off the grid", i));
  const double g = gap(i);
  if (!(g >= 0.0) || !std::isfinite(g))
    throw InvalidArgument(fmt::format("MARS gap at cell {} is {}; a gap is finite and >= 0", i, g));
  return g;
}

}  // namespace

double deposition_target_volume(const Heightmap& gap, const std::vector<CellIndex>& cells) {
  CellMask footprint = CellMask::Zero(gap.rows(), gap.cols());
  for (const CellIndex i : cells) {
    checked_gap(gap, i);
    footprint(i.row, i.col) = 1;
  }
  return deposition_target_volume(gap, footprint);
}

double deposition_target_volume(const Heightmap& gap, const CellMask& footprint) {
  if (footprint.rows() != gap.rows() || footprint.cols() != gap.cols())
    throw InvalidArgument(fmt::format("footprint mask is {} x {} but the gap grid is {} x {}", footprint.rows(),
                                      footprint.cols(), gap.rows(), gap.cols()));
  double sum_m = 0.0;  // row-major, as ever: the same sum to the bit
  for (int r = 0; r < gap.rows(); ++r)
    for (int c = 0; c < gap.cols(); ++c)
      if (footprint(r, c) != 0) sum_m += checked_gap(gap, {r, c});
  return sum_m * gap.cell_size_m() * gap.cell_size_m();
}

double deposition_target_volume(const Heightmap& gap) {
  return deposition_target_volume(gap, CellMask::Ones(gap.rows(), gap.cols()));
}

CellMask path_footprint(const GridGeometry& grid, const std::vector<CellIndex>& path, double delta_m) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m))
    throw InvalidArgument(fmt::format("body length delta must be finite and > 0, got {}", delta_m));
  CellMask footprint = CellMask::Zero(grid.rows, grid.cols);
  // The disc of DiscIterator(grid, p, delta_m / 2), its offsets computed once for the whole path.
  const std::vector<CellIndex> disc = disc_offsets(delta_m / 2.0 / grid.cell_size_m);
  for (const CellIndex p : path) {
    if (!grid.contains(p)) throw InvalidArgument(fmt::format("path cell {} is off the grid", p));
    for (const CellIndex o : disc) {
      const CellIndex q{p.row + o.row, p.col + o.col};
      if (grid.contains(q)) footprint(q.row, q.col) = 1;
    }
  }
  return footprint;
}

}  // namespace marsala
