#include "marsala/core/cell_occupancy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala {
namespace {

TEST(CellOccupiable, MatchesTheNavigabilityProcessorOnRoughTerrains) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    GridGeometry g;
    g.rows = 18 + trial;
    g.cols = 23 - trial;
    g.cell_size_m = 0.1;
    Heightmap h(g, 0.0);
    // Smooth noise below eps with sparse spikes: cells near a spike are not occupiable, the others are.
    std::uniform_real_distribution<double> noise(0.0, 0.02), spike(0.0, 1.0);
    for (long long i = 0; i < h.size(); ++i) h.data()[i] = noise(rng) + (spike(rng) < 0.03 ? 0.3 : 0.0);
    const NavigabilityParams params{0.3, 0.4 + 0.15 * trial, 0.05};
    const CellMask want = NavigabilityProcessor(params).occupiable(h);
    const std::vector<CellIndex> ball = disc_offsets(params.delta_m / (2.0 * g.cell_size_m));
    int occupiable = 0;
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) {
        occupiable += want(r, c);
        ASSERT_EQ(cell_occupiable(h, {r, c}, params, OccupancyMethod::kPairs), want(r, c) != 0)
            << "trial " << trial << " cell " << r << ", " << c;
        ASSERT_EQ(cell_occupiable(h, {r, c}, params, OccupancyMethod::kWindow), want(r, c) != 0);
        ASSERT_EQ(cell_occupiable_in_ball(h, {r, c}, params, ball), want(r, c) != 0);
      }
    // Both answers occur, so the comparison means something.
    EXPECT_GT(occupiable, 0) << trial;
    EXPECT_LT(occupiable, h.size()) << trial;
  }
}

TEST(CellOccupiable, RampsExactlyAtKappaAreOccupiableOneLayerSteeperIsNot) {
  GridGeometry g;
  g.rows = 20;
  g.cols = 30;
  g.cell_size_m = 0.1;
  Heightmap ramp(g, 0.0);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) ramp(r, c) = 0.3 * (c * 0.1);  // slope exactly kappa, steps of eps = 0
  const NavigabilityParams params{0.3, 1.0, 0.0};
  const CellMask want = NavigabilityProcessor(params).occupiable(ramp);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      EXPECT_TRUE(cell_occupiable(ramp, {r, c}, params));
      EXPECT_EQ(want(r, c), 1);
    }
  Heightmap steeper = ramp;
  steeper(10, 15) += 0.0125;
  const CellMask want_steeper = NavigabilityProcessor(params).occupiable(steeper);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c)
      ASSERT_EQ(cell_occupiable(steeper, {r, c}, params), want_steeper(r, c) != 0) << r << ", " << c;
  EXPECT_FALSE(cell_occupiable(steeper, {10, 15}, params));
  EXPECT_TRUE(cell_occupiable(steeper, {10, 2}, params));
}

TEST(CellOccupiable, BigBallsUseTheWindowAndAgree) {
  GridGeometry g;
  g.rows = 70;
  g.cols = 70;
  g.cell_size_m = 0.1;
  Heightmap h(g, 0.0);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) h(r, c) = (r + c) % 7 == 0 ? 0.04 : 0.0;
  h(5, 5) = 3.0;                                    // a pillar near a corner
  const NavigabilityParams params{0.3, 6.0, 0.05};  // ball radius 30 cells: about 2800 cells
  const CellMask want = NavigabilityProcessor(params).occupiable(h);
  int occupiable = 0;
  for (const CellIndex c :
       {CellIndex{35, 35}, CellIndex{5, 40}, CellIndex{60, 60}, CellIndex{20, 20}, CellIndex{5, 30}}) {
    occupiable += want(c.row, c.col);
    EXPECT_EQ(cell_occupiable(h, c, params), want(c.row, c.col) != 0);
    EXPECT_EQ(cell_occupiable(h, c, params, OccupancyMethod::kPairs), want(c.row, c.col) != 0);
  }
  EXPECT_EQ(occupiable, 3);  // the two within 30 cells of the pillar are not
}

