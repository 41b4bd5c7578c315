#include "marsala/core/deposit_shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "marsala/core/error.hpp"

namespace marsala {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

std::map<std::pair<int, int>, double> by_cell(const DepositShape& s) {
  std::map<std::pair<int, int>, double> out;
  for (const CellRise& r : s.rises) {
    EXPECT_TRUE(out.emplace(std::make_pair(r.cell.row, r.cell.col), r.rise_m).second) << "a cell listed twice";
    EXPECT_GT(r.rise_m, 0.0);
  }
  return out;
}

double total_m3(const DepositShape& s, double cs) {
  double v = 0.0;
  for (const CellRise& r : s.rises) v += r.rise_m * cs * cs;
  return v;
}

TEST(DepositorKind, NamesRoundTripAndUnknownListsValid) {
  for (const std::string& name : depositor_names()) EXPECT_EQ(to_string(depositor_kind(name)), name);
  EXPECT_EQ(depositor_names(), (std::vector<std::string>{"cone", "cube", "layer"}));
  try {
    depositor_kind("shovel");
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "unknown depositor 'shovel'; valid: cone, cube, layer");
  }
}

// A 5 x 5 grid of 0.1 m cells with its lower-left corner at (1, 2) m: cell (r, c) spans x in [1 + 0.1 c, ...) and
// y in [2 + 0.1 (4 - r), ...).
const GridGeometry kGrid{5, 5, 1.0, 2.0, 0.1};

TEST(CubeColumn, AlignedCubeOfCellSideRaisesExactlyOneCellBySide) {
  const DepositShape one = cube_column_shape(kGrid, kGrid.cell_center({2, 3}), 0.1, 1);
  ASSERT_EQ(one.rises.size(), 1u);
  EXPECT_EQ(one.rises[0].cell, (CellIndex{2, 3}));
  EXPECT_EQ(one.rises[0].rise_m, 0.1);
  EXPECT_TRUE(one.on_grid);
  const DepositShape three = cube_column_shape(kGrid, kGrid.cell_center({2, 3}), 0.1, 3);
  ASSERT_EQ(three.rises.size(), 1u);
  EXPECT_DOUBLE_EQ(three.rises[0].rise_m, 0.3);
}

TEST(CubeColumn, StraddlingCubeSplitsByArea) {
  // Side 0.1 m centred 0.025 m east and 0.05 m north of cell (2, 2)'s centre: the footprint covers 3/4 of column 2
  // and 1/4 of column 3, half of row 1 and half of row 2. Rise = 2 cubes * 0.1 m * (area fraction):
  // (1, 2), (2, 2): 0.2 * 0.75 * 0.5 = 0.075 m; (1, 3), (2, 3): 0.2 * 0.25 * 0.5 = 0.025 m.
  const Position c = kGrid.cell_center({2, 2});
  const auto rises = by_cell(cube_column_shape(kGrid, {c.x + 0.025, c.y + 0.05}, 0.1, 2));
  ASSERT_EQ(rises.size(), 4u);
  EXPECT_NEAR(rises.at({1, 2}), 0.075, 1e-15);
  EXPECT_NEAR(rises.at({2, 2}), 0.075, 1e-15);
  EXPECT_NEAR(rises.at({1, 3}), 0.025, 1e-15);
  EXPECT_NEAR(rises.at({2, 3}), 0.025, 1e-15);
}

TEST(CubeColumn, CubeOfTwoCellsOnACornerRaisesFourCellsBySide) {
  // Side 0.2 m centred on the corner shared by cells (1, 1), (1, 2), (2, 1), (2, 2): each holds a full cell of it.
  const DepositShape s = cube_column_shape(kGrid, {1.2, 2.3}, 0.2, 1);
  const auto rises = by_cell(s);
  ASSERT_EQ(rises.size(), 4u);
  for (const auto& [cell, rise] : rises) {
    EXPECT_TRUE(cell.first >= 1 && cell.first <= 2 && cell.second >= 1 && cell.second <= 2);
    EXPECT_DOUBLE_EQ(rise, 0.2);
  }
}

