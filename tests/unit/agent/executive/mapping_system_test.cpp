#include "marsala/agent/executive/mapping_system.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/terrain/generators.hpp"

namespace marsala::agent::executive {
namespace {

// A 5 x 7 world at 0.5 m cells cut in 3-cell tiles: tile rows 0..1 (3 and 2 cells), tile cols 0..2 (3, 3, 1).
const GridGeometry kWorld{5, 7, 10.0, 20.0, 0.5};

TerrainTile tile(int tr, int tc, int rows, int cols, double base) {
  TerrainTile t;
  t.tile_row = tr;
  t.tile_col = tc;
  t.rows = rows;
  t.cols = cols;
  // Values that do not survive a round trip through decimal text or float: only a bit copy keeps them.
  for (int i = 0; i < rows * cols; ++i) t.heights.push_back(std::nextafter(base + 0.1 * i, 1e9) / 3.0);
  return t;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(MappingSystem, TilesLandBitForBitAndTheRestStaysUnknown) {
  MappingSystem map(kWorld, 3);
  EXPECT_EQ(map.known_cells(), 0);
  const TerrainTile a = tile(1, 1, 2, 3, 7.0);   // rows 3..4, cols 3..5
  const TerrainTile b = tile(0, 2, 3, 1, -2.0);  // rows 0..2, col 6 (cut by the east edge)
  map.integrate_tile(a);
  map.integrate_tile(b);
  EXPECT_EQ(map.known_cells(), 6 + 3);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(same_bits(map.heights()(3 + r, 3 + c), a.heights[r * 3 + c]));
      EXPECT_TRUE(map.is_known({3 + r, 3 + c}));
    }
  for (int r = 0; r < 3; ++r) EXPECT_TRUE(same_bits(map.heights()(r, 6), b.heights[r]));
  // Everything else: unknown, height 0.
  int unknown = 0;
  for (int r = 0; r < kWorld.rows; ++r)
    for (int c = 0; c < kWorld.cols; ++c)
      if (!map.is_known({r, c})) {
        ++unknown;
        EXPECT_EQ(map.heights()(r, c), 0.0);
      }
  EXPECT_EQ(unknown, 35 - 9);
  EXPECT_FALSE(map.is_known({5, 0}));  // off the grid

  // A changed tile overwrites, and the known count does not double.
  map.integrate_tile(tile(1, 1, 2, 3, 100.0));
  EXPECT_EQ(map.known_cells(), 9);
  EXPECT_TRUE(same_bits(map.heights()(4, 5), tile(1, 1, 2, 3, 100.0).heights[5]));
}

TEST(MappingSystem, RejectsTilesThatDoNotFit) {
  MappingSystem map(kWorld, 3);
  EXPECT_THROW(map.integrate_tile(tile(2, 0, 3, 3, 0.0)), InvalidArgument);   // no tile row 2
  EXPECT_THROW(map.integrate_tile(tile(0, -1, 3, 3, 0.0)), InvalidArgument);  // negative
  EXPECT_THROW(map.integrate_tile(tile(1, 0, 3, 3, 0.0)), InvalidArgument);   // last tile row has 2 rows
  EXPECT_THROW(map.integrate_tile(tile(0, 2, 3, 3, 0.0)), InvalidArgument);   // last tile col has 1 col
  TerrainTile short_tile = tile(0, 0, 3, 3, 0.0);
  short_tile.heights.pop_back();
  EXPECT_THROW(map.integrate_tile(short_tile), InvalidArgument);
  TerrainTile nan_tile = tile(0, 0, 3, 3, 0.0);
  nan_tile.heights[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(map.integrate_tile(nan_tile), InvalidArgument);
  EXPECT_EQ(map.known_cells(), 0);  // nothing of a rejected tile lands
  EXPECT_THROW(MappingSystem(kWorld, 0), InvalidArgument);
  EXPECT_THROW(MappingSystem(GridGeometry{0, 7, 0.0, 0.0, 0.5}, 3), InvalidArgument);
}

TEST(MappingSystem, TrajectoryKeepsTheCellsStoodOnOnce) {
  MappingSystem map(kWorld, 3);
  // Cell (r, c) has its centre at x = 10 + 0.5 (c + 0.5), y = 20 + 0.5 (5 - r - 0.5).
  map.record_pose({10.25, 22.25});  // (0, 0)
  map.record_pose({10.40, 22.10});  // (0, 0) again: kept once
  map.record_pose({10.75, 22.25});  // (0, 1)
  map.record_pose({10.75, 21.75});  // (1, 1)
  map.record_pose({10.25, 22.25});  // back to (0, 0): a new entry
  const std::vector<CellIndex> expected{{0, 0}, {0, 1}, {1, 1}, {0, 0}};
  EXPECT_EQ(map.trajectory(), expected);
  EXPECT_THROW(map.record_pose({9.9, 22.0}), InvalidArgument);
  EXPECT_THROW(map.record_pose({std::nan(""), 22.0}), InvalidArgument);

  map.integrate({tile(0, 0, 3, 3, 1.0)}, {13.25, 20.25});  // the pose is cell (4, 6)
  EXPECT_EQ(map.trajectory().back(), (CellIndex{4, 6}));
  EXPECT_EQ(map.known_cells(), 9);
}

TEST(MappingSystem, RegistrationMovesTilesAndDropsWhatLeavesTheGrid) {
  // A robot that believes itself one row north and two columns west of where it is registers what it senses there.
  MappingSystem map(kWorld, 3);
  map.set_registration({-1, -2});
  const TerrainTile a = tile(1, 1, 2, 3, 7.0);  // world rows 3..4, cols 3..5 -> rows 2..3, cols 1..3
  map.integrate_tile(a);
  EXPECT_EQ(map.known_cells(), 6);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(map.heights()(2 + r, 1 + c), a.heights[r * 3 + c]));
  EXPECT_FALSE(map.is_known({4, 3}));
  EXPECT_FALSE(map.is_known({3, 4}));
  // Moved past the grid's east edge: world col 6 one column east is col 7, off the 7-column grid: nothing lands.
  map.set_registration({-1, 1});
  map.integrate_tile(tile(0, 2, 3, 1, -2.0));
  EXPECT_EQ(map.known_cells(), 6);
  map.set_registration({1, 0});  // one row south: world row 4 leaves the grid
  const TerrainTile b = tile(1, 0, 2, 3, 1.0);
  map.integrate_tile(b);
  EXPECT_EQ(map.known_cells(), 6 + 3);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(map.heights()(4, c), b.heights[c]));
}

/// Errors of the known cells of `map` against `truth` [m]: sorted absolute differences.
std::vector<double> known_errors(const MappingSystem& map, const Heightmap& truth) {
  std::vector<double> errors;
  for (int r = 0; r < truth.rows(); ++r)
    for (int c = 0; c < truth.cols(); ++c)
      if (map.is_known({r, c})) errors.push_back(std::abs(map.heights()(r, c) - truth(r, c)));
  std::sort(errors.begin(), errors.end());
  return errors;
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted.empty() ? 0.0 : sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

/// A generated "mix" terrain of n x n cells of 0.1 m.
Heightmap mix_terrain(int n, std::uint64_t seed) {
  terrain::GeneratorSpec spec;
  spec.rows = n;
  spec.cols = n;
  spec.cell_size_m = 0.1;
  spec.seed = seed;
  return terrain::generate_terrain("mix", spec);
}

/// One scan of `truth` by `sensor` from (x, y), inserted from the true origin.
void scan_into(MappingSystem& map, const Heightmap& truth, double x, double y, double heading, std::uint64_t seed) {
  const Point3 origin = sensor_origin(truth, x, y, map.sensor());
  map.integrate_scan(cast_scan(truth, origin, heading, map.sensor(), seed), origin);
}

// A laser robot scanning a generated 12 x 12 m terrain (0.1 m cells, relief ~0.5 m) from poses 1 m apart: the
// derived heightmap holds the true heights over its known cells within the laser's noise, the known region grows
// with every scan, and the cells known after the first scan stay as good (each holds its latest reading). The numbers
// are printed for docs/runtime.md#mapping.
TEST(MappingSystem, ALaserMapConvergesToTheTerrainAsScansAccumulate) {
  const Heightmap truth = mix_terrain(120, 7);
  MappingSystem map(truth.geometry(), 16, sensor_defaults(SensorKind::kLaser));

  scan_into(map, truth, 2.05, 6.05, 0.0, 1);
  const CellMask first_known = map.known();
  const long long first_count = map.known_cells();
  const auto first_errors = [&] {
    double sum2 = 0.0;
    for (int r = 0; r < truth.rows(); ++r)
      for (int c = 0; c < truth.cols(); ++c)
        if (first_known(r, c) != 0) sum2 += std::pow(map.heights()(r, c) - truth(r, c), 2);
    return std::sqrt(sum2 / static_cast<double>(first_count));
  };
  const double rms_after_1 = first_errors();
  std::vector<double> errors = known_errors(map, truth);
  std::printf("scans 1: known %lld cells, median %.4f m, p95 %.4f m, rms (first cells) %.4f m\n", map.known_cells(),
              quantile(errors, 0.5), quantile(errors, 0.95), rms_after_1);
  long long known_before = map.known_cells();
  for (int k = 2; k <= 8; ++k) {
    scan_into(map, truth, 2.05 + (k - 1), 6.05, 0.0, k);
    EXPECT_GE(map.known_cells(), known_before);
    known_before = map.known_cells();
    errors = known_errors(map, truth);
    std::printf("scans %d: known %lld cells, median %.4f m, p95 %.4f m, rms (first cells) %.4f m\n", k,
                map.known_cells(), quantile(errors, 0.5), quantile(errors, 0.95), first_errors());
  }
  const double rms_after_8 = first_errors();
  // Each cell holds its latest scan's reading (the terrain changes under construction): the error stays at one
  // scan's noise, it does not grow as scans replace each other.
  EXPECT_LT(rms_after_8, 1.25 * rms_after_1);
  EXPECT_LT(quantile(errors, 0.5), 0.01);  // the laser's noise is 1 cm sd
  EXPECT_LT(quantile(errors, 0.95), 0.05);
  // A fifth of the terrain from 8 scans along one line, although hits within three noise spreads of a cell edge
  // (hits on walls and on a slope's steps scatter across it) are left out.
  EXPECT_GT(map.known_cells(), truth.size() / 5);
  EXPECT_GT(map.octree_leaves(), 0u);
  // Cells never hit stay unknown and at 0.
  for (int r = 0; r < truth.rows(); ++r)
    for (int c = 0; c < truth.cols(); ++c)
      if (!map.is_known({r, c})) {
        EXPECT_EQ(map.heights()(r, c), 0.0);
      }
}

// A 0.3 m wall at x in [3.0, 3.2) before a camera 0.5 m up at x = 2.05: it shadows the ground up to x = 3.2 +
// 0.3 * 1.15 / 0.2 = 4.925 m, which stays unknown, col 32 just past the wall too (hits on the wall's edge that noise
// pushes past it are left out); the wall's top is known at its height, the ground before and beyond the shadow at 0.
TEST(MappingSystem, OccludedCellsStayUnknown) {
  Heightmap truth(GridGeometry{60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 60; ++r)
    for (int c = 30; c < 32; ++c) truth(r, c) = 0.3;
  // A camera whose noise does not grow with range (2 mm): it places hits in cells past the shadow too (the default's
  // grows by 2 mm/m^2 and leaves hits beyond 2 m out: AHitTooNoisyToPlaceInACellIsLeftOut).
  SensorSpec camera = sensor_defaults(SensorKind::kRgbd);
  camera.noise_sd_per_m2 = 0.0;
  MappingSystem map(truth.geometry(), 16, camera);
  scan_into(map, truth, 2.05, 3.05, 0.0, 5);  // looking east
  for (int r = 0; r < 60; ++r)
    for (int c = 32; c < 49; ++c) EXPECT_FALSE(map.is_known({r, c})) << r << ", " << c;  // the shadow
  int wall_known = 0;
  for (int r = 25; r <= 35; ++r)
    for (int c = 30; c <= 31; ++c)
      if (map.is_known({r, c})) {
        ++wall_known;
        EXPECT_NEAR(map.heights()(r, c), 0.3, 0.04) << r << ", " << c;  // face hits mixed in: a few cm
      }
  EXPECT_GT(wall_known, 3);
  EXPECT_TRUE(map.is_known({30, 25}));
  EXPECT_NEAR(map.heights()(30, 25), 0.0, 0.02);
  long long beyond = 0;
  for (int r = 0; r < 60; ++r)
    for (int c = 50; c < 100; ++c)
      if (map.is_known({r, c})) {
        ++beyond;
        EXPECT_NEAR(map.heights()(r, c), 0.0, 0.05) << r << ", " << c;
      }
  EXPECT_GT(beyond, 30);
  // Nothing behind the camera either.
  EXPECT_FALSE(map.is_known({30, 10}));
}

// A cell rises (a deposit within the same voxel): the map follows within a few scans.
TEST(MappingSystem, TheMapFollowsADeposit) {
  Heightmap truth(GridGeometry{60, 60, 0.0, 0.0, 0.1}, 0.0);
  SensorSpec laser = sensor_defaults(SensorKind::kLaser);
  laser.noise_sd_m = 0.0;
  MappingSystem map(truth.geometry(), 16, laser);
  scan_into(map, truth, 3.05, 3.05, 0.0, 1);
  ASSERT_TRUE(map.is_known({30, 40}));
  EXPECT_NEAR(map.heights()(30, 40), 0.0, 1e-6);
  for (int r = 28; r <= 32; ++r)
    for (int c = 38; c <= 42; ++c) truth(r, c) = 0.05;
  for (int k = 2; k <= 8; ++k) scan_into(map, truth, 3.05, 3.05, 0.0, k);
  EXPECT_NEAR(map.heights()(30, 40), 0.05, 0.005);
  // Raised by a voxel and more: the highest occupied voxel wins at once.
  for (int r = 28; r <= 32; ++r)
    for (int c = 38; c <= 42; ++c) truth(r, c) = 0.25;
  scan_into(map, truth, 3.05, 3.05, 0.0, 9);
  EXPECT_NEAR(map.heights()(30, 40), 0.25, 1e-5);
}

TEST(MappingSystem, RefusesAbsurdScans) {
  const GridGeometry world{60, 60, 0.0, 0.0, 0.1};
  MappingSystem map(world, 16, sensor_defaults(SensorKind::kLaser));
  const Point3 origin{3.05, 3.05, 0.5};  // a cell centre: hits near cell edges are left out
  EXPECT_THROW(map.integrate_scan({{std::numeric_limits<float>::quiet_NaN(), 0.0F, 0.0F}}, origin), InvalidArgument);
  EXPECT_THROW(map.integrate_scan({{0.0F, 0.0F, -1e9F}}, origin), InvalidArgument);
  EXPECT_THROW(map.integrate_scan({{0.0F, 20.0F, 0.0F}}, origin), InvalidArgument);  // beyond 8 m + noise
  EXPECT_THROW(map.integrate_scan({}, {std::nan(""), 3.0, 0.5}), InvalidArgument);
  std::vector<ScanPoint> too_many(static_cast<std::size_t>(map.sensor().ray_count() + 1), ScanPoint{0.0F, 0.0F, -0.5F});
  EXPECT_NE(scan_problem(too_many, map.sensor()), "");
  EXPECT_EQ(map.known_cells(), 0);
  // Points off the grid are left out, not an error.
  map.integrate_scan({{-5.0F, 0.0F, -0.5F}, {0.0F, 0.0F, -0.5F}}, origin);
  EXPECT_EQ(map.known_cells(), 1);
  EXPECT_THROW(MappingSystem(GridGeometry{40000, 10, 0.0, 0.0, 0.1}, 16, sensor_defaults(SensorKind::kLaser)),
               InvalidArgument);
}

TEST(MappingSystem, AssumedGroundFillsOnlyUnknownCellsUnderTheBody) {
  const GridGeometry world{60, 60, 0.0, 0.0, 0.1};
  MappingSystem map(world, 16, sensor_defaults(SensorKind::kRgbd));
  map.assume_ground({3.05, 3.05}, 0.7, 0.5);
  // The disc of radius 0.5 m around cell (29, 30): 81 cell centres (a radius of 5 cells).
  EXPECT_EQ(map.known_cells(), 81);
  EXPECT_EQ(map.heights()(29, 30), 0.7);
  EXPECT_EQ(map.heights()(29, 35), 0.7);
  EXPECT_FALSE(map.is_known({29, 36}));
  EXPECT_THROW(map.assume_ground({30.0, 3.0}, 0.7, 0.5), InvalidArgument);
}

// An empty map of a 6 x 6 m world at 0.1 m cells for a laser without range noise.
MappingSystem exact_laser_map() {
  SensorSpec exact = sensor_defaults(SensorKind::kLaser);
  exact.noise_sd_m = 0.0;
  exact.noise_sd_per_m2 = 0.0;
  return MappingSystem(GridGeometry{60, 60, 0.0, 0.0, 0.1}, 16, exact);
}

// A robot at 1.0 m on the edge of a 1 m deep trench (cols 30-32 of row 30, 0.1 m cells): one noise-free laser ray
// from its sensor (2.95, 2.95, 1.5) to the trench floor at the centre of col 32 (3.25, 2.95, 0.0) crosses col 30 from
// 1.25 m down to 0.75 m and col 31 from 0.75 m to 0.25 m, both below 0.9 m (the ground less 0.1 m): those cells lie
// lower than the robot stands and stay unknown. Col 32 is known from the hit; col 33, which the ray never reached, and
// the trench cells of row 29, which no ray crossed, are assumed at 1.0 m, and so is everything without the check.
TEST(MappingSystem, GroundARayWentBelowIsNotAssumed) {
  MappingSystem map = exact_laser_map();
  map.integrate_scan({{0.3F, 0.0F, -1.5F}}, {2.95, 2.95, 1.5});
  ASSERT_TRUE(map.is_known({30, 32}));
  ASSERT_EQ(map.known_cells(), 1);
  MappingSystem unchecked = map;
  map.assume_ground({2.95, 2.95}, 1.0, 0.5, 0.1);
  EXPECT_FALSE(map.is_known({30, 30}));
  EXPECT_FALSE(map.is_known({30, 31}));
  EXPECT_FALSE(map.assumed()(30, 32));
  for (const CellIndex c : {CellIndex{30, 29}, CellIndex{30, 33}, CellIndex{29, 30}, CellIndex{29, 31}}) {
    EXPECT_TRUE(map.is_known(c)) << c.row << ", " << c.col;
    EXPECT_TRUE(map.assumed()(c.row, c.col) != 0) << c.row << ", " << c.col;
    EXPECT_EQ(map.heights()(c), 1.0);
  }
  unchecked.assume_ground({2.95, 2.95}, 1.0, 0.5);
  EXPECT_TRUE(unchecked.is_known({30, 30}));
  EXPECT_TRUE(unchecked.is_known({30, 31}));
  EXPECT_EQ(unchecked.known_cells(), map.known_cells() + 2);
  EXPECT_THROW(map.assume_ground({2.95, 2.95}, 1.0, 0.5, std::nan("")), InvalidArgument);
}

// Ground assumed before any ray came (the trench of the test above, the robot at 1.0 m): the same ray, scanned later,
// went below cols 30 and 31 of row 30, and the next assume_ground() forgets them (unknown again, height 0); col 32 is
// the hit's. A motion the world refused to (30, 33): the assumed cells within 0.1 m of it, (29, 33), (31, 33) and
// (30, 34) (the robot's disc, 5 cells around (30, 29), ends there), are forgotten, (30, 33) itself too; (30, 32), read
// by a scan, and the cells farther away, e.g. (29, 32), stay. No forgotten cell is assumed again.
TEST(MappingSystem, AssumedGroundARayWentBelowOrARefusalNamedIsForgotten) {
  MappingSystem map = exact_laser_map();
  map.assume_ground({2.95, 2.95}, 1.0, 0.5, 0.1);
  ASSERT_EQ(map.known_cells(), 81);
  map.integrate_scan({{0.3F, 0.0F, -1.5F}}, {2.95, 2.95, 1.5});
  ASSERT_TRUE(map.is_known({30, 30}));  // still assumed: nothing looks at it until the robot assumes again
  map.assume_ground({2.95, 2.95}, 1.0, 0.5, 0.1);
  EXPECT_FALSE(map.is_known({30, 30}));
  EXPECT_FALSE(map.is_known({30, 31}));
  EXPECT_EQ(map.heights()(30, 30), 0.0);
  EXPECT_TRUE(map.is_known({30, 32}));
  EXPECT_FALSE(map.assumed()(30, 32));
  EXPECT_EQ(map.known_cells(), 81 - 2);
  map.forget_assumed_ground({30, 33}, 0.1);
  for (const CellIndex c : {CellIndex{30, 33}, CellIndex{29, 33}, CellIndex{31, 33}, CellIndex{30, 34}})
    EXPECT_FALSE(map.is_known(c)) << c.row << ", " << c.col;
  EXPECT_TRUE(map.is_known({30, 32}));
  EXPECT_TRUE(map.is_known({29, 32}));
  EXPECT_EQ(map.known_cells(), 81 - 2 - 4);
  // Forgotten cells are not guessed again: only a reading makes them known.
  map.assume_ground({2.95, 2.95}, 1.0, 0.5, 0.1);
  EXPECT_EQ(map.known_cells(), 81 - 2 - 4);
  EXPECT_FALSE(map.is_known({30, 33}));
  EXPECT_FALSE(map.is_known({30, 30}));
}

// A camera robot drove east along row 15 of a 3 x 3 m world (cols 5 to 15, 0.1 m cells), assuming the ground 0.5 m
// around it at 1.0 m (no scan came): a band of rows 10 to 20. Its body's ball is 0.4 m, so the world vouched for the
// cells within 4 cells of the path; the outer ring (4 to 5 cells from the path) is a guess on both sides. A motion to
// (14, 10) refused for the terrain: its ball is forgotten, and so is the whole guessed ring north of the path, its end
// caps too, down to the path's row (a distance of 4 or less from a cell stood on, or the path's side, stops it); the
// south ring and the rest of the band stay.
TEST(MappingSystem, ARefusalForgetsTheWholeGuessedEdgeOnItsSideOfThePath) {
  const GridGeometry world{30, 30, 0.0, 0.0, 0.1};
  MappingSystem map(world, 16, sensor_defaults(SensorKind::kRgbd));
  for (int col = 5; col <= 15; ++col) {
    const Position at = world.cell_center({15, col});
    map.record_pose(at);
    map.assume_ground(at, 1.0, 0.5);
  }
  const MappingSystem before = map;
  map.forget_assumed_ground({14, 10}, 0.4);
  const auto path_distance2 = [](int row, int col) {  // to the nearest cell of the path [cells^2]
    const int dc = std::max({0, 5 - col, col - 15});
    return (row - 15) * (row - 15) + dc * dc;
  };
  int forgotten = 0;
  for (int row = 0; row < 30; ++row)
    for (int col = 0; col < 30; ++col) {
      if (!before.is_known({row, col})) continue;
      const bool in_ball = (row - 14) * (row - 14) + (col - 10) * (col - 10) <= 16;
      const bool north_ring = row < 15 && path_distance2(row, col) > 16;
      EXPECT_EQ(map.is_known({row, col}), !(in_ball || north_ring)) << row << ", " << col;
      forgotten += in_ball || north_ring ? 1 : 0;
    }
  EXPECT_EQ(map.known_cells(), before.known_cells() - forgotten);
  EXPECT_GT(forgotten, 49 + 11);  // the ball and more than the ring's straight part
  // Without a path (nothing stood on) only the ball is forgotten.
  MappingSystem pathless(world, 16, sensor_defaults(SensorKind::kRgbd));
  pathless.assume_ground(world.cell_center({15, 10}), 1.0, 0.5);
  pathless.forget_assumed_ground({14, 10}, 0.4);
  EXPECT_EQ(pathless.known_cells(), 81 - 49);  // the ball lies in the disc (1 cell off its centre, 4 in radius)
}

// A noise-free laser at (3.55, 2.95, 0.5) m reads cell (30, 40) (x 4.0-4.1 m) at 0 m in its first scan (a ray down to
// its centre). Then robots build there out of its view, and a second scan's rising ray strikes the cell's west face
// (the edge x = 4.0 m) at 0.6 m: the cell rose since it was read (terrain only rises), so its top is at least 0.6 m, a
// surface (a deposition target). The same face hit on a map that never read the cell is a bound (no surface), and so
// is one that comes in the same scan as a reading below it.
TEST(MappingSystem, AFaceAboveAnOlderReadingIsTheSurfaceTheCellRoseTo) {
  const Point3 origin{3.55, 2.95, 0.5};
  const ScanPoint down{0.5F, 0.0F, -0.5F}, face{0.45F, 0.0F, 0.1F};
  MappingSystem rose = exact_laser_map();
  rose.integrate_scan({down}, origin);
  ASSERT_TRUE(rose.is_known({30, 40}));
  ASSERT_NEAR(rose.heights()(30, 40), 0.0, 1e-6);
  rose.integrate_scan({face}, origin);
  EXPECT_NEAR(rose.heights()(30, 40), 0.6, 1e-6);
  EXPECT_EQ(rose.assumed()(30, 40), 0);
  MappingSystem unread = exact_laser_map();
  unread.integrate_scan({face}, origin);
  EXPECT_NEAR(unread.heights()(30, 40), 0.6, 1e-6);
  EXPECT_NE(unread.assumed()(30, 40), 0);
  MappingSystem same_scan = exact_laser_map();
  same_scan.integrate_scan({down, face}, origin);
  EXPECT_NEAR(same_scan.heights()(30, 40), 0.6, 1e-6);
  EXPECT_NE(same_scan.assumed()(30, 40), 0);
}

// Hand-made hits past the edge of a 0.3 m wall (cols 30-31) known from a first scan. A hit inside col 32 at the
// wall's height, from a ray that came over the wall's top (it crossed into col 32 at 0.3 m, within noise of the
// top), is the edge's hit pushed over by noise: left out, col 32 stays unknown. The same point from a ray that came
// down steeply (crossing into col 32 7 cm above the top) is a surface there: col 32 is known at 0.3 m.
TEST(MappingSystem, AHitPushedPastAnEdgeIntoItsShadowIsLeftOut) {
  Heightmap truth(GridGeometry{60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 60; ++r)
    for (int c = 30; c < 32; ++c) truth(r, c) = 0.3;
  SensorSpec laser = sensor_defaults(SensorKind::kLaser);
  MappingSystem map(truth.geometry(), 16, laser);
  const auto hit = [](Point3 origin, double x, double y, double z) {
    return ScanPoint{static_cast<float>(x - origin.x), static_cast<float>(y - origin.y),
                     static_cast<float>(z - origin.z)};
  };
  const Point3 low{2.05, 3.05, 0.35};  // row 29 (y 3.05), 5 cm above the wall's top
  map.integrate_scan({hit(low, 3.05, 3.05, 0.3), hit(low, 3.15, 3.05, 0.3)}, low);  // the wall's top, cols 30, 31
  ASSERT_TRUE(map.is_known({29, 30}));
  ASSERT_NEAR(map.heights()(29, 31), 0.3, 1e-6);
  // The ray from 0.35 m at x 2.05 to (3.25, 0.3) crosses x = 3.2 at 0.302 m: over the top, within 3 cm of it.
  map.integrate_scan({hit(low, 3.25, 3.05, 0.3)}, low);
  EXPECT_FALSE(map.is_known({29, 32}));
  // From 2 m up at x 2.05 the ray crosses x = 3.2 at 0.3 + 1.7 * 0.05 / 1.2 = 0.371 m: 7 cm above the top.
  const Point3 high{2.05, 3.05, 2.0};
  map.integrate_scan({hit(high, 3.25, 3.05, 0.3)}, high);
  ASSERT_TRUE(map.is_known({29, 32}));
  EXPECT_NEAR(map.heights()(29, 32), 0.3, 1e-6);
}

// A depth camera's noise grows with range (2 mm + 2 mm/m^2 r^2): the band left out along cell edges is 3 noise
// spreads at the hit's range, and a hit whose band would exceed 0.3 cell cannot be placed in a cell: at 3 m
// (sd 20 mm, band 60 mm on 0.1 m cells) it is left out; at 1 m (sd 4 mm, band 12 mm) a cell centre's hit is kept.
TEST(MappingSystem, AHitTooNoisyToPlaceInACellIsLeftOut) {
  MappingSystem map(GridGeometry{60, 100, 0.0, 0.0, 0.1}, 16, sensor_defaults(SensorKind::kRgbd));
  const Point3 origin{2.05, 3.05, 0.5};
  const float drop = -0.5F;
  map.integrate_scan({{0.9F, 0.0F, drop}, {3.0F, 0.0F, drop}}, origin);  // ranges 1.03 m and 3.04 m, cell centres
  EXPECT_TRUE(map.is_known({29, 29}));                                   // x 2.95
  EXPECT_FALSE(map.is_known({29, 50}));                                  // x 5.05
  // The band at 1 m is 1.2 cm: a hit 1 cm inside a cell edge is left out, one 1.5 cm inside is kept.
  map.integrate_scan({{0.86F, 0.1F, drop}, {0.865F, 0.2F, drop}}, origin);
  EXPECT_FALSE(map.is_known({28, 29}));  // x 2.91: 1 cm from the edge at 2.9
  EXPECT_TRUE(map.is_known({27, 29}));   // x 2.915
}

// A noise-free sensor before a 1.5 m wall whose face lies exactly on a cell edge (x = 4 m, cols 40 on): every hit on
// the face lies on the edge. The sensor (0.5 m up) sees no higher than its top elevation, so the face is all it sees
// of the wall: its column is known at least as high as the highest face hit (the truth is higher), never as the
// ground; the cells before it read the ground. Expected from the geometry alone: the highest face hit is at
// 0.5 m + d tan(top elevation), d the distance from the sensor to the face.
TEST(MappingSystem, ANoiseFreeWallOnACellEdgeIsMapped) {
  Heightmap truth(GridGeometry{60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 60; ++r)
    for (int c = 40; c < 100; ++c) truth(r, c) = 1.5;
  for (const SensorKind kind : {SensorKind::kRgbd, SensorKind::kLaser}) {
    SensorSpec sensor = sensor_defaults(kind);
    sensor.noise_sd_m = 0.0;
    sensor.noise_sd_per_m2 = 0.0;
    MappingSystem map(truth.geometry(), 16, sensor);
    const double x = 2.05, d = 4.0 - x;
    scan_into(map, truth, x, 3.05, 0.0, 1);  // facing east
    const double top_hit = std::min(1.5, 0.5 + d * std::tan(sensor.vertical_max_deg * M_PI / 180.0));
    ASSERT_TRUE(map.is_known({29, 40})) << to_string(kind);
    EXPECT_GT(map.heights()(29, 40), top_hit - 0.1) << to_string(kind);
    EXPECT_LE(map.heights()(29, 40), 1.5 + 1e-6) << to_string(kind);
    EXPECT_TRUE(map.assumed()(29, 40)) << to_string(kind);  // a bound, not its surface: never a deposition target
    for (int c = 25; c < 40; ++c) {
      if (map.is_known({29, c})) {
        EXPECT_NEAR(map.heights()(29, c), 0.0, 1e-6) << to_string(kind) << " col " << c;
      }
    }
    EXPECT_FALSE(map.is_known({29, 45})) << to_string(kind);  // the top lies above every ray
  }
}

// A noisy camera 1 m before the same wall: the face hits it places in the wall's column came up to it from below (the
// sensor is 0.5 m up), so the column's reading is a lower bound, no surface: marked so (never a deposition target).
// The ground before the wall, hit from above, is a surface.
TEST(MappingSystem, AFaceSeenFromBelowIsABoundNotASurface) {
  Heightmap truth(GridGeometry{60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 60; ++r)
    for (int c = 40; c < 100; ++c) truth(r, c) = 1.5;
  MappingSystem map(truth.geometry(), 16, sensor_defaults(SensorKind::kRgbd));
  for (std::uint64_t k = 1; k <= 5; ++k) scan_into(map, truth, 2.95, 3.05, 0.0, k);
  int bounds = 0;
  for (int r = 20; r <= 40; ++r) {
    if (!map.is_known({r, 40})) continue;
    EXPECT_GT(map.heights()(r, 40), 0.5) << r;  // the highest face hits: above the sensor
    EXPECT_TRUE(map.assumed()(r, 40)) << r;
    ++bounds;
  }
  EXPECT_GT(bounds, 3);
  ASSERT_TRUE(map.is_known({29, 36}));
  EXPECT_FALSE(map.assumed()(29, 36));
  // Those bounds are faces' (bound()), and a face hit is a bound's reading: current while a recent scan hit a face
  // (hit_within), no longer once scans miss it.
  int current = 0;
  for (int r = 20; r <= 40; ++r) {
    if (!map.is_known({r, 40})) continue;
    EXPECT_TRUE(map.bound()(r, 40)) << r;
    current += map.hit_within({r, 40}, 1) ? 1 : 0;
  }
  EXPECT_GT(current, 0);
  EXPECT_FALSE(map.bound()(29, 36));
  for (int k = 0; k < 3; ++k) map.integrate_scan({}, {2.95, 3.05, 0.5});
  for (int r = 20; r <= 40; ++r) EXPECT_FALSE(map.hit_within({r, 40}, 3)) << r;
  // Ground assumed under the body is no face's bound.
  map.assume_ground({1.05, 5.05}, 0.0, 0.3);
  ASSERT_TRUE(map.assumed()(9, 10));
  EXPECT_FALSE(map.bound()(9, 10));
}

// A face hit belongs to the cell whose face the ray crossed, found from the ray's crossings with the grid lines within
// the hit's noise reach (3 noise sd), not to the cell holding the hit point; none when two cells' faces lie within
// 5 sd of it. Camera 0.5 m up at (1.55, 2.05), 0.1 m
// cells (col = floor(x / 0.1), row = 59 - floor(y / 0.1)); rising hits ~0.45 m away: sd 2 mm + 2 mm/m^2 * 0.2 m^2 =
// 2.4 mm, reach 7.2 mm.
TEST(MappingSystem, AFaceHitIsCreditedToTheFaceTheRayCrossed) {
  const GridGeometry grid{60, 100, 0.0, 0.0, 0.1};
  const Point3 origin{1.55, 2.05, 0.5};
  const auto hit = [&](double x, double y, double z) {
    return ScanPoint{static_cast<float>(x - origin.x), static_cast<float>(y - origin.y),
                     static_cast<float>(z - origin.z)};
  };
  // Noise left the hit 3 mm short of the face on x = 2.0 (in col 19); the y lines lie metres away along this ray:
  // the face is that of the cell the ray enters at x = 2.0, (39, 20), at least 0.55 m high; col 19 stays unknown.
  MappingSystem wall(grid, 16, sensor_defaults(SensorKind::kRgbd));
  wall.integrate_scan({hit(1.997, 2.045, 0.55)}, origin);
  ASSERT_TRUE(wall.is_known({39, 20}));
  EXPECT_NEAR(wall.heights()(39, 20), 0.55, 1e-6);
  EXPECT_TRUE(wall.bound()(39, 20));
  EXPECT_FALSE(wall.is_known({39, 19}));
  // Grazing the corner (2.0, 2.0): the ray (0.455, -0.0505) to (2.005, 1.9995) crosses x = 2.0 into (39, 20) 5.0 mm
  // before the hit, then y = 2.0 into (40, 20) 4.5 mm before it: both within the reach, either face may be the one
  // struck, so neither cell is credited.
  MappingSystem corner(grid, 16, sensor_defaults(SensorKind::kRgbd));
  corner.integrate_scan({hit(2.005, 1.9995, 0.55)}, origin);
  EXPECT_FALSE(corner.is_known({39, 20}));
  EXPECT_FALSE(corner.is_known({40, 20}));
  // A crossing within 3 sd and a rival one within 5 sd: the ray (3, 1) / sqrt(10) from (1.55, 2.05191) to
  // (1.99241, 2.199368) (range 0.47 m: sd 2.44 mm) crosses y = 2.2 into (37, 19) 2 mm past the hit, then x = 2.0 into
  // (37, 20) 8 mm past it (over 3 sd, under 5): a hit past 3 sd is rare, but a scan holds thousands of hits, and
  // neither cell is credited.
  const Point3 east_north_east{1.55, 2.05191, 0.5};
  MappingSystem rival(grid, 16, sensor_defaults(SensorKind::kRgbd));
  rival.integrate_scan({{static_cast<float>(1.99241 - 1.55), static_cast<float>(2.199368 - 2.05191), 0.05F}},
                       east_north_east);
  EXPECT_FALSE(rival.is_known({37, 19}));
  EXPECT_FALSE(rival.is_known({37, 20}));
  // The same direction 4.5 cm north of the corner: only x = 2.0 lies within reach, (39, 20) holds the face.
  MappingSystem beside(grid, 16, sensor_defaults(SensorKind::kRgbd));
  beside.integrate_scan({hit(2.005, 2.0445, 0.55)}, origin);
  EXPECT_TRUE(beside.is_known({39, 20}));
  // A noise-free ray exactly through the corner from the north-west crosses both lines at once into the south-east
  // cell (40, 20): that cell's face (its corner edge) is the one struck.
  SensorSpec exact = sensor_defaults(SensorKind::kRgbd);
  exact.noise_sd_m = 0.0;
  exact.noise_sd_per_m2 = 0.0;
  MappingSystem through(grid, 16, exact);
  const Point3 nw{1.55, 2.45, 0.5};
  through.integrate_scan({{0.45F, -0.45F, 0.1F}}, nw);
  ASSERT_TRUE(through.is_known({40, 20}));
  EXPECT_NEAR(through.heights()(40, 20), 0.6, 1e-6);
  EXPECT_FALSE(through.is_known({39, 20}));
  EXPECT_FALSE(through.is_known({40, 19}));
}

// hit_within(cell, n): one of the last n scans hit the cell's surface.
TEST(MappingSystem, HitWithinSaysWhetherARecentScanHitTheCell) {
  MappingSystem map(GridGeometry{60, 60, 0.0, 0.0, 0.1}, 16, sensor_defaults(SensorKind::kLaser));
  const Point3 origin{3.05, 3.05, 0.5};
  EXPECT_FALSE(map.hit_within({29, 35}, 3));
  map.integrate_scan({{0.5F, 0.0F, -0.5F}}, origin);  // cell (29, 35)
  EXPECT_EQ(map.scans(), 1);
  EXPECT_TRUE(map.hit_within({29, 35}, 1));
  map.integrate_scan({{-0.5F, 0.0F, -0.5F}}, origin);  // cell (29, 25)
  map.integrate_scan({{-0.5F, 0.0F, -0.5F}}, origin);
  EXPECT_FALSE(map.hit_within({29, 35}, 2));
  EXPECT_TRUE(map.hit_within({29, 35}, 3));
  EXPECT_TRUE(map.hit_within({29, 25}, 1));
  map.integrate_scan({}, origin);
  EXPECT_FALSE(map.hit_within({29, 35}, 3));
  EXPECT_FALSE(map.hit_within({29, 25}, 1));
  EXPECT_TRUE(map.hit_within({29, 25}, 2));
  EXPECT_TRUE(map.is_known({29, 35}));  // known stays known
  EXPECT_FALSE(map.hit_within({-1, 0}, 10));
}

}  // namespace
// The robot's own construction (record_built): a cell whose surface a scan read is at least its reading plus the
// rise from then on; a cell no sensor read gets no floor (no height to add to): it stays unknown.
TEST(MappingSystem, ABuiltCellGetsAFloorOnlyWhereItsSurfaceWasRead) {
  const Heightmap truth = mix_terrain(80, 11);
  MappingSystem map(truth.geometry(), 16, sensor_defaults(SensorKind::kLaser));
  scan_into(map, truth, 4.05, 4.05, 0.0, 3);
  std::optional<CellIndex> read, unread;
  for (int r = 0; r < truth.rows() && !(read && unread); ++r)
    for (int c = 0; c < truth.cols(); ++c) {
      const CellIndex cell{r, c};
      if (!map.is_known(cell) && !unread) unread = cell;
      if (map.is_known(cell) && map.assumed()(r, c) == 0 && map.last_hit_scan(cell) == map.scans() && !read)
        read = cell;
    }
  ASSERT_TRUE(read && unread);
  const double before = map.heights()(*read);
  map.record_built(*read, 0.25);
  map.record_built(*unread, 0.25);
  scan_into(map, truth, 4.05, 4.05, 0.0, 4);  // the next scan still reads the old surface there
  EXPECT_GE(map.heights()(*read), before + 0.25 - 1e-9);
  EXPECT_FALSE(map.is_known(*unread));
}

// A drop the world named (record_drop): the lower cell stands at the height the body found there, whatever the map
// read, and keeps it against later scans that hit it or its face (an outlier short of the rim's face keeps landing in
// a pit); the robot's own construction raises it, the world naming it higher (record_floor) ends it; the higher cell
// is at least its named height. An unknown cell becomes known at it; off-grid cells and non-finite heights are ignored.
TEST(MappingSystem, ADropTheWorldNamedHoldsItsHeightsAgainstLaterScans) {
  MappingSystem map(GridGeometry{60, 60, 0.0, 0.0, 0.1}, 16, sensor_defaults(SensorKind::kLaser));
  const Point3 origin{3.05, 3.05, 0.5};
  const CellIndex low{29, 35}, high{29, 36};
  map.integrate_scan({{0.5F, 0.0F, -0.1F}, {0.6F, 0.0F, -0.1F}}, origin);  // both read at 0.4 m
  ASSERT_TRUE(map.is_known(low) && map.is_known(high));
  ASSERT_NEAR(map.heights()(low), 0.4, 1e-6);
  map.record_drop(low, 0.02, high, 0.45);
  EXPECT_EQ(map.heights()(low), 0.02);
  EXPECT_EQ(map.assumed()(low.row, low.col), 0);  // a surface to build on
  EXPECT_GE(map.heights()(high), 0.45);
  EXPECT_EQ(map.told_scan(low), map.scans());
  // Scans that hit it again at the rim's height do not lift it.
  for (int i = 0; i < 3; ++i) map.integrate_scan({{0.5F, 0.0F, -0.1F}, {0.6F, 0.0F, -0.1F}}, origin);
  EXPECT_EQ(map.heights()(low), 0.02);
  EXPECT_GE(map.heights()(high), 0.45);
  // The robot's construction there raises it.
  map.record_built(low, 0.3);
  map.integrate_scan({{0.5F, 0.0F, -0.1F}}, origin);
  EXPECT_NEAR(map.heights()(low), 0.32, 1e-9);
  // The world naming it higher ends the ceiling: the next scan reads it again.
  map.record_floor(low, 0.38);
  map.integrate_scan({{0.5F, 0.0F, -0.1F}}, origin);
  EXPECT_NEAR(map.heights()(low), 0.4, 1e-6);
  // An unknown cell becomes known at the height told; off the grid or not finite: nothing.
  ASSERT_FALSE(map.is_known({0, 0}));
  map.record_drop({0, 0}, 0.1, {0, 1}, 0.5);
  EXPECT_TRUE(map.is_known({0, 0}));
  EXPECT_EQ(map.heights()(0, 0), 0.1);
  EXPECT_NO_THROW(map.record_drop({-1, 70}, 0.1, high, 0.5));
  map.record_drop({5, 5}, std::numeric_limits<double>::quiet_NaN(), high, 0.5);
  EXPECT_FALSE(map.is_known({5, 5}));
}

// A floor the world named (record_floor): the cell is at least that high from then on, as after the robot's own
// construction, whatever an older reading says; unknown cells get none.
TEST(MappingSystem, AFloorTheWorldNamedHoldsAgainstAStaleReading) {
  MappingSystem map(GridGeometry{60, 60, 0.0, 0.0, 0.1}, 16, sensor_defaults(SensorKind::kLaser));
  const Point3 origin{3.05, 3.05, 0.5};
  const CellIndex cell{29, 35};
  map.integrate_scan({{0.5F, 0.0F, -0.5F}, {0.4F, 0.0F, -0.5F}}, origin);  // read at 0 m
  // A floor that is not finite is no floor: one kept would hide the next (max(NaN, x) is NaN).
  map.record_floor(cell, std::numeric_limits<double>::quiet_NaN());
  map.record_floor(cell, 0.325);
  EXPECT_NEAR(map.heights()(cell), 0.325, 1e-9);
  map.integrate_scan({{0.4F, 0.0F, -0.5F}, {0.6F, 0.0F, -0.5F}}, origin);  // around it, not on it
  EXPECT_NEAR(map.heights()(cell), 0.325, 1e-9);
  map.record_floor(cell, 0.2);  // a lower floor changes nothing
  EXPECT_NEAR(map.heights()(cell), 0.325, 1e-9);
  // An unknown cell gets none (its height stays the unknown 0 m).
  map.record_floor({0, 0}, 1.0);
  EXPECT_FALSE(map.is_known({0, 0}));
  EXPECT_EQ(map.heights()(0, 0), 0.0);
  EXPECT_NEAR(map.heights()(cell), 0.325, 1e-9);
}

TEST(MappingSystem, ACellStoodOnKeepsItsBallUntilTheRobotBuildsInIt) {
  MappingSystem map(kWorld, 3);
  map.integrate({tile(0, 0, 3, 3, 1.0), tile(0, 1, 3, 3, 2.0), tile(1, 0, 2, 3, 3.0), tile(1, 1, 2, 3, 4.0)},
                {11.25, 21.75});  // cell (1, 2); column 6 stays unknown
  EXPECT_EQ(map.known_map().stood, nullptr);  // nothing stood on yet
  map.record_stood({11.25, 21.75});  // nothing kept before keep_stood_cells()
  EXPECT_EQ(map.known_map().stood, nullptr);
  EXPECT_THROW(map.keep_stood_cells(-1.0, 0.01), InvalidArgument);
  EXPECT_THROW(map.keep_stood_cells(1.0, std::nan("")), InvalidArgument);
  map.keep_stood_cells(1.0, 0.01);
  map.record_stood({11.25, 21.75});  // the ball: (1, 2) and its 4 axis neighbours
  map.record_stood({9.0, 21.75});    // off the grid: ignored
  const deliberative::StoodCells* stood = map.known_map().stood;
  ASSERT_NE(stood, nullptr);
  ASSERT_EQ(stood->balls.size(), 1u);
  const std::vector<double>& ball = stood->balls.at(1 * kWorld.cols + 2);
  const std::vector<CellIndex> offsets = disc_offsets(1.0);
  ASSERT_EQ(ball.size(), offsets.size());
  for (std::size_t i = 0; i < ball.size(); ++i)
    EXPECT_TRUE(same_bits(ball[i], map.heights()(CellIndex{1 + offsets[i].row, 2 + offsets[i].col})));
  EXPECT_EQ(stood->ball, offsets);
  EXPECT_DOUBLE_EQ(stood->margin_m, 0.01);
  // A deposition outside its ball changes nothing; one inside it (the robot's own) ends the fact.
  map.record_built({1, 4}, 0.1);
  EXPECT_EQ(map.known_map().stood->balls.count(1 * kWorld.cols + 2), 1u);
  map.record_built({2, 2}, 0.1);
  EXPECT_EQ(map.known_map().stood, nullptr);
}

// docs/runtime.md#mapping, "Under the rays": a camera 0.5 m above the top of a 3 m cliff, 0.625 m back from its edge
// (x = 8 m, 0.25 m cells), looking over it. No ray reaches the cliff's foot (the edge hides it) and the basin floor's
// hits are too far to place, so the cells below the edge stay unknown; but the rays that clear the edge cross their
// columns, and each stands below the lowest of them. Checked against the truth on every cell: the overflight is never
// below the cell's height (the one ray through the edge's corner row that clears it by the least, at 37.8 deg down,
// lies 0.18 m under the top over the first cell below it, x = 8-8.25 m, and 0.37 m under it over the second). Only the
// latest scan counts, a deposit accepted there raises it, and nothing is recorded beyond the range or without
// record_overflights().
TEST(MappingSystem, TheCellsUnderAScansRaysStandBelowThem) {
  Heightmap truth(GridGeometry{40, 80, 0.0, 0.0, 0.25}, 0.0);
  for (int r = 0; r < truth.rows(); ++r)
    for (int c = 0; c < 32; ++c) truth(r, c) = 3.0;
  const SensorSpec camera = sensor_defaults(SensorKind::kRgbd);
  MappingSystem plain(truth.geometry(), 16, camera);
  MappingSystem map(truth.geometry(), 16, camera);
  EXPECT_THROW(map.record_overflights(-1.0), InvalidArgument);
  map.record_overflights(3.25);
  const Point3 origin = sensor_origin(truth, 7.375, 5.125, camera);
  const auto points = cast_scan(truth, origin, 0.0, camera, 1);
  plain.integrate_scan(points, origin);
  map.integrate_scan(points, origin);
  EXPECT_EQ(plain.overflight().rows(), 0);
  EXPECT_FALSE(plain.overflown({19, 32}));
  int overflown = 0;
  for (int r = 0; r < truth.rows(); ++r)
    for (int c = 0; c < truth.cols(); ++c) {
      if (!map.overflown({r, c})) continue;
      ++overflown;
      EXPECT_GE(map.overflight()(r, c), truth(r, c)) << r << ", " << c;
      const Position at = truth.cell_center({r, c});
      EXPECT_LE(std::abs(at.x - origin.x), 3.25 + 0.25) << r << ", " << c;  // within the range (and a cell)
    }
  EXPECT_GT(overflown, 50);
  // Below the edge, on the camera's row: unknown, under rays that pass well below the top.
  for (int c = 32; c <= 36; ++c) {
    EXPECT_FALSE(map.is_known({19, c})) << c;
    ASSERT_TRUE(map.overflown({19, c})) << c;
  }
  EXPECT_NEAR(map.overflight()(19, 32), 3.0 - 0.18, 0.02);
  EXPECT_NEAR(map.overflight()(19, 33), 3.0 - 0.37, 0.03);
  EXPECT_LT(map.overflight()(19, 36), map.overflight()(19, 33));
  // The robot's own deposit there raises it by the rise: the cell stood below the ray, it stands below that plus it.
  const double before = map.overflight()(19, 33);
  map.record_built({19, 33}, 0.5);
  EXPECT_DOUBLE_EQ(map.overflight()(19, 33), before + 0.5);
  EXPECT_FALSE(map.is_known({19, 33}));  // no surface read: no floor either
  // A later scan from farther back sees nothing over those cells (its rays clearing the edge end beyond 6 m): only
  // the latest scan counts.
  const Point3 back = sensor_origin(truth, 6.375, 5.125, camera);
  map.integrate_scan(cast_scan(truth, back, 0.0, camera, 2), back);
  EXPECT_FALSE(map.overflown({19, 33}));
}

}  // namespace marsala::agent::executive
