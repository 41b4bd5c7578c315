// The material score against an independent computation on small grids: the MARS bound by brute force from its
// definition (P(p) = max over q of h(q) - kappa |p - q|), summed over the cells each kind of task needs.
#include "marsala/world_server/rules/material_score.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

/// P_kappa at cell (r, c) of the rows [r0, r0 + rows) x cols [c0, c0 + cols) of `h`, from the definition.
double brute_mars(const Heightmap& h, int r, int c, double kappa, int r0, int c0, int rows, int cols) {
  double best = -std::numeric_limits<double>::infinity();
  for (int qr = r0; qr < r0 + rows; ++qr)
    for (int qc = c0; qc < c0 + cols; ++qc)
      best = std::max(best, h(qr, qc) - kappa * h.cell_size_m() * std::hypot(qr - r, qc - c));
  return best;
}

Heightmap random_terrain(int rows, int cols, double cs, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> height(0.0, 1.0);
  Heightmap t(GridGeometry{rows, cols, 0.0, 0.0, cs});
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) t(r, c) = height(rng);
  return t;
}

TEST(MaterialScore, ASiteNeedsItsCropFilledToTheCropsOwnMarsBound) {
  const double cs = 0.5;
  const Heightmap initial = random_terrain(6, 8, cs, 7);
  WorldState state;
  state.terrain = initial;
  state.completion = scenario::CompletionKind::kLevelSite;
  state.site.navigability.kappa = 0.2;
  // Cell centres x = 0.25 + 0.5 c, y = 3 - 0.25 - 0.5 r: the crop is rows 1..3, cols 2..5.
  state.site.area = Rect{1.0, 1.0, 2.8, 2.5};
  double want = 0.0;
  for (int r = 1; r <= 3; ++r)
    for (int c = 2; c <= 5; ++c) want += brute_mars(initial, r, c, 0.2, 1, 2, 3, 4) - initial(r, c);
  want *= cs * cs;
  // Raise one crop cell and one cell outside it: only the second is off the band.
  state.terrain(2, 3) += 0.4;
  state.terrain(5, 0) += 0.3;
  state.deposited_volume_m3 = 0.7 * cs * cs;
  const MaterialScore s = material_score(state, initial, 99.0);
  EXPECT_NEAR(s.needed_m3, want, 1e-12);
  EXPECT_GT(s.needed_m3, 0.0);
  EXPECT_DOUBLE_EQ(s.deposited_m3, 0.7 * cs * cs);
  EXPECT_NEAR(s.ratio, 0.7 * cs * cs / want, 1e-12);
  EXPECT_NEAR(s.off_band_m3, 0.3 * cs * cs, 1e-12);
}

TEST(MaterialScore, APayloadNeedsItsRouteBandFilledToTheWholeGridsMarsBound) {
  const double cs = 1.0;
  Heightmap initial = random_terrain(7, 9, cs, 11);
  WorldState state;
  state.terrain = initial;
  state.completion = scenario::CompletionKind::kPayloadPath;
  state.payload_path.navigability = {0.3, 2.0, 0.05};
  state.payload_path.from = {0.5, 3.5};
  state.payload_path.to = {8.5, 3.5};
  state.check.route = plan_route_gap(initial, state.payload_path);
  ASSERT_FALSE(state.check.route.cells.empty());
  double want = 0.0;
  for (const std::int64_t i : state.check.route.cells) {
    const int r = static_cast<int>(i / 9), c = static_cast<int>(i % 9);
    want += std::max(0.0, brute_mars(initial, r, c, 0.3, 0, 0, 7, 9) - initial(r, c));
  }
  const MaterialScore s = material_score(state, initial, 1.25);
  EXPECT_NEAR(s.needed_m3, want * cs * cs, 1e-12);
  EXPECT_NEAR(s.needed_m3, state.check.route.initial_m3, 1e-12);  // the gap the progress counts down
  EXPECT_DOUBLE_EQ(s.off_band_m3, 1.25);  // the construction band's, passed in
}

TEST(MaterialScore, ARampNeedsTheWedgeUnderEachRobotsWayUpAndNothingElse) {
  // 5 rows x 12 cols of 0.5 m, flat at 0 with a 1 m platform on cols 9..11. One robot (delta = one cell: its band is
  // its route) from col 0 to col 10 on the middle row: the wedge before the platform, 1 - kappa d at distance d
  // from the platform's edge cell, 1 m / 0.25 = 4 m long: 7 cells above the ground.
  const double cs = 0.5;
  Heightmap initial(GridGeometry{5, 12, 0.0, 0.0, cs}, 0.0);
  for (int r = 0; r < 5; ++r)
    for (int c = 9; c < 12; ++c) initial(r, c) = 1.0;
  WorldState state;
  state.terrain = initial;
  state.completion = scenario::CompletionKind::kAgentsAtGoal;
  AgentRecord a;
  a.id = 1;
  a.type.body.navigability = {0.25, cs, 0.05};
  a.start = initial.geometry().cell_center({2, 0});
  a.target = initial.geometry().cell_center({2, 10});
  state.agents.push_back(a);
  double want = 0.0;
  for (int c = 0; c <= 10; ++c) want += std::max(0.0, brute_mars(initial, 2, c, 0.25, 0, 0, 5, 12) - initial(2, c));
  want *= cs * cs;
  EXPECT_NEAR(want, (0.875 + 0.75 + 0.625 + 0.5 + 0.375 + 0.25 + 0.125) * cs * cs, 1e-12);  // the wedge by hand
  state.terrain(0, 0) += 0.5;  // beside the way: off the band
  state.terrain(2, 8) += 0.5;  // on it
  state.deposited_volume_m3 = 1.0 * cs * cs;
  const MaterialScore s = material_score(state, initial, 0.0);
  EXPECT_NEAR(s.needed_m3, want, 1e-12);
  EXPECT_NEAR(s.off_band_m3, 0.5 * cs * cs, 1e-12);
  EXPECT_NEAR(s.ratio, cs * cs / want, 1e-12);
}

TEST(MaterialScore, NothingNeededGivesRatioZeroAndOtherGridsAreRefused) {
  const Heightmap flat(GridGeometry{4, 4, 0.0, 0.0, 1.0}, 0.0);
  WorldState state;
  state.terrain = flat;
  state.completion = scenario::CompletionKind::kAgentsAtGoal;
  AgentRecord a;
  a.start = {0.5, 0.5};
  a.target = {3.5, 3.5};
  state.agents.push_back(a);
  const MaterialScore s = material_score(state, flat, 0.0);
  EXPECT_EQ(s.needed_m3, 0.0);
  EXPECT_EQ(s.ratio, 0.0);
  EXPECT_THROW(material_score(state, Heightmap(GridGeometry{4, 5, 0.0, 0.0, 1.0}, 0.0), 0.0), InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
