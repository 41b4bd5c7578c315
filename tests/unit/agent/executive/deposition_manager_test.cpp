#include "marsala/agent/executive/deposition_manager.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include "unit/agent/agent_test_support.hpp"
#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::executive {
namespace {

using deliberative::LocalMap;

constexpr double kCs = 0.1;
constexpr double kQ = 0.0125;  // cube 0.05 m on 0.1 m cells: 0.05^3 / 0.01

LocalMap make_map(const Heightmap& heights, const Heightmap& gap, NavigabilityParams nav, CellIndex robot,
                  std::optional<CellIndex> origin) {
  return test::make_local_map(heights, gap, nav, robot, origin);
}

DepositionParams params(double delta_m = 0.4, double max_deposit_m3 = 0.02) {
  DepositionParams p;
  p.navigability = {0.5, delta_m, 0.05};
  p.footprint_m = delta_m;
  p.reach_m = 1.5;
  p.max_deposit_m3 = max_deposit_m3;
  p.cube_layer_m = kQ;
  p.max_height_m = 1.0;
  p.neighbour_keep_out_m = 0.7;
  p.neighbour_step_m = 0.2;
  return p;
}

std::vector<CellIndex> row_path(int row, int from_col, int to_col) {
  std::vector<CellIndex> path;
  for (int c = from_col; from_col <= to_col ? c <= to_col : c >= to_col; c += from_col <= to_col ? 1 : -1)
    path.push_back({row, c});
  return path;
}

double dist(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

const GridGeometry kGrid{21, 31, 0.0, 0.0, kCs};

TEST(DepositionManager, RoundsDownToWholeCubeLayersAndCapsOneMetre) {
  Heightmap gap(kGrid, 0.0);
  gap(10, 20) = 2.8 * kQ;       // -> 2 layers: never above P (nearest would overshoot)
  gap(10, 21) = 3.0 * kQ;       // an exact multiple -> 3 layers
  gap(10, 22) = 0.999999 * kQ;  // below one layer -> nothing
  gap(10, 23) = 2.5;            // -> capped at 1 m (80 layers)
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
  const DepositionManager dm(params(0.4, 1.0));  // budget large enough for all of them
  const Position robot = kGrid.cell_center({10, 10});
  const auto c = dm.candidates(map, row_path(10, 10, 25), robot, 10.0, {1, robot, {}});
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].cell, (CellIndex{10, 20}));
  EXPECT_EQ(c[0].layers, 2);
  EXPECT_EQ(c[0].height_m, 2 * kQ);
  EXPECT_EQ(c[1].layers, 3);
  EXPECT_EQ(c[2].cell, (CellIndex{10, 23}));
  EXPECT_EQ(c[2].layers, 80);
  EXPECT_DOUBLE_EQ(c[2].height_m, 1.0);
}

// A scanning robot leaves its noise margin of each MARS gap unfilled, but a notch's cap (LocalMap::fill_cap) is not
// shrunk by it: a cell raised up to its notch level, not a margin under it (docs/runtime.md#mapping, notches).
TEST(DepositionManager, TheNoiseMarginShrinksTheGapNotANotchsCap) {
  Heightmap gap(kGrid, 0.0), cap(kGrid, std::numeric_limits<double>::infinity());
  gap(10, 20) = 10.0 * kQ, cap(10, 20) = 4.0 * kQ;  // a notch: gap - margin 6.4 layers, cap 4 -> 4 (before: 0)
  gap(10, 21) = 10.0 * kQ, cap(10, 21) = 8.0 * kQ;  // the margin binds: 6.4 -> 6 layers
  gap(10, 22) = 10.0 * kQ;                          // no cap: 6 layers
  LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
  map.fill_cap = cap;
  DepositionParams p = params(0.4, 1.0);
  p.gap_margin_m = 3.6 * kQ;
  const DepositionManager dm(p);
  const Position robot = kGrid.cell_center({10, 10});
  const auto c = dm.candidates(map, row_path(10, 10, 25), robot, 10.0, {1, robot, {}});
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].cell, (CellIndex{10, 20}));
  EXPECT_EQ(c[0].layers, 4);
  EXPECT_EQ(c[1].layers, 6);
  EXPECT_EQ(c[2].layers, 6);
  // The cone depositor's wish (wanted(), no margin) is capped alike.
  const auto w = dm.wanted(map, row_path(10, 10, 25), robot, {1, robot, {}});
  ASSERT_GE(w.size(), 3u);
  EXPECT_NEAR(w[0].gap_m, 4.0 * kQ, 1e-12);
}

