#include "marsala/core/heightmap.hpp"

#include <gtest/gtest.h>

#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala {
namespace {

GridGeometry geometry(int rows, int cols, double cs = 0.5) { return {rows, cols, 10.0, 20.0, cs}; }

TEST(Heightmap, CellCentresFollowTheAscConvention) {
  const Heightmap map(geometry(4, 3));
  // Row 0 is northmost: its centre is half a cell below the top edge y = 20 + 4 * 0.5.
  EXPECT_DOUBLE_EQ(map.cell_center({0, 0}).x, 10.25);
  EXPECT_DOUBLE_EQ(map.cell_center({0, 0}).y, 21.75);
  EXPECT_DOUBLE_EQ(map.cell_center({3, 2}).x, 11.25);
  EXPECT_DOUBLE_EQ(map.cell_center({3, 2}).y, 20.25);
}

TEST(Heightmap, CellAtInvertsCellCenter) {
  const Heightmap map(geometry(5, 7));
  for (SubmapIterator it(map.geometry(), {0, 0}, 5, 7); !it.is_past_end(); ++it) {
    const auto back = map.cell_at(map.cell_center(*it));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, *it);
  }
  EXPECT_FALSE(map.cell_at({9.99, 21.0}).has_value());
  EXPECT_FALSE(map.cell_at({11.0, 22.5}).has_value());
}

TEST(Heightmap, CheckedAccessThrowsOffGrid) {
  Heightmap map(geometry(2, 2), 1.5);
  EXPECT_DOUBLE_EQ(map.at({1, 1}), 1.5);
  EXPECT_THROW(map.at({2, 0}), InvalidArgument);
  EXPECT_THROW(map.at({0, -1}), InvalidArgument);
}

TEST(Heightmap, RejectsBadGeometry) {
  EXPECT_THROW(Heightmap(geometry(0, 3)), InvalidArgument);
  EXPECT_THROW(Heightmap(geometry(3, 3, 0.0)), InvalidArgument);
  EXPECT_THROW(Heightmap(geometry(3, 3, -1.0)), InvalidArgument);
}

TEST(Heightmap, WindowKeepsWorldPositions) {
  Heightmap map(geometry(6, 5));
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 5; ++c) map(r, c) = r * 10 + c;
  const Heightmap win = map.window({2, 1}, 3, 2);
  ASSERT_EQ(win.rows(), 3);
  ASSERT_EQ(win.cols(), 2);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 2; ++c) {
      EXPECT_DOUBLE_EQ(win(r, c), map(r + 2, c + 1));
      EXPECT_DOUBLE_EQ(win.cell_center({r, c}).x, map.cell_center({r + 2, c + 1}).x);
      EXPECT_DOUBLE_EQ(win.cell_center({r, c}).y, map.cell_center({r + 2, c + 1}).y);
    }
  EXPECT_THROW(map.window({4, 4}, 3, 2), InvalidArgument);
}

TEST(Iterators, DiscOffsetsHonourTheTieTolerance) {
  // 0.6 / 0.2 is 2.9999999999999996 in floating point; (3, 0) must still be in the ball.
  const auto offsets = disc_offsets(0.6 / 0.2 / 2.0 * 2.0);
  bool has_three = false;
  for (auto o : offsets) has_three |= (o.row == 3 && o.col == 0);
  EXPECT_TRUE(has_three);
  // Brute-force count of lattice points with dr^2 + dc^2 <= 9.
  EXPECT_EQ(offsets.size(), 29u);
  EXPECT_EQ(disc_offsets(0.0).size(), 1u);
  EXPECT_EQ(disc_offsets(1.0).size(), 5u);
}

TEST(Iterators, DiscIteratorClipsToGrid) {
  const GridGeometry g = geometry(4, 4, 1.0);
  int count = 0;
  for (DiscIterator it(g, {0, 0}, 1.0); !it.is_past_end(); ++it) {
    EXPECT_TRUE(g.contains(*it));
    ++count;
  }
  EXPECT_EQ(count, 3);  // (0,0), (0,1), (1,0)
}

TEST(Iterators, SubmapIteratorVisitsEachCellOnce) {
  const GridGeometry g = geometry(5, 5);
  int count = 0;
  for (SubmapIterator it(g, {3, -1}, 4, 3); !it.is_past_end(); ++it) ++count;
  EXPECT_EQ(count, 2 * 2);  // rows 3..4, cols 0..1
}

TEST(Iterators, LineIteratorIsEightConnectedAndEndsAtTheTarget) {
  const GridGeometry g = geometry(20, 20);
  const CellIndex start{2, 3}, end{15, 9};
  CellIndex previous = start;
  int count = 0;
  CellIndex last{};
  for (LineIterator it(g, start, end); !it.is_past_end(); ++it, ++count) {
    if (count > 0) {
      EXPECT_LE(std::abs((*it).row - previous.row), 1);
      EXPECT_LE(std::abs((*it).col - previous.col), 1);
    }
    previous = last = *it;
  }
  EXPECT_EQ(last, end);
  EXPECT_EQ(count, 14);  // max(|13|, |6|) + 1 cells
}

}  // namespace
}  // namespace marsala
