#pragma once
// Deposition target volume (paper §II): the MARS gap restricted to a set of cells.

#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Sum of gap * cell area over the listed cells [m^3]; each cell counts once however often it is listed.
/// Throws InvalidArgument naming the first cell off the grid or with a negative or non-finite gap.
double deposition_target_volume(const Heightmap& gap, const std::vector<CellIndex>& cells);

/// Sum of gap * cell area over the cells where `footprint` is non-zero [m^3]; throws InvalidArgument when the mask
/// and the gap differ in size.
double deposition_target_volume(const Heightmap& gap, const CellMask& footprint);

/// Sum of gap * cell area over the whole grid [m^3].
double deposition_target_volume(const Heightmap& gap);

/// The cells within delta/2 of any cell of `path` (the footprint a robot of body length delta sweeps along it),
/// as a mask of the grid's size; path cells off the grid throw InvalidArgument.
CellMask path_footprint(const GridGeometry& grid, const std::vector<CellIndex>& path, double delta_m);

}  // namespace marsala