TEST(CellOccupiable, OffGridThrows) {
  GridGeometry g;
  g.rows = 4;
  g.cols = 4;
  EXPECT_THROW(cell_occupiable(Heightmap(g, 0.0), {4, 0}, {}), InvalidArgument);
  EXPECT_THROW(cell_occupiable(Heightmap(g, 0.0), {0, -1}, {}), InvalidArgument);
  EXPECT_THROW(cell_occupiable_in_ball(Heightmap(g, 0.0), {0, 4}, {}, disc_offsets(1.0)), InvalidArgument);
}

/// A rough grid (cells of 0.1 m): up to 3 cm of noise, 0.3 m spikes on a share `spikes` of the cells and -0.25 m pits
/// on as many.
Heightmap spiky_grid(std::mt19937_64& rng, int rows, int cols, double spikes) {
  std::uniform_real_distribution<double> noise(0.0, 0.03), u(0.0, 1.0);
  Heightmap h({rows, cols, 0.0, 0.0, 0.1}, 0.0);
  for (long long i = 0; i < h.size(); ++i) {
    const double v = u(rng);
    h.data()[i] = noise(rng) + (v < spikes ? 0.3 : v < 2.0 * spikes ? -0.25 : 0.0);
  }
  return h;
}

TEST(OccupancyBreach, NamesThePairThatBreaksTheRuleByTheMostExactlyWhereTheCellIsNotOccupiable) {
  // Brute force over the ball's pairs on rough grids with spikes and pits: the breach is there exactly when the cell
  // is not occupiable, its cells lie in the ball, the lower first, and no pair breaks the rule by more.
  std::mt19937_64 rng(11);
  int breaches = 0, clear = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const Heightmap h = spiky_grid(rng, 15 + trial, 17, 0.02);
    const NavigabilityParams params{0.3, 0.5 + 0.1 * trial, 0.05};
    const std::vector<CellIndex> offsets = disc_offsets(params.delta_m / (2.0 * h.cell_size_m()));
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) {
        const std::optional<OccupancyBreach> breach = occupancy_breach(h, {r, c}, params);
        ASSERT_EQ(breach.has_value(), !cell_occupiable(h, {r, c}, params)) << trial << ": " << r << ", " << c;
        if (!breach) {
          ++clear;
          continue;
        }
        ++breaches;
        const auto in_ball = [&](CellIndex q) {
          return std::find(offsets.begin(), offsets.end(), CellIndex{q.row - r, q.col - c}) != offsets.end();
        };
        ASSERT_TRUE(in_ball(breach->low) && in_ball(breach->high));
        const auto excess = [&](CellIndex a, CellIndex b) {
          const double d = h.cell_size_m() * std::hypot(a.row - b.row, a.col - b.col);
          return std::abs(h(a) - h(b)) - (params.eps_m + params.kappa * d);
        };
        EXPECT_LT(h(breach->low), h(breach->high));
        const double named = excess(breach->low, breach->high);
        EXPECT_GT(named, 0.0);
        for (const CellIndex& a : offsets)
          for (const CellIndex& b : offsets) {
            const CellIndex p{r + a.row, c + a.col}, q{r + b.row, c + b.col};
            if (h.contains(p) && h.contains(q)) {
              ASSERT_LE(excess(p, q), named + 1e-12);
            }
          }
      }
  }
  // Both answers occur, so the comparison means something.
  EXPECT_GT(breaches, 0);
  EXPECT_GT(clear, 0);
  EXPECT_THROW(occupancy_breach(Heightmap({4, 4, 0.0, 0.0, 0.1}, 0.0), {4, 0}, {0.3, 0.5, 0.05}), InvalidArgument);
}

