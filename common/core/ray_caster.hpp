#pragma once
// Ray casting of a heightmap (the laser and rgbd sensors, docs/runtime.md#sensing): rays from a sensor origin, the
// exact first hit of the terrain surface, range noise from a seed. Pure: no IO, no threads.
//
// The surface: every cell is a vertical prism with a flat top at its height (the same blocks the world validates
// and deposits on). A ray hits a cell's top face where it comes down through it, or the side face it enters through
// when it arrives below the cell's top (a wall between two cells of different heights). Cells off the grid hold no
// surface: a ray that leaves the grid misses.

#include <cstdint>
#include <optional>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/sensor_spec.hpp"

namespace marsala {

/// A point in the world frame [m].
struct Point3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

/// Distance along the unit direction (dx, dy, dz) from `origin` to the first hit of the surface of `terrain` [m], or
/// nullopt when the ray leaves the grid or passes max_range_m first. Walks the cells the ray's horizontal projection
/// crosses in order (a grid DDA), so no cell and no face is skipped.
std::optional<double> first_hit(const Heightmap& terrain, Point3 origin, Point3 direction, double max_range_m);

/// The sensor origin of a robot standing at (x, y) [m]: terrain height of the cell under it plus the mount height.
/// Throws InvalidArgument when (x, y) is off the grid.
Point3 sensor_origin(const Heightmap& terrain, double x_m, double y_m, const SensorSpec& sensor);

/// The seed of one scan: from the run's seed, the agent id and the step, so a run scans the same points every time.
std::uint64_t scan_seed(std::uint64_t run_seed, std::uint32_t agent_id, std::uint64_t step);

/// One scan of `sensor` from `origin` [m], the robot facing `heading_rad` (from east, counter-clockwise; used by
/// "rgbd", the "laser" is world-aligned): for each ray (azimuth-major, then elevation, both ascending), the first hit
/// within [min_range_m, max_range_m], its range perturbed by Gaussian noise of sd noise_sd_at(range) drawn from
/// `seed`, as an offset from `origin`. Rays that miss or hit out of range give no point. Requires
/// sensor_problem(sensor) to be empty (throws InvalidArgument otherwise).
std::vector<ScanPoint> cast_scan(const Heightmap& terrain, Point3 origin, double heading_rad, const SensorSpec& sensor,
                                 std::uint64_t seed);

}  // namespace marsala
