#include "marsala/core/goal_vector_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "marsala/core/error.hpp"

namespace marsala {
namespace {

// 12 x 12 cells of 1 m with the lower-left corner at (100, -20): cell centres at 100.5 + k and -19.5 + k.
GridGeometry grid_1m() { return {12, 12, 100.0, -20.0, 1.0}; }

GoalVectorMapSpec spec(double x0, double y0, double x1, double y1, double w, double len, Heading h) {
  GoalVectorMapSpec s;
  s.area.x0 = x0;
  s.area.y0 = y0;
  s.area.x1 = x1;
  s.area.y1 = y1;
  s.strip_width_m = w;
  s.arrow_length_m = len;
  s.heading = h;
  return s;
}

// Arrow (tail, head, strip, index), compared exactly: every coordinate is a cell centre, exact in binary.
struct Golden {
  double tx, ty, hx, hy;
  int strip, index;
};

void expect_arrows(const GoalVectorMap& map, const std::vector<Golden>& golden) {
  ASSERT_EQ(map.arrows().size(), golden.size());
  for (std::size_t i = 0; i < golden.size(); ++i) {
    const GoalArrow& a = map.arrows()[i];
    const Golden& g = golden[i];
    EXPECT_EQ(a.tail.x, g.tx) << "arrow " << i;
    EXPECT_EQ(a.tail.y, g.ty) << "arrow " << i;
    EXPECT_EQ(a.head.x, g.hx) << "arrow " << i;
    EXPECT_EQ(a.head.y, g.hy) << "arrow " << i;
    EXPECT_EQ(a.strip, g.strip) << "arrow " << i;
    EXPECT_EQ(a.index, g.index) << "arrow " << i;
  }
}

// Site [100, 110] x [-20, -15], strips 2 m, arrows 4 m. Across: bands [-20, -18], [-18, -16], [-16, -15] (the last
// narrower), middles -19, -17, -15.5 -> cells [-19, -18), [-17, -16), [-16, -15) -> centre lines -18.5, -16.5,
// -15.5. Along: cuts 100, 104, 108, 110; the far edge 110 is pulled to 109.5 -> centres 100.5, 104.5, 108.5, 109.5.
TEST(GoalVectorMap, GoldenEast) {
  const GoalVectorMap map(spec(100, -20, 110, -15, 2, 4, Heading::kEast), grid_1m());
  EXPECT_EQ(map.strips(), 3);
  expect_arrows(map, {{100.5, -18.5, 104.5, -18.5, 0, 0},
                      {104.5, -18.5, 108.5, -18.5, 0, 1},
                      {108.5, -18.5, 109.5, -18.5, 0, 2},  // the last arrow is shorter
                      {100.5, -16.5, 104.5, -16.5, 1, 0},
                      {104.5, -16.5, 108.5, -16.5, 1, 1},
                      {108.5, -16.5, 109.5, -16.5, 1, 2},
                      {100.5, -15.5, 104.5, -15.5, 2, 0},
                      {104.5, -15.5, 108.5, -15.5, 2, 1},
                      {108.5, -15.5, 109.5, -15.5, 2, 2}});
}

// Same site heading west: cuts 110 (far edge -> 109.5), 106, 102, 100 -> centres 109.5, 106.5, 102.5, 100.5.
TEST(GoalVectorMap, GoldenWest) {
  const GoalVectorMap map(spec(100, -20, 110, -15, 2, 4, Heading::kWest), grid_1m());
  EXPECT_EQ(map.strips(), 3);
  expect_arrows(map, {{109.5, -18.5, 106.5, -18.5, 0, 0},
                      {106.5, -18.5, 102.5, -18.5, 0, 1},
                      {102.5, -18.5, 100.5, -18.5, 0, 2},
                      {109.5, -16.5, 106.5, -16.5, 1, 0},
                      {106.5, -16.5, 102.5, -16.5, 1, 1},
                      {102.5, -16.5, 100.5, -16.5, 1, 2},
                      {109.5, -15.5, 106.5, -15.5, 2, 0},
                      {106.5, -15.5, 102.5, -15.5, 2, 1},
                      {102.5, -15.5, 100.5, -15.5, 2, 2}});
}

// Site [100, 105] x [-20, -10], strips 2 m (strip 0 west), arrows 4 m. Across x: bands [100, 102], [102, 104],
// [104, 105] -> lines 101.5, 103.5, 104.5. Along y: cuts -20, -16, -12, -10 (far edge -> -10.5) -> -19.5, -15.5,
// -11.5, -10.5.
TEST(GoalVectorMap, GoldenNorth) {
  const GoalVectorMap map(spec(100, -20, 105, -10, 2, 4, Heading::kNorth), grid_1m());
  EXPECT_EQ(map.strips(), 3);
  expect_arrows(map, {{101.5, -19.5, 101.5, -15.5, 0, 0},
                      {101.5, -15.5, 101.5, -11.5, 0, 1},
                      {101.5, -11.5, 101.5, -10.5, 0, 2},
                      {103.5, -19.5, 103.5, -15.5, 1, 0},
                      {103.5, -15.5, 103.5, -11.5, 1, 1},
                      {103.5, -11.5, 103.5, -10.5, 1, 2},
                      {104.5, -19.5, 104.5, -15.5, 2, 0},
                      {104.5, -15.5, 104.5, -11.5, 2, 1},
                      {104.5, -11.5, 104.5, -10.5, 2, 2}});
}

// Heading south: cuts -10 (far edge -> -10.5), -14, -18, -20 -> -10.5, -13.5, -17.5, -19.5.
TEST(GoalVectorMap, GoldenSouth) {
  const GoalVectorMap map(spec(100, -20, 105, -10, 2, 4, Heading::kSouth), grid_1m());
  EXPECT_EQ(map.strips(), 3);
  expect_arrows(map, {{101.5, -10.5, 101.5, -13.5, 0, 0},
                      {101.5, -13.5, 101.5, -17.5, 0, 1},
                      {101.5, -17.5, 101.5, -19.5, 0, 2},
                      {103.5, -10.5, 103.5, -13.5, 1, 0},
                      {103.5, -13.5, 103.5, -17.5, 1, 1},
                      {103.5, -17.5, 103.5, -19.5, 1, 2},
                      {104.5, -10.5, 104.5, -13.5, 2, 0},
                      {104.5, -13.5, 104.5, -17.5, 2, 1},
                      {104.5, -17.5, 104.5, -19.5, 2, 2}});
}

// Along [100, 108.5] with arrows of 4 m: cuts 100, 104, 108, 108.5; the 0.5 m remainder is shorter than a cell and
// merges into the previous arrow: 100.5 -> 104.5 -> 108.5 (108.5 is the far edge, pulled to 108 -> centre 108.5).
// One strip: band [-20, -19], line -19.5.
TEST(GoalVectorMap, RemainderShorterThanACellMergesIntoThePreviousArrow) {
  const GoalVectorMap map(spec(100, -20, 108.5, -19, 1, 4, Heading::kEast), grid_1m());
  EXPECT_EQ(map.strips(), 1);
  expect_arrows(map, {{100.5, -19.5, 104.5, -19.5, 0, 0}, {104.5, -19.5, 108.5, -19.5, 0, 1}});
  // Heading west the remainder lies at x0: cuts 108.5 (-> 108.5), 104.5, 100.5, 100 -> merged: 108.5 -> 104.5 ->
  // 100.5.
  const GoalVectorMap west(spec(100, -20, 108.5, -19, 1, 4, Heading::kWest), grid_1m());
  expect_arrows(west, {{108.5, -19.5, 104.5, -19.5, 0, 0}, {104.5, -19.5, 100.5, -19.5, 0, 1}});
}

// Along [100, 109] with arrows of 4 m: the remainder is exactly one cell, but its tail (cut 108 -> 108.5) and head
// (far edge 109 -> 108.5) snap to the same cell; a zero-length arrow is merged too.
TEST(GoalVectorMap, RemainderThatSnapsToNothingMergesIntoThePreviousArrow) {
  const GoalVectorMap map(spec(100, -20, 109, -19, 1, 4, Heading::kEast), grid_1m());
  expect_arrows(map, {{100.5, -19.5, 104.5, -19.5, 0, 0}, {104.5, -19.5, 108.5, -19.5, 0, 1}});
  // Two cells of remainder survive as a one-cell arrow.
  const GoalVectorMap longer(spec(100, -20, 110, -19, 1, 4, Heading::kEast), grid_1m());
  expect_arrows(
      longer,
      {{100.5, -19.5, 104.5, -19.5, 0, 0}, {104.5, -19.5, 108.5, -19.5, 0, 1}, {108.5, -19.5, 109.5, -19.5, 0, 2}});
}

// Half-metre cells: site [0, 3] x [0, 1.5], strips 1 m, arrows 1.25 m east. Across: bands [0, 1], [1, 1.5] ->
// middles 0.5 (cell [0.5, 1) -> 0.75) and 1.25 (-> 1.25). Along: cuts 0, 1.25, 2.5, 3 -> 0.25, 1.25, 2.75, 2.75
// (far edge 3 -> 2.75): the last 0.5 m (one cell) snaps to nothing and merges.
TEST(GoalVectorMap, GoldenHalfMetreCells) {
  const GoalVectorMap map(spec(0, 0, 3, 1.5, 1, 1.25, Heading::kEast), {4, 8, 0.0, 0.0, 0.5});
  EXPECT_EQ(map.strips(), 2);
  expect_arrows(map, {{0.25, 0.75, 1.25, 0.75, 0, 0},
                      {1.25, 0.75, 2.75, 0.75, 0, 1},
                      {0.25, 1.25, 1.25, 1.25, 1, 0},
                      {1.25, 1.25, 2.75, 1.25, 1, 1}});
}

// Random specs in every heading. `aligned`: the rectangle on cell edges, strip width and arrow length whole numbers
// of cells; otherwise anything valid.
struct RandomSpecs {
  std::mt19937 rng{20240611};
  GridGeometry grid{40, 50, -3.0, 7.0, 0.25};

  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  int integer(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }

