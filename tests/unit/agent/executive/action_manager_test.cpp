#include "marsala/agent/executive/action_manager.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "unit/agent/agent_test_support.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::executive {
namespace {

const GridGeometry kGrid{15, 15, 0.0, 0.0, 0.1};
const NavigabilityParams kNav{0.5, 0.4, 0.05};  // ball radius 2 cells

deliberative::LocalMap flat_map(CellIndex robot) {
  return test::make_local_map(Heightmap(kGrid, 0.0), Heightmap(kGrid, 0.0), kNav, robot, std::nullopt);
}

std::vector<CellIndex> line(CellIndex from, int d_row, int d_col, int n) {
  std::vector<CellIndex> path;
  for (int i = 0; i < n; ++i) path.push_back({from.row + i * d_row, from.col + i * d_col});
  return path;
}

TEST(ActionManager, AdvancesToTheFarthestPathCellWithinTheStep) {
  const ActionManager am(0.2);
  const deliberative::LocalMap map = flat_map({7, 3});
  const Position robot = kGrid.cell_center({7, 3});
  // Straight east: 0.1 m per cell, 0.2 m reaches path[2] exactly.
  auto m = am.advance(map, line({7, 3}, 0, 1, 8), robot);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{7, 5}));
  EXPECT_EQ(m->path_index, 2u);
  EXPECT_NEAR(m->distance_m, 0.2, 1e-12);
  EXPECT_EQ(m->target.x, kGrid.cell_center({7, 5}).x);  // the cell centre
  EXPECT_EQ(m->target.y, kGrid.cell_center({7, 5}).y);
  // Diagonal: path[1] is 0.141 m away, path[2] 0.283 m.
  m = am.advance(map, line({7, 3}, -1, 1, 5), robot);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->path_index, 1u);
  // A longer step reaches further.
  m = ActionManager(0.45).advance(map, line({7, 3}, 0, 1, 8), robot);
  EXPECT_EQ(m->path_index, 4u);
}

TEST(ActionManager, AStepShorterThanTheDiagonalStillMovesDiagonally) {
  // Step 0.1 m = one cell: the diagonal neighbour's centre (0.141 m) is out of reach, so the robot goes 0.1 m
  // towards it; 0.1 / sqrt(2) = 0.0707 m along each axis passes the cell boundary (0.05 m) and lands in that cell.
  const ActionManager am(0.1);
  const deliberative::LocalMap map = flat_map({7, 3});
  const Position robot = kGrid.cell_center({7, 3});
  const auto m = am.advance(map, line({7, 3}, -1, 1, 5), robot);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{6, 4}));
  EXPECT_EQ(m->path_index, 1u);
  EXPECT_LE(m->distance_m, 0.1);
  EXPECT_NEAR(m->distance_m, 0.1, 1e-9);
  EXPECT_NEAR(m->target.x - robot.x, 0.1 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(m->target.y - robot.y, 0.1 / std::sqrt(2.0), 1e-9);  // row 6 is north of row 7
  // From that off-centre point the next motion centres it on (6, 4), 0.029 m per axis away.
  const deliberative::LocalMap there = flat_map({6, 4});
  const auto next = am.advance(there, line({6, 4}, -1, 1, 4), m->target);
  ASSERT_TRUE(next.has_value());
  EXPECT_LE(next->distance_m, 0.1);
  // A step shorter than half a cell's diagonal lands in no new cell (nor does it reach the boundary): no motion.
  EXPECT_FALSE(ActionManager(0.06).advance(map, line({7, 3}, -1, 1, 5), robot).has_value());
}

TEST(ActionManager, StopsBeforeTheFirstCellThatIsNotNavigable) {
  Heightmap h(kGrid, 0.0);
  h(7, 7) = 0.5;  // a post: cells within 2 cells of it are not occupiable, (7, 5) among them
  const deliberative::LocalMap map = test::make_local_map(h, Heightmap(kGrid, 0.0), kNav, {7, 3}, std::nullopt);
  ASSERT_EQ(map.navigable(7, 4), 1);
  ASSERT_EQ(map.navigable(7, 5), 0);
  const ActionManager am(0.45);
  const auto m = am.advance(map, line({7, 3}, 0, 1, 10), kGrid.cell_center({7, 3}));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{7, 4}));
  // Blocked at once: no motion.
  EXPECT_FALSE(am.advance(map, line({7, 4}, 0, 1, 6), kGrid.cell_center({7, 4})).has_value());
  // A one-cell path (the robot is at its goal): no motion.
  EXPECT_FALSE(am.advance(map, {{7, 3}}, kGrid.cell_center({7, 3})).has_value());
}

