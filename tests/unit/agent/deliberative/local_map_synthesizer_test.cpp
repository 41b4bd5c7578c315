#include "marsala/agent/deliberative/local_map_synthesizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigable_path_planner.hpp"
#include "marsala/core/ray_caster.hpp"
#include "support/mars_brute_force.hpp"
#include "support/navigability_brute_force.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::deliberative {
namespace {

// 60 rows x 80 cols at 0.1 m, lower-left corner (0, 0): cell (r, c) has its centre at
// x = 0.1 c + 0.05, y = 0.1 (59 - r) + 0.05.
const GridGeometry kWorld{60, 80, 0.0, 0.0, 0.1};
const NavigabilityParams kBody{0.5, 0.4, 0.05};
const Position kRobot{4.05, 2.95};  // cell (30, 40)

TEST(SensingWindow, IsTheSquareClippedToTheGrid) {
  // Square [3.05, 5.05] x [1.95, 3.95]: cols 30..50, rows 20..40 (hand-derived from the cell formula).
  const Window w = sensing_window(kWorld, kRobot, 1.0);
  EXPECT_EQ(w.top_left, (CellIndex{20, 30}));
  EXPECT_EQ(w.rows, 21);
  EXPECT_EQ(w.cols, 21);
  // In the south-west corner: [-0.95, 1.05]^2 clipped to cols 0..10, rows 49..59.
  const Window corner = sensing_window(kWorld, {0.05, 0.05}, 1.0);
  EXPECT_EQ(corner.top_left, (CellIndex{49, 0}));
  EXPECT_EQ(corner.rows, 11);
  EXPECT_EQ(corner.cols, 11);
  // A range wider than the grid: the whole grid.
  const Window all = sensing_window(kWorld, kRobot, 100.0);
  EXPECT_EQ(all.top_left, (CellIndex{0, 0}));
  EXPECT_EQ(all.rows, 60);
  EXPECT_EQ(all.cols, 80);
  EXPECT_THROW(sensing_window(kWorld, {-0.01, 1.0}, 1.0), InvalidArgument);
  EXPECT_THROW(sensing_window(kWorld, kRobot, -1.0), InvalidArgument);
}

Heightmap bumpy_terrain() {
  Heightmap h(kWorld, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) h(r, c) = 0.01 * ((r * 7 + c * 3) % 5);
  for (int r = 25; r < 28; ++r)
    for (int c = 44; c < 47; ++c) h(r, c) = 0.6;  // a block north-east of the robot
  return h;
}

TEST(LocalMapSynthesizer, WindowGapAndNavigabilityMatchReferences) {
  const Heightmap h = bumpy_terrain();
  executive::MappingSystem map = test::full_map(h);
  map.record_pose(kRobot);
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  const LocalMap local = synthesizer.synthesize(map.known_map(), kRobot, {4.55, 2.95});
  EXPECT_EQ(local.offset, (CellIndex{20, 30}));
  ASSERT_EQ(local.rows(), 21);
  ASSERT_EQ(local.cols(), 21);
  EXPECT_EQ(local.robot, (CellIndex{10, 10}));
  EXPECT_EQ(local.to_global(local.robot), (CellIndex{30, 40}));
  const Heightmap expected = h.window({20, 30}, 21, 21);
  EXPECT_TRUE(local.heights.heights() == expected.heights());
  EXPECT_EQ(local.geometry(), expected.geometry());
  // The gap and the masks against the brute-force references on the window alone.
  const Heightmap p = testing::mars_brute_force(expected, kBody.kappa);
  for (int r = 0; r < 21; ++r)
    for (int c = 0; c < 21; ++c) EXPECT_NEAR(local.gap(r, c), p(r, c) - expected(r, c), 1e-9);
  EXPECT_TRUE(local.occupiable == testing::occupiable_brute_force(expected, kBody));
  EXPECT_TRUE(local.navigable == testing::navigable_brute_force(expected, kBody, {10, 10}));
  EXPECT_EQ(local.blind.cast<int>().sum(), 0);
  // The block is not occupiable, so the navigable region has a hole.
  EXPECT_EQ(local.occupiable(6, 15), 0);
  EXPECT_GT(local.navigable.cast<int>().sum(), 300);
}

// One synthesizer asked again and again, as a robot's is each step: the same window, a window whose heights changed
// by one deposit, a window moved by one cell. Each answer is the brute-force reference of its own window, never the
// answer kept from the window before.
TEST(LocalMapSynthesizer, AWindowAskedAgainGivesItsOwnGapAfterADepositOrAMove) {
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  const Position target{4.55, 2.95};
  const auto check = [&](const Heightmap& terrain, Position robot, const char* what) {
    SCOPED_TRACE(what);
    executive::MappingSystem map = test::full_map(terrain);
    map.record_pose(robot);
    const LocalMap local = synthesizer.synthesize(map.known_map(), robot, target);
    const Heightmap window = terrain.window(local.offset, local.rows(), local.cols());
    const Heightmap p = testing::mars_brute_force(window, kBody.kappa);
    for (int r = 0; r < local.rows(); ++r)
      for (int c = 0; c < local.cols(); ++c) ASSERT_NEAR(local.gap(r, c), p(r, c) - window(r, c), 1e-9);
    EXPECT_TRUE(local.occupiable == testing::occupiable_brute_force(window, kBody));
  };
  Heightmap h = bumpy_terrain();
  check(h, kRobot, "first");
  check(h, kRobot, "the same window again");
  h(31, 41) += 0.3;  // a deposit beside the robot: the window holds the same cells, one of them higher
  check(h, kRobot, "after a deposit");
  check(h, {4.15, 2.95}, "moved one cell east");
  check(bumpy_terrain(), {4.15, 2.95}, "the deposit gone, same place");
}

// A robot's synthesizer keeps the occupiable cells of its last window and judges again only the cells whose balls
// moved across a window edge or hold a changed height. Along a random walk (steps of one cell, jumps, the grid's
// corners, where the window is clipped) on terrain full of ties (ramps at exactly slope kappa with steps of exactly
// eps) with random deposits, every window's mask is the processor's on that window alone.
TEST(LocalMapSynthesizer, OccupiableAfterAMoveOrADepositIsTheProcessorsOnTheNewWindow) {
  std::mt19937 rng(5);
  Heightmap h = bumpy_terrain();
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c)
      if ((r / 10 + c / 10) % 3 == 0)  // ramps east at slope kappa, a step of eps every 5 columns
        h(r, c) = kBody.kappa * 0.1 * (c % 10) + ((c % 10) >= 5 ? kBody.eps_m : 0.0);
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  int row = 30, col = 40, not_occupiable = 0;
  for (int step = 0; step < 400; ++step) {
    const int move = static_cast<int>(rng() % 10);
    if (move < 6) {  // a step to one of the 8 neighbours
      row = std::clamp(row + static_cast<int>(rng() % 3) - 1, 0, h.rows() - 1);
      col = std::clamp(col + static_cast<int>(rng() % 3) - 1, 0, h.cols() - 1);
    } else if (move == 6) {  // a jump, now and then to a corner
      row = rng() % 2 ? static_cast<int>(rng() % h.rows()) : (rng() % 2 ? 0 : h.rows() - 1);
      col = rng() % 2 ? static_cast<int>(rng() % h.cols()) : (rng() % 2 ? 0 : h.cols() - 1);
    }
    if (rng() % 3 == 0) {  // a deposit near the robot: one cube layer, or a kappa step
      const int r = std::clamp(row + static_cast<int>(rng() % 7) - 3, 0, h.rows() - 1);
      const int c = std::clamp(col + static_cast<int>(rng() % 7) - 3, 0, h.cols() - 1);
      h(r, c) += rng() % 2 ? 0.1 : kBody.kappa * 0.1;
    }
    const Position robot = kWorld.cell_center({row, col});
    executive::MappingSystem map = test::full_map(h);
    map.record_pose(robot);
    const LocalMap local = synthesizer.synthesize(map.known_map(), robot, {4.55, 2.95});
    const Heightmap window = h.window(local.offset, local.rows(), local.cols());
    const CellMask expected = NavigabilityProcessor(kBody).occupiable(window);
    ASSERT_TRUE(local.heights_occupiable == expected) << "step " << step << " at row " << row << ", col " << col;
    not_occupiable += static_cast<int>(expected.size() - expected.cast<int>().sum());
  }
  EXPECT_GT(not_occupiable, 4000);  // many cells along the way were not occupiable: not only flat ground
}

