// The progress of a payload_path run (docs/runtime.md#progress): the payload's route planned on the initial terrain,
// its band and MARS bound checked against brute force on a small grid, the gap left on it as the band is filled, and
// the progress the world reports from it.

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "marsala/world_server/rules/completion.hpp"
#include "support/mars_brute_force.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::flat_terrain;
using testing::payload_block;
using testing::small_scenario_text_completing;

constexpr double kKappa = 0.2;   // payload_block(): kappa 0.2, delta 0.3 m
constexpr double kDeltaM = 0.3;  // its ball: the 3 x 3 cells around a cell (1.5 cells, corners at sqrt 2)

scenario::Scenario payload_scenario() {
  return scenario::parse_scenario(small_scenario_text_completing(payload_block(1)), "small.pbtxt");
}

/// 40 x 40 cells of 0.1 m: a terrace 0.3 m high west of column 18 holding the payload's start (row 34, col 5), the
/// ground at 0 east of it holding its end (row 9, col 30): a ramp of slope 0.2 (1.5 m) must be built down the edge.
Heightmap terrace() {
  Heightmap h = flat_terrain();
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < 18; ++c) h(r, c) = 0.3;
  return h;
}

/// The band by definition: cells whose centre lies within delta/2 of a route cell's centre (tie tolerance 1e-9 in
/// squared cell units, ARCHITECTURE.md), found by visiting every cell.
std::set<std::pair<int, int>> band_by_brute_force(const Heightmap& h, const std::vector<CellIndex>& route) {
  const double radius_cells = kDeltaM / (2.0 * h.cell_size_m());
  std::set<std::pair<int, int>> band;
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c)
      for (const CellIndex& p : route) {
        const double d2 = double(r - p.row) * (r - p.row) + double(c - p.col) * (c - p.col);
        if (d2 <= radius_cells * radius_cells + 1e-9) {
          band.insert({r, c});
          break;
        }
      }
  return band;
}

TEST(RouteGap, BandBoundAndVolumeAgreeWithBruteForce) {
  const Heightmap h = terrace();
  const scenario::Scenario s = payload_scenario();
  const RouteGap route = plan_route_gap(h, s.payload_path);

  ASSERT_GE(route.route.size(), 2u);
  EXPECT_EQ(route.route.front(), (CellIndex{34, 5}));
  EXPECT_EQ(route.route.back(), (CellIndex{9, 30}));
  for (std::size_t i = 1; i < route.route.size(); ++i) {
    const int dr = std::abs(route.route[i].row - route.route[i - 1].row);
    const int dc = std::abs(route.route[i].col - route.route[i - 1].col);
    EXPECT_TRUE(std::max(dr, dc) == 1) << "route cells " << i - 1 << " and " << i << " are not 8-adjacent";
  }

  const std::set<std::pair<int, int>> expected = band_by_brute_force(h, route.route);
  std::set<std::pair<int, int>> band;
  for (std::int64_t k : route.cells) band.insert({static_cast<int>(k / h.cols()), static_cast<int>(k % h.cols())});
  EXPECT_EQ(band, expected);
  ASSERT_EQ(route.cells.size(), route.ceiling_m.size());

  const Heightmap p = marsala::testing::mars_brute_force(h, kKappa);
  double volume = 0.0;
  for (std::size_t i = 0; i < route.cells.size(); ++i) {
    const int r = static_cast<int>(route.cells[i] / h.cols()), c = static_cast<int>(route.cells[i] % h.cols());
    EXPECT_NEAR(route.ceiling_m[i], p(r, c), 1e-9) << "cell " << r << ", " << c;
    volume += (p(r, c) - h(r, c)) * h.cell_size_m() * h.cell_size_m();
  }
  // The ramp down a 0.3 m edge at slope 0.2 is 1.5 m long: a few hundredths of a cubic metre on a 0.3 m band.
  EXPECT_GT(volume, 0.01);
  EXPECT_NEAR(route.initial_m3, volume, 1e-12);
  EXPECT_NEAR(route_gap_m3(h, route), volume, 1e-12);
}