TEST(DepositionManager, RespectsReachBudgetAndNeverDepositsUnderTheRobot) {
  const Heightmap gap(kGrid, 0.3);  // 24 layers everywhere
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
  const DepositionManager dm(params(0.4, 0.02));
  // The robot moves to (10, 12) this step: reach and "under the robot" count from there.
  const Position robot = kGrid.cell_center({10, 12});
  const auto plan = dm.plan(map, row_path(10, 10, 30), robot, 10.0, {1, kGrid.cell_center({10, 10}), {}});
  ASSERT_FALSE(plan.depositions.empty());
  double volume = 0.0;
  for (const auto& d : plan.depositions) {
    const double r = dist(kGrid.cell_center({d.row, d.col}), robot);
    EXPECT_GT(r, 0.2);  // delta / 2
    EXPECT_LE(r, 1.5);  // reach
    const double n = d.height_m / kQ;
    EXPECT_NEAR(n, std::round(n), 1e-9);
    volume += d.height_m * kCs * kCs;
  }
  // The budget is filled to the last whole layer: 0.02 m^3 = 160 layers of 1.25e-4 m^3.
  EXPECT_NEAR(volume, 0.02, 1e-12);
  EXPECT_LE(volume, 0.02 + 1e-12);
  EXPECT_NEAR(plan.volume_m3, volume, 1e-15);
  // Path order: the ball of path cell (10, 10) first, from its centre out. Its centre is 0.2 m from the robot
  // (under it); of the four cells at one cell's distance, row-major, (9, 10) comes first and lies 0.224 m away.
  EXPECT_EQ(plan.depositions.front().row, 9);
  EXPECT_EQ(plan.depositions.front().col, 10);

  // Material on board binds when it is below the threshold; none on board, no deposition.
  const auto little = dm.plan(map, row_path(10, 10, 30), robot, 0.005, {1, robot, {}});
  double v = 0.0;
  for (const auto& d : little.depositions) v += d.height_m * kCs * kCs;
  EXPECT_NEAR(v, 0.005, 1e-12);
  EXPECT_LE(v, 0.005 + 1e-12);
  EXPECT_TRUE(dm.plan(map, row_path(10, 10, 30), robot, 0.0, {1, robot, {}}).depositions.empty());
  EXPECT_TRUE(dm.plan(map, row_path(10, 10, 30), robot, 1e-4, {1, robot, {}}).depositions.empty());  // < a cube
}

TEST(DepositionManager, WithoutASureWayOutNothingIsRaisedThatCouldCloseANeighbourCell) {
  // A scanned map: a pair of readings next to the robot may be off by 0.02 m.
  DepositionParams scanned = params(0.4);
  scanned.exit_margin_m = 0.02;
  const NavigabilityParams& nav = scanned.navigability;  // kappa 0.5, delta 0.4 (a ball of radius 2 cells), eps 0.05
  const CellIndex robot_cell{10, 10};
  const Position robot = kGrid.cell_center(robot_cell);
  const double under_m = 0.2;
  const double neighbours_m = 0.2 + std::sqrt(2.0) * kCs;  // a cell whose raise can reach a neighbour's ball
  const Heightmap gap(kGrid, 0.3);

  // Ground whose cells next to each other differ by 0.09 m (a checkerboard): occupiable with eps (0.09 <= 0.05 +
  // 0.5 * 0.1), not with eps less the margin (0.09 > 0.03 + 0.05), so the robot's way out may be the map's noise.
  Heightmap bumpy(kGrid, 0.0);
  for (int r = 0; r < bumpy.rows(); ++r)
    for (int c = 0; c < bumpy.cols(); ++c) bumpy(r, c) = (r + c) % 2 == 0 ? 0.0 : 0.09;
  const LocalMap rough = make_map(bumpy, gap, nav, robot_cell, {{10, 0}});
  ASSERT_EQ(rough.navigable.cast<int>().sum(), rough.rows() * rough.cols());
  const DepositionManager dm(scanned);
  EXPECT_NEAR(dm.clearance_m(rough, robot), neighbours_m, 1e-5);
  const auto plan = dm.plan(rough, row_path(10, 10, 30), robot, 10.0, {1, robot, {}});
  ASSERT_FALSE(plan.depositions.empty());
  Heightmap after = bumpy;
  for (const auto& d : plan.depositions) {
    EXPECT_GT(dist(kGrid.cell_center({d.row, d.col}), robot), neighbours_m);
    after(d.row, d.col) += d.height_m;
  }
  // So every neighbour cell is as occupiable as before, whatever was raised (an independent check on the grid).
  const CellMask before_occ = NavigabilityProcessor(nav).occupiable(bumpy);
  const CellMask after_occ = NavigabilityProcessor(nav).occupiable(after);
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc)
      EXPECT_EQ(after_occ(10 + dr, 10 + dc), before_occ(10 + dr, 10 + dc)) << dr << " " << dc;
  // An exact map (no margin) or a sure way out (flat ground) keeps only the body clear.
  EXPECT_NEAR(DepositionManager(params(0.4)).clearance_m(rough, robot), under_m, 1e-5);
  const LocalMap flat = make_map(Heightmap(kGrid, 0.0), gap, nav, robot_cell, {{10, 0}});
  EXPECT_NEAR(dm.clearance_m(flat, robot), under_m, 1e-5);
  bool near = false;
  for (const auto& d : dm.plan(flat, row_path(10, 10, 30), robot, 10.0, {1, robot, {}}).depositions)
    near = near || dist(kGrid.cell_center({d.row, d.col}), robot) <= neighbours_m;
  EXPECT_TRUE(near);
}