TEST(ActionManager, NeverCutsThroughACellItMayNotEnter) {
  // The path goes round (7, 4), which is not navigable: (7, 3) -> (6, 4) -> (7, 5). (7, 5) is 0.2 m away, within the
  // step, but the straight way there runs through (7, 4), which the world would reject
  // (docs/runtime.md#rule-2-motion): the motion stops at (6, 4), whose diagonal only touches (7, 4)'s corner.
  deliberative::LocalMap map = flat_map({7, 3});
  map.navigable(7, 4) = 0;
  const ActionManager am(0.2);
  const std::vector<CellIndex> detour{{7, 3}, {6, 4}, {7, 5}, {7, 6}};
  const auto m = am.advance(map, detour, kGrid.cell_center({7, 3}));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{6, 4}));
  EXPECT_EQ(m->path_index, 1u);
  // From (6, 4) the way to (7, 5) is a diagonal again, and (7, 6) is 0.22 m away: the motion takes (7, 5).
  const auto next = am.advance(map, {{6, 4}, {7, 5}, {7, 6}}, kGrid.cell_center({6, 4}));
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(next->cell, (CellIndex{7, 5}));
  // With (7, 4) navigable the robot goes straight to (7, 5).
  const auto straight = am.advance(flat_map({7, 3}), detour, kGrid.cell_center({7, 3}));
  ASSERT_TRUE(straight.has_value());
  EXPECT_EQ(straight->cell, (CellIndex{7, 5}));
  // Off centre, south of (7, 3)'s centre, the way to (6, 4) runs through (7, 4): no path cell is reachable, and the
  // robot centres itself first.
  const Position low{kGrid.cell_center({7, 3}).x + 0.03, kGrid.cell_center({7, 3}).y - 0.04};
  const auto centre = am.advance(map, detour, low);
  ASSERT_TRUE(centre.has_value());
  EXPECT_EQ(centre->cell, (CellIndex{7, 3}));
  EXPECT_EQ(centre->path_index, 0u);
}

TEST(ActionManager, CentresAnOffCentreRobotWhenTheNextCellIsOutOfRange) {
  const deliberative::LocalMap map = flat_map({7, 3});
  const Position off{kGrid.cell_center({7, 3}).x - 0.04, kGrid.cell_center({7, 3}).y};
  // Step 0.1 m: path[1] lies 0.14 m away, the robot's own centre 0.04 m.
  const auto m = ActionManager(0.1).advance(map, line({7, 3}, 0, 1, 5), off);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{7, 3}));
  EXPECT_EQ(m->path_index, 0u);
  EXPECT_NEAR(m->distance_m, 0.04, 1e-12);
  // On the centre already, the same step reaches path[1].
  EXPECT_EQ(ActionManager(0.1).advance(map, line({7, 3}, 0, 1, 5), kGrid.cell_center({7, 3}))->path_index, 1u);
}

TEST(ActionManager, APathOfTheRobotsCellAloneCentresAnOffCentreRobot) {
  // A route that ends where the robot stands (its goal is its own cell) after a partial diagonal move left it off
  // the centre: the goal is the centre, e.g. a base station whose radius takes the centre but not the robot.
  const deliberative::LocalMap map = flat_map({7, 3});
  const Position centre = kGrid.cell_center({7, 3});
  const auto m = ActionManager(0.1).advance(map, {{7, 3}}, {centre.x + 0.03, centre.y - 0.02});
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{7, 3}));
  EXPECT_DOUBLE_EQ(m->target.x, centre.x);
  EXPECT_DOUBLE_EQ(m->target.y, centre.y);
  EXPECT_NEAR(m->distance_m, std::hypot(0.03, 0.02), 1e-12);
  // Centred already, or the path empty: no motion.
  EXPECT_FALSE(ActionManager(0.1).advance(map, {{7, 3}}, centre).has_value());
  EXPECT_FALSE(ActionManager(0.1).advance(map, {}, centre).has_value());
}

TEST(ActionManager, LeavesACellItCannotOccupyThroughOccupiableCells) {
  Heightmap h(kGrid, 0.0);
  h(5, 3) = 0.3;  // within the robot's ball: its own cell (7, 3) is not occupiable
  const deliberative::LocalMap map = test::make_local_map(h, Heightmap(kGrid, 0.0), kNav, {7, 3}, std::nullopt);
  ASSERT_EQ(map.occupiable(7, 3), 0);
  ASSERT_EQ(map.navigable.cast<int>().sum(), 0);
  // South, (8, 3) and (9, 3) are occupiable (their balls miss (5, 3)); (9, 3) is the farthest within 0.2 m.
  const auto m = ActionManager(0.2).advance(map, line({7, 3}, 1, 0, 5), kGrid.cell_center({7, 3}));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->cell, (CellIndex{9, 3}));
  EXPECT_THROW(ActionManager(0.0), InvalidArgument);
  EXPECT_THROW(ActionManager(std::nan("")), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::executive
