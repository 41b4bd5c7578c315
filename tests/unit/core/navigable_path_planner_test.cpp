#include "marsala/core/navigable_path_planner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala {
namespace {

// Hand-made gap maps on 11 x 11 cells of 0.1 m; body length 0.2 m, so the footprint ball is the plus sign of 5
// cells: (0,0), (+-1,0), (0,+-1).
const GridGeometry kGrid{11, 11, 0.0, 0.0, 0.1};
const CellMask kAll = CellMask::Ones(11, 11);

PlannerParams params(double alpha, double beta = 1.0) { return {alpha, beta, 0.2}; }

/// A wall of gap 1 m along col 5, rows 0..7; rows 8..10 are an opening.
Heightmap wall_with_opening() {
  Heightmap gap(kGrid, 0.0);
  for (int r = 0; r <= 7; ++r) gap(r, 5) = 1.0;
  return gap;
}

bool eight_connected(const std::vector<CellIndex>& path) {
  for (std::size_t i = 1; i < path.size(); ++i)
    if (std::max(std::abs(path[i].row - path[i - 1].row), std::abs(path[i].col - path[i - 1].col)) != 1) return false;
  return true;
}

TEST(NavigablePathPlanner, FlatGroundGivesTheStraightLine) {
  const NavigablePathPlanner planner(params(0.02));
  const PlannerResult r = planner.plan(Heightmap(kGrid, 0.0), kAll, {5, 0}, {5, 10});
  ASSERT_TRUE(r.found);
  std::vector<CellIndex> expected;
  for (int c = 0; c <= 10; ++c) expected.push_back({5, c});
  EXPECT_EQ(r.path, expected);
  EXPECT_NEAR(r.length_m, 1.0, 1e-12);
  EXPECT_EQ(r.gap_cost_m, 0.0);
  EXPECT_EQ(r.target_volume_m3, 0.0);
  // A pure diagonal is unique too.
  const PlannerResult d = planner.plan(Heightmap(kGrid, 0.0), kAll, {1, 2}, {7, 8});
  ASSERT_EQ(d.path.size(), 7u);
  for (int i = 0; i <= 6; ++i) EXPECT_EQ(d.path[i], (CellIndex{1 + i, 2 + i}));
  EXPECT_NEAR(d.length_m, 0.6 * std::sqrt(2.0), 1e-12);
  // Start == goal: a one-cell path.
  const PlannerResult same = planner.plan(Heightmap(kGrid, 0.0), kAll, {3, 3}, {3, 3});
  ASSERT_TRUE(same.found);
  EXPECT_EQ(same.path, (std::vector<CellIndex>{{3, 3}}));
}

TEST(NavigablePathPlanner, AlphaTradesConstructionAgainstDetour) {
  const Heightmap gap = wall_with_opening();
  // Straight along row 1: g = 1.0 m; c = 1 (col 4) + 3 (col 5) + 1 (col 6) = 5 m.
  // Through the opening at (9, 5), where the ball touches no wall cell: g = 2 (5 sqrt 2 + 3) cs = 2.0142 m, c = 0.
  // Crossing at (0, 5), where the ball is cut by the map edge and priced at its mean (2 m over 4 cells, x 5):
  // g = (8 + 2 sqrt 2) cs = 1.0828 m, c = 1 + 2.5 + 1 = 4.5 m. (Crossing at row 8: g = 1.8142 m, c = 1 m, never
  // the cheapest.) So: straight for alpha < 0.1657, the edge crossing up to 0.2070, the opening beyond.
  const double detour_m = 2.0 * (5.0 * std::sqrt(2.0) + 3.0) * 0.1;
  for (double alpha : {0.0, 0.02, 0.15}) {
    const PlannerResult r = NavigablePathPlanner(params(alpha)).plan(gap, kAll, {1, 0}, {1, 10});
    ASSERT_TRUE(r.found);
    std::vector<CellIndex> straight;
    for (int c = 0; c <= 10; ++c) straight.push_back({1, c});
    EXPECT_EQ(r.path, straight) << "alpha " << alpha;
    EXPECT_NEAR(r.length_m, 1.0, 1e-12);
    EXPECT_NEAR(r.gap_cost_m, 5.0, 1e-12);
    // Footprint rows 0..2 of col 5: three wall cells of 1 m on 0.01 m^2.
    EXPECT_NEAR(r.target_volume_m3, 0.03, 1e-15);
  }
  const PlannerResult edge = NavigablePathPlanner(params(0.19)).plan(gap, kAll, {1, 0}, {1, 10});
  ASSERT_TRUE(edge.found);
  EXPECT_NE(std::find(edge.path.begin(), edge.path.end(), CellIndex{0, 5}), edge.path.end());
  EXPECT_NEAR(edge.length_m, (8.0 + 2.0 * std::sqrt(2.0)) * 0.1, 1e-12);
  EXPECT_NEAR(edge.gap_cost_m, 4.5, 1e-12);
  for (double alpha : {0.21, 1.0, 10.0}) {
    const PlannerResult r = NavigablePathPlanner(params(alpha)).plan(gap, kAll, {1, 0}, {1, 10});
    ASSERT_TRUE(r.found);
    EXPECT_NE(std::find(r.path.begin(), r.path.end(), CellIndex{9, 5}), r.path.end()) << "alpha " << alpha;
    EXPECT_NEAR(r.length_m, detour_m, 1e-12);
    EXPECT_EQ(r.gap_cost_m, 0.0);
    EXPECT_EQ(r.target_volume_m3, 0.0);
    EXPECT_TRUE(eight_connected(r.path));
    EXPECT_EQ(r.path.front(), (CellIndex{1, 0}));
    EXPECT_EQ(r.path.back(), (CellIndex{1, 10}));
  }
}

TEST(NavigablePathPlanner, BetaOneIsOptimalAndLargerBetaExpandsLess) {
  const Heightmap gap = wall_with_opening();
  const PlannerResult dijkstra = NavigablePathPlanner(params(0.5, 0.0)).plan(gap, kAll, {1, 0}, {1, 10});
  const PlannerResult astar = NavigablePathPlanner(params(0.5, 1.0)).plan(gap, kAll, {1, 0}, {1, 10});
  const PlannerResult greedy = NavigablePathPlanner(params(0.5, 3.0)).plan(gap, kAll, {1, 0}, {1, 10});
  ASSERT_TRUE(dijkstra.found && astar.found && greedy.found);
  const auto cost = [](const PlannerResult& r) { return r.length_m + 0.5 * r.gap_cost_m; };
  EXPECT_NEAR(cost(astar), cost(dijkstra), 1e-12);
  EXPECT_GE(cost(greedy), cost(astar) - 1e-12);
  EXPECT_LT(astar.expanded, dijkstra.expanded);
  EXPECT_LE(greedy.expanded, astar.expanded);
}

TEST(NavigablePathPlanner, TheMapEdgeIsNoCheapCorridor) {
  // Uniform gap: a footprint cut by the edge is priced at its mean, so along the edge each node costs 5 x 1 m.
  const Heightmap gap(kGrid, 1.0);
  const PlannerResult r = NavigablePathPlanner(params(0.02)).plan(gap, kAll, {0, 0}, {0, 10});
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.gap_cost_m, 50.0, 1e-9);
  const PlannerResult inside = NavigablePathPlanner(params(0.02)).plan(gap, kAll, {5, 0}, {5, 10});
  EXPECT_NEAR(inside.gap_cost_m, r.gap_cost_m, 1e-9);
}

