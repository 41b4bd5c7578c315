#pragma once
// Colour maps for terrain heights and overlays; lightness rises monotonically along each map.

#include "marsala/render/detail/raster.hpp"

namespace marsala::render::detail {

/// Terrain height colour at t in [0, 1] (0 = lowest): deep blue through slate and sand to near white.
Colour terrain_colour(double t);
/// Heat colour at t in [0, 1] (0 = smallest): pale yellow through orange and red to dark crimson.
Colour heat_colour(double t);

}  // namespace marsala::render::detail
