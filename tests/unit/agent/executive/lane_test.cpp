#include "marsala/agent/executive/lane.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <random>

#include "marsala/core/mars_processor.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::executive {
namespace {

// 80 x 80 cells of 0.1 m (8 x 8 m). A flat band 3 m wide (rows 25..54, y in [2.5, 5.5)) between walls 5 m high;
// bodies 1 m (ball radius 5 cells): robot centres are navigable on rows 30..49, a corridor 2 m across.
const GridGeometry kGrid{80, 80, 0.0, 0.0, 0.1};
const NavigabilityParams kBody{0.3, 1.0, 0.05};

deliberative::LocalMap band_map(CellIndex robot, bool walls = true) {
  Heightmap h(kGrid, 0.0);
  if (walls)
    for (int r = 0; r < 80; ++r)
      for (int c = 0; c < 80; ++c)
        if (r < 25 || r > 54) h(r, c) = 5.0;
  return test::make_local_map(h, Heightmap(kGrid, 0.0), kBody, robot, std::nullopt);
}

std::vector<CellIndex> row_path(int row, int from_col, int to_col) {
  std::vector<CellIndex> path;
  const int step = to_col >= from_col ? 1 : -1;
  for (int c = from_col; c != to_col + step; c += step) path.push_back({row, c});
  return path;
}

TEST(Lane, KeepsRightOfTheCorridorsCentreWhereverTheRobotStands) {
  const deliberative::LocalMap map = band_map({40, 5});
  ASSERT_NE(map.navigable(30, 40), 0);
  ASSERT_EQ(map.navigable(29, 40), 0);
  ASSERT_NE(map.navigable(49, 40), 0);
  ASSERT_EQ(map.navigable(50, 40), 0);
  // Eastwards, right is south (higher rows). The corridor's centre is between rows 39 and 40 (y = 4.0 m); 0.75 m to
  // the right of it is y = 3.25 m, row 47; the lane is entered at 45 degrees at most (from row 32: 15 cells).
  for (int row : {32, 40, 47}) {
    const auto lane = lane_path(map, map.navigable, row_path(row, 5, 70), 0.75, 3.0);
    ASSERT_GE(lane.size(), 2u);
    EXPECT_EQ(lane.front(), (CellIndex{row, 5}));  // the robot's own cell stays
    for (std::size_t i = 1; i < lane.size(); ++i)
      if (lane[i].col > 25 && lane[i].col < 65) {
        EXPECT_EQ(lane[i].row, 47) << "from row " << row;
      }
  }
  // Westwards, right is north: y = 4.75 m, row 32 (reached at 45 degrees from row 40: by column 62).
  const auto back = lane_path(map, map.navigable, row_path(40, 70, 5), 0.75, 3.0);
  for (const CellIndex& c : back)
    if (c.col < 50 && c.col > 10) {
      EXPECT_EQ(c.row, 32);
    }
  // The two lanes are 1.5 m apart: bodies of 1 m pass with 0.5 m to spare.
}

TEST(Lane, ALaneBeyondTheCorridorStopsAtItsEdge) {
  const deliberative::LocalMap map = band_map({40, 5});
  const auto lane = lane_path(map, map.navigable, row_path(40, 5, 70), 1.5, 3.0);
  for (std::size_t i = 1; i < lane.size(); ++i)
    if (lane[i].col > 25 && lane[i].col < 65) {  // the last navigable row
      EXPECT_EQ(lane[i].row, 49);
    }
}

TEST(Lane, IsEnteredAtFortyFiveDegreesAtMost) {
  const deliberative::LocalMap map = band_map({40, 5});
  const auto lane = lane_path(map, map.navigable, row_path(40, 5, 70), 0.75, 3.0);
  for (std::size_t i = 1; i < lane.size(); ++i) {
    EXPECT_LE(std::abs(lane[i].row - lane[i - 1].row), 1) << i;
    EXPECT_LE(std::abs(lane[i].col - lane[i - 1].col), 1) << i;
  }
}

TEST(Lane, OpenGroundAndNoOffsetLeaveThePathAlone) {
  const deliberative::LocalMap open = band_map({40, 5}, false);
  const auto path = row_path(40, 5, 70);
  EXPECT_EQ(lane_path(open, open.navigable, path, 0.75, 3.0), path);
  const deliberative::LocalMap map = band_map({40, 5});
  EXPECT_EQ(lane_path(map, map.navigable, path, 0.0, 3.0), path);
  const std::vector<CellIndex> alone{CellIndex{40, 5}};
  EXPECT_EQ(lane_path(map, map.navigable, alone, 0.75, 3.0), alone);
}

TEST(Lane, AnOccupiedLaneCellFallsBackToThePath) {
  // The corridor mask has the band; the navigable mask lacks the right half (other robots stand there).
  deliberative::LocalMap map = band_map({40, 5});
  const CellMask corridor = map.navigable;
  for (int r = 41; r < 50; ++r)
    for (int c = 0; c < 80; ++c) map.navigable(r, c) = 0;
  const auto path = row_path(40, 5, 70);
  const auto lane = lane_path(map, corridor, path, 0.75, 3.0);
  EXPECT_EQ(lane, path);
}

// band_centre_path against a brute force: corridors drawn by hand on a 0.1 m grid (row-major, y north, so "right"
// of an eastward path is the next row down the array), each column's run of corridor cells [lo, hi] wandering at
// random; the centre of a column's run is row (lo + hi) / 2, found without sampling along a direction; a path cell
// moves towards it by at most the shift allowed.
struct HandCorridor {
  std::vector<int> lo, hi;  // per column; lo > hi: the whole column is open ground
  CellMask mask;
};

constexpr int kRows = 80, kCols = 80;  // kGrid

HandCorridor random_corridor(std::mt19937& rng) {
  HandCorridor h{std::vector<int>(kCols), std::vector<int>(kCols), CellMask::Zero(kRows, kCols)};
  std::uniform_int_distribution<int> step(-1, 1), width(6, 24), open_at(0, 2 * kCols);
  int lo = 40 - width(rng) / 2, hi = lo + width(rng);
  const int open_from = open_at(rng);  // past this column (when on the grid) the corridor ends: open ground
  for (int c = 0; c < kCols; ++c) {
    lo = std::clamp(lo + step(rng), 30, 40);
    hi = std::clamp(hi + step(rng), 41, 50);  // every edge within 1.5 m of the path (rows 36..44): found
    h.lo[static_cast<std::size_t>(c)] = c < open_from ? lo : 1;
    h.hi[static_cast<std::size_t>(c)] = c < open_from ? hi : 0;
    for (int r = 0; r < kRows; ++r)
      if (c >= open_from || (r >= lo && r <= hi)) h.mask(r, c) = 1;
  }
  return h;
}

TEST(Lane, BandCentrePathFollowsTheCorridorsCentreLikeABruteForce) {
  const deliberative::LocalMap map = band_map({40, 0}, false);  // the grid; the corridor is the hand-made mask
  const double cs = kGrid.cell_size_m, width_m = 1.6, max_shift_m = 0.55;
  std::mt19937 rng(25);
  int checked = 0, carried = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const HandCorridor h = random_corridor(rng);
    const bool east = trial % 2 == 0;
    const int row = 36 + trial % 9;
    const auto path = east ? row_path(row, 0, kCols - 1) : row_path(row, kCols - 1, 0);
    const auto moved = band_centre_path(map, h.mask, path, width_m, max_shift_m);
    ASSERT_EQ(moved.size(), path.size()) << trial;  // straight along a row: one cell per column, none merged
    // Brute force: the columns whose run holds the path's row and ends within width_m on both sides, in stretches of
    // kMinCorridorCells columns; each such column's centre, unless farther off than max_shift_m.
    std::vector<double> centre(kCols, std::nan(""));
    for (int c = 0; c < kCols; ++c) {
      const int lo = h.lo[static_cast<std::size_t>(c)], hi = h.hi[static_cast<std::size_t>(c)];
      // Sampled every half cell, an edge is found within half a cell: keep away from the width's limit by a cell.
      if (lo <= row && row <= hi && (row - lo + 1) * cs < width_m && (hi - row + 1) * cs < width_m)
        centre[static_cast<std::size_t>(c)] = 0.5 * (lo + hi);
    }
    std::optional<double> last;  // the last shift [rows]
    for (int i = 0; i < kCols; ++i) {
      const int c = east ? i : kCols - 1 - i;
      int run = 0;  // the stretch of corridor columns through c
      for (int d = c; d >= 0 && !std::isnan(centre[static_cast<std::size_t>(d)]); --d) ++run;
      for (int d = c + 1; d < kCols && !std::isnan(centre[static_cast<std::size_t>(d)]); ++d) ++run;
      const double want = run >= kMinCorridorCells ? centre[static_cast<std::size_t>(c)] - row : std::nan("");
      const auto& got = moved[static_cast<std::size_t>(i)];
      EXPECT_EQ(got.col, c) << trial;
      if (!std::isnan(want)) {  // towards the centre, at most max_shift_m
        last = std::clamp(want, -max_shift_m / cs, max_shift_m / cs);
        EXPECT_LE(std::abs(got.row - (row + *last)), 1.0) << "trial " << trial << " col " << c;
        ++checked;
      } else if (last) {  // no corridor here: the last shift carries on
        EXPECT_LE(std::abs(got.row - (row + *last)), 1.0) << "trial " << trial << " col " << c << " carried";
        ++carried;
      } else {
        EXPECT_EQ(got.row, row) << "trial " << trial << " col " << c << " before any corridor";
      }
    }
  }
  EXPECT_GT(checked, 3000);  // the brute force found centres and the carried line often enough to mean something
  EXPECT_GT(carried, 300);
}

