#include "marsala/core/route_sites.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "marsala/core/error.hpp"

namespace marsala {
namespace {

// Terraces falling to the east, as tests/integration/scenarios/path_three_gaps.pbtxt: 40 x 240 cells of 0.25 m,
// cliffs 0.8 m high at x = 15, 30 and 45 m. Below each cliff the kappa-0.2 gap of the cell k cells past it is
// 0.8 - 0.05 k (k = 1..15, centres 0.25 k - 0.125 m past the cliff; the cell next to the cliff is 0.25 m from the top
// terrace's last centre): 15 cells, gap sum 6 m, so 6 * 0.0625 m^2 = 0.375 m^3 per band row.
Heightmap three_cliffs() {
  Heightmap h(GridGeometry{40, 240, 0.0, 0.0, 0.25});
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const double x = h.cell_center({r, c}).x;
      h(r, c) = 0.8 * ((x < 15.0) + (x < 30.0) + (x < 45.0));
    }
  return h;
}

// From (5.125, 5.125) m to (56.125, 5.125) m: row 19, columns 20 .. 224.
constexpr CellIndex kFrom{19, 20}, kTo{19, 224};

RouteSiteParams params(double width_m) {
  RouteSiteParams p;
  p.width_m = width_m;
  p.min_natural_m = 2.0;
  return p;
}

TEST(RouteSites, ThreeCliffsGiveThreeSitesWhereTheRampsLie) {
  const Heightmap terrain = three_cliffs();
  const RouteSites r = plan_route_sites(route_gap(terrain, 0.2), kFrom, kTo, params(2.0));
  ASSERT_EQ(r.route.size(), 205u);  // the straight line: no detour saves gap on terraces
  for (const CellIndex& c : r.route) EXPECT_EQ(c.row, 19);
  EXPECT_DOUBLE_EQ(r.length_m, 51.0);
  // A 2 m band is 9 rows wide (ball of radius 4 cells): 9 * 0.375 = 3.375 m^3 per cliff.
  EXPECT_NEAR(r.band_volume_m3, 3 * 3.375, 1e-9);
  ASSERT_EQ(r.sites.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    // Cells 60 + 60 k .. 74 + 60 k need a ramp: 10 + 15 k .. 13.5 + 15 k m from column 20.
    EXPECT_DOUBLE_EQ(r.sites[k].from_m, 10.0 + 15.0 * k) << k;
    EXPECT_DOUBLE_EQ(r.sites[k].to_m, 13.5 + 15.0 * k) << k;
    EXPECT_NEAR(r.sites[k].volume_m3, 3.375, 1e-9) << k;
    EXPECT_NEAR(r.sites[k].max_gap_m, 0.75, 1e-9) << k;
  }
  EXPECT_EQ(r.from_gap_m, 0.0);
  EXPECT_EQ(r.to_gap_m, 0.0);
}

TEST(RouteSites, ShallowGapsAndShortNaturalGround) {
  const Heightmap gap = route_gap(three_cliffs(), 0.2);
  // Only gaps >= 0.3 m count: k = 1..10, 10 .. 12.25 m; the volume stays the band's.
  RouteSiteParams deep = params(2.0);
  deep.min_depth_m = 0.3;
  const RouteSites d = plan_route_sites(gap, kFrom, kTo, deep);
  ASSERT_EQ(d.sites.size(), 3u);
  EXPECT_DOUBLE_EQ(d.sites[0].to_m, 12.25);
  EXPECT_NEAR(d.sites[0].volume_m3, 3.375, 1e-9);
  // 11.5 m of natural ground between sites: asking for 12 merges them into one.
  RouteSiteParams merged = params(2.0);
  merged.min_natural_m = 12.0;
  const RouteSites m = plan_route_sites(gap, kFrom, kTo, merged);
  ASSERT_EQ(m.sites.size(), 1u);
  EXPECT_DOUBLE_EQ(m.sites[0].from_m, 10.0);
  EXPECT_DOUBLE_EQ(m.sites[0].to_m, 43.5);
  EXPECT_NEAR(m.sites[0].volume_m3, 3 * 3.375, 1e-9);
}

TEST(RouteSites, LocalGapSeesOnlyItsSquare) {
  // Within 1 m (4 cells) of the cliff's top only k = 1..4 get a gap: 0.75 + 0.7 + 0.65 + 0.6 = 2.7 m per row.
  const RouteSites r = plan_route_sites(route_gap(three_cliffs(), 0.2, 1.0), kFrom, kTo, params(2.0));
  ASSERT_EQ(r.sites.size(), 3u);
  EXPECT_DOUBLE_EQ(r.sites[1].from_m, 25.0);
  EXPECT_DOUBLE_EQ(r.sites[1].to_m, 25.75);
  EXPECT_NEAR(r.sites[1].volume_m3, 9 * 2.7 * 0.0625, 1e-9);
}

TEST(RouteSites, LocalGapMatchesBruteForceAndTheWholeMarsWhenItSeesEverything) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 2.0);
  Heightmap h(GridGeometry{13, 17, 1.0, -2.0, 0.5});
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) h(r, c) = u(rng);
  const Heightmap whole = route_gap(h, 0.3);
  const Heightmap wide = route_gap(h, 0.3, 20.0);
  const Heightmap local = route_gap(h, 0.3, 1.5);  // 3 cells
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      EXPECT_NEAR(wide(r, c), whole(r, c), 1e-9) << r << "," << c;
      double best = h(r, c);
      for (int rr = 0; rr < h.rows(); ++rr)
        for (int cc = 0; cc < h.cols(); ++cc)
          if (std::abs(rr - r) <= 3 && std::abs(cc - c) <= 3)
            best = std::max(best, h(rr, cc) - 0.3 * 0.5 * std::hypot(rr - r, cc - c));
      EXPECT_NEAR(local(r, c), best - h(r, c), 1e-12) << r << "," << c;
    }
}

TEST(RouteSites, BadInputThrows) {
  const Heightmap gap = route_gap(three_cliffs(), 0.2);
  EXPECT_THROW(plan_route_sites(gap, {40, 0}, kTo, params(2.0)), InvalidArgument);
  EXPECT_THROW(plan_route_sites(gap, kFrom, {0, -1}, params(2.0)), InvalidArgument);
  EXPECT_THROW(plan_route_sites(gap, kFrom, kTo, params(0.0)), InvalidArgument);
  EXPECT_THROW(plan_route_sites(gap, kFrom, kTo, params(std::nan(""))), InvalidArgument);
  EXPECT_THROW(route_gap(three_cliffs(), 0.2, -1.0), InvalidArgument);
  EXPECT_THROW(route_gap(three_cliffs(), 0.0), InvalidArgument);
}

}  // namespace
}  // namespace marsala