TEST(DepositionManager, NeighboursKeepOutAndTerritoriesDoNotOverlap) {
  const Heightmap gap(kGrid, 0.3);
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, std::nullopt);
  DepositionParams p = params(0.4, 10.0);
  p.neighbour_keep_out_m = 0.25;
  const DepositionManager dm(p);
  const Position a = kGrid.cell_center({10, 10}), b = kGrid.cell_center({10, 16});  // 0.6 m apart
  const auto path = row_path(10, 0, 30);
  const auto of_a = dm.candidates(map, path, a, 100.0, {1, a, {{2, b.x, b.y, 0.0}}});
  const auto of_b = dm.candidates(map, path, b, 100.0, {2, b, {{1, a.x, a.y, 0.0}}});
  ASSERT_FALSE(of_a.empty());
  ASSERT_FALSE(of_b.empty());
  std::set<std::pair<int, int>> cells_a;
  bool a_has_tie = false;
  for (const auto& c : of_a) {
    cells_a.insert({c.cell.row, c.cell.col});
    EXPECT_GT(dist(map.center(c.cell), b), 0.25);  // keep-out around the neighbour
    EXPECT_LE(c.cell.col, 13);                     // its territory: cells nearer (10, 10) in whole cells
    a_has_tie = a_has_tie || c.cell.col == 13;     // col 13 is as near to both: the lower id takes it
  }
  EXPECT_TRUE(a_has_tie);
  for (const auto& c : of_b) {
    EXPECT_EQ(cells_a.count({c.cell.row, c.cell.col}), 0u) << c.cell.row << ", " << c.cell.col;
    EXPECT_GT(dist(map.center(c.cell), a), 0.25);
    EXPECT_GE(c.cell.col, 14);
  }
}

/// A corridor along row 10 (rows 8..12 at 0 m) between 2 m walls; with delta 0.4 m only row 10 is occupiable.
Heightmap corridor() {
  Heightmap h(kGrid, 2.0);
  for (int r = 8; r <= 12; ++r)
    for (int c = 0; c < kGrid.cols; ++c) h(r, c) = 0.0;
  return h;
}

TEST(DepositionManager, KeepsTheRobotsWayBack) {
  const Heightmap h = corridor();
  Heightmap gap(kGrid, 0.0);
  for (int c = 0; c < kGrid.cols; ++c) gap(10, c) = 0.3;
  // The robot at (10, 20) plans west, through its own way back to the origin (10, 1).
  const LocalMap map = make_map(h, gap, params().navigability, {10, 20}, {{10, 1}});
  ASSERT_EQ(map.navigable(10, 1), 1);
  const DepositionManager dm(params());
  const Position robot = kGrid.cell_center({10, 20});
  const auto path = row_path(10, 20, 0);
  const auto all = dm.candidates(map, path, robot, 10.0, {1, robot, {}});
  ASSERT_FALSE(all.empty());
  EXPECT_FALSE(dm.keeps_way_back(map, robot, all, {1, robot, {}}));
  const auto plan = dm.plan(map, path, robot, 10.0, {1, robot, {}});
  EXPECT_TRUE(plan.depositions.empty());
  EXPECT_EQ(plan.dropped_for_way_back, plan.candidates);
  // Planning east instead (away from the origin) keeps everything.
  const auto east = dm.plan(map, row_path(10, 20, 30), robot, 10.0, {1, robot, {}});
  EXPECT_FALSE(east.depositions.empty());
  EXPECT_EQ(east.dropped_for_way_back, 0);
}

// A scanned map opens cells the robot stood on that its heights alone hold not occupiable (a reading a few mm off:
// docs/runtime.md#cells-stood-on). The robot's way back to its origin runs through them: a deposit ahead of it, out of
// their balls, keeps that way as on the same corridor without the misread cell; a deposit in their ball judges them
// again on the heights, and it is dropped.
TEST(DepositionManager, CellsTheMapOpensStayOpenUntilADepositLandsInTheirBall) {
  const DepositionParams p = params();
  const DepositionManager dm(p);
  const CellIndex centre{10, 20};
  const Position robot = kGrid.cell_center(centre);
  Heightmap gap(kGrid, 0.0);
  gap(10, 26) = 0.05;  // ahead, 0.6 m from the robot
  gap(10, 13) = 0.05;  // in the ball of (10, 11) and (10, 12)
  const auto ahead = row_path(10, 21, 30);
  const auto behind = row_path(10, 19, 12);

  // The reference: the corridor read right. The deposit ahead is kept, the one behind too (nothing breaks there).
  const LocalMap right = make_map(corridor(), gap, p.navigability, centre, {{10, 1}});
  ASSERT_EQ(dm.plan(right, ahead, robot, 10.0, {1, robot, {}}).depositions.size(), 1u);

  Heightmap misread = corridor();
  misread(10, 10) = 0.12;  // 0.12 m over its neighbours, where eps + kappa cs allows 0.10 m
  LocalMap map = make_map(misread, gap, p.navigability, centre, {{10, 1}});
  map.heights_occupiable = map.occupiable;
  map.heights_navigability = p.navigability;
  for (int c = 8; c <= 12; ++c) {
    ASSERT_EQ(map.occupiable(10, c), 0) << c;
    map.occupiable(10, c) = 1;  // stood on
  }
  map.navigable = NavigabilityProcessor::navigable_from(map.occupiable, centre);
  ASSERT_EQ(map.navigable(10, 1), 1);

  const DepositionPlan kept = dm.plan(map, ahead, robot, 10.0, {1, robot, {}});
  ASSERT_EQ(kept.depositions.size(), 1u);
  EXPECT_EQ(kept.depositions[0].col, 26);
  EXPECT_EQ(kept.dropped_for_way_back, 0);
  const DepositionPlan dropped = dm.plan(map, behind, robot, 10.0, {1, robot, {}});
  EXPECT_EQ(dropped.candidates, 1);
  EXPECT_TRUE(dropped.depositions.empty());
}