TEST(CubeColumn, ConservesVolumeAnywhere) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(1.2, 1.3), y(2.2, 2.3), side(0.03, 0.2);
  for (int i = 0; i < 500; ++i) {
    const double s = side(rng);
    const int k = 1 + i % 5;
    const DepositShape shape = cube_column_shape(kGrid, {x(rng), y(rng)}, s, k);
    ASSERT_TRUE(shape.on_grid);
    const double expected = k * s * s * s;
    EXPECT_NEAR(total_m3(shape, 0.1), expected, 1e-15 * expected * 10) << "side " << s << " cubes " << k;
    EXPECT_NEAR(shape.volume_m3, expected, 1e-14 * expected);
    // No cell rises more than the column is tall.
    for (const CellRise& r : shape.rises) EXPECT_LE(r.rise_m, k * s * (s / 0.1) * (s / 0.1) + 1e-15);
  }
}

TEST(CubeColumn, OffTheGridIsFlaggedAndOnlyTheOnGridPartIsReturned) {
  // Centred on the west edge: half the footprint is off the grid.
  const DepositShape s = cube_column_shape(kGrid, {1.0, kGrid.cell_center({2, 0}).y}, 0.1, 1);
  EXPECT_FALSE(s.on_grid);
  ASSERT_EQ(s.rises.size(), 1u);
  EXPECT_EQ(s.rises[0].cell, (CellIndex{2, 0}));
  EXPECT_NEAR(s.rises[0].rise_m, 0.05, 1e-15);
  EXPECT_FALSE(cube_column_shape(kGrid, {-50.0, 7.0}, 0.1, 1).on_grid);
  EXPECT_TRUE(cube_column_shape(kGrid, {-50.0, 7.0}, 0.1, 1).rises.empty());
}

TEST(CubeColumn, ThrowsOnBadInput) {
  EXPECT_THROW(cube_column_shape(kGrid, {kNaN, 2.2}, 0.1, 1), InvalidArgument);
  EXPECT_THROW(cube_column_shape(kGrid, {1.2, 2.2}, kNaN, 1), InvalidArgument);
  EXPECT_THROW(cube_column_shape(kGrid, {1.2, 2.2}, 0.0, 1), InvalidArgument);
  EXPECT_THROW(cube_column_shape(kGrid, {1.2, 2.2}, -0.1, 1), InvalidArgument);
  EXPECT_THROW(cube_column_shape(kGrid, {1.2, 2.2}, 0.1, -1), InvalidArgument);
  EXPECT_TRUE(cube_column_shape(kGrid, {1.2, 2.2}, 0.1, 0).rises.empty());
}

TEST(WholeCubes, CountsOnlyWholeNumbers) {
  EXPECT_EQ(whole_cubes(0.003, 0.1), 3);
  EXPECT_EQ(whole_cubes(0.0, 0.1), 0);
  EXPECT_EQ(whole_cubes(0.0025, 0.1), -1);
  EXPECT_EQ(whole_cubes(-0.001, 0.1), -1);
  EXPECT_EQ(whole_cubes(kNaN, 0.1), -1);
  EXPECT_EQ(whole_cubes(1e300, 0.1), -1);
}

Heightmap rough(int rows, int cols, double cs, unsigned seed) {
  Heightmap h({rows, cols, 0.0, 0.0, cs});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 0.3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) h(r, c) = u(rng) + 0.02 * c;
  return h;
}

// The reference: the added volume is increasing in the apex height z; find z by plain bisection on every cell of
// the grid (no window, no sorting) and build the rises from the definition.
std::map<std::pair<int, int>, double> brute_cone(const Heightmap& h, Position dump, double volume, double repose) {
  const double t = std::tan(repose * kPi / 180.0), cs = h.cell_size_m();
  const auto added = [&](double z) {
    double v = 0.0;
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) {
        const Position p = h.cell_center({r, c});
        v += std::max(0.0, z - t * std::hypot(p.x - dump.x, p.y - dump.y) - h(r, c)) * cs * cs;
      }
    return v;
  };
  double lo = h.min_height(), hi = h.max_height() + volume / (cs * cs) + 100.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (added(mid) < volume ? lo : hi) = mid;
  }
  std::map<std::pair<int, int>, double> out;
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const Position p = h.cell_center({r, c});
      const double rise = hi - t * std::hypot(p.x - dump.x, p.y - dump.y) - h(r, c);
      if (rise > 1e-12) out[{r, c}] = rise;
    }
  return out;
}