  GoalVectorMapSpec make(bool aligned) {
    const double cs = grid.cell_size_m;
    GoalVectorMapSpec s;
    s.heading = static_cast<Heading>(integer(0, 3));
    if (aligned) {
      const int c0 = integer(0, grid.cols - 4), r0 = integer(0, grid.rows - 4);
      s.area.x0 = grid.xll_m + c0 * cs;
      s.area.x1 = grid.xll_m + integer(c0 + 3, grid.cols) * cs;
      s.area.y0 = grid.yll_m + r0 * cs;
      s.area.y1 = grid.yll_m + integer(r0 + 3, grid.rows) * cs;
      s.strip_width_m = integer(1, 8) * cs;
      s.arrow_length_m = integer(1, 12) * cs;
    } else {
      s.area.x0 = uniform(grid.xll_m, grid.xll_m + grid.cols * cs - 2.0);
      s.area.x1 = uniform(s.area.x0 + 1.0, grid.xll_m + grid.cols * cs);
      s.area.y0 = uniform(grid.yll_m, grid.yll_m + grid.rows * cs - 2.0);
      s.area.y1 = uniform(s.area.y0 + 1.0, grid.yll_m + grid.rows * cs);
      s.strip_width_m = uniform(cs, 2.5);
      s.arrow_length_m = uniform(cs, 4.0);
    }
    return s;
  }
};

// The map of a random draw. Aligned draws always make one; other draws may leave a last strip narrower than a
// cell, which is refused (and only that).
std::optional<GoalVectorMap> try_make(const GoalVectorMapSpec& s, const GridGeometry& g, bool aligned) {
  try {
    return GoalVectorMap(s, g);
  } catch (const InvalidArgument& e) {
    EXPECT_FALSE(aligned) << e.what();
    EXPECT_NE(std::string(e.what()).find("narrower than one cell"), std::string::npos) << e.what();
    return std::nullopt;
  }
}

double along(const GoalVectorMapSpec& s, Position p) {
  switch (s.heading) {
    case Heading::kEast: return p.x;
    case Heading::kWest: return -p.x;
    case Heading::kNorth: return p.y;
    case Heading::kSouth: return -p.y;
  }
  return 0.0;
}
double across(const GoalVectorMapSpec& s, Position p) {
  return s.heading == Heading::kEast || s.heading == Heading::kWest ? p.y : p.x;
}

TEST(GoalVectorMap, TailsAndHeadsAreCellCentresAndChainAlongEachStrip) {
  RandomSpecs random;
  int built = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const bool aligned = trial % 2 == 0;
    const GoalVectorMapSpec s = random.make(aligned);
    const std::optional<GoalVectorMap> map = try_make(s, random.grid, aligned);
    if (!map) continue;
    ++built;
    const double cs = random.grid.cell_size_m;
    const std::vector<GoalArrow>& arrows = map->arrows();
    ASSERT_FALSE(arrows.empty());
    for (std::size_t i = 0; i < arrows.size(); ++i) {
      const GoalArrow& a = arrows[i];
      for (const Position p : {a.tail, a.head}) {
        const std::optional<CellIndex> cell = random.grid.cell_at(p);
        ASSERT_TRUE(cell.has_value());
        const Position c = random.grid.cell_center(*cell);
        EXPECT_EQ(p.x, c.x);
        EXPECT_EQ(p.y, c.y);
      }
      // Points along the heading by at least one cell, on the strip's line.
      EXPECT_GE(along(s, a.head) - along(s, a.tail), cs - 1e-9) << "trial " << trial << " arrow " << i;
      EXPECT_EQ(across(s, a.head), across(s, a.tail));
      // Arrows come strip by strip, upwind to downwind; a head is the next arrow's tail.
      const bool first_of_strip = i == 0 || arrows[i - 1].strip != a.strip;
      EXPECT_EQ(a.index, first_of_strip ? 0 : arrows[i - 1].index + 1);
      if (!first_of_strip) {
        EXPECT_EQ(a.strip, arrows[i - 1].strip);
        EXPECT_EQ(a.tail.x, arrows[i - 1].head.x);
        EXPECT_EQ(a.tail.y, arrows[i - 1].head.y);
      } else if (i > 0) {
        EXPECT_EQ(a.strip, arrows[i - 1].strip + 1);
        EXPECT_GT(across(s, a.tail), across(s, arrows[i - 1].tail));  // strip 0 at the low side
      }
    }
    EXPECT_EQ(arrows.back().strip, map->strips() - 1);
  }
  EXPECT_GT(built, 300);  // unaligned draws, too, mostly make maps
}

// Every cell centre in the rectangle lies within strip_width/2 of some strip's centre line (the line its arrows run
// on), and between the upwind tail and the downwind head of that strip. Exact when the rectangle and the strip width
// are on cell edges; otherwise snapping may shift a line by up to half a cell.
TEST(GoalVectorMap, StripsCoverTheRectangleBruteForce) {
  RandomSpecs random;
  for (int trial = 0; trial < 300; ++trial) {
    const bool aligned = trial % 3 != 0;
    const GoalVectorMapSpec s = random.make(aligned);
    const std::optional<GoalVectorMap> map = try_make(s, random.grid, aligned);
    if (!map) continue;
    const GridGeometry& g = random.grid;
    const double slack = aligned ? 1e-9 : 0.5 * g.cell_size_m + 1e-9;
    // Per strip: centre line, and the first tail and last head along the heading.
    std::vector<double> line(static_cast<std::size_t>(map->strips()));
    std::vector<std::pair<double, double>> span(line.size());
    for (const GoalArrow& a : map->arrows()) {
      const auto k = static_cast<std::size_t>(a.strip);
      line[k] = across(s, a.tail);
      if (a.index == 0) span[k].first = along(s, a.tail);
      span[k].second = along(s, a.head);
    }
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c) {
        const Position p = g.cell_center({r, c});
        if (p.x < s.area.x0 || p.x > s.area.x1 || p.y < s.area.y0 || p.y > s.area.y1) continue;
        bool covered = false;
        for (std::size_t k = 0; k < line.size() && !covered; ++k)
          covered = std::abs(across(s, p) - line[k]) <= 0.5 * s.strip_width_m + slack &&
                    along(s, p) >= span[k].first - slack && along(s, p) <= span[k].second + slack;
        EXPECT_TRUE(covered) << "trial " << trial << " cell (" << r << ", " << c << ")";
      }
  }
}