TEST(NavigablePathPlanner, NoPathIsAResultAndBadInputThrows) {
  const Heightmap gap(kGrid, 0.0);
  CellMask blocked = kAll;
  blocked.col(5).setZero();
  const NavigablePathPlanner planner(params(0.02));
  const PlannerResult none = planner.plan(gap, blocked, {1, 0}, {1, 10});
  EXPECT_FALSE(none.found);
  EXPECT_TRUE(none.path.empty());
  EXPECT_FALSE(planner.plan(gap, blocked, {1, 5}, {1, 10}).found);  // start not allowed
  EXPECT_FALSE(planner.plan(gap, blocked, {1, 0}, {1, 5}).found);   // goal not allowed
  EXPECT_THROW(planner.plan(gap, kAll, {-1, 0}, {1, 10}), InvalidArgument);
  EXPECT_THROW(planner.plan(gap, kAll, {1, 0}, {1, 11}), InvalidArgument);
  EXPECT_THROW(planner.plan(gap, CellMask::Ones(10, 11), {1, 0}, {1, 10}), InvalidArgument);
  Heightmap negative(kGrid, 0.0);
  negative(1, 1) = -0.1;
  EXPECT_THROW(planner.plan(negative, kAll, {1, 0}, {1, 10}), InvalidArgument);
  EXPECT_THROW(NavigablePathPlanner(params(-1.0)), InvalidArgument);
  EXPECT_THROW(NavigablePathPlanner(params(0.1, std::nan(""))), InvalidArgument);
  EXPECT_THROW(NavigablePathPlanner({0.1, 1.0, 0.0}), InvalidArgument);
}