TEST(ConePile, MatchesBruteForceOnSmallGrids) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> where(0.6, 1.4), vol(0.0005, 0.05), angle(15.0, 60.0);
  for (int i = 0; i < 40; ++i) {
    const Heightmap h = rough(20, 20, 0.1, 100 + i);
    const Position dump{where(rng), where(rng)};
    const double v = vol(rng), a = angle(rng);
    const DepositShape s = cone_pile_shape(h, dump, v, a);
    const auto got = by_cell(s);
    const auto want = brute_cone(h, dump, v, a);
    for (const auto& [cell, rise] : want)
      if (rise > 1e-9) {
        EXPECT_TRUE(got.count(cell)) << "cell " << cell.first << "," << cell.second << " missing";
      }
    for (const auto& [cell, rise] : got) {
      const auto it = want.find(cell);
      EXPECT_NEAR(rise, it == want.end() ? 0.0 : it->second, 1e-9) << "cell " << cell.first << "," << cell.second;
    }
  }
}

TEST(ConePile, ConservesVolumeWithinTolerance) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(1.0, 3.0), vol(1e-6, 0.5), angle(5.0, 85.0);
  for (int i = 0; i < 200; ++i) {
    const Heightmap h = rough(40, 40, 0.1, i);
    const double v = vol(rng);
    const DepositShape s = cone_pile_shape(h, {where(rng), where(rng)}, v, angle(rng));
    EXPECT_LE(std::abs(total_m3(s, 0.1) - v), kConeVolumeRelTolerance * v);
    EXPECT_LE(std::abs(s.volume_m3 - v), kConeVolumeRelTolerance * v);
  }
}

TEST(ConePile, SurfaceNeverSteeperThanTheAngleOfRepose) {
  for (unsigned seed = 0; seed < 20; ++seed) {
    const Heightmap h = rough(30, 30, 0.1, seed);
    const double repose = 20.0 + seed * 2.0, t = std::tan(repose * kPi / 180.0);
    const DepositShape s = cone_pile_shape(h, {1.5, 1.5}, 0.03, repose);
    Heightmap after = h;
    for (const CellRise& r : s.rises) after(r.cell) += r.rise_m;
    // From every changed cell to every other cell: the pile's surface never stands higher than the slope allows.
    for (const CellRise& r : s.rises)
      for (int row = 0; row < h.rows(); ++row)
        for (int col = 0; col < h.cols(); ++col) {
          const Position p = h.cell_center(r.cell), q = h.cell_center({row, col});
          EXPECT_LE(after(r.cell) - after(row, col), t * std::hypot(p.x - q.x, p.y - q.y) + 1e-9);
        }
  }
}

TEST(ConePile, SymmetricOnFlatGroundWithTheApexAtTheDumpCell) {
  const Heightmap flat({41, 41, 0.0, 0.0, 0.1}, 1.0);
  const DepositShape s = cone_pile_shape(flat, flat.cell_center({20, 20}), 0.02, 34.0);
  const auto rises = by_cell(s);
  ASSERT_GT(rises.size(), 9u);
  double top = 0.0;
  for (const auto& [cell, rise] : rises) {
    const int dr = cell.first - 20, dc = cell.second - 20;
    for (const auto& [mr, mc] : std::vector<std::pair<int, int>>{{-dr, dc}, {dr, -dc}, {dc, dr}, {-dc, -dr}}) {
      const auto it = rises.find({20 + mr, 20 + mc});
      ASSERT_NE(it, rises.end());
      EXPECT_NEAR(it->second, rise, 1e-12);  // distances of mirrored cells round differently
    }
    top = std::max(top, rise);
  }
  EXPECT_NEAR(rises.at({20, 20}), top, 1e-12);
  // A cone of the same volume in the continuum: V = pi r^2 h / 3 with h = tan(34) r: h ~ 0.175 m; the grid's
  // apex is near it.
  const double t = std::tan(34.0 * kPi / 180.0), r = std::cbrt(3.0 * 0.02 / (kPi * t));
  EXPECT_NEAR(top, t * r, 0.03);
  EXPECT_TRUE(s.on_grid);
}