TEST(LocalMapSynthesizer, OccupiableIsTheWorldsSingleCellAnswer) {
  // A ramp at exactly slope kappa with a step of exactly eps halfway, beside the bumps and the block: the pairs across
  // the step are ties (|dh| = eps + kappa |r - q|). The agent judges each cell of its window as the world judges one
  // cell (core cell_occupiable) on the same heights, and a cell whose ball lies inside the window as the world judges
  // it on the whole terrain.
  Heightmap h = bumpy_terrain();
  for (int r = 30; r < 40; ++r)
    for (int c = 30; c < 40; ++c) h(r, c) = kBody.kappa * 0.1 * (c - 30) + (c >= 35 ? kBody.eps_m : 0.0);
  executive::MappingSystem map = test::full_map(h);
  map.record_pose(kRobot);
  const LocalMap local = LocalMapSynthesizer(kBody, 1.0).synthesize(map.known_map(), kRobot, {4.55, 2.95});
  const int ball = 2;  // delta / 2 = 0.2 m = 2 cells
  int inside = 0, not_occupiable = 0;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const bool agent = local.occupiable(r, c) != 0;
      EXPECT_EQ(agent, cell_occupiable(local.heights, {r, c}, kBody, OccupancyMethod::kPairs)) << r << ", " << c;
      not_occupiable += !agent;
      if (r < ball || c < ball || r >= local.rows() - ball || c >= local.cols() - ball) continue;
      ++inside;
      EXPECT_EQ(agent, cell_occupiable(h, local.to_global({r, c}), kBody)) << r << ", " << c;
    }
  EXPECT_EQ(inside, 17 * 17);
  EXPECT_GT(not_occupiable, 10);  // the block and the bumps' steps are judged, not only flat ground
}

