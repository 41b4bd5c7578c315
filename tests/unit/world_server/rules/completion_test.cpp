// The pure completion functions of payload_path and level_site runs against brute-force references written from
// the definitions (tests/support: every pair of every ball; here: Bellman-Ford distances, union-find components)
// on small seeded grids, and golden values worked out by hand.

#include "marsala/world_server/rules/completion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "marsala/core/error.hpp"
#include "support/navigability_brute_force.hpp"

namespace marsala::world_server {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;

/// Flat ground with a few raised blocks and millimetre noise: occupiable regions separated by walls.
Heightmap blocky(std::mt19937& rng, int rows, int cols, double cs = 0.1) {
  Heightmap h(GridGeometry{rows, cols, 0.0, 0.0, cs});
  std::uniform_int_distribution<int> row(0, rows - 1), col(0, cols - 1), size(1, 5), count(1, 5);
  std::uniform_real_distribution<double> rise(0.05, 0.3), noise(0.0, 0.004);
  const int blocks = count(rng);
  for (int b = 0; b < blocks; ++b) {
    const int r0 = row(rng), c0 = col(rng), rs = size(rng), csz = size(rng);
    const double dz = rise(rng);
    for (int r = r0; r < std::min(rows, r0 + rs); ++r)
      for (int c = c0; c < std::min(cols, c0 + csz); ++c) h(r, c) += dz;
  }
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) h(r, c) += noise(rng);
  return h;
}

/// Shortest 8-connected distances from `from` over 1-cells by Bellman-Ford relaxation until nothing changes.
std::vector<double> distances_brute_force(const CellMask& m, CellIndex from, double cs) {
  const int rows = static_cast<int>(m.rows()), cols = static_cast<int>(m.cols());
  std::vector<double> d(static_cast<std::size_t>(rows) * cols, std::numeric_limits<double>::infinity());
  if (m(from.row, from.col) == 0) return d;
  d[from.row * cols + from.col] = 0.0;
  for (bool changed = true; changed;) {
    changed = false;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        if (m(r, c) == 0 || !std::isfinite(d[r * cols + c])) continue;
        for (int dr = -1; dr <= 1; ++dr)
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = r + dr, cc = c + dc;
            if ((dr == 0 && dc == 0) || rr < 0 || cc < 0 || rr >= rows || cc >= cols || m(rr, cc) == 0) continue;
            const double nd = d[r * cols + c] + (dr != 0 && dc != 0 ? cs * std::sqrt(2.0) : cs);
            if (nd < d[rr * cols + cc] - 1e-12) {
              d[rr * cols + cc] = nd;
              changed = true;
            }
          }
      }
  }
  return d;
}

/// Largest 8-connected component by union-find.
long long largest_component_brute_force(const CellMask& m) {
  const int rows = static_cast<int>(m.rows()), cols = static_cast<int>(m.cols());
  std::vector<int> parent(static_cast<std::size_t>(rows) * cols);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      for (int dr = 0; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if ((dr == 0 && dc <= 0) || rr >= rows || cc < 0 || cc >= cols) continue;
          if (m(r, c) && m(rr, cc)) parent[find(r * cols + c)] = find(rr * cols + cc);
        }
  std::vector<long long> size(parent.size(), 0);
  long long best = 0;
  for (int k = 0; k < rows * cols; ++k)
    if (m(k / cols, k % cols)) best = std::max(best, ++size[find(k)]);
  return best;
}

scenario::PayloadPath payload(double kappa, double delta, double eps, Position from, Position to) {
  scenario::PayloadPath p;
  p.navigability = {kappa, delta, eps};
  p.from.x = from.x;
  p.from.y = from.y;
  p.to.x = to.x;
  p.to.y = to.y;
  return p;
}

scenario::Site site(double x0, double y0, double x1, double y1, double kappa = 0.1, double delta = 0.3,
                    double eps = 0.05) {
  scenario::Site s;
  s.area.x0 = x0;
  s.area.y0 = y0;
  s.area.x1 = x1;
  s.area.y1 = y1;
  s.navigability = {kappa, delta, eps};
  return s;
}