/// The plan of a robot at `centre` along `cells` with 10 m^3 on board, after checking that every cell is a candidate
/// and that all of them together would not keep its way back.
DepositionPlan plan_cut_short(const LocalMap& map, const DepositionParams& p, CellIndex centre,
                              const std::vector<CellIndex>& cells) {
  const DepositionManager dm(p);
  const Position robot = kGrid.cell_center(centre);
  const auto all = dm.candidates(map, cells, robot, 10.0, {1, robot, {}});
  EXPECT_EQ(all.size(), cells.size());
  EXPECT_FALSE(dm.keeps_way_back(map, robot, all, {1, robot, {}}));
  return dm.plan(map, cells, robot, 10.0, {1, robot, {}});
}

TEST(DepositionManager, NeverRingsInARobotWhoseOriginIsItsOwnCell) {
  // A robot that has not moved yet: its local origin is its own cell, so the origin test alone is vacuous. The gap
  // is a square ring three cells from it; filled whole, the ring's walls (0.3 m against eps 0.05 m) would leave it
  // no way out of the window.
  const Heightmap flat(kGrid, 0.0);
  const CellIndex centre{10, 15};
  Heightmap gap(kGrid, 0.0);
  std::vector<CellIndex> ring;
  for (int c = centre.col - 3; c <= centre.col + 3; ++c) ring.push_back({centre.row - 3, c});
  for (int r = centre.row - 2; r <= centre.row + 3; ++r) ring.push_back({r, centre.col + 3});
  for (int c = centre.col + 2; c >= centre.col - 3; --c) ring.push_back({centre.row + 3, c});
  for (int r = centre.row + 2; r >= centre.row - 2; --r) ring.push_back({r, centre.col - 3});
  for (const CellIndex p : ring) gap(p) = 0.3;
  const DepositionParams p = params(0.4, 10.0);
  const LocalMap map = make_map(flat, gap, p.navigability, centre, centre);
  const DepositionPlan plan = plan_cut_short(map, p, centre, ring);
  EXPECT_GT(plan.depositions.size(), 0u);
  EXPECT_LT(plan.depositions.size(), ring.size());
  // Independent check: after the plan's depositions the robot still reaches the window's border.
  Heightmap after = flat;
  for (const Deposition& d : plan.depositions) after(CellIndex{d.row, d.col}) += d.height_m;
  const CellMask reach =
      NavigabilityProcessor::navigable_from(NavigabilityProcessor(p.navigability).occupiable(after), centre);
  EXPECT_TRUE(reach.row(0).any() || reach.row(kGrid.rows - 1).any() || reach.col(0).any() ||
              reach.col(kGrid.cols - 1).any());
}

/// Flat ground with a 1 m wall all round `centre`, 8 cells (Chebyshev) from it: a pocket no way leads out of.
Heightmap pocket(CellIndex centre) {
  Heightmap h(kGrid, 0.0);
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 0; c < kGrid.cols; ++c)
      if (std::max(std::abs(r - centre.row), std::abs(c - centre.col)) >= 8) h(r, c) = 1.0;
  return h;
}

