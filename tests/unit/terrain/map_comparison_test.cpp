#include "marsala/terrain/map_comparison.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::terrain {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

GridGeometry grid(int rows, int cols, double cell_size_m = 0.1) {
  GridGeometry g;
  g.rows = rows;
  g.cols = cols;
  g.cell_size_m = cell_size_m;
  return g;
}

/// The definition of ARCHITECTURE.md written out pair by pair, with unknown (NaN) cells in the ball making the cell
/// not passable: the oracle compare_maps() is checked against.
bool brute_passable(const Heightmap& h, int row, int col, const NavigabilityParams& body) {
  if (std::isnan(h(row, col))) return false;
  const double radius = body.delta_m / (2.0 * h.cell_size_m());
  const int reach = static_cast<int>(std::ceil(radius)) + 1;
  std::vector<std::pair<CellIndex, double>> ball;
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc) {
      if (dr * dr + dc * dc > radius * radius + 1e-9) continue;
      const CellIndex q{row + dr, col + dc};
      if (!h.contains(q)) continue;
      if (std::isnan(h(q))) return false;
      ball.push_back({q, h(q)});
    }
  for (const auto& [a, ha] : ball)
    for (const auto& [b, hb] : ball) {
      const double d = h.cell_size_m() * std::hypot(a.row - b.row, a.col - b.col);
      if (std::abs(ha - hb) > body.eps_m + body.kappa * d + 1e-9) return false;
    }
  return true;
}

/// Nearest-rank quantile of a sorted copy: element floor(q (n - 1) + 0.5).
double brute_quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::floor(q * static_cast<double>(v.size() - 1) + 0.5))];
}

/// A hand-made terrain: flat ground, a wall 0.4 m high from column 6 on, and a gentle slope (0.2) beside it.
Heightmap hand_terrain() {
  Heightmap h(grid(9, 12));
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 12; ++c) h(r, c) = c >= 6 ? 0.4 : (r >= 6 ? 0.02 * c : 0.0);
  return h;
}

TEST(MapComparison, AnExactCompleteMapHasNoErrorAndNoFalsePassableCell) {
  const Heightmap truth = hand_terrain();
  const NavigabilityParams body{0.3, 0.5, 0.05};
  const MapComparison m = compare_maps(truth, truth, body);
  EXPECT_EQ(m.cells, 108);
  EXPECT_EQ(m.known_cells, 108);
  EXPECT_DOUBLE_EQ(m.known_fraction(), 1.0);
  EXPECT_EQ(m.median_error_m, 0.0);
  EXPECT_EQ(m.p95_error_m, 0.0);
  EXPECT_EQ(m.max_error_m, 0.0);
  EXPECT_EQ(m.believed_passable_not, 0);
  EXPECT_EQ(m.believed_passable, m.true_passable);
  // The cells whose ball (2.5 cells) holds both sides of the wall (columns 4..8) are not occupiable.
  long long expected = 0;
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 12; ++c) expected += brute_passable(truth, r, c, body) ? 1 : 0;
  EXPECT_EQ(m.true_passable, expected);
  EXPECT_LT(m.true_passable, 108);
}

TEST(MapComparison, AMapThatMissesTheWallBelievesItsFootPassable) {
  const Heightmap truth = hand_terrain();
  Heightmap believed = truth;
  for (int r = 0; r < 9; ++r)
    for (int c = 6; c < 12; ++c) believed(r, c) = 0.0;  // the wall not seen: read as the ground before it
  const NavigabilityParams body{0.3, 0.5, 0.05};
  const MapComparison m = compare_maps(believed, truth, body);
  EXPECT_EQ(m.known_cells, 108);
  // 54 of 108 cells 0.4 m off: the median is the upper middle (nearest rank), the 95th percentile 0.4 m.
  EXPECT_DOUBLE_EQ(m.median_error_m, 0.4);
  EXPECT_DOUBLE_EQ(m.p95_error_m, 0.4);
  EXPECT_DOUBLE_EQ(m.max_error_m, 0.4);
  // Brute force over every cell; by hand: the balls (2.5 cells) of columns 4..8 hold both sides of the wall's edge
  // (between columns 5 and 6), 0.4 m apart within 0.5 m, so none of them is occupiable in truth; on rows 0..2, whose
  // balls reach row 4 at most, the believed map is flat there: 3 x 5 cells believed passable that are not.
  long long believed_count = 0, wrong = 0;
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 12; ++c) {
      const bool b = brute_passable(believed, r, c, body);
      believed_count += b ? 1 : 0;
      wrong += b && !brute_passable(truth, r, c, body) ? 1 : 0;
    }
  EXPECT_EQ(m.believed_passable, believed_count);
  EXPECT_EQ(m.believed_passable_not, wrong);
  EXPECT_GE(m.believed_passable_not, 15);
  const CellMask passable = believed_passable(believed, body);
  for (int r = 0; r <= 2; ++r)
    for (int c = 4; c <= 8; ++c) EXPECT_EQ(passable(r, c), 1) << r << ", " << c;
}

