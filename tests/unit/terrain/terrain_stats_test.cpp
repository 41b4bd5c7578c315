#include "marsala/terrain/terrain_stats.hpp"

#include <gtest/gtest.h>

namespace marsala::terrain {
namespace {

TEST(TerrainStats, PlaneHasItsSlopeEverywhere) {
  // h = 0.3 x + 0.4 y: gradient magnitude 0.5 on every cell, borders included (one-sided differences are exact).
  Heightmap map({6, 8, 0.0, 0.0, 0.25});
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 8; ++c) {
      const Position p = map.cell_center({r, c});
      map(r, c) = 0.3 * p.x + 0.4 * p.y;
    }
  const TerrainStats s = compute_terrain_stats(map);
  EXPECT_EQ(s.rows, 6);
  EXPECT_EQ(s.cols, 8);
  EXPECT_DOUBLE_EQ(s.width_m, 2.0);
  EXPECT_DOUBLE_EQ(s.height_m, 1.5);
  EXPECT_NEAR(s.mean_slope, 0.5, 1e-12);
  EXPECT_NEAR(s.max_slope, 0.5, 1e-12);
  EXPECT_NEAR(s.min_height_m, 0.3 * 0.125 + 0.4 * 0.125, 1e-12);
  EXPECT_NEAR(s.max_height_m, 0.3 * 1.875 + 0.4 * 1.375, 1e-12);
}

TEST(TerrainStats, SingleCellHasNoSlope) {
  const TerrainStats s = compute_terrain_stats(Heightmap({1, 1, 0.0, 0.0, 1.0}, 4.0));
  EXPECT_DOUBLE_EQ(s.mean_slope, 0.0);
  EXPECT_DOUBLE_EQ(s.mean_height_m, 4.0);
}

}  // namespace
}  // namespace marsala::terrain