TEST(Lane, BandCentrePathMovesEveryPathInTheBandOntoItsCentreAtOnce) {
  const deliberative::LocalMap map = band_map({47, 5});
  // The corridor's centre is y = 4.0 m, between rows 39 and 40: every cell of a path anywhere in it, the first (the
  // robot's) included, moves there at once, whichever side the path runs on and whichever way.
  for (int row : {32, 40, 47})
    for (const bool east : {true, false}) {
      const auto centred =
          band_centre_path(map, map.navigable, east ? row_path(row, 5, 70) : row_path(row, 70, 5), 3.0, 1.0);
      ASSERT_FALSE(centred.empty());
      for (const CellIndex& c : centred) EXPECT_TRUE(c.row == 39 || c.row == 40) << "from row " << row << ": " << c.row;
    }
  // A path farther from the centre than the shift allowed moves by that much: row 47 is 0.75 m off it, 0.5 m
  // towards it is row 42.
  for (const CellIndex& c : band_centre_path(map, map.navigable, row_path(47, 5, 70), 3.0, 0.5)) EXPECT_EQ(c.row, 42);
  // On open ground there is no corridor: the path stays as it is.
  const deliberative::LocalMap open = band_map({47, 5}, false);
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(47, 5, 70), 3.0, 1.0), row_path(47, 5, 70));
}

