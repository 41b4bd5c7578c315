#include "marsala/core/ray_caster.hpp"

#include <cmath>
#include <limits>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/random.hpp"

namespace marsala {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A standard normal deviate (Box-Muller on the portable generator; libm's log, sqrt and cos): its two uniforms are
/// drawn for every ray, its value is worked out only for a ray that hit (the same value, without a log and a cosine
/// for each miss).
struct NormalDeviate {
  double u1, u2;
  explicit NormalDeviate(random::Rng& rng) : u1(1.0 - rng.uniform()), u2(rng.uniform()) {}  // u1 in (0, 1]
  double value() const { return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2); }
};

/// first_hit(), knowing that no cell the ray can reach stands above ceiling_m [m]: a ray that does not descend and
/// is above it can hit nothing more (a laser's upward rays end there instead of walking to their full range).
std::optional<double> first_hit_below(const Heightmap& terrain, Point3 origin, Point3 d, double max_range_m,
                                      double ceiling_m) {
  const GridGeometry& g = terrain.geometry();
  const double cs = g.cell_size_m;
  // Grid coordinates: u east from the west edge, v north from the south edge [cells].
  const double u0 = (origin.x - g.xll_m) / cs, v0 = (origin.y - g.yll_m) / cs;
  long long iu = static_cast<long long>(std::floor(u0)), iv = static_cast<long long>(std::floor(v0));
  const auto on_grid = [&](long long u, long long v) { return u >= 0 && u < g.cols && v >= 0 && v < g.rows; };
  if (!on_grid(iu, iv)) return std::nullopt;
  const int step_u = d.x > 0.0 ? 1 : -1, step_v = d.y > 0.0 ? 1 : -1;
  // Distance along the ray [m] to the next vertical grid line in u and in v, and between two of them.
  const double du = d.x / cs, dv = d.y / cs;  // cells per metre along the ray
  double next_u = du != 0.0 ? ((step_u > 0 ? std::floor(u0) + 1.0 : std::floor(u0)) - u0) / du : kInf;
  double next_v = dv != 0.0 ? ((step_v > 0 ? std::floor(v0) + 1.0 : std::floor(v0)) - v0) / dv : kInf;
  const double delta_u = du != 0.0 ? std::abs(1.0 / du) : kInf;
  const double delta_v = dv != 0.0 ? std::abs(1.0 / dv) : kInf;

  double t_enter = 0.0;
  for (;;) {
    if (d.z >= 0.0 && origin.z + d.z * t_enter > ceiling_m) return std::nullopt;  // rising above every top
    const double h = terrain(static_cast<int>(g.rows - 1 - iv), static_cast<int>(iu));
    // Entering below this cell's top: the side face it came through (the start cell: the origin is inside it).
    if (origin.z + d.z * t_enter <= h) return t_enter <= max_range_m ? std::optional<double>(t_enter) : std::nullopt;
    const double t_exit = std::min(next_u, next_v);
    // Coming down through the top face inside this cell.
    if (d.z < 0.0) {
      const double t_top = (h - origin.z) / d.z;
      if (t_top <= t_exit) return t_top <= max_range_m ? std::optional<double>(t_top) : std::nullopt;
    }
    if (t_exit > max_range_m) return std::nullopt;  // also a vertical ray that rises: t_exit is infinite
    if (next_u < next_v) {
      iu += step_u;
      next_u += delta_u;
    } else {
      iv += step_v;
      next_v += delta_v;
    }
    t_enter = t_exit;
    if (!on_grid(iu, iv)) return std::nullopt;
  }
}

/// The highest cell [m] within the square of half-side reach_m [m] around (x, y) (the cells a ray of that range can
/// cross), -infinity when none is on the grid.
double highest_within(const Heightmap& terrain, double x, double y, double reach_m) {
  const GridGeometry& g = terrain.geometry();
  const double cs = g.cell_size_m;
  const auto col = [&](double at) { return static_cast<long long>(std::floor((at - g.xll_m) / cs)); };
  const auto row = [&](double at) { return g.rows - 1 - static_cast<long long>(std::floor((at - g.yll_m) / cs)); };
  const long long c0 = std::max(0LL, col(x - reach_m) - 1), c1 = std::min<long long>(g.cols - 1, col(x + reach_m) + 1);
  const long long r0 = std::max(0LL, row(y + reach_m) - 1), r1 = std::min<long long>(g.rows - 1, row(y - reach_m) + 1);
  double top = -kInf;
  for (long long r = r0; r <= r1; ++r)
    for (long long c = c0; c <= c1; ++c) top = std::max(top, terrain(static_cast<int>(r), static_cast<int>(c)));
  return top;
}

}  // namespace

