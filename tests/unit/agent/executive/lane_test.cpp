#include "marsala/agent/executive/lane.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::executive {
namespace {

// 80 x 80 cells of 0.1 m (8 x 8 m). A flat band 3 m wide (rows 25..54, y in [2.5, 5.5)) between walls 5 m high;
// bodies 1 m (ball radius 5 cells): robot centres are navigable on rows 30..49, a corridor 2 m across.
const GridGeometry kGrid{80, 80, 0.0, 0.0, 0.1};
const NavigabilityParams kBody{0.3, 1.0, 0.05};

deliberative::LocalMap band_map(CellIndex robot, bool walls = true) {
  Heightmap h(kGrid, 0.0);
  if (walls)
    for (int r = 0; r < 80; ++r)
      for (int c = 0; c < 80; ++c)
        if (r < 25 || r > 54) h(r, c) = 5.0;
  return test::make_local_map(h, Heightmap(kGrid, 0.0), kBody, robot, std::nullopt);
}

std::vector<CellIndex> row_path(int row, int from_col, int to_col) {
  std::vector<CellIndex> path;
  const int step = to_col >= from_col ? 1 : -1;
  for (int c = from_col; c != to_col + step; c += step) path.push_back({row, c});
  return path;
}

TEST(Lane, KeepsRightOfTheCorridorsCentreWhereverTheRobotStands) {
  const deliberative::LocalMap map = band_map({40, 5});
  ASSERT_NE(map.navigable(30, 40), 0);
  ASSERT_EQ(map.navigable(29, 40), 0);
  ASSERT_NE(map.navigable(49, 40), 0);
  ASSERT_EQ(map.navigable(50, 40), 0);
  // Eastwards, right is south (higher rows). The corridor's centre is between rows 39 and 40 (y = 4.0 m); 0.75 m to
  // the right of it is y = 3.25 m, row 47; the lane is entered at 45 degrees at most (from row 32: 15 cells).
  for (int row : {32, 40, 47}) {
    const auto lane = lane_path(map, map.navigable, row_path(row, 5, 70), 0.75, 3.0);
    ASSERT_GE(lane.size(), 2u);
    EXPECT_EQ(lane.front(), (CellIndex{row, 5}));  // the robot's own cell stays
    for (std::size_t i = 1; i < lane.size(); ++i)
      if (lane[i].col > 25 && lane[i].col < 65) {
        EXPECT_EQ(lane[i].row, 47) << "from row " << row;
      }
  }
  // Westwards, right is north: y = 4.75 m, row 32 (reached at 45 degrees from row 40: by column 62).
  const auto back = lane_path(map, map.navigable, row_path(40, 70, 5), 0.75, 3.0);
  for (const CellIndex& c : back)
    if (c.col < 50 && c.col > 10) {
      EXPECT_EQ(c.row, 32);
    }
  // The two lanes are 1.5 m apart: bodies of 1 m pass with 0.5 m to spare.
}

TEST(Lane, ALaneBeyondTheCorridorStopsAtItsEdge) {
  const deliberative::LocalMap map = band_map({40, 5});
  const auto lane = lane_path(map, map.navigable, row_path(40, 5, 70), 1.5, 3.0);
  for (std::size_t i = 1; i < lane.size(); ++i)
    if (lane[i].col > 25 && lane[i].col < 65) {  // the last navigable row
      EXPECT_EQ(lane[i].row, 49);
    }
}

TEST(Lane, IsEnteredAtFortyFiveDegreesAtMost) {
  const deliberative::LocalMap map = band_map({40, 5});
  const auto lane = lane_path(map, map.navigable, row_path(40, 5, 70), 0.75, 3.0);
  for (std::size_t i = 1; i < lane.size(); ++i) {
    EXPECT_LE(std::abs(lane[i].row - lane[i - 1].row), 1) << i;
    EXPECT_LE(std::abs(lane[i].col - lane[i - 1].col), 1) << i;
  }
}

TEST(Lane, OpenGroundAndNoOffsetLeaveThePathAlone) {
  const deliberative::LocalMap open = band_map({40, 5}, false);
  const auto path = row_path(40, 5, 70);
  EXPECT_EQ(lane_path(open, open.navigable, path, 0.75, 3.0), path);
  const deliberative::LocalMap map = band_map({40, 5});
  EXPECT_EQ(lane_path(map, map.navigable, path, 0.0, 3.0), path);
  const std::vector<CellIndex> alone{CellIndex{40, 5}};
  EXPECT_EQ(lane_path(map, map.navigable, alone, 0.75, 3.0), alone);
}

TEST(Lane, AnOccupiedLaneCellFallsBackToThePath) {
  // The corridor mask has the band; the navigable mask lacks the right half (other robots stand there).
  deliberative::LocalMap map = band_map({40, 5});
  const CellMask corridor = map.navigable;
  for (int r = 41; r < 50; ++r)
    for (int c = 0; c < 80; ++c) map.navigable(r, c) = 0;
  const auto path = row_path(40, 5, 70);
  const auto lane = lane_path(map, corridor, path, 0.75, 3.0);
  EXPECT_EQ(lane, path);
}

}  // namespace
}  // namespace marsala::agent::executive