// Open ground (no corridor of navigable cells) with a structure: rows `first`..`last` raised, from column 0 to column
// `tip` (cells of 0.1 m: row r spans y in [7.9 - 0.1 r, 8.0 - 0.1 r)).
CellMask raised_strip(int first, int last, int tip) {
  CellMask m = CellMask::Zero(80, 80);
  for (int r = first; r <= last; ++r)
    for (int c = 0; c <= tip; ++c) m(r, c) = 1;
  return m;
}

TEST(Lane, BandCentrePathBuildsNothingBesideTheStructureButGoesOnPastItsTip) {
  const deliberative::LocalMap open = band_map({60, 5}, false);
  const CellMask strip = raised_strip(25, 54, 40);  // 3 m across, as wide as the band
  // Row 60 runs 0.6 m south of the strip's edge (row 54): beside it as far as column 40 (a column's cells across
  // the path meet the strip there), past its tip from column 41 on, where the path is kept as it is.
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(60, 5, 70), 3.0, 1.0, &strip), row_path(60, 41, 70));
  // Row 75 is 2.05 m from the edge, within the 3 m looked across: beside too.
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(75, 5, 70), 3.0, 1.0, &strip), row_path(75, 41, 70));
  // A structure farther than 3 m across (rows 25..29, row 62 is 3.25 m from row 29) is not beside the path.
  const CellMask far = raised_strip(25, 29, 40);
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(62, 5, 70), 3.0, 1.0, &far), row_path(62, 5, 70));
  // A narrow structure whose far edge lies within half the band (rows 50..54, 0.75 m at most from row 57) is one
  // the band centred on the path still holds: kept (it is being built, not widened).
  const CellMask narrow = raised_strip(50, 54, 40);
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(57, 5, 70), 3.0, 1.0, &narrow), row_path(57, 5, 70));
  // A notch in a structure narrower than the band (rows 28..37 and 43..51: both edges 1.2 m from row 40) is filled,
  // not skipped.
  CellMask notch = raised_strip(28, 51, 40);
  for (int r = 38; r <= 42; ++r)
    for (int c = 0; c <= 40; ++c) notch(r, c) = 0;
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(40, 5, 70), 3.0, 1.0, &notch), row_path(40, 5, 70));
  // A path along the structure, on it, keeps every cell (on open ground nothing moves it either).
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(47, 5, 70), 3.0, 1.0, &strip), row_path(47, 5, 70));
  // A path that leaves the structure across it keeps every cell.
  std::vector<CellIndex> across;
  for (int r = 47; r <= 79; ++r) across.push_back({r, 20});
  EXPECT_EQ(band_centre_path(open, open.navigable, across, 3.0, 1.0, &strip), across);
  // Without the structure (or with one of another size) the path stays.
  const CellMask other = CellMask::Ones(10, 10);
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(60, 5, 70), 3.0, 1.0), row_path(60, 5, 70));
  EXPECT_EQ(band_centre_path(open, open.navigable, row_path(60, 5, 70), 3.0, 1.0, &other), row_path(60, 5, 70));
}

