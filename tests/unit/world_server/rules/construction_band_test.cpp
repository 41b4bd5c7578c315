#include "marsala/world_server/rules/construction_band.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::world_server {
namespace {

// The band by its definition: a cell is in it when its centre lies within width / 2 of a route cell's centre.
bool in_band_by_distance(const std::vector<CellIndex>& route, CellIndex cell, double cs, double width_m) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const CellIndex& r : route) nearest = std::min(nearest, std::hypot(r.row - cell.row, r.col - cell.col) * cs);
  return nearest <= 0.5 * width_m + 1e-9;
}

TEST(ConstructionBand, ACrossAroundOneCellAndEverythingElseOutside) {
  // 5 x 5 cells of 1 m, route = the middle cell, band 2 m wide: the middle cell and its four edge neighbours (1 m
  // away; the corners are sqrt 2 m away). Every cell raised by 0.1 m: 20 cells outside, 2 m^3.
  const GridGeometry grid{5, 5, 0.0, 0.0, 1.0};
  const Heightmap initial(grid, 3.0);
  const Heightmap raised(grid, 3.1);
  const CellMask band = construction_band({{2, 2}}, 5, 5, 1.0, 2.0);
  EXPECT_EQ(band.cast<int>().sum(), 5);
  EXPECT_EQ(band(1, 2), 1);
  EXPECT_EQ(band(1, 1), 0);
  EXPECT_NEAR(deposited_outside_band_m3(initial, raised, band), 20 * 0.1, 1e-9);
}

TEST(ConstructionBand, LoweredCellsAndTheBandItselfCountNothing) {
  const GridGeometry grid{4, 6, 0.0, 0.0, 0.5};
  const Heightmap initial(grid, 1.0);
  Heightmap final_terrain = initial;
  final_terrain(0, 0) = 0.5;   // lowered, outside: counts 0
  final_terrain(3, 5) = 1.2;   // raised 0.2 m, outside: 0.2 x 0.25 = 0.05 m^3
  final_terrain(1, 2) = 1.7;   // raised, in the band (route cell)
  const CellMask band = construction_band({{1, 1}, {1, 2}, {1, 3}}, 4, 6, 0.5, 1.0);
  EXPECT_NEAR(deposited_outside_band_m3(initial, final_terrain, band), 0.05, 1e-12);
}

TEST(ConstructionBand, RandomRoutesAgreeWithTheDistanceDefinition) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    const int rows = 8 + static_cast<int>(rng() % 20), cols = 8 + static_cast<int>(rng() % 20);
    const double cs = trial % 2 == 0 ? 0.25 : 0.5;
    const double width = std::uniform_real_distribution<double>(0.2, 3.5)(rng);
    const GridGeometry grid{rows, cols, 10.0, 20.0, cs};
    // A random 8-connected walk, as the planner's routes are.
    std::vector<CellIndex> route{{static_cast<int>(rng() % rows), static_cast<int>(rng() % cols)}};
    for (int i = 0; i < 15; ++i) {
      const CellIndex last = route.back();
      route.push_back({std::clamp(last.row + static_cast<int>(rng() % 3) - 1, 0, rows - 1),
                       std::clamp(last.col + static_cast<int>(rng() % 3) - 1, 0, cols - 1)});
    }
    Heightmap initial(grid, 0.0), final_terrain(grid, 0.0);
    std::uniform_real_distribution<double> height(-1.0, 1.0);
    double expected = 0.0;
    const CellMask band = construction_band(route, rows, cols, cs, width);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        initial(r, c) = height(rng);
        final_terrain(r, c) = initial(r, c) + height(rng);
        const bool inside = in_band_by_distance(route, {r, c}, cs, width);
        EXPECT_EQ(band(r, c) != 0, inside) << "trial " << trial << " cell " << r << "," << c;
        if (!inside) expected += std::max(0.0, final_terrain(r, c) - initial(r, c)) * cs * cs;
      }
    EXPECT_NEAR(deposited_outside_band_m3(initial, final_terrain, band), expected, 1e-9) << "trial " << trial;
  }
}

TEST(ConstructionBand, FollowsThePayloadsFinalPathWhenItHasOneElseThePlannedRoute) {
  WorldState state;
  state.check.route.route = {{0, 0}, {1, 1}};
  EXPECT_EQ(band_route_cells(state, std::nullopt), state.check.route.route);
  PayloadRoute final_path;
  final_path.cells = {{5, 5}, {5, 6}, {5, 7}};
  EXPECT_EQ(band_route_cells(state, final_path), final_path.cells);
}

TEST(ConstructionBand, TerrainsOfDifferentSizesAreRefused) {
  const Heightmap a(GridGeometry{4, 4, 0.0, 0.0, 1.0}, 0.0), b(GridGeometry{4, 5, 0.0, 0.0, 1.0}, 0.0);
  EXPECT_THROW(deposited_outside_band_m3(a, b, CellMask::Zero(4, 4)), InvalidArgument);
  EXPECT_THROW(deposited_outside_band_m3(a, a, CellMask::Zero(4, 5)), InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