TEST(LocalMapSynthesizer, LocalGoalIsTheTargetInsideOrWhereTheLineLeaves) {
  const executive::MappingSystem map = test::full_map(Heightmap(kWorld, 0.0));
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  // Inside: the target's own cell (32, 45).
  LocalMap local = synthesizer.synthesize(map.known_map(), kRobot, {4.55, 2.75});
  EXPECT_EQ(local.to_global(local.goal), (CellIndex{32, 45}));
  EXPECT_TRUE(local.goal_is_target);
  // Due east and off the grid: the line leaves at x = 5.05 on the robot's row -> (30, 50).
  local = synthesizer.synthesize(map.known_map(), kRobot, {10.0, 2.95});
  EXPECT_EQ(local.to_global(local.goal), (CellIndex{30, 50}));
  EXPECT_FALSE(local.goal_is_target);
  // East-north-east: dx = 3, dy = 1.5 leaves the east side at t = 1/3, y = 3.45 -> row 59 - 34 = 25.
  local = synthesizer.synthesize(map.known_map(), kRobot, {7.05, 4.45});
  EXPECT_EQ(local.to_global(local.goal), (CellIndex{25, 50}));
  // Due south-west through the corner of the window: (40, 30).
  local = synthesizer.synthesize(map.known_map(), kRobot, {2.05, 0.95});
  EXPECT_EQ(local.to_global(local.goal), (CellIndex{40, 30}));
  // A target on a cell boundary maps through the world grid: x = 4.5 lies in col 45 for the world.
  local = synthesizer.synthesize(map.known_map(), kRobot, {4.5, 2.95});
  EXPECT_EQ(local.to_global(local.goal), *kWorld.cell_at({4.5, 2.95}));
}