TEST(BandFill, TheBandIsTheCellsWithinHalfTheWidthOfItsPaths) {
  const deliberative::LocalMap map = band_map({40, 5}, false);
  // 0.2 m = 2 cells around (40, 40): the 13 cells with dr^2 + dc^2 <= 4; around (0, 79) the part inside the window.
  const CellMask band = band_mask(map, {{{40, 40}}, {{0, 79}}}, 0.2);
  long long count = 0;
  for (int r = 0; r < 80; ++r)
    for (int c = 0; c < 80; ++c) {
      const bool near_a = (r - 40) * (r - 40) + (c - 40) * (c - 40) <= 4;
      const bool near_b = r * r + (c - 79) * (c - 79) <= 4;
      EXPECT_EQ(band(r, c), near_a || near_b ? 1 : 0) << r << ", " << c;
      count += band(r, c);
    }
  EXPECT_EQ(count, 13 + 6);
}

// gap_below_bound_of() projects the sources only on the cells whose gap it reads (gap_cells()): the result is
// gap_below() of the whole projection, bit for bit, on rough windows with flat patches (gap 0), -0.0 heights and a
// gap cleared on some cells, whatever the sources (the first-seen heights, a band's).
TEST(BandFill, TheBoundOnTheCellsWithAGapIsTheWholeBoundsBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double kappa = 0.1;
  for (int trial = 0; trial < 40; ++trial) {
    const GridGeometry g{41, 33 + trial % 9, 0.0, 0.0, 0.25};
    Heightmap h(g, 0.0);
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c) {
        const double v = u(rng);
        h(r, c) = v < 0.3 ? -0.0 : v < 0.5 ? 0.25 : 0.6 * u(rng);
      }
    Heightmap gap = MarsProcessor(kappa).gap(h);
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c)
        if (u(rng) < 0.1) gap(r, c) = 0.0;
    const deliberative::LocalMap map = test::make_local_map(h, gap, kBody, {20, 10}, std::nullopt);
    CellMask band = CellMask::Zero(g.rows, g.cols);
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c) band(r, c) = u(rng) < (trial % 2 == 0 ? 0.3 : 0.9);
    const Heightmap sources = band_sources(map, band);
    const Heightmap part = gap_below_bound_of(map, sources, kappa);
    const Heightmap whole = gap_below(map, MarsProcessor(kappa).project(sources));
    const CellMask cells = gap_cells(map);
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c) {
        const double a = part(r, c), b = whole(r, c);
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << trial << ": (" << r << ", " << c << ") " << a << " vs " << b;
        EXPECT_EQ(cells(r, c) != 0, map.gap(r, c) > 0.0);
      }
  }
}

