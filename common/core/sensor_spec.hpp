#pragma once
// What a robot senses the terrain with (paper §IV: sensing modules chosen per robot), as a plain value: the sensor's
// name and, for the ray-casting sensors, their geometry, range and noise. The scenario chooses it per robot type; the
// world casts the rays (common/core/ray_caster.hpp) and the agent maps the points (agent/executive/mapping_system).
// Rules: docs/runtime.md#sensing.

#include <string>
#include <vector>

namespace marsala {

/// One measured surface point of a scan, as an offset from the sensor's origin in world-aligned axes (x east,
/// y north, z up) [m]. Floats: a centimetre-noise sensor needs no more on the wire.
struct ScanPoint {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float z_m = 0.0F;
  friend bool operator==(const ScanPoint& a, const ScanPoint& b) {
    return a.x_m == b.x_m && a.y_m == b.y_m && a.z_m == b.z_m;
  }
};

/// The terrain sensor kinds, named in scenarios "ground_truth", "laser", "rgbd".
enum class SensorKind { kGroundTruth, kLaser, kRgbd };
/// "ground_truth", "laser", "rgbd".
std::string to_string(SensorKind kind);
/// The kind named `name`; throws InvalidArgument "unknown sensor 'x'; valid: ground_truth, laser, rgbd".
SensorKind sensor_kind(const std::string& name);

/// A terrain sensor. "ground_truth": exact heights in tiles of the square window (no ray casting; the other fields
/// are unused). "laser": a 3D laser scanner, world-aligned (azimuth 0 = east, counter-clockwise). "rgbd": a depth
/// camera looking along the robot's heading. Angles [deg]: azimuth in the horizontal plane, elevation above it.
struct SensorSpec {
  SensorKind kind = SensorKind::kGroundTruth;
  double mount_height_m = 0.5;             ///< sensor origin above the terrain under the robot's centre [m]
  double horizontal_fov_deg = 360.0;       ///< azimuth span, centred on the heading (rgbd) or starting east (laser)
  double horizontal_resolution_deg = 2.0;  ///< azimuth between neighbouring rays [deg]
  double vertical_min_deg = -60.0;         ///< lowest elevation [deg] (negative: below the horizontal)
  double vertical_max_deg = 10.0;          ///< highest elevation [deg]
  double vertical_resolution_deg = 1.0;    ///< elevation between neighbouring rays [deg]
  double min_range_m = 0.1;                ///< hits nearer than this are dropped [m]
  double max_range_m = 8.0;                ///< hits farther than this are dropped [m]
  double noise_sd_m = 0.01;                ///< range noise standard deviation at range 0 [m]
  double noise_sd_per_m2 = 0.0;            ///< plus this times range^2 [1/m] (depth cameras: grows with range)
  int scan_every_steps = 1;                ///< a scan every this many steps (steps divisible by it) [steps]

  /// True for the sensors whose frames carry points instead of tiles.
  bool casts_rays() const { return kind != SensorKind::kGroundTruth; }
  /// Range noise standard deviation at range r [m].
  double noise_sd_at(double range_m) const { return noise_sd_m + noise_sd_per_m2 * range_m * range_m; }
  /// Number of rays per scan (azimuths x elevations).
  long long ray_count() const;
};

/// The defaults of a sensor kind: ground truth, laser (360 deg, -60..+10 deg at 2 x 1 deg, 0.1-8 m, sd 1 cm),
/// rgbd (87 x 58 deg tilted 15 deg down, 64 x 48 rays, 0.3-6 m, sd 2 mm + 2 mm/m^2 r^2).
SensorSpec sensor_defaults(SensorKind kind);
/// Empty when `s` is usable; otherwise the first problem, naming the field (e.g. "max_range_m: nan must be ...").
std::string sensor_problem(const SensorSpec& s);

}  // namespace marsala