TEST(OccupancyBreach, AllBreachesNameEveryLowCellOfTheBallOnceWithItsWorstPartner) {
  // Brute force over the ball's pairs: the cells named low are exactly those of the ball that lie too far below
  // another, each once, with the partner it breaks the rule against by the most, the most first (so the first is the
  // ball's worst pair); none exactly where the cell is occupiable.
  std::mt19937_64 rng(17);
  int several = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const Heightmap h = spiky_grid(rng, 14 + trial, 16, 0.03);
    const NavigabilityParams params{0.3, 0.6 + 0.1 * trial, 0.05};
    const std::vector<CellIndex> offsets = disc_offsets(params.delta_m / (2.0 * h.cell_size_m()));
    const auto excess = [&](CellIndex a, CellIndex b) {
      const double d = h.cell_size_m() * std::hypot(a.row - b.row, a.col - b.col);
      return h(b) - h(a) - (params.eps_m + params.kappa * d);
    };
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) {
        std::vector<CellIndex> ball;
        for (const CellIndex& o : offsets)
          if (h.contains({r + o.row, c + o.col})) ball.push_back({r + o.row, c + o.col});
        std::map<CellIndex, double> expected;  // low cell -> its largest excess
        for (const CellIndex& p : ball)
          for (const CellIndex& q : ball)
            if (excess(p, q) > 1e-9) expected[p] = std::max(expected.count(p) ? expected[p] : 0.0, excess(p, q));
        const std::vector<OccupancyBreach> all = occupancy_breaches(h, {r, c}, params);
        ASSERT_EQ(all.size(), expected.size()) << trial << ": " << r << ", " << c;
        EXPECT_EQ(all.empty(), cell_occupiable(h, {r, c}, params));
        if (all.empty()) continue;
        if (all.size() > 1) ++several;
        double worst = 0.0;
        for (const auto& [low, most] : expected) worst = std::max(worst, most);
        EXPECT_NEAR(excess(all.front().low, all.front().high), worst, 1e-12);
        double before = std::numeric_limits<double>::infinity();
        std::set<CellIndex> seen;
        for (const OccupancyBreach& b : all) {
          ASSERT_EQ(expected.count(b.low), 1u);
          EXPECT_TRUE(seen.insert(b.low).second);
          EXPECT_NE(std::find(ball.begin(), ball.end(), b.high), ball.end());
          EXPECT_NEAR(excess(b.low, b.high), expected[b.low], 1e-12);
          EXPECT_LE(excess(b.low, b.high), before + 1e-12);
          before = excess(b.low, b.high);
        }
      }
  }
  EXPECT_GT(several, 0);  // balls with several low cells occur, so the list is tried
  EXPECT_THROW(occupancy_breaches(Heightmap({4, 4, 0.0, 0.0, 0.1}, 0.0), {0, 4}, {0.3, 0.5, 0.05}), InvalidArgument);
}

TEST(BlindCells, AreTheCellsWhoseBallHoldsAnUnknownCell) {
  std::mt19937 rng(3);
  std::bernoulli_distribution unknown(0.03);
  for (const double radius : {0.0, 1.0, 2.5, 4.0}) {
    CellMask known(23, 31);
    for (int r = 0; r < known.rows(); ++r)
      for (int c = 0; c < known.cols(); ++c) known(r, c) = unknown(rng) ? 0 : 1;
    const CellMask blind = blind_cells(known, radius);
    // From the definition: any unknown cell at a centre distance of at most the radius (tie tolerance 1e-9 cells^2).
    for (int r = 0; r < known.rows(); ++r)
      for (int c = 0; c < known.cols(); ++c) {
        bool expected = false;
        for (int q = 0; q < known.rows() && !expected; ++q)
          for (int p = 0; p < known.cols() && !expected; ++p)
            expected = known(q, p) == 0 && (q - r) * (q - r) + (p - c) * (p - c) <= radius * radius + 1e-9;
        EXPECT_EQ(blind(r, c) != 0, expected) << "radius " << radius << " cell " << r << "," << c;
      }
  }
  EXPECT_EQ(blind_cells(CellMask::Ones(5, 5), 3.0).maxCoeff(), 0);
}

}  // namespace
}  // namespace marsala