TEST(LocalMapSynthesizer, LocalOriginIsTheTrajectoryCellNearestTheBoundary) {
  Heightmap h(kWorld, 0.0);
  executive::MappingSystem map = test::full_map(h);
  // Came from the west along row 30 (cols 10 .. 40); in the window: cols 30 .. 40; col 30 lies on the square's
  // west side (x = 3.05 = 4.05 - 1).
  for (int c = 10; c <= 40; ++c) map.record_pose(kWorld.cell_center({30, c}));
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  LocalMap local = synthesizer.synthesize(map.known_map(), kRobot, {7.0, 2.95});
  ASSERT_TRUE(local.origin.has_value());
  EXPECT_EQ(local.to_global(*local.origin), (CellIndex{30, 30}));

  // A tie (the square's north side, row 20, is as near as its west side): the older cell wins.
  executive::MappingSystem tie = test::full_map(h);
  tie.record_pose(kWorld.cell_center({20, 40}));
  tie.record_pose(kWorld.cell_center({30, 30}));
  tie.record_pose(kRobot);
  local = synthesizer.synthesize(tie.known_map(), kRobot, {7.0, 2.95});
  EXPECT_EQ(local.to_global(*local.origin), (CellIndex{20, 40}));

  // A wall across row 30 at cols 33..34 (and rows 20..40) cuts cols 30..32 off: the nearest navigable cell wins.
  for (int r = 0; r < 60; ++r)
    for (int c = 33; c <= 34; ++c) h(r, c) = 2.0;
  executive::MappingSystem walled = test::full_map(h);
  for (int c = 10; c <= 40; ++c) walled.record_pose(kWorld.cell_center({30, c}));
  local = synthesizer.synthesize(walled.known_map(), kRobot, {7.0, 2.95});
  ASSERT_TRUE(local.origin.has_value());
  EXPECT_EQ(local.navigable(local.origin->row, local.origin->col), 1);
  // Col 37 is the first east of the wall whose ball (radius 2 cells) holds no wall cell.
  EXPECT_EQ(local.to_global(*local.origin), (CellIndex{30, 37}));
}

TEST(LocalMapSynthesizer, UnknownCellsAreNeverOccupiableNorTargets) {
  const Heightmap h(kWorld, 0.3);
  executive::MappingSystem map(kWorld, 16);
  // Only tile columns 2 and 3 (cols 32..63) of tile rows 1 and 2 (rows 16..47) are known.
  for (int tr = 1; tr <= 2; ++tr)
    for (int tc = 2; tc <= 3; ++tc) map.integrate_tile(test::cut_tile(h, 16, tr, tc));
  map.record_pose(kRobot);
  const LocalMapSynthesizer synthesizer(kBody, 1.0);
  const LocalMap local = synthesizer.synthesize(map.known_map(), kRobot, {7.0, 2.95});
  // Window cols 30..50: cols 30, 31 unknown. Ball radius 2 cells: cols 30..33 are blind.
  for (int r = 0; r < local.rows(); ++r) {
    for (int c = 0; c < local.cols(); ++c) {
      const bool known = local.to_global({r, c}).col >= 32;
      EXPECT_EQ(local.known(r, c), known ? 1 : 0);
      if (!known) {
        EXPECT_EQ(local.gap(r, c), 0.0);
      }
      if (c <= 3) {
        EXPECT_EQ(local.occupiable(r, c), 0) << r << ", " << c;
      }
    }
  }
  EXPECT_EQ(local.blind(10, 3), 1);
  EXPECT_EQ(local.blind(10, 4), 0);
  EXPECT_EQ(local.occupiable(10, 4), 1);
  // Unknown cells take the lowest known height (0.3): no MARS gap appears on flat known ground.
  EXPECT_EQ(local.gap.heights().maxCoeff(), 0.0);
}

// A map from one laser scan has holes everywhere (between the rings, behind the block): no unknown cell is ever
// occupiable or navigable, nor any cell whose body ball holds one, and the planner routes around unknown cells and
// never ends on one, even when unknown cells are the shorter way.
TEST(LocalMapSynthesizer, ScannedMapsNeverLetTheRobotOntoUnknownCells) {
  const Heightmap h = bumpy_terrain();
  executive::MappingSystem map(kWorld, 16, sensor_defaults(SensorKind::kLaser));
  const Point3 origin = sensor_origin(h, kRobot.x, kRobot.y, map.sensor());
  map.integrate_scan(cast_scan(h, origin, 0.0, map.sensor(), 3), origin);
  map.assume_ground(kRobot, h(30, 40), 0.5 * kBody.delta_m);  // as the behaviours do: it stands there
  map.record_pose(kRobot);
  ASSERT_GT(map.known_cells(), 500);
  ASSERT_LT(map.known_cells(), kWorld.size());
  const LocalMapSynthesizer synthesizer(kBody, 2.5);
  const LocalMap local = synthesizer.synthesize(map.known_map(), kRobot, {7.0, 2.95});
  const auto ball = disc_offsets(kBody.delta_m / (2.0 * kWorld.cell_size_m));
  long long unknown = 0, navigable = 0;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      bool sees_unknown = false;
      for (const CellIndex o : ball) {
        const CellIndex q{r + o.row, c + o.col};
        sees_unknown = sees_unknown || (local.contains(q) && local.known(q.row, q.col) == 0);
      }
      unknown += local.known(r, c) == 0;
      navigable += local.navigable(r, c);
      if (sees_unknown) {
        EXPECT_EQ(local.occupiable(r, c), 0) << r << ", " << c;
        EXPECT_EQ(local.navigable(r, c), 0) << r << ", " << c;
      }
    }
  EXPECT_GT(unknown, 0);
  EXPECT_GT(navigable, 0);

  // The planner takes the known cells as its allowed cells: every path cell is known, and an unknown goal is
  // never reached.
  const NavigablePathPlanner planner(default_planner_params(kBody.delta_m, kWorld.cell_size_m));
  for (int r = 0; r < local.rows(); r += 3)
    for (int c = 0; c < local.cols(); c += 3) {
      const PlannerResult plan = planner.plan(local.gap, local.known, local.robot, {r, c});
      if (local.known(r, c) == 0) {
        EXPECT_FALSE(plan.found) << r << ", " << c;
      }
      for (const CellIndex p : plan.path) EXPECT_EQ(local.known(p.row, p.col), 1) << r << ", " << c;
    }
}