// A robot in a pocket its map gives no way out of (a 1 m wall all round): the depositions keep every cell it can still
// reach. The gap across the pocket is a thin layer on its west half (within eps: it cuts nothing) and a 0.3 m wall on
// its east half, which would cut the cells beside it off; the plan keeps the layer and none of the wall, checked on the
// heights after it.
TEST(DepositionManager, WithoutAWayOutTheRobotKeepsEveryCellItCanStillReach) {
  const CellIndex centre{10, 15};
  Heightmap h = pocket(centre);
  Heightmap gap(kGrid, 0.0);
  std::vector<CellIndex> line;
  for (int c = centre.col - 7; c <= centre.col + 7; ++c) {
    line.push_back({centre.row - 3, c});
    gap(centre.row - 3, c) = c < centre.col ? 0.04 : 0.3;
  }
  DepositionParams p = params(0.4, 10.0);
  p.keep_reach_without_way_out = true;
  const LocalMap map = make_map(h, gap, p.navigability, centre, centre);
  const NavigabilityProcessor nav(p.navigability);
  const CellMask before = NavigabilityProcessor::navigable_from(nav.occupiable(h), centre);
  ASSERT_FALSE(before.row(0).any() || before.row(kGrid.rows - 1).any() || before.col(0).any() ||
               before.col(kGrid.cols - 1).any());  // no way out
  const DepositionPlan plan = plan_cut_short(map, p, centre, line);
  EXPECT_EQ(plan.depositions.size(), 7u);  // the layer's cells
  for (const Deposition& d : plan.depositions) EXPECT_LT(d.col, centre.col);
  Heightmap after = h;
  for (const Deposition& d : plan.depositions) after(CellIndex{d.row, d.col}) += d.height_m;
  const CellMask now = NavigabilityProcessor::navigable_from(nav.occupiable(after), centre);
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 0; c < kGrid.cols; ++c)
      if (before(r, c) != 0) {
        EXPECT_NE(now(r, c), 0) << r << "," << c;
      }
  // Without the rule (an exact map) the whole line is filled: the pocket's way out was already gone.
  p.keep_reach_without_way_out = false;
  EXPECT_EQ(DepositionManager(p).plan(map, line, kGrid.cell_center(centre), 10.0, {1, kGrid.cell_center(centre), {}})
                .depositions.size(),
            line.size());
}

// The cells kept without a way out are the robot's way back, those no nearer its goal than it stands: what lies ahead
// is what it builds. The same pocket; a 0.3 m wall to fill on the east half of the row three cells north (listed from
// the east). With the goal east, the wall's eastern cells are built (they cut only cells nearer the goal), and every
// cell it could reach that is no nearer the goal stays reachable; with the goal west, nothing of it is built.
TEST(DepositionManager, WithoutAWayOutTheRobotKeepsTheCellsBehindItNotThoseAhead) {
  const CellIndex centre{10, 15};
  Heightmap h = pocket(centre);
  Heightmap gap(kGrid, 0.0);
  std::vector<CellIndex> line;
  for (int c = centre.col + 7; c > centre.col; --c) {
    line.push_back({centre.row - 3, c});
    gap(centre.row - 3, c) = 0.3;
  }
  DepositionParams p = params(0.4, 10.0);
  p.keep_reach_without_way_out = true;
  const NavigabilityProcessor nav(p.navigability);
  const CellMask before = NavigabilityProcessor::navigable_from(nav.occupiable(h), centre);
  const Position robot = kGrid.cell_center(centre);
  const auto plan_towards = [&](CellIndex goal) {
    LocalMap map = make_map(h, gap, p.navigability, centre, centre);
    map.goal = goal;
    return DepositionManager(p).plan(map, line, robot, 10.0, {1, robot, {}});
  };
  const auto to = [](CellIndex a, CellIndex b) {
    return (a.row - b.row) * (a.row - b.row) + (a.col - b.col) * (a.col - b.col);
  };
  const CellIndex east{centre.row, kGrid.cols - 1};
  const DepositionPlan ahead = plan_towards(east);
  ASSERT_FALSE(ahead.depositions.empty());
  Heightmap after = h;
  for (const Deposition& d : ahead.depositions) after(CellIndex{d.row, d.col}) += d.height_m;
  const CellMask now = NavigabilityProcessor::navigable_from(nav.occupiable(after), centre);
  int cut_ahead = 0;
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 0; c < kGrid.cols; ++c) {
      if (before(r, c) == 0) continue;
      if (to({r, c}, east) >= to(centre, east)) {
        EXPECT_NE(now(r, c), 0) << r << "," << c;
      } else if (now(r, c) == 0) {
        ++cut_ahead;
      }
    }
  EXPECT_GT(cut_ahead, 0);
  EXPECT_TRUE(plan_towards({centre.row, 0}).depositions.empty());
}

// The cells kept without a way out are read within the map's noise: a cell the map holds just not occupiable (a pair
// in its ball 1 cm over the rule) may be the real way back. The same pocket with a 0.11 m bump four cells west of the
// robot (1 cm over eps + kappa d against the cells beside it, so the 13 cells whose ball holds it are not occupiable
// on the heights) and a 0.3 m gap on it: with a noise margin of 3 cm those cells count as reachable and the bump is not
// raised (it would close them by far more than the noise); without one they were never reachable and it is.
TEST(DepositionManager, WithoutAWayOutTheCellsKeptAreReadWithinTheMapsNoise) {
  const CellIndex centre{10, 15};
  const CellIndex bump{centre.row, centre.col - 4};
  Heightmap h = pocket(centre);
  h(bump) = 0.11;
  Heightmap gap(kGrid, 0.0);
  gap(bump) = 0.3;
  const auto raises_bump = [&](double margin_m) {
    DepositionParams p = params(0.4, 10.0);
    p.keep_reach_without_way_out = true;
    p.gap_margin_m = margin_m;
    const LocalMap map = make_map(h, gap, p.navigability, centre, centre);
    const Position robot = kGrid.cell_center(centre);
    const DepositionPlan plan = DepositionManager(p).plan(map, {bump}, robot, 10.0, {1, robot, {}});
    return std::any_of(plan.depositions.begin(), plan.depositions.end(),
                       [&](const Deposition& d) { return CellIndex{d.row, d.col} == bump; });
  };
  ASSERT_FALSE(NavigabilityProcessor(params(0.4).navigability).occupiable(h)(bump.row, bump.col + 1));
  EXPECT_FALSE(raises_bump(0.03));
  EXPECT_TRUE(raises_bump(0.0));
}