std::optional<double> first_hit(const Heightmap& terrain, Point3 origin, Point3 d, double max_range_m) {
  return first_hit_below(terrain, origin, d, max_range_m, kInf);
}

Point3 sensor_origin(const Heightmap& terrain, double x_m, double y_m, const SensorSpec& sensor) {
  const std::optional<CellIndex> cell = terrain.cell_at({x_m, y_m});
  if (!cell) throw InvalidArgument(fmt::format("ray caster: sensor position {} is off the grid", Position{x_m, y_m}));
  return {x_m, y_m, terrain(*cell) + sensor.mount_height_m};
}

std::uint64_t scan_seed(std::uint64_t run_seed, std::uint32_t agent_id, std::uint64_t step) {
  return random::derive_seed(random::derive_seed(run_seed, 0x5ca11e55ULL + agent_id), step);
}

std::vector<ScanPoint> cast_scan(const Heightmap& terrain, Point3 origin, double heading_rad, const SensorSpec& sensor,
                                 std::uint64_t seed) {
  const std::string problem = sensor_problem(sensor);
  if (!problem.empty()) throw InvalidArgument(fmt::format("ray caster: sensor {}", problem));
  if (!sensor.casts_rays()) return {};
  const double deg = kPi / 180.0;
  const bool wraps = sensor.horizontal_fov_deg >= 360.0;
  const long long azimuths =
      static_cast<long long>(std::floor(sensor.horizontal_fov_deg / sensor.horizontal_resolution_deg + 1e-9)) +
      (wraps ? 0 : 1);
  const long long elevations = static_cast<long long>(std::floor(
                                   (sensor.vertical_max_deg - sensor.vertical_min_deg) / sensor.vertical_resolution_deg +
                                   1e-9)) +
                               1;
  // The laser's azimuths start east; the camera's are centred on its heading.
  const double azimuth0 = sensor.kind == SensorKind::kRgbd ? heading_rad - 0.5 * sensor.horizontal_fov_deg * deg : 0.0;
  random::Rng rng(seed);
  const double ceiling = highest_within(terrain, origin.x, origin.y, sensor.max_range_m);
  std::vector<ScanPoint> points;
  points.reserve(static_cast<std::size_t>(azimuths * elevations / 2));
  // The elevations' cosines and sines, once per scan rather than once per ray (the same values).
  std::vector<double> cos_e(static_cast<std::size_t>(elevations)), sin_e(static_cast<std::size_t>(elevations));
  for (long long j = 0; j < elevations; ++j) {
    const double e = (sensor.vertical_min_deg + static_cast<double>(j) * sensor.vertical_resolution_deg) * deg;
    cos_e[static_cast<std::size_t>(j)] = std::cos(e);
    sin_e[static_cast<std::size_t>(j)] = std::sin(e);
  }
  for (long long i = 0; i < azimuths; ++i) {
    const double a = azimuth0 + static_cast<double>(i) * sensor.horizontal_resolution_deg * deg;
    const double ca = std::cos(a), sa = std::sin(a);
    for (long long j = 0; j < elevations; ++j) {
      const std::size_t at = static_cast<std::size_t>(j);
      const Point3 dir{cos_e[at] * ca, cos_e[at] * sa, sin_e[at]};
      // One deviate per ray, hit or not, so a change of the terrain far away leaves the noise of other rays alone.
      const NormalDeviate deviate(rng);
      const std::optional<double> hit = first_hit_below(terrain, origin, dir, sensor.max_range_m, ceiling);
      if (!hit || *hit < sensor.min_range_m) continue;
      const double range = *hit + deviate.value() * sensor.noise_sd_at(*hit);
      if (!(range > 0.0)) continue;
      points.push_back({static_cast<float>(dir.x * range), static_cast<float>(dir.y * range),
                        static_cast<float>(dir.z * range)});
    }
  }
  return points;
}

}  // namespace marsala