/// A state of two agents on a 1 m platform (x >= 2 m) of a flat 0.1 m grid, the goal the platform top, each
/// agent's target 1 m in from the platform's edge.
WorldState platform_state(double target_radius_m) {
  Heightmap h(GridGeometry{40, 40, 0.0, 0.0, 0.1});
  for (int r = 0; r < 40; ++r)
    for (int c = 20; c < 40; ++c) h(r, c) = 1.0;
  WorldState state;
  state.terrain = h;
  state.goal = {2.0, 0.0, 4.0, 4.0, 0.9, target_radius_m};
  for (std::uint32_t id = 1; id <= 2; ++id) {
    AgentRecord a;
    a.id = id;
    a.admitted = a.alive = true;
    a.target.x = 3.05;
    a.target.y = id == 1 ? 1.05 : 3.05;
    state.agents.push_back(a);
  }
  return state;
}

TEST(AgentsAtGoal, WithATargetRadiusEachAgentMustStandAtItsOwnTarget) {
  WorldState state = platform_state(0.25);
  AgentRecord& a = state.agents[0];
  AgentRecord& b = state.agents[1];
  // Both on the platform's edge, half the body over the ramp: inside the box and high enough, but 1 m short.
  a.position.x = b.position.x = 2.05;
  a.position.y = 1.05, b.position.y = 3.05;
  EXPECT_FALSE(at_goal(state, a));
  EXPECT_FALSE(is_completed(state));
  EXPECT_DOUBLE_EQ(progress(state), 0.0);
  // The box alone (no radius) took them as arrived: the old completion.
  state.goal.target_radius_m = 0.0;
  EXPECT_TRUE(is_completed(state));
  state.goal.target_radius_m = 0.25;
  // Agent 1 at 0.25 m from its target (a tie, inclusive); agent 2 on the other's target, 2 m from its own.
  a.position.x = 2.80;
  b.position.x = 3.05, b.position.y = 1.05;
  EXPECT_TRUE(at_goal(state, a));
  EXPECT_FALSE(at_goal(state, b));
  EXPECT_DOUBLE_EQ(progress(state), 0.5);
  EXPECT_FALSE(is_completed(state));
  b.position.y = 2.85;  // 0.2 m from its own
  EXPECT_TRUE(is_completed(state));
  // On its target but below min_height_m (the cell under it sunk to 0.5 m): not at the goal.
  a.position.x = 3.05;
  EXPECT_TRUE(at_goal(state, a));
  state.terrain(29, 30) = 0.5;  // (3.05, 1.05) m: row 39 - 10, col 30
  EXPECT_FALSE(at_goal(state, a));
}

TEST(PayloadPath, NavigabilityAndShortestPathsMatchBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0), delta(0.2, 0.55);
  int found = 0, missing = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const int rows = 8 + trial % 7, cols = 9 + trial % 5;
    const Heightmap h = blocky(rng, rows, cols);
    const Position from{unit(rng) * cols * 0.1, unit(rng) * rows * 0.1},
        to{unit(rng) * cols * 0.1, unit(rng) * rows * 0.1};
    const scenario::PayloadPath p = payload(0.3, delta(rng), 0.03, from, to);
    const NavigabilityParams params = p.navigability;
    const CellIndex a = *h.cell_at(from), b = *h.cell_at(to);
    const bool navigable = testing::navigable_brute_force(h, params, a)(b.row, b.col) != 0;
    ASSERT_EQ(payload_path_navigable(h, p), navigable) << "trial " << trial;

    const auto route = payload_path(h, p);
    ASSERT_EQ(route.has_value(), navigable) << "trial " << trial;
    if (!route) {
      ++missing;
      continue;
    }
    ++found;
    const CellMask occupiable = testing::occupiable_brute_force(h, params);
    const std::vector<double> d = distances_brute_force(occupiable, a, 0.1);
    EXPECT_NEAR(route->length_m, d[b.row * cols + b.col], 1e-9) << "trial " << trial;
    ASSERT_FALSE(route->cells.empty());
    EXPECT_EQ(route->cells.front(), a);
    EXPECT_EQ(route->cells.back(), b);
    double sum = 0.0;
    for (std::size_t i = 0; i < route->cells.size(); ++i) {
      const CellIndex c = route->cells[i];
      EXPECT_EQ(occupiable(c.row, c.col), 1) << "trial " << trial << " step " << i;
      if (i == 0) continue;
      const int dr = std::abs(c.row - route->cells[i - 1].row), dc = std::abs(c.col - route->cells[i - 1].col);
      ASSERT_TRUE(std::max(dr, dc) == 1) << "trial " << trial << " step " << i;
      sum += dr + dc == 2 ? 0.1 * kSqrt2 : 0.1;
    }
    EXPECT_NEAR(sum, route->length_m, 1e-12);
  }
  // Both outcomes occur often enough for the comparison to mean something.
  EXPECT_GT(found, 20);
  EXPECT_GT(missing, 20);
}