// A robot whose own cell is not occupiable in its map (a 0.5 m column read beside it): the world lets it drive out of
// its cell (docs/runtime.md#rule-2-motion). On a scanned map its cell counts as occupiable, so the cells around it stay
// navigable and it can leave; on a ground-truth map (exact: the world judges the same cells) it is left as it is.
TEST(LocalMapSynthesizer, AScannedMapKeepsTheRobotsWayOutOfItsOwnCell) {
  Heightmap h(kWorld, 0.0);
  h(30, 41) = 0.5;  // in the robot's ball (delta 0.4 m: 2 cells), a step far beyond eps + kappa cs
  const CellMask known = CellMask::Ones(kWorld.rows, kWorld.cols);
  const CellMask assumed = CellMask::Zero(kWorld.rows, kWorld.cols);
  const std::vector<CellIndex> trajectory{{30, 40}};
  ASSERT_FALSE(cell_occupiable(h, {30, 40}, kBody));
  const LocalMapSynthesizer synthesizer(kBody, 2.5);
  for (const bool scanned : {true, false}) {
    const LocalMap local =
        synthesizer.synthesize({h, known, assumed, assumed, trajectory, scanned}, kRobot, {7.0, 2.95});
    EXPECT_EQ(local.occupiable(local.robot.row, local.robot.col), scanned ? 1 : 0);
    const CellIndex west{local.robot.row, local.robot.col - 3};  // occupiable ground beside the robot's ball
    ASSERT_EQ(local.occupiable(west.row, west.col), 1);
    EXPECT_EQ(local.navigable(west.row, west.col), scanned ? 1 : 0);
  }
}

// A cell the robot stood on was occupiable (the world put its body there): a scanned map keeps it so while its ball
// reads as it did then, within the margin, even where its readings break the rule by a few mm. Before, a step read 1
// cm above eps + kappa cs walled a laser robot in on an island of its own map, and its depositions closed the true way
// down.
TEST(LocalMapSynthesizer, AScannedMapKeepsTheCellsItStoodOnWhileTheirBallsReadTheSame) {
  Heightmap h(kWorld, 0.0);
  // West of the robot, cell (30, 36) holds in its ball (radius 2 cells) a step of 0.11 m between (30, 37) and
  // (30, 38): 0.01 m more than eps + kappa cs (0.05 + 0.05).
  for (int r = 0; r < kWorld.rows; ++r)
    for (int c = 38; c < kWorld.cols; ++c) h(r, c) = 0.11;
  const CellIndex stood{30, 36};
  ASSERT_FALSE(cell_occupiable(h, stood, kBody));
  const CellMask known = CellMask::Ones(kWorld.rows, kWorld.cols);
  const CellMask none = CellMask::Zero(kWorld.rows, kWorld.cols);
  const std::vector<CellIndex> trajectory{stood, {30, 40}};
  // The ball as the map read it when the robot stood there: 0.1 m at the step, within the margin of 0.11.
  StoodCells cells;
  cells.ball = disc_offsets(2.0);
  cells.margin_m = 0.015;
  std::vector<double> then;
  for (const CellIndex o : disc_offsets(2.0)) then.push_back(stood.col + o.col >= 38 ? 0.10 : 0.0);
  cells.balls[static_cast<long long>(stood.row) * kWorld.cols + stood.col] = then;
  const LocalMapSynthesizer synthesizer(kBody, 2.5);
  const auto occupiable_at = [&](const Heightmap& heights, bool scanned, const StoodCells* with) {
    const LocalMap local = synthesizer.synthesize({heights, known, none, none, trajectory, scanned, with}, kRobot,
                                                  {7.0, 2.95});
    return local.occupiable(local.to_local(stood).row, local.to_local(stood).col);
  };
  EXPECT_EQ(occupiable_at(h, true, nullptr), 0);
  EXPECT_EQ(occupiable_at(h, true, &cells), 1);
  EXPECT_EQ(occupiable_at(h, false, &cells), 0);  // an exact map is the truth: nothing kept against it
  // A ball cell raised beyond the margin since (0.13 m read, 0.10 then): the fact is gone.
  Heightmap raised = h;
  raised(30, 38) = 0.13;
  EXPECT_EQ(occupiable_at(raised, true, &cells), 0);
}