TEST(DepositionManager, KeepsANeighboursWayBack) {
  const Heightmap h = corridor();
  Heightmap gap(kGrid, 0.0);
  for (int c = 0; c < kGrid.cols; ++c) gap(10, c) = 0.3;
  // This robot near the origin (10, 1) at (10, 2) builds east; a neighbour stands at (10, 20) further east.
  const LocalMap map = make_map(h, gap, params().navigability, {10, 2}, {{10, 1}});
  const DepositionManager dm(params());
  const Position robot = kGrid.cell_center({10, 2}), other = kGrid.cell_center({10, 20});
  const auto path = row_path(10, 2, 30);
  const auto alone = dm.plan(map, path, robot, 10.0, {1, robot, {}});
  EXPECT_FALSE(alone.depositions.empty());  // nobody to wall in
  const auto with = dm.plan(map, path, robot, 10.0, {1, robot, {{2, other.x, other.y, 0.0}}});
  EXPECT_TRUE(with.depositions.empty());  // every one of them would cut the neighbour off the origin
  EXPECT_GT(with.dropped_for_way_back, 0);
}

TEST(DepositionManager, NeverBuildsOnTheBasePad) {
  // The same gap everywhere; a pad of radius 0.3 m on the path 0.4 m east of the robot: of the cells it would fill,
  // those whose centres lie on the pad are left out.
  const Heightmap gap(kGrid, 0.3);
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
  DepositionParams p = params(0.4, 1.0);
  p.pad_centre = kGrid.cell_center({10, 14});
  p.pad_radius_m = 0.3;
  const DepositionManager dm(p);
  const Position robot = kGrid.cell_center({10, 10});
  const auto plan = dm.plan(map, row_path(10, 10, 30), robot, 10.0, {1, robot, {}});  // over the pad
  ASSERT_FALSE(plan.depositions.empty());
  for (const auto& d : plan.depositions)
    EXPECT_GT(dist(kGrid.cell_center({d.row, d.col}), p.pad_centre), 0.3) << d.row << ", " << d.col;
  // Without the pad the same plan builds on it.
  const auto bare = DepositionManager(params(0.4, 1.0)).plan(map, row_path(10, 10, 30), robot, 10.0, {1, robot, {}});
  bool on_pad = false;
  for (const auto& d : bare.depositions)
    on_pad = on_pad || dist(kGrid.cell_center({d.row, d.col}), p.pad_centre) <= 0.3;
  EXPECT_TRUE(on_pad);
}

// The straight way to a target, cell by cell: hand-derived on the 0.1 m grid. From (0, 0) to the centre of (2, 4)
// the half-cell samples lie at (row, col) offsets (2i/9, 4i/9), i = 1..9, rounded to cells.
TEST(DepositionManager, TheLineToATargetCrossesItsCellsUpToTheWindowsEdge) {
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), Heightmap(kGrid, 0.0), params().navigability, {10, 10}, {});
  const std::vector<CellIndex> diagonal{{0, 0}, {0, 1}, {1, 1}, {1, 2}, {1, 3}, {2, 3}, {2, 4}};
  EXPECT_EQ(line_cells(map, {0, 0}, kGrid.cell_center({2, 4})), diagonal);
  // A target beyond the window's east edge: the row up to the last column.
  const Position east{kGrid.cell_center({10, 30}).x + 5.0, kGrid.cell_center({10, 30}).y};
  EXPECT_EQ(line_cells(map, {10, 10}, east), row_path(10, 10, 30));
  EXPECT_EQ(line_cells(map, {10, 10}, kGrid.cell_center({10, 10})), (std::vector<CellIndex>{{10, 10}}));
}

// docs/runtime.md#mapping: a path that turned aside (east) leaves the gap on the straight way to the target (south)
// out of its footprint; the line to the target holds it. Robot at (10, 10), footprint 0.4 m (2 cells each side of a
// path cell): the gap cells (14, 10) and (15, 10), 0.4 and 0.5 m away, in reach, are candidates only along the line,
// nearest first, 5 layers each.
TEST(DepositionManager, AGapOnTheLineToTheTargetOffThePathIsACandidateAlongThatLine) {
  Heightmap gap(kGrid, 0.0);
  gap(14, 10) = 5.0 * kQ;
  gap(15, 10) = 5.0 * kQ;
  const LocalMap map = make_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
  const DepositionManager dm(params());
  const Position robot = kGrid.cell_center({10, 10});
  EXPECT_TRUE(dm.candidates(map, row_path(10, 10, 25), robot, 10.0, {1, robot, {}}).empty());
  const Position south{robot.x, kGrid.cell_center({20, 10}).y - 3.0};
  const auto c = dm.candidates(map, line_cells(map, {10, 10}, south), robot, 10.0, {1, robot, {}});
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].cell, (CellIndex{14, 10}));
  EXPECT_EQ(c[1].cell, (CellIndex{15, 10}));
  EXPECT_EQ(c[0].layers, 5);
  EXPECT_EQ(c[1].layers, 5);
}