TEST(PayloadPath, GoldenLengths) {
  // Flat 40 x 40 at 0.1 m: straight along a row, and along the diagonal.
  const Heightmap flat(GridGeometry{40, 40, 0.0, 0.0, 0.1});
  const auto straight = payload_path(flat, payload(0.2, 2.0, 0.05, {0.55, 0.55}, {3.05, 0.55}));
  ASSERT_TRUE(straight);
  EXPECT_NEAR(straight->length_m, 2.5, 1e-12);
  EXPECT_EQ(straight->cells.size(), 26u);
  const auto diagonal = payload_path(flat, payload(0.2, 2.0, 0.05, {0.55, 0.55}, {3.05, 3.05}));
  ASSERT_TRUE(diagonal);
  EXPECT_NEAR(diagonal->length_m, 2.5 * kSqrt2, 1e-12);
  // Same cell: a path of one cell and length 0.
  const auto here = payload_path(flat, payload(0.2, 2.0, 0.05, {0.51, 0.51}, {0.59, 0.59}));
  ASSERT_TRUE(here);
  EXPECT_EQ(here->cells.size(), 1u);
  EXPECT_EQ(here->length_m, 0.0);

  // A wall in column 2 open only at row 4 (cs 1 m): from (0, 0) to (0, 4) through (4, 2), each half 2 side steps
  // and 2 diagonal ones: 4 + 4 sqrt 2.
  CellMask m = CellMask::Ones(5, 5);
  for (int r = 0; r < 4; ++r) m(r, 2) = 0;
  const auto around = shortest_path(m, {0, 0}, {0, 4}, 1.0);
  ASSERT_TRUE(around);
  EXPECT_NEAR(around->length_m, 4.0 + 4.0 * kSqrt2, 1e-12);
  EXPECT_NE(std::find(around->cells.begin(), around->cells.end(), CellIndex{4, 2}), around->cells.end());
  m(4, 2) = 0;
  EXPECT_FALSE(shortest_path(m, {0, 0}, {0, 4}, 1.0));
  EXPECT_FALSE(shortest_path(m, {0, 2}, {0, 4}, 1.0));  // the start is blocked
  EXPECT_FALSE(connected(m, {0, 0}, {0, 4}));
  EXPECT_TRUE(connected(m, {0, 0}, {4, 1}));

  // A 0.1 m deep, one cell wide trench across the grid stops a payload of eps 0.05 (and kappa 0.2): its ball of
  // 3 x 3 cells would hold a 0.1 m step between neighbours (> 0.05 + 0.02).
  Heightmap trench = flat;
  for (int r = 0; r < 40; ++r) trench(r, 20) = -0.1;
  const scenario::PayloadPath across = payload(0.2, 0.3, 0.05, {0.55, 0.55}, {3.05, 0.55});
  EXPECT_FALSE(payload_path_navigable(trench, across));
  EXPECT_FALSE(payload_path(trench, across));
  trench(5, 20) = 0.0;  // one filled cell is not enough: its neighbours' balls still hold the trench
  EXPECT_FALSE(payload_path_navigable(trench, across));
}

TEST(PayloadPath, EndsOffTheGridAreErrors) {
  const Heightmap flat(GridGeometry{10, 10, 0.0, 0.0, 0.1});
  EXPECT_THROW(payload_path_navigable(flat, payload(0.2, 0.3, 0.05, {-0.1, 0.5}, {0.5, 0.5})), InvalidArgument);
  EXPECT_THROW(payload_path(flat, payload(0.2, 0.3, 0.05, {0.5, 0.5}, {0.5, 1.0})), InvalidArgument);
  CellMask m = CellMask::Ones(3, 3);
  EXPECT_THROW(shortest_path(m, {0, 0}, {3, 0}, 1.0), InvalidArgument);
  EXPECT_THROW(shortest_path(m, {0, 0}, {1, 1}, 0.0), InvalidArgument);
  EXPECT_THROW(connected(m, {-1, 0}, {1, 1}), InvalidArgument);
}