// arrow_at against its definition, checked per arrow: the point lies in its strip's band across the heading (a
// point on the line between two bands in the lower strip) and between its tail and head along it (the first arrow
// open to the upwind side, the last one to the downwind side, a point on a head in the arrow that ends there).
TEST(GoalVectorMap, ArrowAtMatchesTheStretchOfEachArrow) {
  RandomSpecs random;
  int points = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const bool aligned = trial % 2 == 0;
    const GoalVectorMapSpec s = random.make(aligned);
    const std::optional<GoalVectorMap> map = try_make(s, random.grid, aligned);
    if (!map) continue;
    const std::vector<GoalArrow>& arrows = map->arrows();
    const double lo = s.heading == Heading::kEast || s.heading == Heading::kWest ? s.area.y0 : s.area.x0;
    // Cell centres of the grid, the arrows' own tails and heads, and random points in and around the rectangle.
    std::vector<Position> probes;
    for (int r = 0; r < random.grid.rows; ++r)
      for (int c = 0; c < random.grid.cols; ++c) probes.push_back(random.grid.cell_center({r, c}));
    for (const GoalArrow& a : arrows) probes.insert(probes.end(), {a.tail, a.head});
    for (int k = 0; k < 200; ++k)
      probes.push_back({random.uniform(s.area.x0 - 1.0, s.area.x1 + 1.0), random.uniform(s.area.y0 - 1.0, s.area.y1 + 1.0)});
    for (const Position p : probes) {
      const bool inside = p.x >= s.area.x0 && p.x <= s.area.x1 && p.y >= s.area.y0 && p.y <= s.area.y1;
      const std::optional<std::size_t> at = map->arrow_at(p);
      ASSERT_EQ(at.has_value(), inside) << "trial " << trial << " point (" << p.x << ", " << p.y << ")";
      if (!at) continue;
      ++points;
      const GoalArrow& a = arrows[*at];
      const double band_lo = lo + a.strip * s.strip_width_m;
      const double band_hi = band_lo + s.strip_width_m;
      const double x = across(s, p);
      EXPECT_TRUE((x > band_lo + 1e-9 || a.strip == 0) && (x <= band_hi + 1e-9 || a.strip == map->strips() - 1))
          << "trial " << trial << " strip " << a.strip << " across " << x;
      const bool first = a.index == 0;
      const bool last = *at + 1 == arrows.size() || arrows[*at + 1].strip != a.strip;
      EXPECT_TRUE(first || along(s, p) > along(s, a.tail) + 1e-9) << "trial " << trial << " arrow " << *at;
      EXPECT_TRUE(last || along(s, p) <= along(s, a.head) + 1e-9) << "trial " << trial << " arrow " << *at;
    }
  }
  EXPECT_GT(points, 50000);
  const GoalVectorMap map(spec(100.5, -19, 111, -9.5, 1.5, 2.5, Heading::kNorth), grid_1m());
  EXPECT_FALSE(map.arrow_at({std::nan(""), -15.0}).has_value());
  EXPECT_FALSE(map.arrow_at({105.0, std::numeric_limits<double>::infinity()}).has_value());
}