/// The way-back check as first written, the reference for the incremental one: the whole window's occupiable mask
/// recomputed from the raised heights, and every reach before the depositions searched again.
bool reaches_border_ref(const CellMask& reach) {
  const auto rows = reach.rows(), cols = reach.cols();
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c)
      if ((r == 0 || c == 0 || r == rows - 1 || c == cols - 1) && reach(r, c) != 0) return true;
  return false;
}

CellMask occupiable_after_ref(const LocalMap& map, const NavigabilityParams& nav,
                              const std::vector<DepositionCandidate>& depositions) {
  Heightmap after = map.heights;
  for (const auto& d : depositions) after(d.cell) += d.height_m;
  CellMask occupiable = NavigabilityProcessor(nav).occupiable(after);
  const double radius = nav.delta_m / (2.0 * map.geometry().cell_size_m);
  const bool opened = map.heights_occupiable.rows() == map.rows() && map.heights_occupiable.cols() == map.cols();
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c) {
      if (map.blind(r, c) != 0) occupiable(r, c) = 0;
      // A cell the map opened beyond its heights stays open while no deposit lies in its ball.
      if (!opened || map.occupiable(r, c) == 0 || map.heights_occupiable(r, c) != 0) continue;
      bool in_ball = false;
      for (const auto& d : depositions)
        in_ball = in_ball || static_cast<double>((d.cell.row - r) * (d.cell.row - r) + (d.cell.col - c) * (d.cell.col - c)) <=
                                 radius * radius + tolerance::kBallCells2;
      if (!in_ball) occupiable(r, c) = 1;
    }
  return occupiable;
}

bool keeps_way_back_ref(const LocalMap& map, const DepositionParams& p, Position robot,
                        const std::vector<DepositionCandidate>& depositions, const Neighbourhood& neighbours) {
  const auto cell = map.cell_at(robot);
  if (!cell) return false;
  if (depositions.empty()) return true;
  std::vector<CellIndex> robots{*cell};
  const double cs = map.geometry().cell_size_m;
  for (const Neighbour& n : neighbours.others)
    if (const auto c = map.cell_at(n.position))
      for (const CellIndex o : disc_offsets(p.neighbour_step_m / cs)) {
        const CellIndex q{c->row + o.row, c->col + o.col};
        if (map.contains(q)) robots.push_back(q);
      }
  const bool has_origin = map.origin && map.occupiable(map.origin->row, map.origin->col) != 0;
  const CellMask occupiable = occupiable_after_ref(map, p.navigability, depositions);
  if (map.occupiable(cell->row, cell->col) != 0 && occupiable(cell->row, cell->col) == 0) return false;
  if (map.occupiable(cell->row, cell->col) != 0 &&
      reaches_border_ref(NavigabilityProcessor::navigable_from(map.occupiable, *cell)) &&
      !reaches_border_ref(NavigabilityProcessor::navigable_from(occupiable, *cell)))
    return false;
  if (!has_origin) return true;
  const CellMask before = NavigabilityProcessor::navigable_from(map.occupiable, *map.origin);
  const CellMask reach = NavigabilityProcessor::navigable_from(occupiable, *map.origin);
  for (const CellIndex q : robots)
    if (before(q.row, q.col) != 0 && reach(q.row, q.col) == 0) return false;
  return true;
}

/// A random small window: terraces and rough patches (heights on a 0.0125 m lattice, so pairs land exactly on the
/// eps threshold too), some unknown cells and their blind balls, the robot and the origin anywhere.
struct RandomWindow {
  LocalMap map;
  Position robot;
  Neighbourhood neighbours;
};

