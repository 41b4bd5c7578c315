#include "marsala/agent/executive/depositor.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::executive {
namespace {

using deliberative::LocalMap;

constexpr double kCs = 0.1;
constexpr double kEps = 0.05;
const GridGeometry kGrid{21, 41, 0.0, 0.0, kCs};

DepositionParams params() {
  DepositionParams p;
  p.navigability = {0.5, 0.4, kEps};
  p.footprint_m = 0.4;
  p.reach_m = 1.5;
  p.max_deposit_m3 = 0.02;
  p.cube_layer_m = 0.1;
  p.max_height_m = 1.0;
  p.neighbour_keep_out_m = 0.7;
  p.neighbour_step_m = 0.2;
  return p;
}

std::vector<CellIndex> row_path(int row, int from_col, int to_col) {
  std::vector<CellIndex> path;
  for (int c = from_col; c <= to_col; ++c) path.push_back({row, c});
  return path;
}

double dist(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

/// Flat ground with a ramp-shaped MARS gap ahead of the robot at (10, 10): 0.03 m per cell from column 12 on.
LocalMap ramp_map(double per_cell_m = 0.03) {
  Heightmap gap(kGrid, 0.0);
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 12; c < kGrid.cols; ++c) gap(r, c) = per_cell_m * (c - 11);
  return test::make_local_map(Heightmap(kGrid, 0.0), gap, params().navigability, {10, 10}, {{10, 0}});
}

RobotType type_with(const std::string& depositor) {
  RobotType t;
  t.depositor.kind = depositor_kind(depositor);
  t.depositor.cube_size_m = 0.1;
  t.depositor.repose_deg = 34.0;
  return t;
}

/// The terrain after the plan's deposits, shaped as the world shapes them, in order.
Heightmap after(const LocalMap& map, const DepositionPlan& plan, const RobotType& type) {
  Heightmap h = map.heights;
  for (const Deposit& d : plan.deposits) {
    const DepositShape s = type.depositor.kind == DepositorKind::kCube
                               ? cube_column_shape(h.geometry(), d.centre, *type.depositor.cube_size_m,
                                                   static_cast<int>(std::lround(d.volume_m3 / 0.001)))
                               : cone_pile_shape(h, d.centre, d.volume_m3, type.depositor.repose_deg);
    EXPECT_TRUE(s.on_grid);
    for (const CellRise& r : s.rises) h(r.cell) += r.rise_m;
  }
  return h;
}

TEST(Depositor, UnknownNameListsTheValidOnes) {
  try {
    make_depositor(type_with("shovel"));
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "unknown depositor 'shovel'; valid: cone, cube, layer");
  }
  EXPECT_EQ(make_depositor(type_with("layer"))->name(), "layer");
}

TEST(Depositor, LayerIsTheManagersPlanUnchanged) {
  const LocalMap map = ramp_map();
  const DepositionManager dm(params());
  const Position robot = kGrid.cell_center({10, 10});
  const DepositionPlan a = make_depositor(type_with("layer"))->plan(dm, map, row_path(10, 10, 40), robot, 10.0,
                                                                     {1, robot, {}});
  const DepositionPlan b = dm.plan(map, row_path(10, 10, 40), robot, 10.0, {1, robot, {}});
  ASSERT_EQ(a.depositions.size(), b.depositions.size());
  for (std::size_t i = 0; i < a.depositions.size(); ++i) {
    EXPECT_EQ(a.depositions[i].row, b.depositions[i].row);
    EXPECT_EQ(a.depositions[i].col, b.depositions[i].col);
    EXPECT_EQ(a.depositions[i].height_m, b.depositions[i].height_m);
  }
  EXPECT_TRUE(a.deposits.empty());
}