TEST(GoalVectorMap, NearestFreeTailMatchesBruteForce) {
  const GoalVectorMap map(spec(100.5, -19, 111, -9.5, 1.5, 2.5, Heading::kNorth), grid_1m());
  const std::size_t n = map.arrows().size();
  ASSERT_GT(n, 20u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(95.0, 117.0), y(-25.0, -3.0), coin(0.0, 1.0);
  std::uniform_int_distribution<std::size_t> length(0, n + 3);
  for (int trial = 0; trial < 2000; ++trial) {
    const Position p{x(rng), y(rng)};
    const double density = coin(rng);
    std::vector<bool> excluded(length(rng));  // shorter or longer than arrows()
    for (std::size_t i = 0; i < excluded.size(); ++i) excluded[i] = coin(rng) < density;
    // Reference: every free arrow as (squared distance, index), the smallest pair.
    std::optional<std::pair<double, std::size_t>> best;
    for (std::size_t i = 0; i < n; ++i) {
      if (i < excluded.size() && excluded[i]) continue;
      const Position t = map.arrows()[i].tail;
      const std::pair<double, std::size_t> key{(t.x - p.x) * (t.x - p.x) + (t.y - p.y) * (t.y - p.y), i};
      if (!best || key < *best) best = key;
    }
    const std::optional<std::size_t> got = map.nearest_free_tail(p, excluded);
    ASSERT_EQ(got.has_value(), best.has_value()) << "trial " << trial;
    if (best) {
      EXPECT_EQ(*got, best->second) << "trial " << trial;
    }
  }
  EXPECT_FALSE(map.nearest_free_tail({100, -10}, std::vector<bool>(n, true)).has_value());
  EXPECT_THROW(map.nearest_free_tail({std::nan(""), 0.0}, {}), InvalidArgument);
}

TEST(GoalVectorMap, NearestFreeTailTiesGoToTheLowerIndex) {
  // GoldenEast: strip 0 tails at (100.5, -18.5), (104.5, -18.5); the point halfway is equally far from both.
  const GoalVectorMap map(spec(100, -20, 110, -15, 2, 4, Heading::kEast), grid_1m());
  EXPECT_EQ(map.nearest_free_tail({102.5, -18.5}, {}), std::optional<std::size_t>(0));
  EXPECT_EQ(map.nearest_free_tail({102.5, -18.5}, {true}), std::optional<std::size_t>(1));
  // Tails of strips 0 and 1 at x = 100.5 sit at y -18.5 and -16.5.
  EXPECT_EQ(map.nearest_free_tail({100.5, -17.5}, {}), std::optional<std::size_t>(0));
  EXPECT_EQ(map.nearest_free_tail({100.5, -17.4}, {}), std::optional<std::size_t>(3));
}

TEST(GoalVectorMap, NextFollowsTheStripAndStopsAtItsEnd) {
  const GoalVectorMap map(spec(100, -20, 110, -15, 2, 4, Heading::kEast), grid_1m());
  ASSERT_EQ(map.arrows().size(), 9u);
  for (std::size_t i = 0; i < 9; ++i) {
    if (i % 3 == 2) {
      EXPECT_FALSE(map.next(i).has_value()) << i;
    } else {
      EXPECT_EQ(map.next(i), std::optional<std::size_t>(i + 1)) << i;
    }
  }
  EXPECT_THROW(map.next(9), InvalidArgument);
  EXPECT_THROW(map.next(std::numeric_limits<std::size_t>::max()), InvalidArgument);
}

TEST(GoalVectorMap, HeadingNamesRoundTrip) {
  for (Heading h : {Heading::kEast, Heading::kWest, Heading::kNorth, Heading::kSouth})
    EXPECT_EQ(heading_from_string(to_string(h)), h);
  EXPECT_EQ(to_string(Heading::kSouth), "south");
  EXPECT_THROW(heading_from_string("up"), InvalidArgument);
  EXPECT_THROW(heading_from_string("East"), InvalidArgument);
}

// The message of the error a spec raises (empty when it builds).
std::string error_of(const GoalVectorMapSpec& s, const GridGeometry& g = grid_1m()) {
  try {
    GoalVectorMap map(s, g);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return {};
}

TEST(GoalVectorMap, RejectsBadSpecsWithClearMessages) {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  const GoalVectorMapSpec good = spec(100, -20, 110, -15, 2, 4, Heading::kEast);
  ASSERT_EQ(error_of(good), "");
  const auto with = [&](auto change) {
    GoalVectorMapSpec s = good;
    change(s);
    return error_of(s);
  };
  const auto contains = [](const std::string& what, const std::string& part) {
    return what.find(part) != std::string::npos;
  };
  // Not finite: every field.
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.area.x0 = nan; }), "x0_m is nan"));
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.area.y0 = nan; }), "y0_m"));
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.area.x1 = inf; }), "x1_m is inf"));
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.area.y1 = nan; }), "y1_m"));
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.strip_width_m = nan; }), "strip_width_m"));
  EXPECT_TRUE(contains(with([&](GoalVectorMapSpec& s) { s.arrow_length_m = -inf; }), "arrow_length_m"));
  // Empty rectangles.
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.x1 = s.area.x0; }), "is empty"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.x1 = 99; }), "is empty"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.y1 = -20; }), "is empty"));
  // Outside the grid [100, 112] x [-20, -8], on each side.
  EXPECT_TRUE(
      contains(with([](GoalVectorMapSpec& s) { s.area.x0 = 99.9; }), "not inside the grid [100, 112] x [-20, -8]"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.x1 = 112.1; }), "not inside the grid"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.y0 = -20.01; }), "not inside the grid"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.y1 = -7.5; }), "not inside the grid"));
  EXPECT_EQ(with([](GoalVectorMapSpec& s) {
              s.area.x1 = 112;
              s.area.y1 = -8;
            }),
            "");  // touching the edges is inside
  // Non-positive strip width or arrow length.
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.strip_width_m = 0; }), "strip_width_m is 0, must be > 0"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.strip_width_m = -1; }), "must be > 0"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.arrow_length_m = 0; }), "arrow_length_m is 0, must be > 0"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.arrow_length_m = -4; }), "must be > 0"));
  // Strips narrower than a cell: all of them, or the last one (5.5 m across in strips of 2.5 m leaves 0.5 m).
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.strip_width_m = 0.75; }), "narrower than one cell (1 m)"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) {
                         s.area.y1 = -14.5;
                         s.strip_width_m = 2.5;
                       }),
                       "strip 2 of 3 is only 0.5 m wide, narrower than one cell"));
  EXPECT_EQ(with([](GoalVectorMapSpec& s) {
              s.area.y1 = -14;
              s.strip_width_m = 2.5;
            }),
            "");  // last strip 1 m
  // Arrows shorter than a cell, and a site whose upwind and downwind cells coincide.
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.arrow_length_m = 0.5; }), "shorter than one cell"));
  EXPECT_TRUE(contains(with([](GoalVectorMapSpec& s) { s.area.x1 = 101; }), "only 1 m long along heading east"));
  EXPECT_EQ(with([](GoalVectorMapSpec& s) { s.area.x1 = 102; }), "");  // two cells: one arrow of one cell
  for (Heading h : {Heading::kWest, Heading::kNorth, Heading::kSouth}) {
    GoalVectorMapSpec s = good;
    s.heading = h;
    s.area.x0 = 99;
    EXPECT_TRUE(contains(error_of(s), "not inside the grid")) << to_string(h);
    s = good;
    s.heading = h;
    s.strip_width_m = 0.5;
    EXPECT_TRUE(contains(error_of(s), "narrower than one cell")) << to_string(h);
  }
  EXPECT_THROW(GoalVectorMap(good, GridGeometry{0, 12, 100.0, -20.0, 1.0}), InvalidArgument);
}

}  // namespace
}  // namespace marsala
