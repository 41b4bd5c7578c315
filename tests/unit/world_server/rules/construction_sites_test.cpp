#include "marsala/world_server/rules/construction_sites.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "marsala/core/error.hpp"

namespace marsala::world_server {
namespace {

// 20 x 100 cells of 0.5 m (10 x 50 m); the route runs along row 10 from column 0 to 99 (49.5 m).
const GridGeometry kGrid{20, 100, 0.0, 0.0, 0.5};

PayloadRoute row_route() {
  PayloadRoute r;
  for (int c = 0; c < 100; ++c) r.cells.push_back({10, c});
  r.length_m = 99 * 0.5;
  return r;
}

void raise(Heightmap& h, int r0, int r1, int c0, int c1, double dz) {
  for (int r = r0; r <= r1; ++r)
    for (int c = c0; c <= c1; ++c) h(r, c) += dz;
}

TEST(ConstructionSites, ThreeSitesWithNaturalGroundBetween) {
  const Heightmap initial(kGrid, 1.0);
  Heightmap built = initial;
  raise(built, 8, 12, 10, 19, 0.2);   // site 1: columns 10..19 (5.0 .. 9.5 m), 5 x 10 cells
  raise(built, 9, 11, 40, 45, 0.5);   // site 2: columns 40..45 (20.0 .. 22.5 m), 3 x 6 cells
  raise(built, 10, 10, 70, 89, 0.1);  // site 3: columns 70..89 (35.0 .. 44.5 m), 1 x 20 cells
  raise(built, 0, 2, 50, 60, 1.0);    // off the route: counted in no site
  const auto sites = construction_sites(initial, built, row_route(), 2.0);
  ASSERT_EQ(sites.size(), 3u);
  EXPECT_DOUBLE_EQ(sites[0].from_m, 5.0);
  EXPECT_DOUBLE_EQ(sites[0].to_m, 9.5);
  EXPECT_EQ(sites[0].cells, 50);
  EXPECT_NEAR(sites[0].volume_m3, 50 * 0.2 * 0.25, 1e-9);
  EXPECT_DOUBLE_EQ(sites[1].from_m, 20.0);
  EXPECT_DOUBLE_EQ(sites[1].to_m, 22.5);
  EXPECT_NEAR(sites[1].volume_m3, 18 * 0.5 * 0.25, 1e-9);
  EXPECT_DOUBLE_EQ(sites[2].from_m, 35.0);
  EXPECT_DOUBLE_EQ(sites[2].to_m, 44.5);
  EXPECT_EQ(sites[2].cells, 20);
}

TEST(ConstructionSites, ShortNaturalStretchesDoNotSeparateSites) {
  const Heightmap initial(kGrid, 0.0);
  Heightmap built = initial;
  raise(built, 10, 10, 10, 19, 0.1);
  raise(built, 10, 10, 23, 30, 0.1);  // 3 unraised cells (columns 20..22): 2.0 m from column 19 to 23
  raise(built, 10, 10, 36, 40, 0.1);  // 5 unraised cells: 3.0 m from column 30 to 36
  auto sites = construction_sites(initial, built, row_route(), 2.5);
  ASSERT_EQ(sites.size(), 2u);  // 2.0 m < 2.5 m merges the first two, 3.0 m separates the third
  EXPECT_DOUBLE_EQ(sites[0].from_m, 5.0);
  EXPECT_DOUBLE_EQ(sites[0].to_m, 15.0);
  EXPECT_EQ(sites[0].cells, 18);
  EXPECT_DOUBLE_EQ(sites[1].from_m, 18.0);
  sites = construction_sites(initial, built, row_route(), 1.0);
  EXPECT_EQ(sites.size(), 3u);
}

TEST(ConstructionSites, ARegionCrossedTwiceCountsOnceWithTheFirstSite) {
  // A U-shaped structure: the route crosses its two arms, joined away from the route.
  const Heightmap initial(kGrid, 0.0);
  Heightmap built = initial;
  raise(built, 5, 12, 20, 21, 0.1);  // arm 1 (crosses row 10 at columns 20, 21)
  raise(built, 5, 12, 40, 41, 0.1);  // arm 2
  raise(built, 5, 6, 22, 39, 0.1);   // the bottom of the U, rows 5..6
  const auto sites = construction_sites(initial, built, row_route(), 2.0);
  ASSERT_EQ(sites.size(), 2u);
  EXPECT_EQ(sites[0].cells, 2 * 8 * 2 + 2 * 18);
  EXPECT_EQ(sites[1].cells, 0);
  EXPECT_DOUBLE_EQ(sites[1].volume_m3, 0.0);
}

TEST(ConstructionSites, DiagonalStepsCountTheirLengthAndNothingBuiltIsNoSite) {
  const Heightmap initial(kGrid, 0.0);
  Heightmap built = initial;
  PayloadRoute diagonal;
  for (int i = 0; i < 10; ++i) diagonal.cells.push_back({i, i});
  built(9, 9) += 0.1;
  const auto sites = construction_sites(initial, built, diagonal, 1.0);
  ASSERT_EQ(sites.size(), 1u);
  EXPECT_NEAR(sites[0].from_m, 9 * 0.5 * std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(construction_sites(initial, initial, diagonal, 1.0).empty());
}

TEST(ConstructionSites, MismatchedTerrainsOrARouteOffTheGridAreRefused) {
  const Heightmap initial(kGrid, 0.0);
  const Heightmap other({10, 10, 0.0, 0.0, 0.5}, 0.0);
  EXPECT_THROW(construction_sites(initial, other, row_route(), 1.0), InvalidArgument);
  PayloadRoute off;
  off.cells = {{0, 0}, {20, 0}};
  EXPECT_THROW(construction_sites(initial, initial, off, 1.0), InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
