#include "marsala/core/ray_caster.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/random.hpp"

namespace marsala {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

Point3 direction(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

double norm(const ScanPoint& p) {
  return std::sqrt(double{p.x_m} * p.x_m + double{p.y_m} * p.y_m + double{p.z_m} * p.z_m);
}

SensorSpec noiseless(SensorKind kind) {
  SensorSpec s = sensor_defaults(kind);
  s.noise_sd_m = 0.0;
  s.noise_sd_per_m2 = 0.0;
  return s;
}

/// An independent reference: walk the ray in tiny steps and stop at the first sample inside a cell's prism. Slow, and
/// only as exact as its step, which is why the ray caster does not work this way.
std::optional<double> sampled_hit(const Heightmap& terrain, Point3 o, Point3 d, double max_range_m, double step_m) {
  for (double t = 0.0; t <= max_range_m; t += step_m) {
    const auto cell = terrain.cell_at({o.x + d.x * t, o.y + d.y * t});
    if (!cell) return std::nullopt;
    if (o.z + d.z * t <= terrain(*cell)) return t;
  }
  return std::nullopt;
}

// A flat plane h0 under a sensor H above it: a ray at elevation -e meets it at H / sin(e).
TEST(RayCaster, FlatPlaneHitsAtHeightOverSineOfTheAngle) {
  const double h0 = 1.25, H = 0.7;
  const Heightmap flat(GridGeometry{400, 400, -20.0, -20.0, 0.1}, h0);
  const Point3 origin{0.03, -0.07, h0 + H};
  for (double e = -89.0; e < -3.0; e += 3.7)  // hits within 14 m, on the grid
    for (double a = 0.0; a < 360.0; a += 17.3) {
      const auto t = first_hit(flat, origin, direction(a, e), 100.0);
      ASSERT_TRUE(t.has_value()) << a << " " << e;
      EXPECT_NEAR(*t, H / std::sin(-e * kDeg), 1e-9) << "azimuth " << a << " elevation " << e;
    }
  // Level and rising rays never meet a plane below them.
  EXPECT_FALSE(first_hit(flat, origin, direction(30.0, 0.0), 100.0).has_value());
  EXPECT_FALSE(first_hit(flat, origin, direction(30.0, 5.0), 100.0).has_value());
  EXPECT_NEAR(first_hit(flat, origin, {0.0, 0.0, -1.0}, 100.0).value(), H, 1e-12);  // straight down

  // The scan: every point on the plane, at the analytic range, no point beyond max range or before min range; a
  // ray is missing exactly when its analytic range lies outside [min, max].
  const SensorSpec laser = noiseless(SensorKind::kLaser);
  const std::vector<ScanPoint> points = cast_scan(flat, origin, 0.0, laser, 1);
  long long expected = 0;
  const long long azimuths = static_cast<long long>(360.0 / laser.horizontal_resolution_deg + 1e-9);
  for (double e = laser.vertical_min_deg; e <= laser.vertical_max_deg + 1e-9; e += laser.vertical_resolution_deg) {
    const double range = e < 0.0 ? H / std::sin(-e * kDeg) : 1e9;
    if (range >= laser.min_range_m && range <= laser.max_range_m) expected += azimuths;
  }
  EXPECT_EQ(static_cast<long long>(points.size()), expected);
  for (const ScanPoint& p : points) {
    EXPECT_NEAR(p.z_m, -H, 1e-5);
    EXPECT_LE(norm(p), laser.max_range_m + 1e-5);
    EXPECT_GE(norm(p), laser.min_range_m - 1e-5);
  }
}

// A 2 m wall one cell thick at x in [5, 5.1): it shadows the ground behind it, and level rays end on its face.
TEST(RayCaster, AWallOccludesWhatLiesBehindIt) {
  Heightmap terrain(GridGeometry{100, 150, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 100; ++r) terrain(r, 50) = 2.0;
  const Point3 origin{2.0, 5.0, 0.5};
  EXPECT_NEAR(first_hit(terrain, origin, direction(0.0, 0.0), 20.0).value(), 3.0, 1e-12);       // the face at x = 5
  EXPECT_NEAR(first_hit(terrain, origin, direction(0.0, 20.0), 20.0).value(), 3.0 / std::cos(20 * kDeg), 1e-9);
  // Over the top: a ray that clears the wall's top lands behind it, at the analytic place.
  const Point3 high{2.0, 5.0, 4.0};
  const double e = -std::atan2(4.0, 8.0) / kDeg;  // aimed at the ground at x = 10: 2.45 m up at x = 5.1
  EXPECT_NEAR(first_hit(terrain, high, direction(0.0, e), 20.0).value(), std::hypot(8.0, 4.0), 1e-9);
  // Aimed at the ground at x = 6 from 0.5 m up: the wall is in the way.
  const double low = -std::atan2(0.5, 4.0) / kDeg;
  const double t = first_hit(terrain, origin, direction(0.0, low), 20.0).value();
  EXPECT_NEAR(t * std::cos(low * kDeg), 3.0, 1e-9);

  SensorSpec laser = noiseless(SensorKind::kLaser);
  laser.max_range_m = 20.0;
  for (const ScanPoint& p : cast_scan(terrain, origin, 0.0, laser, 7))
    EXPECT_LE(origin.x + p.x_m, 5.1 + 1e-4) << "a point behind the wall: " << p.x_m << " " << p.y_m << " " << p.z_m;
}

// The grid walk against a fine-stepping reference on rough random terrain, rays in every direction.
TEST(RayCaster, FirstHitsAgreeWithAFineSteppingReference) {
  random::Rng rng(42);
  Heightmap terrain(GridGeometry{40, 50, 3.0, -2.0, 0.2}, 0.0);
  for (int r = 0; r < terrain.rows(); ++r)
    for (int c = 0; c < terrain.cols(); ++c) terrain(r, c) = rng.uniform(0.0, 1.5);
  const double step = 2e-4;
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const Point3 o{rng.uniform(3.5, 12.5), rng.uniform(-1.5, 5.5), 0.0};
    const Point3 origin{o.x, o.y, terrain(*terrain.cell_at({o.x, o.y})) + rng.uniform(0.05, 1.0)};
    const Point3 d = direction(rng.uniform(0.0, 360.0), rng.uniform(-80.0, 10.0));
    const auto fast = first_hit(terrain, origin, d, 6.0);
    const auto slow = sampled_hit(terrain, origin, d, 6.0, step);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << "ray " << i;
    if (!fast) continue;
    ++hits;
    EXPECT_LE(*fast, *slow + 1e-12) << "ray " << i;  // never later than the first inside sample
    EXPECT_GT(*fast, *slow - step - 1e-12) << "ray " << i;
  }
  EXPECT_GT(hits, 200);
}

TEST(RayCaster, NoiseIsSeededAndHasTheConfiguredSpread) {
  const double H = 1.0;
  const Heightmap flat(GridGeometry{300, 300, -15.0, -15.0, 0.1}, 0.0);
  const Point3 origin{0.0, 0.0, H};
  SensorSpec laser = sensor_defaults(SensorKind::kLaser);
  laser.horizontal_resolution_deg = 0.5;
  laser.vertical_min_deg = -80.0;
  laser.vertical_max_deg = -10.0;
  laser.noise_sd_m = 0.05;
  const std::vector<ScanPoint> a = cast_scan(flat, origin, 0.0, laser, 123);
  const std::vector<ScanPoint> b = cast_scan(flat, origin, 0.0, laser, 123);
  const std::vector<ScanPoint> c = cast_scan(flat, origin, 0.0, laser, 124);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_NE(scan_seed(1, 2, 3), scan_seed(1, 2, 4));
  EXPECT_NE(scan_seed(1, 2, 3), scan_seed(1, 3, 3));
  EXPECT_NE(scan_seed(1, 2, 3), scan_seed(2, 2, 3));

  // Each point lies on its ray: its range error is (measured range) - H / sin(elevation).
  double sum = 0.0, sum2 = 0.0;
  for (const ScanPoint& p : a) {
    const double range = norm(p);
    const double sin_e = -p.z_m / range;
    const double error = range - H / sin_e;
    sum += error;
    sum2 += error * error;
  }
  const double n = static_cast<double>(a.size());
  ASSERT_GT(n, 40000);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.002);
  EXPECT_NEAR(sd, 0.05, 0.05 * 0.03);
}

// The camera looks along the heading, over its horizontal field of view only.
TEST(RayCaster, TheCameraFollowsTheHeading) {
  const Heightmap flat(GridGeometry{200, 200, -10.0, -10.0, 0.1}, 0.0);
  const SensorSpec rgbd = noiseless(SensorKind::kRgbd);
  for (double heading_deg : {0.0, 90.0, 200.0, -45.0}) {
    const std::vector<ScanPoint> points = cast_scan(flat, {0.0, 0.0, 0.5}, heading_deg * kDeg, rgbd, 3);
    ASSERT_FALSE(points.empty());
    for (const ScanPoint& p : points) {
      double off = std::atan2(p.y_m, p.x_m) / kDeg - heading_deg;
      off = std::remainder(off, 360.0);
      EXPECT_LE(std::abs(off), 0.5 * rgbd.horizontal_fov_deg + 1e-3);
    }
  }
}

TEST(RayCaster, RefusesABadSensorAndAPositionOffTheGrid) {
  const Heightmap flat(GridGeometry{10, 10, 0.0, 0.0, 0.1}, 0.0);
  SensorSpec bad = sensor_defaults(SensorKind::kLaser);
  bad.max_range_m = std::nan("");
  EXPECT_THROW(cast_scan(flat, {0.5, 0.5, 1.0}, 0.0, bad, 1), InvalidArgument);
  EXPECT_THROW(sensor_origin(flat, 5.0, 0.5, sensor_defaults(SensorKind::kLaser)), InvalidArgument);
  EXPECT_TRUE(cast_scan(flat, {0.5, 0.5, 1.0}, 0.0, SensorSpec{}, 1).empty());  // ground truth casts nothing
  EXPECT_THROW(sensor_kind("sonar"), InvalidArgument);
  EXPECT_EQ(sensor_kind("rgbd"), SensorKind::kRgbd);
  EXPECT_EQ(to_string(SensorKind::kGroundTruth), "ground_truth");
}

}  // namespace
}  // namespace marsala
