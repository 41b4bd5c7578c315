#pragma once
// Summary statistics of a terrain, as `marsala-terrain info` prints them.

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain {

/// Size, extent, height range and slope of a heightmap.
struct TerrainStats {
  int rows = 0;
  int cols = 0;
  double cell_size_m = 0.0;
  double width_m = 0.0;   ///< east-west extent [m]
  double height_m = 0.0;  ///< north-south extent [m]
  double min_height_m = 0.0;
  double max_height_m = 0.0;
  double mean_height_m = 0.0;
  double mean_slope = 0.0;  ///< mean gradient magnitude, rise over run [m/m] (central differences)
  double max_slope = 0.0;   ///< largest gradient magnitude [m/m]
};

/// Computes the statistics; slopes are 0 on a 1x1 grid.
TerrainStats compute_terrain_stats(const Heightmap& map);

}  // namespace marsala::terrain
