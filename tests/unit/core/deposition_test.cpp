#include "marsala/core/deposition.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala {
namespace {

Heightmap gap_grid(int rows, int cols, double cs) {
  Heightmap gap({rows, cols, 0.0, 0.0, cs});
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) gap(r, c) = 0.01 * (r * cols + c);
  return gap;
}

TEST(DepositionTargetVolume, SumsGapTimesCellArea) {
  const Heightmap gap = gap_grid(3, 4, 0.5);
  // Cells (0,1) = 0.01, (2,3) = 0.11: (0.01 + 0.11) * 0.25 m^2.
  EXPECT_NEAR(deposition_target_volume(gap, std::vector<CellIndex>{{0, 1}, {2, 3}}), 0.03, 1e-15);
  // Whole grid: 0.01 * (0 + ... + 11) * 0.25 = 0.165.
  EXPECT_NEAR(deposition_target_volume(gap), 0.165, 1e-15);
}

TEST(DepositionTargetVolume, CountsRepeatedCellsOnce) {
  const Heightmap gap = gap_grid(2, 2, 1.0);
  EXPECT_DOUBLE_EQ(deposition_target_volume(gap, std::vector<CellIndex>{{1, 1}, {1, 1}, {1, 1}}), 0.03);
}

TEST(DepositionTargetVolume, RejectsBadInput) {
  Heightmap gap = gap_grid(2, 2, 1.0);
  EXPECT_THROW(deposition_target_volume(gap, std::vector<CellIndex>{{2, 0}}), InvalidArgument);
  EXPECT_THROW(deposition_target_volume(gap, CellMask::Ones(3, 2)), InvalidArgument);
  gap(0, 0) = -0.1;
  EXPECT_THROW(deposition_target_volume(gap), InvalidArgument);
  gap(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(deposition_target_volume(gap), InvalidArgument);
}

TEST(PathFootprint, IsTheUnionOfBallsAlongThePath) {
  const GridGeometry g{10, 10, 0.0, 0.0, 0.1};
  // delta 0.2 m at 0.1 m cells: a ball of radius 1 cell, 5 cells (a plus sign).
  const CellMask one = path_footprint(g, {{5, 5}}, 0.2);
  EXPECT_EQ(one.cast<int>().sum(), 5);
  // Two adjacent path cells: two plus signs sharing 2 cells -> 8.
  const CellMask two = path_footprint(g, {{5, 5}, {5, 6}}, 0.2);
  EXPECT_EQ(two.cast<int>().sum(), 8);
  // A ball at the corner is clipped: (0,0), (0,1), (1,0).
  EXPECT_EQ(path_footprint(g, {{0, 0}}, 0.2).cast<int>().sum(), 3);
  EXPECT_THROW(path_footprint(g, {{10, 0}}, 0.2), InvalidArgument);
  EXPECT_THROW(path_footprint(g, {{1, 1}}, 0.0), InvalidArgument);
}

// The footprint against the cells whose centres lie within delta / 2 of a path cell's centre (the ball's tolerance
// of ARCHITECTURE.md), for several body lengths and paths along and across the grid's edges.
TEST(PathFootprint, EqualsTheCellsWithinHalfABodyOfThePath) {
  const GridGeometry g{13, 17, 0.0, 0.0, 0.1};
  const std::vector<std::vector<CellIndex>> paths = {
      {{0, 0}}, {{6, 8}}, {{12, 16}, {12, 15}, {11, 14}}, {{0, 3}, {1, 3}, {2, 4}, {3, 5}, {4, 5}}, {{6, 0}, {6, 16}}};
  for (const double delta_m : {0.1, 0.2, 0.3, 0.45, 0.6, 1.0})
    for (const auto& path : paths) {
      const CellMask footprint = path_footprint(g, path, delta_m);
      const double radius = delta_m / (2.0 * g.cell_size_m);
      for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
          bool in = false;
          for (const CellIndex p : path) {
            const double dr = r - p.row, dc = c - p.col;
            in = in || dr * dr + dc * dc <= radius * radius + 1e-9;
          }
          EXPECT_EQ(footprint(r, c) != 0, in) << "delta " << delta_m << " cell (" << r << ", " << c << ")";
        }
    }
}

}  // namespace
}  // namespace marsala
