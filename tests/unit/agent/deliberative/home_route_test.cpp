#include "marsala/agent/deliberative/home_route.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <vector>

#include "../agent_test_support.hpp"
#include "support/navigability_brute_force.hpp"

namespace marsala::agent::deliberative {
namespace {

constexpr NavigabilityParams kBody{0.3, 0.4, 0.05};  // a ball of radius 2 cells at 0.1 m

/// Route length [cells]: steps of 1 and sqrt 2; checks that each step joins 8-neighbours.
double route_length(const std::vector<CellIndex>& route) {
  double length = 0.0;
  for (std::size_t i = 1; i < route.size(); ++i) {
    const int dr = std::abs(route[i].row - route[i - 1].row), dc = std::abs(route[i].col - route[i - 1].col);
    EXPECT_LE(std::max(dr, dc), 1) << "step " << i << " is no 8-neighbour";
    length += dr + dc == 2 ? std::sqrt(2.0) : 1.0;
  }
  return length;
}

/// The independent reference: Dijkstra over the brute-force occupiable cells (all known), to the nearest cell within
/// radius of the base [cells of route length].
double shortest_home(const Heightmap& h, CellIndex from, Position base, double radius_m) {
  const CellMask occ = testing::occupiable_brute_force(h, kBody);
  std::vector<double> d(static_cast<std::size_t>(h.rows() * h.cols()), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  if (occ(from.row, from.col) == 0) return -1.0;
  d[static_cast<std::size_t>(from.row * h.cols() + from.col)] = 0.0;
  open.push({0.0, from.row * h.cols() + from.col});
  while (!open.empty()) {
    const auto [dist, i] = open.top();
    open.pop();
    if (dist > d[static_cast<std::size_t>(i)]) continue;
    const CellIndex c{i / h.cols(), i % h.cols()};
    const Position p = h.cell_center(c);
    if (std::hypot(p.x - base.x, p.y - base.y) <= radius_m) return dist;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const CellIndex n{c.row + dr, c.col + dc};
        if ((dr == 0 && dc == 0) || !h.contains(n) || occ(n.row, n.col) == 0) continue;
        const double next = dist + (dr != 0 && dc != 0 ? std::sqrt(2.0) : 1.0);
        const int j = n.row * h.cols() + n.col;
        if (next < d[static_cast<std::size_t>(j)]) d[static_cast<std::size_t>(j)] = next, open.push({next, j});
      }
  }
  return -1.0;
}

/// A 4 x 6 m field at 0.1 m cells; a pocket: walls 1 m high round x in [2, 4.5] m, y in [1, 3] m, open only to the
/// north-east corner's top, so the way out of it runs away from a base at (1, 2) m west of the pocket.
Heightmap pocket() {
  Heightmap h({40, 60, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const Position p = h.cell_center({r, c});
      const bool wall_x = (p.x > 1.8 && p.x < 2.0) || (p.x > 4.5 && p.x < 4.7);
      const bool wall_y = (p.y > 0.8 && p.y < 1.0) || (p.y > 3.0 && p.y < 3.2);
      const bool in_x = p.x > 1.8 && p.x < 4.7, in_y = p.y > 0.8 && p.y < 3.2;
      const bool gap = p.x > 4.0 && p.x < 4.5 && p.y > 3.0;  // the opening in the north wall, at its east end
      if (((wall_x && in_y) || (wall_y && in_x)) && !gap) h(r, c) = 1.0;
    }
  return h;
}

TEST(HomeRoute, LeavesAPocketThroughItsOpeningOnAShortestRoute) {
  const Heightmap h = pocket();
  const auto map = test::full_map(h);
  const CellIndex from = *h.geometry().cell_at({2.5, 2.0});  // inside, near the west wall: the base is 1.5 m away
  const Position base{1.0, 2.0};
  const auto route = home_route(map.known_map(), kBody, from, base, 0.5, 5.0);
  ASSERT_TRUE(route.has_value());
  EXPECT_EQ(route->front(), from);
  const Position end = h.cell_center(route->back());
  EXPECT_LE(std::hypot(end.x - base.x, end.y - base.y), 0.5);
  const CellMask occ = testing::occupiable_brute_force(h, kBody);
  bool through_opening = false;
  for (const CellIndex c : *route) {
    EXPECT_NE(occ(c.row, c.col), 0) << "route cell " << c.row << "," << c.col << " is not occupiable";
    const Position p = h.cell_center(c);
    through_opening = through_opening || (p.x > 4.0 && p.x < 4.5 && p.y > 3.0 && p.y < 3.2);
  }
  EXPECT_TRUE(through_opening);
  EXPECT_NEAR(route_length(*route), shortest_home(h, from, base, 0.5), 1e-9);
  EXPECT_GT(route_length(*route) * 0.1, 4.0);  // much longer than the 1.5 m straight line
}

TEST(HomeRoute, MatchesTheShortestRouteOnRandomTerrains) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Heightmap h({24, 24, 0.0, 0.0, 0.1}, 0.0);
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) h(r, c) = u(rng) < 0.08 ? 0.5 : 0.0;  // scattered posts
    const auto map = test::full_map(h);
    const CellIndex from{static_cast<int>(u(rng) * 24), static_cast<int>(u(rng) * 24)};
    const Position base{0.3 + u(rng) * 1.8, 0.3 + u(rng) * 1.8};
    const double expected = shortest_home(h, from, base, 0.3);
    const auto route = home_route(map.known_map(), kBody, from, base, 0.3, 5.0);
    if (expected < 0.0) {
      EXPECT_FALSE(route.has_value()) << "trial " << trial;
      continue;
    }
    ASSERT_TRUE(route.has_value()) << "trial " << trial;
    EXPECT_NEAR(route_length(*route), expected, 1e-9) << "trial " << trial;
  }
}

TEST(HomeRoute, NeverCrossesCellsItCannotJudge) {
  // A flat field whose map knows everything but a band across its middle: no way home across it, but around it when
  // the band leaves a known strip open.
  const Heightmap h({30, 30, 0.0, 0.0, 0.1}, 0.0);
  const auto map = test::full_map(h, 10);
  const CellIndex from{5, 15};
  const Position base = h.cell_center({25, 15});
  // Without holes: straight down.
  ASSERT_TRUE(home_route(map.known_map(), kBody, from, base, 0.2, 5.0).has_value());
  // A map without the middle row of tiles (rows 10-19) but its east tile: the way home goes round by the east.
  executive::MappingSystem east(h.geometry(), 10);
  for (int tr = 0; tr < 3; ++tr)
    for (int tc = 0; tc < 3; ++tc)
      if (tr != 1 || tc == 2) east.integrate_tile(test::cut_tile(h, 10, tr, tc));
  const auto around = home_route(east.known_map(), kBody, from, base, 0.2, 5.0);
  ASSERT_TRUE(around.has_value());
  for (const CellIndex c : *around) {
    if (c.row < 10 || c.row >= 20) continue;
    EXPECT_GE(c.col, 22) << "cell " << c.row << "," << c.col << ": its ball reaches the unknown tiles (cols < 20)";
  }
  executive::MappingSystem cut(h.geometry(), 10);
  for (int tr = 0; tr < 3; ++tr)
    for (int tc = 0; tc < 3; ++tc)
      if (tr != 1) cut.integrate_tile(test::cut_tile(h, 10, tr, tc));
  EXPECT_FALSE(home_route(cut.known_map(), kBody, from, base, 0.2, 5.0).has_value());
}

}  // namespace
}  // namespace marsala::agent::deliberative
