#include "marsala/core/segment_cells.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "marsala/core/error.hpp"

namespace marsala {
namespace {

// A grid placed off the origin, large enough that every segment of these tests stays on it.
const GridGeometry kGrid{200, 300, 10.0, -5.0, 0.1};

/// Length of the segment a -> b inside the closed square of `cell` (Liang-Barsky clipping) [m].
double length_inside(const GridGeometry& g, CellIndex cell, Position a, Position b) {
  const Position c = g.cell_center(cell);
  const double h = 0.5 * g.cell_size_m;
  double t0 = 0.0, t1 = 1.0;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const auto clip = [&](double p, double q) {  // keep p t <= q
    if (p == 0.0) return q >= 0.0;
    const double t = q / p;
    if (p < 0.0) t0 = std::max(t0, t);
    else t1 = std::min(t1, t);
    return t0 <= t1;
  };
  if (!clip(-dx, a.x - (c.x - h)) || !clip(dx, (c.x + h) - a.x) || !clip(-dy, a.y - (c.y - h)) ||
      !clip(dy, (c.y + h) - a.y))
    return 0.0;
  return (t1 - t0) * std::hypot(dx, dy);
}

TEST(SegmentCells, AgreesWithDenseSamplingOnRandomSegments) {
  // The reference: the cells of 20001 points along the segment, by GridGeometry::cell_at. Sampling can miss a cell
  // the segment clips over less than two sample spacings (near a corner); every other cell must match, in order.
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> x(12.0, 38.0), y(-3.0, 13.0), len(0.0, 1.2), angle(0.0, 6.283185307179586);
  constexpr int kSamples = 20001;
  int missed_by_sampling = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Position a{x(rng), y(rng)};
    const double l = len(rng), phi = angle(rng);
    const Position b{a.x + l * std::cos(phi), a.y + l * std::sin(phi)};
    const std::vector<CellIndex> cells = cells_on_segment(kGrid, a, b);
    std::vector<CellIndex> sampled;
    for (int i = 0; i < kSamples; ++i) {
      const double t = static_cast<double>(i) / (kSamples - 1);
      const auto c = kGrid.cell_at({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
      ASSERT_TRUE(c.has_value());
      if (sampled.empty() || !(sampled.back() == *c)) sampled.push_back(*c);
    }
    ASSERT_EQ(cells.front(), sampled.front());
    ASSERT_EQ(cells.back(), sampled.back());
    std::size_t j = 0;
    for (const CellIndex& c : cells) {
      if (j < sampled.size() && sampled[j] == c) {
        ++j;
        continue;
      }
      ++missed_by_sampling;
      EXPECT_LT(length_inside(kGrid, c, a, b), 2.0 * l / (kSamples - 1))
          << "trial " << trial << ": cell (" << c.row << ", " << c.col << ") not sampled";
    }
    ASSERT_EQ(j, sampled.size()) << "trial " << trial << ": a sampled cell is missing or out of order";
    // Each cell once, and consecutive cells are neighbours (8-connected): the segment is continuous.
    for (std::size_t i = 1; i < cells.size(); ++i) {
      EXPECT_LE(std::abs(cells[i].row - cells[i - 1].row), 1);
      EXPECT_LE(std::abs(cells[i].col - cells[i - 1].col), 1);
      for (std::size_t k = 0; k < i; ++k) EXPECT_FALSE(cells[k] == cells[i]);
    }
  }
  EXPECT_LT(missed_by_sampling, 20);  // a handful of near-corner clips, no more
}

TEST(SegmentCells, ADiagonalThroughACornerTouchesNeitherSideCell) {
  // Centre to centre diagonally, all four ways: the segment passes the shared corner only.
  const CellIndex from{100, 100};
  for (const auto& [dr, dc] : std::vector<std::pair<int, int>>{{1, 1}, {1, -1}, {-1, 1}, {-1, -1}}) {
    const CellIndex to{from.row + dr, from.col + dc};
    const std::vector<CellIndex> cells = cells_on_segment(kGrid, kGrid.cell_center(from), kGrid.cell_center(to));
    ASSERT_EQ(cells.size(), 2u) << dr << ", " << dc;
    EXPECT_EQ(cells[0], from);
    EXPECT_EQ(cells[1], to);
  }
}

TEST(SegmentCells, StraightMovesListEveryCellInOrder) {
  const Position a = kGrid.cell_center({50, 60});
  const std::vector<CellIndex> east = cells_on_segment(kGrid, a, {a.x + 0.33, a.y});
  EXPECT_EQ(east, (std::vector<CellIndex>{{50, 60}, {50, 61}, {50, 62}, {50, 63}}));
  const std::vector<CellIndex> north = cells_on_segment(kGrid, a, {a.x, a.y + 0.2});
  EXPECT_EQ(north, (std::vector<CellIndex>{{50, 60}, {49, 60}, {48, 60}}));
  EXPECT_EQ(cells_on_segment(kGrid, a, a), (std::vector<CellIndex>{{50, 60}}));
}

TEST(SegmentCells, AlongABoundaryThePointsBelongToTheirHalfOpenCell) {
  // y on the line between rows 50 and 49: by cell_at, such points are in the northern cell (row 49).
  const double y = kGrid.cell_center({49, 60}).y - 0.05;
  const double x = kGrid.cell_center({49, 60}).x;
  const std::vector<CellIndex> cells = cells_on_segment(kGrid, {x, y}, {x + 0.2, y});
  ASSERT_EQ(kGrid.cell_at({x, y}), (CellIndex{49, 60}));
  EXPECT_EQ(cells, (std::vector<CellIndex>{{49, 60}, {49, 61}, {49, 62}}));
  // Ending exactly on a vertical boundary: the end is in the eastern cell, which the motion reaches.
  const Position c = kGrid.cell_center({20, 20});
  const std::vector<CellIndex> to_edge = cells_on_segment(kGrid, c, {c.x + 0.05, c.y});
  EXPECT_EQ(to_edge, (std::vector<CellIndex>{{20, 20}, {20, 21}}));
}

TEST(SegmentCells, OffTheGridIndicesAreReportedNotDropped) {
  const GridGeometry small{4, 4, 0.0, 0.0, 1.0};
  const std::vector<CellIndex> cells = cells_on_segment(small, {3.5, 0.5}, {5.5, 0.5});
  EXPECT_EQ(cells, (std::vector<CellIndex>{{3, 3}, {3, 4}, {3, 5}}));
}

TEST(SegmentCells, NonFiniteCoordinatesAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(cells_on_segment(kGrid, {nan, 0.0}, {1.0, 0.0}), InvalidArgument);
  EXPECT_THROW(cells_on_segment(kGrid, {1.0, 0.0}, {1.0, std::numeric_limits<double>::infinity()}), InvalidArgument);
}

}  // namespace
}  // namespace marsala