// A bound (faces seen from below, no surface read) lying below both its neighbours along a grid axis is a notch in
// that line: its MARS gap counts, capped at its notch level (the higher over the two axes of the lower neighbour of
// the pair), and the map's noise margin shrinks the MARS gap, not that cap. Before, only a bound below all four
// neighbours was filled, up to the lowest of them less the margin: a notch on a ramp's edge (beside the ground) and a
// two-cell dip were never filled, and a pit on a slope stopped a margin under its downhill rim, too deep for the body
// between it and its uphill neighbour.
TEST(LocalMapSynthesizer, ABoundInANotchIsFilledUpToItsNotchLevel) {
  // A slope rising east by 0.05 m a cell, exactly kappa (0.5) steep: its MARS height is itself, 0.05 c at column c.
  Heightmap h(kWorld, 0.0);
  for (int r = 0; r < kWorld.rows; ++r)
    for (int c = 0; c < kWorld.cols; ++c) h(r, c) = 0.05 * c;
  const CellMask known = CellMask::Ones(kWorld.rows, kWorld.cols);
  CellMask assumed = CellMask::Zero(kWorld.rows, kWorld.cols), bound = assumed;
  const CellIndex pit{30, 45}, edge{20, 45}, dip_west{40, 45}, dip_east{40, 46}, wall{30, 60}, guess{10, 45};
  for (const CellIndex c : {pit, edge, dip_west, dip_east, wall, guess}) h(c) -= 0.10, assumed(c.row, c.col) = 1;
  for (const CellIndex c : {pit, edge, dip_west, dip_east, wall}) bound(c.row, c.col) = 1;
  h(edge.row - 1, edge.col) = 0.0;                        // the ground beside a ramp's edge, north of it
  h(wall.row, wall.col - 1) = h(wall.row - 1, wall.col) = 0.0;  // a wall's corner: ground west and north
  const std::vector<CellIndex> trajectory{{30, 40}};
  const LocalMapSynthesizer synthesizer(kBody, 2.5);
  const LocalMap local = synthesizer.synthesize({h, known, assumed, bound, trajectory, true}, kRobot, {7.0, 2.95});
  const auto at = [&](CellIndex c) { return local.to_local(c); };
  const auto gap = [&](CellIndex c) { return local.gap(at(c)); };
  const auto rise = [&](CellIndex c, double margin_m) { return rise_wanted_m(local, at(c), margin_m); };
  // Hand-derived (heights 0.05 c, each cell above 0.10 m under its own): every notch's MARS gap is 0.10 m.
  // pit (45): west 2.20, east 2.30, north and south 2.25: notch level max(2.20, 2.25) = 2.25, a cap of 0.10 m (the
  // lowest rim gave 0.05 m). edge: north 0 m, so only east-west counts: 2.20, a cap of 0.05 m (no pit before: 0).
  // The dip: west cell between 2.20 (west) and its partner at 2.20, north-south 2.25: 0.10 m; east cell between its
  // partner at 2.15 and 2.35, north-south 2.30: 0.10 m (before: 0.05 m and none). The wall's corner (ground on two
  // sides) and the assumed ground get none.
  for (const CellIndex c : {pit, edge, dip_west, dip_east}) EXPECT_NEAR(gap(c), 0.10, 1e-9) << c.row << ", " << c.col;
  EXPECT_NEAR(local.fill_cap(at(pit)), 0.10, 1e-9);
  EXPECT_NEAR(local.fill_cap(at(edge)), 0.05, 1e-9);
  EXPECT_NEAR(local.fill_cap(at(dip_west)), 0.10, 1e-9);
  EXPECT_NEAR(local.fill_cap(at(dip_east)), 0.10, 1e-9);
  for (const CellIndex c : {wall, guess}) {
    EXPECT_EQ(gap(c), 0.0) << c.row << ", " << c.col;
    EXPECT_FALSE(rise(c, 0.0) > 0.0) << c.row << ", " << c.col;
  }
  // A margin of 0.04 m: the MARS gap less it (0.06 m) where the cap is wider, the whole cap (0.05 m) on the edge.
  EXPECT_NEAR(rise(pit, 0.04), 0.06, 1e-9);
  EXPECT_NEAR(rise(edge, 0.04), 0.05, 1e-9);
  EXPECT_NEAR(notch_fill({h, known, assumed, bound, trajectory, true}, edge), 0.05, 1e-9);
  // The same cells as surfaces read: their full MARS gaps, no cap.
  const CellMask none = CellMask::Zero(kWorld.rows, kWorld.cols);
  const LocalMap read = synthesizer.synthesize({h, known, none, none, trajectory, true}, kRobot, {7.0, 2.95});
  EXPECT_EQ(read.fill_cap.rows(), 0);
  EXPECT_NEAR(read.gap(read.to_local(guess)), 0.10, 1e-9);
  EXPECT_NEAR(rise_wanted_m(read, read.to_local(edge), 0.04), 0.06, 1e-9);
}