TEST(BandFill, WhatIsLeftToFillIsTheBandsOwnMarsGap) {
  // 12 x 14 cells of 0.25 m: a band on rows 0..5; beside it a 1 m strip on row 9 (another front's, or high ground)
  // and a 0.4 m top at (3, 2) inside it.
  const GridGeometry g{12, 14, 0.0, 0.0, 0.25};
  const double kappa = 0.2;
  Heightmap h(g, 0.1);
  for (int c = 0; c < 14; ++c) h(9, c) = 1.0;
  h(3, 2) = 0.4;
  h(11, 13) = 0.0;  // the window's lowest cell
  const deliberative::LocalMap map =
      test::make_local_map(h, MarsProcessor(kappa).gap(h), kBody, {3, 3}, std::nullopt);
  CellMask band = CellMask::Zero(12, 14);
  band.topRows(6).setOnes();
  const Heightmap gap = band_fill_gap(map, band, kappa);
  // Brute force: cones of slope kappa from the band's cells only (the others are no sources).
  for (int r = 0; r < 12; ++r)
    for (int c = 0; c < 14; ++c) {
      double top = h(r, c);
      for (int qr = 0; qr < 6; ++qr)
        for (int qc = 0; qc < 14; ++qc) top = std::max(top, h(qr, qc) - kappa * 0.25 * std::hypot(qr - r, qc - c));
      EXPECT_NEAR(gap(r, c), top - h(r, c), 1e-9) << r << ", " << c;
    }
  // The strip beside the band would have asked for 1 - 0.2 x 0.75 - 0.1 m at the band's edge (row 6 is 3 cells away).
  EXPECT_NEAR(map.gap(6, 10), 0.75, 1e-9);
  EXPECT_LT(gap(6, 10), 0.01);
}

TEST(BandFill, WhatIsLeftToFillAlongAWayIsTheMarsGapOfTheSurfaceTheBodyDrivesOn) {
  // 16 x 20 cells of 0.25 m, fractal-free but uneven: a slope along the columns, a 0.6 m ridge on row 3 (inside a
  // 3 m band centred on row 8, outside a 0.5 m body radius of the way on row 8), a 0.35 m top on the way at (8, 4)
  // and a pit on the way at (8, 12).
  const GridGeometry g{16, 20, 0.0, 0.0, 0.25};
  const double kappa = 0.2;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(0.0, 0.05);
  Heightmap h(g, 0.0);
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 20; ++c) h(r, c) = 0.3 - 0.01 * c + noise(rng);
  for (int c = 0; c < 20; ++c) h(3, c) = 0.6;
  h(8, 4) = 0.35;
  h(8, 12) = -0.2;
  h(15, 19) = -0.5;  // the window's lowest cell
  const deliberative::LocalMap map =
      test::make_local_map(h, MarsProcessor(kappa).gap(h), kBody, {8, 1}, std::nullopt);
  const std::vector<CellIndex> way = row_path(8, 1, 18);
  const double radius = 0.5;  // 2 cells
  const Heightmap gap = way_fill_gap(map, way, radius, kappa);
  // Brute force: cones of slope kappa from the cells within the radius of a cell of the way; never above the
  // window's own gap.
  for (int r = 0; r < 16; ++r)
    for (int c = 0; c < 20; ++c) {
      double top = h(r, c);
      for (int qr = 0; qr < 16; ++qr)
        for (int qc = 0; qc < 20; ++qc) {
          const bool source = std::any_of(way.begin(), way.end(), [&](CellIndex p) {
            return 0.25 * std::hypot(qr - p.row, qc - p.col) <= radius + 1e-9;
          });
          if (source) top = std::max(top, h(qr, qc) - kappa * 0.25 * std::hypot(qr - r, qc - c));
        }
      EXPECT_NEAR(gap(r, c), std::min(map.gap(r, c), top - h(r, c)), 1e-9) << r << ", " << c;
    }
  // The pit on the way is filled from the way's own surface around it, not from the ridge inside the band: the band's
  // own surface asks more there.
  const CellMask band = band_mask(map, {way}, 1.5);
  const Heightmap band_gap = band_fill_gap(map, band, kappa);
  EXPECT_GT(gap(8, 12), 0.2);
  EXPECT_GT(band_gap(8, 12), gap(8, 12) + 0.05);
  EXPECT_GT(band_gap(7, 10), gap(7, 10) + 0.05);
}

}  // namespace
}  // namespace marsala::agent::executive