TEST(ConePile, FlowsDownIntoAHoleBesideTheDump) {
  Heightmap h({21, 21, 0.0, 0.0, 0.1}, 1.0);
  h(10, 12) = 0.5;  // a hole 0.5 m deep two cells east of the dump cell
  // The hole starts to fill at apex height 0.5 + tan(34) 0.2 = 0.635 m, the dump cell only at 1 m: the hole alone
  // takes (1 - 0.635) 0.01 = 0.00365 m^3 first, so 0.003 m^3 (0.3 m over one cell) all runs into it.
  const auto small = by_cell(cone_pile_shape(h, h.cell_center({10, 10}), 0.003, 34.0));
  ASSERT_EQ(small.size(), 1u);
  EXPECT_NEAR(small.at({10, 12}), 0.3, 1e-12);
  // More material fills the hole and builds the cone over it; the hole holds the most.
  const auto big = by_cell(cone_pile_shape(h, h.cell_center({10, 10}), 0.02, 34.0));
  ASSERT_TRUE(big.count({10, 10}));
  EXPECT_GT(big.at({10, 12}), big.at({10, 10}));
}

TEST(ConePile, SmallVolumeStaysInTheDumpCell) {
  const Heightmap flat({9, 9, 0.0, 0.0, 0.1}, 0.0);
  // tan(34) * 0.1 m = 0.0675 m before a neighbour starts to rise: 0.0005 m^3 is 0.05 m over one cell.
  const DepositShape s = cone_pile_shape(flat, flat.cell_center({4, 4}), 0.0005, 34.0);
  ASSERT_EQ(s.rises.size(), 1u);
  EXPECT_NEAR(s.rises[0].rise_m, 0.05, 1e-15);
}

TEST(ConePile, AnApexThatOnlyTiesANeighbourLeavesItAsItIs) {
  // Flat ground: the dump cell alone takes material until the apex reaches tan(repose) 0.1 m, where its four
  // neighbours start. Exactly that volume ties them: rounding must not decide, they stay (kConeTieM).
  const Heightmap flat({9, 9, 0.0, 0.0, 0.1}, 0.0);
  const double t = std::tan(34.0 * kPi / 180.0);
  for (const double v : {t * 0.1 * 0.01, std::nextafter(t * 0.1 * 0.01, 1.0), std::nextafter(t * 0.1 * 0.01, 0.0)}) {
    const DepositShape s = cone_pile_shape(flat, flat.cell_center({4, 4}), v, 34.0);
    ASSERT_EQ(s.rises.size(), 1u) << v;
    EXPECT_NEAR(s.rises[0].rise_m, t * 0.1, 1e-15);
  }
  // Clearly more: the four neighbours rise too.
  EXPECT_EQ(cone_pile_shape(flat, flat.cell_center({4, 4}), t * 0.1 * 0.01 + 1e-9, 34.0).rises.size(), 5u);
}

TEST(ConePile, ReachingTheBorderOrDumpedOffTheGridIsFlagged) {
  const Heightmap flat({9, 9, 0.0, 0.0, 0.1}, 0.0);
  EXPECT_FALSE(cone_pile_shape(flat, flat.cell_center({1, 4}), 0.01, 34.0).on_grid);
  EXPECT_FALSE(cone_pile_shape(flat, {-1.0, 0.5}, 0.01, 34.0).on_grid);
  EXPECT_TRUE(cone_pile_shape(flat, {-1.0, 0.5}, 0.01, 34.0).rises.empty());
  EXPECT_TRUE(cone_pile_shape(flat, flat.cell_center({4, 4}), 0.0005, 34.0).on_grid);
}

TEST(ConePile, ThrowsOnBadInput) {
  const Heightmap flat({9, 9, 0.0, 0.0, 0.1}, 0.0);
  EXPECT_THROW(cone_pile_shape(flat, {kNaN, 0.4}, 0.01, 34.0), InvalidArgument);
  EXPECT_THROW(cone_pile_shape(flat, {0.4, 0.4}, kNaN, 34.0), InvalidArgument);
  EXPECT_THROW(cone_pile_shape(flat, {0.4, 0.4}, -0.01, 34.0), InvalidArgument);
  EXPECT_THROW(cone_pile_shape(flat, {0.4, 0.4}, 0.01, 0.0), InvalidArgument);
  EXPECT_THROW(cone_pile_shape(flat, {0.4, 0.4}, 0.01, 90.0), InvalidArgument);
  EXPECT_THROW(cone_pile_shape(flat, {0.4, 0.4}, 0.01, kNaN), InvalidArgument);
  EXPECT_TRUE(cone_pile_shape(flat, {0.4, 0.4}, 0.0, 34.0).rises.empty());
}

}  // namespace
}  // namespace marsala
