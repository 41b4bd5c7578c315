#pragma once
// Crop and resample heightmaps in the world frame.

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain {

/// The cells whose centres lie in the world-frame rectangle [x0, x0+w) x [y0, y0+h) [m] (exact comparisons
/// on the centres as GridGeometry::cell_center computes them); the result keeps world positions (xll/yll of
/// the first kept cell). Throws InvalidArgument when the rectangle holds no cell or w, h <= 0 or non-finite.
Heightmap crop(const Heightmap& map, double x0_m, double y0_m, double width_m, double height_m);

/// Bilinear resampling to a new cell size [m] over the same extent: cols' = floor(width / cs' + 1e-9)
/// (likewise rows), same xll/yll; heights interpolated between source cell centres, clamped at the border
/// (so a constant map is reproduced exactly and a plane exactly up to rounding between the outermost centres).
/// Throws InvalidArgument for cs' <= 0 or non-finite, or a result with < 1 cell or more than 2^31 cells.
Heightmap resample_bilinear(const Heightmap& map, double cell_size_m);

}  // namespace marsala::terrain