TEST(Depositor, CubeColumnsStayUnderMarsWithinReachBudgetAndKeepOut) {
  const LocalMap map = ramp_map();
  const DepositionManager dm(params());
  const RobotType type = type_with("cube");
  const Position robot = kGrid.cell_center({10, 10});
  const DepositionPlan plan = make_depositor(type)->plan(dm, map, row_path(10, 10, 40), robot, 10.0, {1, robot, {}});
  ASSERT_FALSE(plan.deposits.empty());
  EXPECT_TRUE(plan.depositions.empty());
  double volume = 0.0;
  for (const Deposit& d : plan.deposits) {
    EXPECT_LE(dist(d.centre, robot), 1.5);
    const double cubes = d.volume_m3 / 0.001;
    EXPECT_NEAR(cubes, std::round(cubes), 1e-9);
    EXPECT_GE(std::round(cubes), 1.0);
    volume += d.volume_m3;
  }
  EXPECT_LE(volume, 0.02 + 1e-12);
  EXPECT_NEAR(plan.volume_m3, volume, 1e-15);
  const Heightmap h = after(map, plan, type);
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 0; c < kGrid.cols; ++c) {
      EXPECT_LE(h(r, c), map.gap(r, c) + 1e-12) << r << "," << c;  // never above the MARS height
      if (h(r, c) > 0.0) {
        EXPECT_GT(dist(kGrid.cell_center({r, c}), robot), 0.2);  // not under the robot
      }
    }
  // In path order: the first column stands on the first wanted cell (a cube's rise 0.1 m is wanted from column 15
  // on: 0.03 * 4 = 0.12 m), on the path's row.
  EXPECT_DOUBLE_EQ(plan.deposits[0].centre.x, kGrid.cell_center({10, 15}).x);
  EXPECT_DOUBLE_EQ(plan.deposits[0].centre.y, kGrid.cell_center({10, 15}).y);
}

TEST(Depositor, CubeRespectsMaterialAndStopsWhenNoCubeFits) {
  const DepositionManager dm(params());
  const RobotType type = type_with("cube");
  const Position robot = kGrid.cell_center({10, 10});
  const DepositionPlan three =
      make_depositor(type)->plan(dm, ramp_map(), row_path(10, 10, 40), robot, 0.0035, {1, robot, {}});
  double volume = 0.0;
  for (const Deposit& d : three.deposits) volume += d.volume_m3;
  EXPECT_NEAR(volume, 0.003, 1e-15);
  // Gaps below one cube's rise everywhere: nothing (the robot moves on instead of looping).
  const DepositionPlan none =
      make_depositor(type)->plan(dm, ramp_map(0.003), row_path(10, 10, 40), robot, 10.0, {1, robot, {}});
  EXPECT_FALSE(none.any());
}

TEST(Depositor, ConePilesStayUnderTheMarsHeightAndKeepOut) {
  const LocalMap map = ramp_map();
  const DepositionManager dm(params());
  const RobotType type = type_with("cone");
  const Position robot = kGrid.cell_center({10, 10});
  // A neighbour at (4, 20): nothing within 0.7 m of it may rise.
  Neighbour n;
  n.agent_id = 2;
  n.position.x = kGrid.cell_center({4, 20}).x;
  n.position.y = kGrid.cell_center({4, 20}).y;
  n.radius_m = 0.2;
  const DepositionPlan plan = make_depositor(type)->plan(dm, map, row_path(10, 10, 40), robot, 10.0, {1, robot, {n}});
  ASSERT_FALSE(plan.deposits.empty());
  ASSERT_LE(plan.deposits.size(), static_cast<std::size_t>(kMaxConesPerStep));
  double volume = 0.0;
  for (const Deposit& d : plan.deposits) {
    EXPECT_LE(dist(d.centre, robot), 1.5);
    volume += d.volume_m3;
  }
  EXPECT_LE(volume, 0.02 + 1e-12);
  const Heightmap h = after(map, plan, type);
  double under = 0.0, added = 0.0;
  for (int r = 0; r < kGrid.rows; ++r)
    for (int c = 0; c < kGrid.cols; ++c) {
      const double rise = h(r, c) - map.heights(r, c);
      if (!(rise > 0.0)) continue;
      EXPECT_LE(rise, map.gap(r, c) + 1e-9) << r << "," << c;
      EXPECT_GT(dist(kGrid.cell_center({r, c}), robot), 0.2);
      EXPECT_GT(dist(kGrid.cell_center({r, c}), n.position), 0.7);
      under += std::min(rise, map.gap(r, c)) * kCs * kCs;
      added += rise * kCs * kCs;
    }
  EXPECT_NEAR(added, volume, 1e-9 * volume);
  EXPECT_NEAR(under, added, 1e-9);  // all of it under the MARS height
}