// A scanned map whose goal (where the line to the target leaves the window) cannot be judged yet: a hole in the
// known corridor lies within its body ball. The robot heads for the nearest known cell that can be judged and
// reaches it through such cells only (LocalMap::passable); before, it followed the blind cells along the edge of its
// knowledge, where a structure's side hides what lies beyond and the robot stalled.
TEST(LocalMapSynthesizer, AScannedMapsGoalAndPathAvoidCellsItCannotJudge) {
  executive::MappingSystem map(kWorld, 16, sensor_defaults(SensorKind::kLaser));
  // Known flat ground (assumed, which marks cells known): the corridor rows 27..33, cols 25..79, but cell (31, 64).
  for (int r = 27; r <= 33; ++r)
    for (int c = 25; c < 80; ++c)
      if (!(r == 31 && c == 64)) map.assume_ground(kWorld.cell_center({r, c}), 0.0, 0.0);
  map.record_pose(kRobot);
  const LocalMapSynthesizer synthesizer(kBody, 2.5);  // ball radius 2 cells; window cols 15..65
  const LocalMap local =
      synthesizer.synthesize(map.known_map(), kRobot, {7.05, 2.95});  // the target (30, 70), off the window
  const CellIndex exit = local.to_local({30, 65});
  ASSERT_EQ(local.blind(exit.row, exit.col), 1);  // (31, 64) lies within its ball
  // Judged cells reachable through judged cells end before the hole: (29, 64), (30, 63) and (31, 63) hold it in
  // their balls, (28, 64) the unknown row 26. The nearest of them to the exit cell: (29, 63), d^2 = 5.
  EXPECT_EQ(local.to_global(local.goal), (CellIndex{29, 63}));
  EXPECT_FALSE(local.goal_is_target);
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      EXPECT_EQ(local.passable(r, c), local.known(r, c) != 0 && local.blind(r, c) == 0) << r << ", " << c;
  const NavigablePathPlanner planner(default_planner_params(kBody.delta_m, kWorld.cell_size_m));
  const PlannerResult plan = planner.plan(local.gap, local.passable, local.robot, local.goal);
  ASSERT_TRUE(plan.found);
  for (const CellIndex p : plan.path) EXPECT_EQ(local.blind(p.row, p.col), 0) << p.row << ", " << p.col;

  // Known ground only as far as the robot's own body ball (radius 2 cells): every other cell is blind, and the robot's
  // own cell is the only judged one. The goal is then the known cell nearest the exit, reached through known cells
  // (before, the robot's own cell: it stood still, "at its goal").
  executive::MappingSystem small(kWorld, 16, sensor_defaults(SensorKind::kLaser));
  for (const CellIndex o : disc_offsets(2.0))
    small.assume_ground(kWorld.cell_center({30 + o.row, 40 + o.col}), 0.0, 0.0);
  const LocalMap boxed = synthesizer.synthesize(small.known_map(), kRobot, {7.05, 2.95});
  ASSERT_EQ(boxed.blind(boxed.robot.row, boxed.robot.col), 0);
  EXPECT_EQ(boxed.to_global(boxed.goal), (CellIndex{30, 42}));
  EXPECT_EQ(boxed.passable, boxed.known);

  // A ground-truth map is whole: the goal is the exit cell and every known cell is passable.
  executive::MappingSystem exact(kWorld, 16);
  for (int r = 27; r <= 33; ++r)
    for (int c = 25; c < 80; ++c) exact.assume_ground(kWorld.cell_center({r, c}), 0.0, 0.0);
  const LocalMap whole = synthesizer.synthesize(exact.known_map(), kRobot, {7.05, 2.95});
  EXPECT_EQ(whole.to_global(whole.goal), (CellIndex{30, 65}));
  EXPECT_EQ(whole.passable, whole.known);
}