TEST(RouteGap, FallsAsTheBandIsFilledAndAFilledBandIsANavigablePath) {
  Heightmap h = terrace();
  const scenario::Scenario s = payload_scenario();
  const RouteGap route = plan_route_gap(h, s.payload_path);
  EXPECT_FALSE(payload_path_navigable(h, s.payload_path));

  // Half of every band cell's gap filled: half the volume left. Cells off the band change nothing.
  const Heightmap p = marsala::testing::mars_brute_force(h, kKappa);
  Heightmap half = h;
  for (std::int64_t k : route.cells) {
    const int r = static_cast<int>(k / h.cols()), c = static_cast<int>(k % h.cols());
    half(r, c) += 0.5 * (p(r, c) - h(r, c));
  }
  half(0, 39) += 1.0;  // far from the route
  EXPECT_NEAR(route_gap_m3(half, route), 0.5 * route.initial_m3, 1e-12);

  // Filled up to the bound: no gap left, and the payload's path exists (the band is the route cells' balls).
  Heightmap filled = h;
  for (std::int64_t k : route.cells) {
    const int r = static_cast<int>(k / h.cols()), c = static_cast<int>(k % h.cols());
    filled(r, c) = p(r, c);
  }
  EXPECT_NEAR(route_gap_m3(filled, route), 0.0, 1e-12);
  EXPECT_TRUE(payload_path_navigable(filled, s.payload_path));

  // Overfilling never counts as negative gap.
  Heightmap over = filled;
  over(route.route.front()) += 1.0;
  EXPECT_NEAR(route_gap_m3(over, route), 0.0, 1e-12);
}

TEST(RouteGap, ProgressIsTheShareOfTheRoutesGapFilledAndOneWhenThePathIsFound) {
  WorldState w = make_world_state(payload_scenario(), terrace(), 1);
  ASSERT_FALSE(is_completed(w));
  const double initial = w.check.route.initial_m3;
  EXPECT_GT(initial, 0.0);
  EXPECT_EQ(w.check.route_gap_m3, initial);
  EXPECT_EQ(progress(w), 0.0);
  EXPECT_NE(progress_detail(w).find(" m3 of MARS gap left on the route"), std::string::npos)
      << progress_detail(w);

  // Fill the band in four passes, a quarter of each cell's initial gap each time, but the target's own cell (the run
  // completes only with it kept: docs/runtime.md#payload_path); the check after each pass.
  const Heightmap p = marsala::testing::mars_brute_force(terrace(), kKappa);
  const Heightmap start = terrace();
  const double cs2 = start.cell_size_m() * start.cell_size_m();
  const double kept = std::max(0.0, p(w.check.to) - start(w.check.to)) * cs2;  // the target's gap, never filled
  double last = progress(w);
  for (int pass = 1; pass <= 4; ++pass) {
    for (std::int64_t k : w.check.route.cells) {
      const CellIndex c{static_cast<int>(k / start.cols()), static_cast<int>(k % start.cols())};
      if (c == w.check.to) continue;
      w.terrain(c) = start(c) + 0.25 * pass * (p(c) - start(c));
      w.check.occupancy.mark_changed(c);
    }
    evaluate_completion(w);
    const double now = progress(w);
    EXPECT_GE(now, last) << "pass " << pass;
    if (!is_completed(w)) {
      EXPECT_NEAR(now, 0.25 * pass * (initial - kept) / initial, 1e-9) << "pass " << pass;
    }
    last = now;
  }
  EXPECT_TRUE(is_completed(w));
  EXPECT_EQ(progress(w), 1.0);
  EXPECT_EQ(progress_detail(w), "the payload's path is navigable");
}

}  // namespace
}  // namespace marsala::world_server