TEST(MapComparison, UnknownCellsAreNotPassableNorAnythingWithinHalfABodyOfThem) {
  Heightmap truth(grid(7, 7), 0.0);
  Heightmap believed = truth;
  believed(3, 3) = kNan;
  const NavigabilityParams body{0.3, 0.5, 0.05};  // ball radius 2.5 cells: offsets with dr^2 + dc^2 <= 6.25
  const MapComparison m = compare_maps(believed, truth, body);
  EXPECT_EQ(m.known_cells, 48);
  EXPECT_EQ(m.true_passable, 49);
  // 21 offsets within 2.5 cells (1 + 4 + 4 + 4 + 8), all on the 7 x 7 grid around its centre.
  EXPECT_EQ(m.believed_passable, 49 - 21);
  EXPECT_EQ(m.believed_passable_not, 0);
  const CellMask passable = believed_passable(believed, body);
  EXPECT_EQ(passable(3, 3), 0);
  EXPECT_EQ(passable(3, 5), 0);  // 2 cells away
  EXPECT_EQ(passable(5, 5), 1);  // sqrt(8) = 2.83 cells away
  EXPECT_EQ(passable(1, 2), 0);  // sqrt(5) = 2.24 cells away
}

TEST(MapComparison, AgreesWithTheBruteForceOnRandomMapsWithHoles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> height(0.0, 0.3);
  std::uniform_real_distribution<double> noise(-0.06, 0.06);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    const int rows = 5 + trial % 6, cols = 6 + trial % 5;
    Heightmap truth(grid(rows, cols, 0.1 + 0.05 * (trial % 3)));
    // Smooth enough that some cells are occupiable: a tilted plane with bumps.
    const double tilt = 0.01 * (trial % 7);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) truth(r, c) = tilt * c + (unit(rng) < 0.15 ? height(rng) : 0.0);
    Heightmap believed = truth;
    std::vector<double> errors;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        if (unit(rng) < 0.2) {
          believed(r, c) = kNan;
          continue;
        }
        believed(r, c) += unit(rng) < 0.5 ? noise(rng) : 0.0;
        errors.push_back(std::abs(believed(r, c) - truth(r, c)));
      }
    const NavigabilityParams body{0.2 + 0.05 * (trial % 4), 0.3 + 0.1 * (trial % 5), 0.02 + 0.01 * (trial % 3)};
    const MapComparison m = compare_maps(believed, truth, body);
    long long passable = 0, wrong = 0, really = 0;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const bool b = brute_passable(believed, r, c, body), t = brute_passable(truth, r, c, body);
        passable += b;
        really += t;
        wrong += b && !t;
      }
    SCOPED_TRACE(trial);
    EXPECT_EQ(m.cells, static_cast<long long>(rows) * cols);
    EXPECT_EQ(m.known_cells, static_cast<long long>(errors.size()));
    EXPECT_EQ(m.median_error_m, brute_quantile(errors, 0.5));
    EXPECT_EQ(m.p95_error_m, brute_quantile(errors, 0.95));
    EXPECT_EQ(m.max_error_m, errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end()));
    EXPECT_EQ(m.believed_passable, passable);
    EXPECT_EQ(m.true_passable, really);
    EXPECT_EQ(m.believed_passable_not, wrong);
  }
}

TEST(MapComparison, AMapThatKnowsNothingHasNoErrorsAndNoPassableCell) {
  const Heightmap truth = hand_terrain();
  const Heightmap believed(truth.geometry(), kNan);
  const MapComparison m = compare_maps(believed, truth, NavigabilityParams{});
  EXPECT_EQ(m.known_cells, 0);
  EXPECT_EQ(m.known_fraction(), 0.0);
  EXPECT_EQ(m.median_error_m, 0.0);
  EXPECT_EQ(m.believed_passable, 0);
  EXPECT_EQ(m.believed_passable_not, 0);
}

TEST(MapComparison, RefusesGridsThatDifferAndHeightsThatAreNotFinite) {
  const Heightmap truth = hand_terrain();
  const NavigabilityParams body;
  EXPECT_THROW(compare_maps(Heightmap(grid(9, 11)), truth, body), InvalidArgument);
  EXPECT_THROW(compare_maps(Heightmap(grid(9, 12, 0.2)), truth, body), InvalidArgument);
  GridGeometry moved = truth.geometry();
  moved.xll_m = 1.0;
  EXPECT_THROW(compare_maps(Heightmap(moved), truth, body), InvalidArgument);
  Heightmap bad_truth = truth;
  bad_truth(2, 2) = kNan;
  EXPECT_THROW(compare_maps(truth, bad_truth, body), InvalidArgument);
  Heightmap infinite = truth;
  infinite(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(compare_maps(infinite, truth, body), InvalidArgument);
  EXPECT_THROW(compare_maps(truth, truth, NavigabilityParams{0.0, 1.0, 0.05}), InvalidArgument);
}

}  // namespace
}  // namespace marsala::terrain
