#include "marsala/agent/executive/body_clearance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "marsala/agent/executive/action_manager.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::executive {
namespace {

const GridGeometry kGrid{40, 40, 0.0, 0.0, 0.1};  // 4 x 4 m
const NavigabilityParams kNav{0.3, 0.4, 0.05};     // a small ball: every cell of the flat map is occupiable

TEST(BodyClearance, DiscsAreBothRadiiPlusAStepForALowerId) {
  const std::vector<Neighbour> seen = {{2, 1.0, 1.0, 0.0, 0.5}, {7, 3.0, 1.0, 0.0, 0.75}};
  const auto discs = body_clearances(seen, 5, 0.5, 0.25);
  ASSERT_EQ(discs.size(), 2u);
  EXPECT_DOUBLE_EQ(discs[0].min_distance_m, 0.5 + 0.5 + 0.25);  // id 2 moves before 5 in the step
  EXPECT_DOUBLE_EQ(discs[1].min_distance_m, 0.5 + 0.75);        // id 7 moves after: where the frame shows it
  // Itself and nonsense are skipped.
  EXPECT_TRUE(body_clearances({{5, 1.0, 1.0, 0.0, 0.5}, {6, NAN, 1.0, 0.0, 0.5}}, 5, 0.5, 0.25).empty());
}

TEST(BodyClearance, ClearOfFollowsTheWorldsRule) {
  const std::vector<BodyClearance> one = {{2, {2.0, 2.0}, 1.0}};
  EXPECT_TRUE(clear_of(one, {0.5, 2.0}, {1.0, 2.0}));    // touching: 1.0 m
  EXPECT_FALSE(clear_of(one, {0.5, 2.0}, {1.05, 2.0}));  // 0.95 m
  // Already inside: moving apart or keeping the distance is fine, closer is not.
  EXPECT_TRUE(clear_of(one, {1.4, 2.0}, {1.3, 2.0}));
  EXPECT_TRUE(clear_of(one, {1.4, 2.0}, {1.4, 2.0}));
  EXPECT_FALSE(clear_of(one, {1.4, 2.0}, {1.5, 2.0}));
}

// The rule written out with distance() alone, as the world states it: the reference for clear_of()'s shortcut.
bool clear_of_reference(const std::vector<BodyClearance>& others, Position from, Position to) {
  for (const BodyClearance& o : others) {
    const double after = distance(to, o.centre), before = distance(from, o.centre);
    if (after < o.min_distance_m && !(before < o.min_distance_m && after >= before)) return false;
  }
  return true;
}

TEST(BodyClearance, ClearOfAgreesWithTheDistanceRuleAtEveryEnd) {
  // Random ends and discs, many of them exactly on a disc's edge along an axis or a diagonal, and ends a power of two
  // away (where a rounding below the axis difference would show).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> at(-3.0, 3.0), radius(0.1, 2.0);
  std::uniform_int_distribution<int> kind(0, 3), exponent(-4, 1);
  long long disagreements = 0, blocked = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const Position centre{at(rng), at(rng)};
    double d = radius(rng);
    Position from{at(rng), at(rng)}, to{at(rng), at(rng)};
    switch (kind(rng)) {
      case 0: to = {centre.x + d, centre.y}; break;                       // on the edge along x
      case 1: d = std::ldexp(1.0, exponent(rng)); to = {centre.x, centre.y - d}; break;  // a power of two along y
      case 2: to = {centre.x + d / std::sqrt(2.0), centre.y + d / std::sqrt(2.0)}; break;  // near the edge, diagonal
      default: break;
    }
    const std::vector<BodyClearance> others = {{1, centre, d}, {2, {centre.x + at(rng), centre.y}, radius(rng)}};
    const bool expected = clear_of_reference(others, from, to);
    disagreements += clear_of(others, from, to) != expected;
    blocked += !expected;
  }
  EXPECT_EQ(disagreements, 0);
  EXPECT_GT(blocked, 10000);  // both answers occur often
}

TEST(BodyClearance, KeepClearTakesTheDiscsOutAndReconnects) {
  // A robot at (0.55, 2.05) and a neighbour whose disc (1.0 m) blocks a wall-to-wall band 1.2 m high: a corridor of
  // rows, with its ends open only through the disc.
  Heightmap h(kGrid, 0.0);
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c)
      if (r < 14 || r > 25) h(r, c) = 5.0;  // walls north and south of the corridor rows 14..25
  deliberative::LocalMap map = test::make_local_map(h, Heightmap(kGrid, 0.0), kNav, {19, 5}, std::nullopt);
  const Position robot = map.center(map.robot);
  ASSERT_NE(map.navigable(19, 35), 0);
  const std::vector<BodyClearance> others = {{3, {2.05, 2.05}, 1.0}};
  const long long removed = keep_clear(map, robot, others);
  EXPECT_GT(removed, 0);
  long long inside = 0;
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) {
      const bool near = distance(map.center({r, c}), others[0].centre) < 1.0;
      if (near) inside += 1;
      if (near) {
        EXPECT_EQ(map.occupiable(r, c), 0) << r << "," << c;
      }
      if (map.navigable(r, c) != 0) {
        EXPECT_NE(map.occupiable(r, c), 0);
      }
    }
  EXPECT_NE(map.navigable(19, 5), 0);  // its own cell stays
  EXPECT_EQ(map.navigable(19, 35), 0);  // the far end is cut off: no route through the other robot
  EXPECT_GT(inside, 0);
}