// A scanned map whose judged cells bring the robot less than a body radius nearer its goal, where known cells lead
// on: the robot heads along the known cells. Before, the judged cell one step ahead was the goal; standing there, the
// judged cells held nothing nearer and the known cells' path was taken, and from the next cell the judged one was
// nearer again: a laser robot shuttled between two cells at a ramp's head for 5000 steps.
TEST(LocalMapSynthesizer, AScannedMapsJudgedCellsLeadTheRobotOnlyWhenTheyBringItABodyRadiusNearer) {
  executive::MappingSystem map(kWorld, 16, sensor_defaults(SensorKind::kLaser));
  // Known ground: the balls (radius 2 cells) of (30, 40) and (30, 41), and a ring's line of hits (30, 43..65). Judged
  // (no unknown cell in the ball): (30, 40) and (30, 41) only.
  for (const int col : {40, 41})
    for (const CellIndex o : disc_offsets(2.0))
      map.assume_ground(kWorld.cell_center({30 + o.row, col + o.col}), 0.0, 0.0);
  for (int c = 43; c <= 65; ++c) map.assume_ground(kWorld.cell_center({30, c}), 0.0, 0.0);
  const LocalMapSynthesizer synthesizer(kBody, 2.5);  // ball radius 2 cells; window cols 15..65 around (30, 40)
  for (const CellIndex robot : {CellIndex{30, 40}, CellIndex{30, 41}}) {
    const LocalMap local = synthesizer.synthesize(map.known_map(), kWorld.cell_center(robot), {7.05, 2.95});
    ASSERT_EQ(local.blind(local.robot.row, local.robot.col), 0) << robot.col;
    // The known cell nearest where the line to the target leaves the window ((30, 65) or (30, 66)), through known cells.
    EXPECT_EQ(local.to_global(local.goal), (CellIndex{30, 65})) << robot.col;
    EXPECT_EQ(local.passable, local.known) << robot.col;
  }
  // Judged cells up to (30, 43) (the balls of (30, 40..43) known): three cells nearer than the robot at (30, 40), more
  // than the radius (2): the judged cells lead, and the path runs through them only.
  executive::MappingSystem wider(kWorld, 16, sensor_defaults(SensorKind::kLaser));
  for (int col = 40; col <= 43; ++col)
    for (const CellIndex o : disc_offsets(2.0))
      wider.assume_ground(kWorld.cell_center({30 + o.row, col + o.col}), 0.0, 0.0);
  for (int c = 46; c <= 65; ++c) wider.assume_ground(kWorld.cell_center({30, c}), 0.0, 0.0);
  const LocalMap judged = synthesizer.synthesize(wider.known_map(), kRobot, {7.05, 2.95});
  EXPECT_EQ(judged.to_global(judged.goal), (CellIndex{30, 43}));
  EXPECT_NE(judged.passable, judged.known);
}

}  // namespace
}  // namespace marsala::agent::deliberative