TEST(LevelSite, SiteCellsAreThoseWhoseCentresLieInside) {
  const GridGeometry g{40, 40, 0.0, 0.0, 0.1};
  // Centres x = 0.05 + 0.1 c in [1.0, 2.0]: c = 10..19; y = (39.5 - r) 0.1 in [0.5, 1.5]: r = 25..34.
  CellRect r = site_cells(g, site(1.0, 0.5, 2.0, 1.5));
  EXPECT_EQ(r.first, (CellIndex{25, 10}));
  EXPECT_EQ(r.rows, 10);
  EXPECT_EQ(r.cols, 10);
  // Edges through centres are inside (closed rectangle).
  r = site_cells(g, site(1.05, 0.55, 1.95, 1.45));
  EXPECT_EQ(r.first, (CellIndex{25, 10}));
  EXPECT_EQ(r.rows, 10);
  EXPECT_EQ(r.cols, 10);
  // Partly off the grid: clipped; wholly off or between centres: empty.
  r = site_cells(g, site(-5.0, 3.5, 0.3, 9.0));
  EXPECT_EQ(r.first, (CellIndex{0, 0}));
  EXPECT_EQ(r.rows, 5);
  EXPECT_EQ(r.cols, 3);
  EXPECT_TRUE(site_cells(g, site(5.0, 0.0, 6.0, 1.0)).empty());
  EXPECT_TRUE(site_cells(g, site(1.01, 1.0, 1.04, 2.0)).empty());
}

TEST(LevelSite, GoldenFractions) {
  // Flat 40 x 40 at 0.1 m; site rows 10..19 x cols 20..29 (100 cells); delta 0.3 m: the ball is the 3 x 3 cells
  // around a cell. A 0.1 m hole spoils every cell whose ball holds it (0.1 > eps 0.05 + kappa 0.1 * 0.1 m).
  Heightmap h(GridGeometry{40, 40, 0.0, 0.0, 0.1});
  const scenario::Site s = site(2.0, 2.0, 3.0, 3.0);
  EXPECT_EQ(site_level_fraction(h, s), 1.0);
  h(15, 25) = -0.1;  // inside: its 3 x 3 neighbourhood is lost
  EXPECT_DOUBLE_EQ(site_level_fraction(h, s), 0.91);
  h(15, 25) = 0.0;
  h(10, 20) = -0.1;  // the site's corner: 4 cells of the site lost
  EXPECT_DOUBLE_EQ(site_level_fraction(h, s), 0.96);
  h(10, 20) = 0.0;
  h(15, 19) = -0.1;  // just west of the site: the crop cuts it off, nothing is lost
  EXPECT_EQ(site_level_fraction(h, s), 1.0);
  // A trench along column 23 splits the site: columns 22..24 lost, 20..21 (20 cells) and 25..29 (50 cells) remain.
  for (int r = 0; r < 40; ++r) h(r, 23) = -0.1;
  EXPECT_DOUBLE_EQ(site_level_fraction(h, s), 0.5);
}

TEST(LevelSite, FractionsMatchBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0), delta(0.2, 0.5);
  for (int trial = 0; trial < 120; ++trial) {
    const int rows = 10 + trial % 6, cols = 8 + trial % 7;
    const Heightmap h = blocky(rng, rows, cols);
    // Random rectangles, some reaching past the grid's edges.
    double x0 = unit(rng) * cols * 0.12 - 0.1, x1 = unit(rng) * cols * 0.12 - 0.1;
    double y0 = unit(rng) * rows * 0.12 - 0.1, y1 = unit(rng) * rows * 0.12 - 0.1;
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    const scenario::Site s = site(x0, y0, x1, y1, 0.2, delta(rng), 0.03);
    // The crop, from the definition: cells whose centres lie inside.
    int r0 = rows, r1 = -1, c0 = cols, c1 = -1;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const Position p = h.cell_center({r, c});
        if (p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1)
          r0 = std::min(r0, r), r1 = std::max(r1, r), c0 = std::min(c0, c), c1 = std::max(c1, c);
      }
    if (r1 < 0) {
      EXPECT_THROW(site_level_fraction(h, s), InvalidArgument) << "trial " << trial;
      continue;
    }
    const Heightmap crop = h.window({r0, c0}, r1 - r0 + 1, c1 - c0 + 1);
    const CellMask occupiable = testing::occupiable_brute_force(crop, s.navigability);
    const double expected =
        static_cast<double>(largest_component_brute_force(occupiable)) / static_cast<double>(crop.size());
    EXPECT_DOUBLE_EQ(site_level_fraction(h, s), expected) << "trial " << trial;
    EXPECT_EQ(largest_component(occupiable), largest_component_brute_force(occupiable)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace marsala::world_server
