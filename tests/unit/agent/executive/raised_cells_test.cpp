#include "marsala/agent/executive/raised_cells.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "marsala/core/error.hpp"
#include "marsala/core/mars_processor.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::executive {
namespace {

const NavigabilityParams kBody{0.3, 1.0, 0.05};

// A 10 x 12 window of 0.25 m cells placed at world cell (5, 7) of a 20 x 30 world grid.
deliberative::LocalMap window(const Heightmap& heights, const CellMask& known) {
  deliberative::LocalMap m = test::make_local_map(heights, Heightmap(heights.geometry(), 0.0), kBody, {5, 5},
                                                  std::nullopt);
  m.offset = {5, 7};
  m.known = known;
  return m;
}

TEST(RaisedCells, ACellIsRaisedWhenItStandsAboveItsFirstHeightByMoreThanTheTolerance) {
  const GridGeometry g{10, 12, 0.0, 0.0, 0.25};
  Heightmap h(g, 1.0);
  CellMask known = CellMask::Ones(10, 12);
  known(2, 3) = 0;  // not seen yet
  RaisedCells cells(20, 30);
  cells.observe(window(h, known));
  EXPECT_DOUBLE_EQ(cells.first_height_m({5 + 4, 7 + 4}), 1.0);
  EXPECT_TRUE(std::isnan(cells.first_height_m({5 + 2, 7 + 3})));
  EXPECT_TRUE(std::isnan(cells.first_height_m({0, 0})));   // never in a window
  EXPECT_TRUE(std::isnan(cells.first_height_m({-1, 0})));  // off the grid
  // Raised since: (4, 4) by two layers of 0.016 m, (4, 5) by less than the tolerance, (2, 3) first seen raised.
  h(4, 4) = 1.032;
  h(4, 5) = 1.005;
  h(2, 3) = 1.5;
  known(2, 3) = 1;
  const deliberative::LocalMap now = window(h, known);
  cells.observe(now);
  const CellMask raised = cells.raised(now, 0.008);
  ASSERT_EQ(raised.rows(), 10);
  ASSERT_EQ(raised.cols(), 12);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 12; ++c) EXPECT_EQ(raised(r, c), r == 4 && c == 4 ? 1 : 0) << r << ", " << c;
  EXPECT_DOUBLE_EQ(cells.first_height_m({5 + 2, 7 + 3}), 1.5);  // its first height is what the map first held
  EXPECT_EQ(cells.raised(now, 0.05)(4, 4), 0);                   // a larger tolerance
}

TEST(RaisedCells, AWindowReachingOffTheGridAndAnUnknownCellAreLeftOut) {
  const GridGeometry g{10, 12, 0.0, 0.0, 0.25};
  Heightmap h(g, 0.0);
  deliberative::LocalMap m = window(h, CellMask::Ones(10, 12));
  m.offset = {15, 25};  // rows 15..24 and columns 25..36 of a 20 x 30 grid: partly off it
  RaisedCells cells(20, 30);
  cells.observe(m);
  EXPECT_DOUBLE_EQ(cells.first_height_m({19, 29}), 0.0);
  m.heights = Heightmap(g, 1.0);
  m.known(0, 0) = 0;
  const CellMask raised = cells.raised(m, 0.01);
  EXPECT_EQ(raised(0, 0), 0);  // unknown now
  EXPECT_EQ(raised(4, 4), 1);  // world (19, 29)
  EXPECT_EQ(raised(5, 4), 0);  // world (20, 29): off the grid
}

TEST(FirstSeenGap, CellsBesideABuiltStripKeepThePriceOfTheTerrainFirstSeen) {
  // A slope falling 0.1 m per cell along the columns (steeper than kappa 0.2 on 0.25 m cells), first seen as it is;
  // then a strip of row 4 raised by 0.3 m (built). Brute force: the cones of slope kappa from the first heights.
  const double kappa = 0.2;
  const GridGeometry g{10, 12, 0.0, 0.0, 0.25};
  Heightmap first(g, 0.0);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 12; ++c) first(r, c) = 2.0 - 0.1 * c;
  RaisedCells cells(20, 30);
  CellMask known = CellMask::Ones(10, 12);
  known(7, 9) = 0;  // never seen: counted at its current height
  cells.observe(window(first, known));
  Heightmap now = first;
  for (int c = 0; c < 12; ++c) now(4, c) += 0.3;
  now(7, 9) += 0.5;
  deliberative::LocalMap m = window(now, CellMask::Ones(10, 12));
  m.gap = MarsProcessor(kappa).gap(now);
  const Heightmap price = first_seen_gap(m, cells, kappa);
  Heightmap sources = first;
  sources(7, 9) = now(7, 9);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 12; ++c) {
      double top = sources(r, c);
      for (int qr = 0; qr < 10; ++qr)
        for (int qc = 0; qc < 12; ++qc)
          top = std::max(top, sources(qr, qc) - kappa * 0.25 * std::hypot(qr - r, qc - c));
      EXPECT_NEAR(price(r, c), std::min(m.gap(r, c), std::max(0.0, top - now(r, c))), 1e-9) << r << ", " << c;
    }
  // Beside the strip (row 5) the built 0.3 m raise the window's gap; the price is the natural slope's alone.
  EXPECT_GT(m.gap(5, 6), price(5, 6) + 0.2);
  EXPECT_NEAR(price(4, 6), 0.0, 1e-12);  // the strip itself stands above the first terrain's bound: free
}

TEST(RaisedCells, RefusesAnEmptyGrid) {
  EXPECT_THROW(RaisedCells(0, 5), InvalidArgument);
  EXPECT_THROW(RaisedCells(5, -1), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::executive