TEST(Depositor, AConePileReachesTheMarsHeightOfItsDumpCellWhenTheBudgetAllows) {
  // The angle of repose (tan 34 deg = 0.67) is steeper than the gap grows (0.3 per metre): a pile whose apex stands at
  // its dump cell's MARS height stays under the MARS height everywhere, and a bigger one would not.
  DepositionParams big = params();
  big.max_deposit_m3 = 1.0;
  const DepositionManager dm(big);
  const LocalMap map = ramp_map();
  const Position robot = kGrid.cell_center({10, 10});
  const DepositionPlan plan =
      make_depositor(type_with("cone"))->plan(dm, map, row_path(10, 10, 40), robot, 10.0, {1, robot, {}});
  ASSERT_FALSE(plan.deposits.empty());
  const Deposit& first = plan.deposits.front();
  const std::optional<CellIndex> dump = map.cell_at(first.centre);
  ASSERT_TRUE(dump);
  const DepositShape shape = cone_pile_shape(map.heights, first.centre, first.volume_m3, 34.0);
  double at_dump = 0.0;
  for (const CellRise& r : shape.rises) {
    EXPECT_LE(r.rise_m, map.gap(r.cell) + 1e-9) << r.cell.row << "," << r.cell.col;
    if (r.cell == *dump) at_dump = r.rise_m;
  }
  EXPECT_GT(map.gap(*dump), 0.0);
  EXPECT_NEAR(at_dump, map.gap(*dump), 1e-5);
}

// On a scanned map the cells a pile may not raise (here under the robot and around a neighbour) read within noise, and
// the world settles the pile on the truth. With pile_margin_m the piles planned on the map leave those cells unraised
// even where the truth lies the margin lower there; without it, the same check finds a pile that reaches one.
TEST(Depositor, ConePilesStayClearOfCellsTheyMayNotRaiseByTheMarginOfAScannedMap) {
  const RobotType type = type_with("cone");
  const Position robot = kGrid.cell_center({10, 10});
  Neighbour n;
  n.agent_id = 2;
  n.position = kGrid.cell_center({7, 16});
  n.radius_m = 0.2;
  const Neighbourhood around{1, robot, {n}};
  // A gap everywhere, so piles press against the cells kept clear.
  const LocalMap map =
      test::make_local_map(Heightmap(kGrid, 0.0), Heightmap(kGrid, 0.25), params().navigability, {10, 10}, {{10, 0}});
  // The truth: every cell the robot may not raise lies `low_m` under the map's reading. How many of them the plan's
  // piles raise there.
  const auto reached = [&](double margin_m, double low_m) {
    DepositionParams p = params();
    p.max_deposit_m3 = 0.5;
    p.pile_margin_m = margin_m;
    const DepositionManager dm(p);
    const DepositionPlan plan = make_depositor(type)->plan(dm, map, row_path(10, 10, 40), robot, 10.0, around);
    EXPECT_FALSE(plan.deposits.empty());
    const double clear_m = dm.clearance_m(map, robot);
    CellMask kept(kGrid.rows, kGrid.cols);
    kept.setZero();
    LocalMap truth = map;
    for (int r = 0; r < kGrid.rows; ++r)
      for (int c = 0; c < kGrid.cols; ++c)
        if (!dm.may_raise(map, {r, c}, robot, around, clear_m)) {
          kept(r, c) = 1;
          truth.heights(r, c) -= low_m;
        }
    const Heightmap h = after(truth, plan, type);
    int cells = 0;
    for (int r = 0; r < kGrid.rows; ++r)
      for (int c = 0; c < kGrid.cols; ++c)
        if (kept(r, c) != 0 && h(r, c) > truth.heights(r, c)) ++cells;
    return cells;
  };
  EXPECT_EQ(reached(0.0, 0.0), 0);    // the map is the truth: nothing reached
  EXPECT_GT(reached(0.0, 0.01), 0);   // the truth 1 cm lower there: a pile planned without a margin reaches one
  EXPECT_EQ(reached(0.01, 0.01), 0);  // with the margin none
  EXPECT_EQ(reached(0.02, 0.015), 0);
}

TEST(Depositor, ConeRespectsMaterialAndStopsOnShallowGaps) {
  const DepositionManager dm(params());
  const RobotType type = type_with("cone");
  const Position robot = kGrid.cell_center({10, 10});
  const DepositionPlan little =
      make_depositor(type)->plan(dm, ramp_map(), row_path(10, 10, 40), robot, 0.001, {1, robot, {}});
  double volume = 0.0;
  for (const Deposit& d : little.deposits) volume += d.volume_m3;
  EXPECT_GT(volume, 0.0);
  EXPECT_LE(volume, 0.001 + 1e-15);
  // No gap at all: nothing to do.
  LocalMap flat = ramp_map(0.0);
  EXPECT_FALSE(make_depositor(type)->plan(dm, flat, row_path(10, 10, 40), robot, 10.0, {1, robot, {}}).any());
}

}  // namespace
}  // namespace marsala::agent::executive