// keep_clear() visits each neighbour's box only: the cells it takes out are those the plain rule takes out (every
// occupiable cell but the robot's that is not clear_of() the neighbours), for neighbours inside, across and beyond the
// window's edges, discs from a fraction of a cell to wider than the window, robots standing inside a disc, windows
// placed off the world's origin.
TEST(BodyClearance, KeepClearTakesOutTheCellsThePlainRuleDoes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const GridGeometry g{17 + trial % 7, 23 - trial % 5, -3.3 + 0.07 * trial, 1.9 - 0.05 * trial, 0.25};
    Heightmap h(g, 0.0);
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c) h(r, c) = u(rng) < 0.1 ? 1.0 : 0.0;
    const CellIndex robot_cell{static_cast<int>(rng() % g.rows), static_cast<int>(rng() % g.cols)};
    deliberative::LocalMap map = test::make_local_map(h, Heightmap(g, 0.0), kNav, robot_cell, std::nullopt);
    const Position robot{map.center(robot_cell).x + 0.1 * (u(rng) - 0.5), map.center(robot_cell).y};
    std::vector<BodyClearance> others;
    const int count = static_cast<int>(rng() % 5);
    for (int k = 0; k < count; ++k) {
      const Position at{g.xll_m + (1.4 * u(rng) - 0.2) * g.cols * g.cell_size_m,
                        g.yll_m + (1.4 * u(rng) - 0.2) * g.rows * g.cell_size_m};
      const double radius = k == 3 ? 20.0 : (0.05 + 1.5 * u(rng));
      others.push_back({static_cast<std::uint32_t>(k + 2), at, radius});
    }
    deliberative::LocalMap plain = map;
    long long plain_removed = 0;
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c)
        if (plain.occupiable(r, c) != 0 && CellIndex{r, c} != plain.robot &&
            !clear_of(others, robot, plain.center({r, c}))) {
          plain.occupiable(r, c) = 0;
          ++plain_removed;
        }
    EXPECT_EQ(keep_clear(map, robot, others), plain_removed) << trial;
    EXPECT_TRUE(map.occupiable == plain.occupiable) << trial;
  }
}

TEST(BodyClearance, KeepOffTakesOutTheCellsAHalfCellDiscWould) {
  // A corridor of rows 14..25 between walls: cells taken out may cut it. Each trial takes a few cells out (the robot's
  // own and off-window ones among them) and compares with keep_clear on discs of half a cell around their centres,
  // which leave out exactly those cells (other cell centres are a whole cell away).
  Heightmap h(kGrid, 0.0);
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c)
      if (r < 14 || r > 25) h(r, c) = 5.0;
  const deliberative::LocalMap base = test::make_local_map(h, Heightmap(kGrid, 0.0), kNav, {20, 5}, std::nullopt);
  const Position robot = base.center({20, 5});
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> index(-2, 41), count(1, 12);
  long long taken = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<CellIndex> cells;
    std::vector<BodyClearance> discs;
    for (int i = count(rng); i > 0; --i) {
      const CellIndex cell = trial % 10 == 0 && i == 1 ? CellIndex{20, 5} : CellIndex{index(rng) / 2 + 10, index(rng)};
      cells.push_back(cell);
      discs.push_back({1, kGrid.cell_center(cell), 0.5 * kGrid.cell_size_m});
    }
    deliberative::LocalMap off = base, clear = base;
    const long long removed = keep_off(off, cells);
    EXPECT_EQ(removed, keep_clear(clear, robot, discs)) << "trial " << trial;
    EXPECT_EQ(off.occupiable, clear.occupiable) << "trial " << trial;
    EXPECT_EQ(off.navigable, clear.navigable) << "trial " << trial;
    EXPECT_NE(off.occupiable(20, 5), 0);  // never the robot's own cell
    taken += removed;
  }
  EXPECT_GT(taken, 500);  // the trials took cells out, not only off-window and wall cells
}

TEST(BodyClearance, TheActionManagerNeverChoosesATargetTheWorldWouldRefuse) {
  // Random neighbours around a robot on flat ground: whatever path it follows, a motion the action manager returns
  // ends clear of every disc (the world's rule 2.5 with a disc of both radii) and, for a higher-id neighbour, at
  // least the two radii away.
  deliberative::LocalMap map = test::make_local_map(Heightmap(kGrid, 0.0), Heightmap(kGrid, 0.0), kNav, {20, 20},
                                                    std::nullopt);
  const Position robot = map.center({20, 20});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const ActionManager am(0.25);
  int moved = 0, refused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<Neighbour> seen;
    for (std::uint32_t id : {2u, 9u}) {
      const double r = 0.9 + 0.6 * u(rng), t = 6.283185307179586 * u(rng);
      seen.push_back({id, robot.x + r * std::cos(t), robot.y + r * std::sin(t), 0.0, 0.5});
    }
    const auto discs = body_clearances(seen, 5, 0.5, 0.25);
    const int dr = static_cast<int>(std::floor(3 * u(rng))) - 1, dc = static_cast<int>(std::floor(3 * u(rng))) - 1;
    std::vector<CellIndex> path;
    for (int i = 0; i < 10; ++i) path.push_back({20 + i * dr, 20 + i * dc});
    const auto m = am.advance(map, path, robot, discs);
    if (!m) {
      ++refused;
      continue;
    }
    ++moved;
    EXPECT_TRUE(clear_of(discs, robot, m->target));
    for (const Neighbour& n : seen) {
      const double d = distance(m->target, n.position);
      const double before = distance(robot, n.position);
      if (d < 1.0) {  // never deeper into a body
        EXPECT_GE(d, before) << "trial " << trial;
      }
    }
  }
  EXPECT_GT(moved, 50);
  EXPECT_GT(refused, 10);
}

}  // namespace
}  // namespace marsala::agent::executive
