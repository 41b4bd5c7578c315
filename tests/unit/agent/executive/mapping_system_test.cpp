#include "marsala/agent/executive/mapping_system.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "marsala/core/error.hpp"

namespace marsala::agent::executive {
namespace {

// A 5 x 7 world at 0.5 m cells cut in 3-cell tiles: tile rows 0..1 (3 and 2 cells), tile cols 0..2 (3, 3, 1).
const GridGeometry kWorld{5, 7, 10.0, 20.0, 0.5};

TerrainTile tile(int tr, int tc, int rows, int cols, double base) {
  TerrainTile t;
  t.tile_row = tr;
  t.tile_col = tc;
  t.rows = rows;
  t.cols = cols;
  // Values that do not survive a round trip through decimal text or float: only a bit copy keeps them.
  for (int i = 0; i < rows * cols; ++i) t.heights.push_back(std::nextafter(base + 0.1 * i, 1e9) / 3.0);
  return t;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(MappingSystem, TilesLandBitForBitAndTheRestStaysUnknown) {
  MappingSystem map(kWorld, 3);
  EXPECT_EQ(map.known_cells(), 0);
  const TerrainTile a = tile(1, 1, 2, 3, 7.0);   // rows 3..4, cols 3..5
  const TerrainTile b = tile(0, 2, 3, 1, -2.0);  // rows 0..2, col 6 (cut by the east edge)
  map.integrate_tile(a);
  map.integrate_tile(b);
  EXPECT_EQ(map.known_cells(), 6 + 3);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(same_bits(map.heights()(3 + r, 3 + c), a.heights[r * 3 + c]));
      EXPECT_TRUE(map.is_known({3 + r, 3 + c}));
    }
  for (int r = 0; r < 3; ++r) EXPECT_TRUE(same_bits(map.heights()(r, 6), b.heights[r]));
  // Everything else: unknown, height 0.
  int unknown = 0;
  for (int r = 0; r < kWorld.rows; ++r)
    for (int c = 0; c < kWorld.cols; ++c)
      if (!map.is_known({r, c})) {
        ++unknown;
        EXPECT_EQ(map.heights()(r, c), 0.0);
      }
  EXPECT_EQ(unknown, 35 - 9);
  EXPECT_FALSE(map.is_known({5, 0}));  // off the grid

  // A changed tile overwrites, and the known count does not double.
  map.integrate_tile(tile(1, 1, 2, 3, 100.0));
  EXPECT_EQ(map.known_cells(), 9);
  EXPECT_TRUE(same_bits(map.heights()(4, 5), tile(1, 1, 2, 3, 100.0).heights[5]));
}

TEST(MappingSystem, RejectsTilesThatDoNotFit) {
  MappingSystem map(kWorld, 3);
  EXPECT_THROW(map.integrate_tile(tile(2, 0, 3, 3, 0.0)), InvalidArgument);   // no tile row 2
  EXPECT_THROW(map.integrate_tile(tile(0, -1, 3, 3, 0.0)), InvalidArgument);  // negative
  EXPECT_THROW(map.integrate_tile(tile(1, 0, 3, 3, 0.0)), InvalidArgument);   // last tile row has 2 rows
  EXPECT_THROW(map.integrate_tile(tile(0, 2, 3, 3, 0.0)), InvalidArgument);   // last tile col has 1 col
  TerrainTile short_tile = tile(0, 0, 3, 3, 0.0);
  short_tile.heights.pop_back();
  EXPECT_THROW(map.integrate_tile(short_tile), InvalidArgument);
  TerrainTile nan_tile = tile(0, 0, 3, 3, 0.0);
  nan_tile.heights[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(map.integrate_tile(nan_tile), InvalidArgument);
  EXPECT_EQ(map.known_cells(), 0);  // nothing of a rejected tile lands
  EXPECT_THROW(MappingSystem(kWorld, 0), InvalidArgument);
  EXPECT_THROW(MappingSystem(GridGeometry{0, 7, 0.0, 0.0, 0.5}, 3), InvalidArgument);
}

TEST(MappingSystem, TrajectoryKeepsTheCellsStoodOnOnce) {
  MappingSystem map(kWorld, 3);
  // Cell (r, c) has its centre at x = 10 + 0.5 (c + 0.5), y = 20 + 0.5 (5 - r - 0.5).
  map.record_pose({10.25, 22.25});  // (0, 0)
  map.record_pose({10.40, 22.10});  // (0, 0) again: kept once
  map.record_pose({10.75, 22.25});  // (0, 1)
  map.record_pose({10.75, 21.75});  // (1, 1)
  map.record_pose({10.25, 22.25});  // back to (0, 0): a new entry
  const std::vector<CellIndex> expected{{0, 0}, {0, 1}, {1, 1}, {0, 0}};
  EXPECT_EQ(map.trajectory(), expected);
  EXPECT_THROW(map.record_pose({9.9, 22.0}), InvalidArgument);
  EXPECT_THROW(map.record_pose({std::nan(""), 22.0}), InvalidArgument);

  map.integrate({tile(0, 0, 3, 3, 1.0)}, {13.25, 20.25});  // the pose is cell (4, 6)
  EXPECT_EQ(map.trajectory().back(), (CellIndex{4, 6}));
  EXPECT_EQ(map.known_cells(), 9);
}

TEST(MappingSystem, RegistrationMovesTilesAndDropsWhatLeavesTheGrid) {
  // A robot that believes itself one row north and two columns west of where it is registers what it senses there.
  MappingSystem map(kWorld, 3);
  map.set_registration({-1, -2});
  const TerrainTile a = tile(1, 1, 2, 3, 7.0);  // world rows 3..4, cols 3..5 -> rows 2..3, cols 1..3
  map.integrate_tile(a);
  EXPECT_EQ(map.known_cells(), 6);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(map.heights()(2 + r, 1 + c), a.heights[r * 3 + c]));
  EXPECT_FALSE(map.is_known({4, 3}));
  EXPECT_FALSE(map.is_known({3, 4}));
  // Moved past the grid's east edge: world col 6 one column east is col 7, off the 7-column grid: nothing lands.
  map.set_registration({-1, 1});
  map.integrate_tile(tile(0, 2, 3, 1, -2.0));
  EXPECT_EQ(map.known_cells(), 6);
  map.set_registration({1, 0});  // one row south: world row 4 leaves the grid
  const TerrainTile b = tile(1, 0, 2, 3, 1.0);
  map.integrate_tile(b);
  EXPECT_EQ(map.known_cells(), 6 + 3);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(map.heights()(4, c), b.heights[c]));
}

}  // namespace
}  // namespace marsala::agent::executive