RandomWindow random_window(std::mt19937& rng, const NavigabilityParams& nav, bool synthesized) {
  std::uniform_int_distribution<int> rows_d(6, 16), cols_d(6, 16), level(0, 8), coin(0, 3);
  const GridGeometry grid{rows_d(rng), cols_d(rng), 0.0, 0.0, kCs};
  Heightmap h(grid, 0.0);
  const int terrace = std::uniform_int_distribution<int>(0, grid.cols - 1)(rng);
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c)
      h(r, c) = (c >= terrace ? 4 * kQ : 0.0) + (coin(rng) == 0 ? level(rng) * kQ : 0.0);
  std::uniform_int_distribution<int> row_d(0, grid.rows - 1), col_d(0, grid.cols - 1);
  const CellIndex robot{row_d(rng), col_d(rng)};
  const CellIndex origin{row_d(rng), col_d(rng)};
  RandomWindow w{test::make_local_map(h, Heightmap(grid, 0.0), nav, robot, origin), grid.cell_center(robot),
                 {1, grid.cell_center(robot), {}}};
  CellMask known = CellMask::Ones(grid.rows, grid.cols);
  if (coin(rng) != 0)
    for (int k = std::uniform_int_distribution<int>(1, 4)(rng); k > 0; --k) known(row_d(rng), col_d(rng)) = 0;
  w.map.known = known;
  w.map.blind = blind_cells(known, nav.delta_m / (2.0 * kCs));
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c)
      if (w.map.blind(r, c) != 0) w.map.occupiable(r, c) = 0;
  if (synthesized) {  // as the synthesizer leaves it: the heights' own mask kept before any cell is opened
    w.map.heights_occupiable = w.map.occupiable;
    w.map.heights_navigability = nav;
  }
  // A scanned map opens the robot's own cell whatever its heights say, and cells it stood on.
  if (coin(rng) == 0) w.map.occupiable(robot.row, robot.col) = 1;
  for (int k = std::uniform_int_distribution<int>(0, 3)(rng); k > 0; --k) {
    const CellIndex stood{row_d(rng), col_d(rng)};
    if (w.map.blind(stood.row, stood.col) == 0) w.map.occupiable(stood.row, stood.col) = 1;
  }
  w.map.navigable = NavigabilityProcessor::navigable_from(w.map.occupiable, robot);
  for (int k = std::uniform_int_distribution<int>(0, 2)(rng); k > 0; --k) {
    const Position n = grid.cell_center({row_d(rng), col_d(rng)});
    w.neighbours.others.push_back({static_cast<std::uint32_t>(2 + k), n, 0.0, 0.2});
  }
  return w;
}

std::vector<DepositionCandidate> random_depositions(std::mt19937& rng, const LocalMap& map) {
  std::uniform_int_distribution<int> count(0, 40), row_d(0, map.rows() - 1), col_d(0, map.cols() - 1), layers(1, 8);
  std::vector<DepositionCandidate> out;
  for (int k = count(rng); k > 0; --k) {
    const int n = layers(rng);
    out.push_back({{row_d(rng), col_d(rng)}, n, n * kQ});  // a cell may repeat: the cube depositors' rises do
  }
  return out;
}

// keeps_way_back() recomputes occupiability only where a deposit lies in a cell's body ball, and searches the reaches
// before the depositions once per context: against the whole-window recomputation on random windows, cell by cell,
// for every prefix of random deposition lists (as the binary search asks them), with and without the synthesizer's
// mask, and for bodies whose balls hold 5 to 29 cells.
TEST(DepositionManager, IncrementalWayBackEqualsTheFullRecomputation) {
  std::mt19937 rng(20261129);
  int differing_masks = 0, kept = 0, refused = 0;
  for (const double delta : {0.2, 0.4, 0.6}) {
    DepositionParams p = params(delta);
    const DepositionManager dm(p);
    for (int trial = 0; trial < 150; ++trial) {
      const RandomWindow w = random_window(rng, p.navigability, trial % 2 == 0);
      const auto deps = random_depositions(rng, w.map);
      DepositionManager::WayBack way = dm.way_back(w.map, w.robot, w.neighbours);
      for (std::size_t n = 0; n <= deps.size(); ++n) {
        const std::vector<DepositionCandidate> prefix(deps.begin(), deps.begin() + static_cast<std::ptrdiff_t>(n));
        const CellMask want = occupiable_after_ref(w.map, p.navigability, prefix);
        const CellMask got = dm.occupiable_after(way, prefix);
        ASSERT_EQ(got.rows(), want.rows());
        ASSERT_EQ(got.cols(), want.cols());
        for (int r = 0; r < want.rows(); ++r)
          for (int c = 0; c < want.cols(); ++c)
            ASSERT_EQ(got(r, c), want(r, c)) << "delta " << delta << " trial " << trial << " prefix " << n << " cell ("
                                             << r << ", " << c << ")";
        if (want != w.map.heights_occupiable && w.map.heights_occupiable.size() != 0) ++differing_masks;
        const bool ref = keeps_way_back_ref(w.map, p, w.robot, prefix, w.neighbours);
        ASSERT_EQ(dm.keeps_way_back(way, prefix), ref) << "delta " << delta << " trial " << trial << " prefix " << n;
        ASSERT_EQ(dm.keeps_way_back(w.map, w.robot, prefix, w.neighbours), ref);
        ++(ref ? kept : refused);
      }
    }
  }
  // The draws exercise both answers and masks the deposits really change.
  EXPECT_GT(differing_masks, 100);
  EXPECT_GT(kept, 100);
  EXPECT_GT(refused, 100);
}

TEST(DepositionManager, RejectsInvalidLimits) {
  DepositionParams p = params();
  p.reach_m = 0.0;
  EXPECT_THROW(DepositionManager{p}, InvalidArgument);
  p = params();
  p.cube_layer_m = std::nan("");
  EXPECT_THROW(DepositionManager{p}, InvalidArgument);
  p = params();
  p.neighbour_keep_out_m = -1.0;
  EXPECT_THROW(DepositionManager{p}, InvalidArgument);
  p = params();
  p.navigability.kappa = 0.0;
  EXPECT_THROW(DepositionManager{p}, InvalidArgument);
  p = params();
  p.pad_radius_m = -1.0;
  EXPECT_THROW(DepositionManager{p}, InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::executive
