#include "marsala/core/sensor_spec.hpp"

#include <cmath>

#include "marsala/core/format.hpp"
#include "marsala/core/enum_names.hpp"

namespace marsala {
namespace {

SensorSpec laser() {
  SensorSpec s;
  s.kind = SensorKind::kLaser;
  return s;  // the struct's defaults are the laser's
}

SensorSpec rgbd() {
  SensorSpec s;
  s.kind = SensorKind::kRgbd;
  s.horizontal_fov_deg = 87.0;
  s.horizontal_resolution_deg = 87.0 / 63.0;  // 64 columns, edges included
  s.vertical_min_deg = -44.0;                 // 58 deg, tilted 15 deg down to see the ground before the robot
  s.vertical_max_deg = 14.0;
  s.vertical_resolution_deg = 58.0 / 47.0;  // 48 rows
  s.min_range_m = 0.3;
  s.max_range_m = 6.0;
  s.noise_sd_m = 0.002;
  s.noise_sd_per_m2 = 0.002;
  return s;
}

constexpr EnumName<SensorKind> kSensorNames[] = {
    {SensorKind::kGroundTruth, "ground_truth"}, {SensorKind::kLaser, "laser"}, {SensorKind::kRgbd, "rgbd"}};

/// Rays along one axis: span / resolution + 1, the span's both ends included (a 360 deg span holds 0 deg once).
long long rays_along(double span_deg, double resolution_deg, bool wraps) {
  const long long n = static_cast<long long>(std::floor(span_deg / resolution_deg + 1e-9));
  return wraps ? n : n + 1;
}

}  // namespace

long long SensorSpec::ray_count() const {
  if (!casts_rays()) return 0;
  return rays_along(horizontal_fov_deg, horizontal_resolution_deg, horizontal_fov_deg >= 360.0) *
         rays_along(vertical_max_deg - vertical_min_deg, vertical_resolution_deg, false);
}

std::string to_string(SensorKind kind) { return enum_to_string(kSensorNames, kind); }

SensorKind sensor_kind(const std::string& name) { return enum_from_string(kSensorNames, name, "sensor"); }

SensorSpec sensor_defaults(SensorKind kind) {
  switch (kind) {
    case SensorKind::kLaser: return laser();
    case SensorKind::kRgbd: return rgbd();
    case SensorKind::kGroundTruth: break;
  }
  return SensorSpec{};
}

std::string sensor_problem(const SensorSpec& s) {
  if (to_string(s.kind) == "unknown") return fmt::format("name: unknown sensor kind {}", static_cast<int>(s.kind));
  const auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  const auto bad = [](const char* field, double v, const char* range) {
    return fmt::format("{}: {} must be {}", field, v, range);
  };
  if (!in(s.mount_height_m, 0.0, 100.0)) return bad("mount_height_m", s.mount_height_m, "in [0, 100] m");
  if (!in(s.horizontal_fov_deg, 0.0, 360.0) || s.horizontal_fov_deg == 0.0)
    return bad("horizontal_fov_deg", s.horizontal_fov_deg, "in (0, 360] deg");
  if (!in(s.horizontal_resolution_deg, 0.01, 360.0))
    return bad("horizontal_resolution_deg", s.horizontal_resolution_deg, "in [0.01, 360] deg");
  if (!in(s.vertical_min_deg, -90.0, 90.0)) return bad("vertical_min_deg", s.vertical_min_deg, "in [-90, 90] deg");
  if (!in(s.vertical_max_deg, s.vertical_min_deg, 90.0))
    return bad("vertical_max_deg", s.vertical_max_deg, "in [vertical_min_deg, 90] deg");
  if (!in(s.vertical_resolution_deg, 0.01, 180.0))
    return bad("vertical_resolution_deg", s.vertical_resolution_deg, "in [0.01, 180] deg");
  if (!in(s.min_range_m, 0.0, 1e4)) return bad("min_range_m", s.min_range_m, "in [0, 10000] m");
  if (!in(s.max_range_m, 0.0, 1e4) || s.max_range_m <= s.min_range_m)
    return bad("max_range_m", s.max_range_m, "in (min_range_m, 10000] m");
  if (!in(s.noise_sd_m, 0.0, 10.0)) return bad("noise_sd_m", s.noise_sd_m, "in [0, 10] m");
  if (!in(s.noise_sd_per_m2, 0.0, 10.0)) return bad("noise_sd_per_m2", s.noise_sd_per_m2, "in [0, 10] 1/m");
  if (s.scan_every_steps < 1 || s.scan_every_steps > 1000000)
    return fmt::format("scan_every_steps: {} must be in [1, 1000000]", s.scan_every_steps);
  // A scan is one frame: keep it within what a frame can reasonably carry.
  if (s.casts_rays() && s.ray_count() > 1000000)
    return fmt::format("resolution: {} rays per scan, at most 1000000", s.ray_count());
  return {};
}

}  // namespace marsala