// The cost at the goal is the sum, over the path's cells after the start, of each cell's ball sum of the gap (the
// ball's cells in disc_offsets order, a ball cut by the edge scaled by its full count over the cells inside):
// recomputed here cell by cell, it must be the planner's to the bit, on random gaps with ties, zeros and -0.0, for
// balls inside the grid and cut by its edges, and along paths hugging the edges.
TEST(NavigablePathPlanner, GapCostIsTheBallSumsOfThePathBitForBit) {
  std::uint64_t x = 12345;
  const auto next = [&x]() {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    return x >> 33;
  };
  for (const double delta_m : {0.2, 0.5, 0.9}) {
    const GridGeometry g{23, 31, 0.0, 0.0, 0.1};
    const auto ball = disc_offsets(delta_m / (2.0 * g.cell_size_m));
    for (int trial = 0; trial < 20; ++trial) {
      Heightmap gap(g, 0.0);
      for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
          const auto kind = next() % 4;
          gap(r, c) = kind == 0   ? 0.0
                      : kind == 1 ? -0.0
                      : kind == 2 ? 0.25
                                  : static_cast<double>(next() % 1000) / 997.0;
        }
      const CellIndex start{static_cast<int>(next() % g.rows), static_cast<int>(next() % g.cols)};
      const CellIndex goal{static_cast<int>(next() % g.rows), trial % 2 == 0 ? 0 : g.cols - 1};
      const NavigablePathPlanner planner({0.001 * (trial % 5), 1.0, delta_m});
      const PlannerResult res = planner.plan(gap, CellMask::Ones(g.rows, g.cols), start, goal);
      ASSERT_TRUE(res.found);
      double cost = 0.0;
      for (std::size_t i = 1; i < res.path.size(); ++i) {
        double sum = 0.0;
        int inside = 0;
        for (const CellIndex o : ball) {
          const CellIndex q{res.path[i].row + o.row, res.path[i].col + o.col};
          if (!gap.contains(q)) continue;
          sum += gap(q);
          ++inside;
        }
        if (inside < static_cast<int>(ball.size())) sum = sum * static_cast<double>(ball.size()) / inside;
        cost += sum;
      }
      EXPECT_EQ(std::memcmp(&cost, &res.gap_cost_m, sizeof cost), 0)
          << "delta " << delta_m << " trial " << trial << ": " << cost << " vs " << res.gap_cost_m;
    }
  }
}

TEST(NavigablePathPlanner, DefaultAlphaIsCellSizeOverBallCells) {
  // delta 1 m at 0.1 m cells: 81 cells within 5 cells of the centre.
  const PlannerParams p = default_planner_params(1.0, 0.1);
  EXPECT_DOUBLE_EQ(p.alpha, 0.1 / 81.0);
  EXPECT_EQ(p.beta, 1.0);
  EXPECT_EQ(p.delta_m, 1.0);
  EXPECT_THROW(default_planner_params(0.0, 0.1), InvalidArgument);
  EXPECT_THROW(default_planner_params(1.0, std::nan("")), InvalidArgument);
}

}  // namespace
}  // namespace marsala
