#include "marsala/terrain/generators.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>

#include <fmt/ranges.h>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/random.hpp"
#include "marsala/core/registry.hpp"
#include "marsala/terrain/detail/det_math.hpp"
#include "marsala/terrain/detail/noise.hpp"

namespace marsala::terrain {
namespace {

using ParamValues = std::map<std::string, double>;

constexpr long long kMaxGeneratedCells = 1LL << 28;
constexpr double kMaxLength = 1e7;  // [m]
constexpr double kMaxHeight = 1e4;  // [m]
constexpr double kEdgeTol = 1e-9;   // [m], platform edges: west/south inclusive, east/north exclusive

/// The grid a generator fills, with its physical size [m].
struct Frame {
  int rows;
  int cols;
  double cs;
  std::uint64_t seed;
  double width_m;   // west-east size
  double depth_m;   // south-north size
  double extent_m;  // longer side
};

Frame make_frame(const GeneratorSpec& spec) {
  const double w = spec.cols * spec.cell_size_m;
  const double d = spec.rows * spec.cell_size_m;
  return {spec.rows, spec.cols, spec.cell_size_m, spec.seed, w, d, std::max(w, d)};
}

/// One parameter of a method: key, default (text for help, value from the frame), valid range, meaning.
struct ParamDef {
  std::string key;
  std::string default_text;
  std::function<double(const Frame&)> default_value;
  double min;
  double max;
  bool integer;
  std::string meaning;
  std::string unit;
};

/// Resolved parameter values of one call (defaults filled in).
class Params {
 public:
  explicit Params(ParamValues values) : values_(std::move(values)) {}
  double get(const std::string& key) const { return values_.at(key); }
  int count(const std::string& key) const { return static_cast<int>(values_.at(key)); }

 private:
  ParamValues values_;
};

using GenerateFn = std::function<HeightMatrix(const Frame&, const Params&)>;

/// A registered method: its generating function and its parameter table.
struct GeneratorEntry {
  GenerateFn generate;
  std::vector<ParamDef> params;
};

using GeneratorRegistry = NamedRegistry<GeneratorEntry>;

// Default helpers: a fixed value, or a fraction of the map extent / width / depth.
ParamDef param(std::string key, double fixed_default, double min, double max, bool integer, std::string meaning,
               std::string unit) {
  return {std::move(key),
          fmt::to_string(fixed_default),
          [fixed_default](const Frame&) { return fixed_default; },
          min,
          max,
          integer,
          std::move(meaning),
          std::move(unit)};
}

ParamDef scaled_param(std::string key, double fraction, double min, double max, std::string meaning) {
  // The default's text is a description, not a value to read back: "3%", not the product's "3.0000000000000004%".
  return {std::move(key),
          fmt::format("{:g}% of the map extent", 100.0 * fraction),
          [fraction](const Frame& f) { return fraction * f.extent_m; },
          min,
          max,
          false,
          std::move(meaning),
          "m"};
}

ParamValues resolve(const std::string& method, const GeneratorEntry& entry, const Frame& frame,
                    const ParamValues& given) {
  for (const auto& [key, value] : given) {
    const bool known =
        std::any_of(entry.params.begin(), entry.params.end(), [&k = key](const ParamDef& d) { return d.key == k; });
    if (!known) {
      std::vector<std::string> keys;
      for (const auto& d : entry.params) keys.push_back(d.key);
      throw InvalidArgument(
          keys.empty()
              ? fmt::format("terrain generator '{}': unknown parameter '{}'; valid parameters: (none)", method, key)
              : fmt::format("terrain generator '{}': unknown parameter '{}'; valid parameters: {}", method, key,
                            fmt::join(keys, ", ")));
    }
  }
  ParamValues out;
  for (const auto& d : entry.params) {
    const auto it = given.find(d.key);
    if (it == given.end()) {
      out[d.key] = d.default_value(frame);
      continue;
    }
    const double v = it->second;
    if (!(v >= d.min && v <= d.max))
      throw InvalidArgument(fmt::format("terrain generator '{}': parameter '{}' = {} is out of range [{}, {}]", method,
                                        d.key, v, d.min, d.max));
    if (d.integer && v != std::floor(v))
      throw InvalidArgument(
          fmt::format("terrain generator '{}': parameter '{}' = {} must be a whole number in [{}, {}]", method, d.key,
                      v, d.min, d.max));
    out[d.key] = v;
  }
  return out;
}

void check_spec(const std::string& method, const GeneratorSpec& spec) {
  if (spec.rows <= 0 || spec.cols <= 0)
    throw InvalidArgument(
        fmt::format("terrain generator '{}': grid size must be positive, got {} x {}", method, spec.rows, spec.cols));
  if (static_cast<long long>(spec.rows) * spec.cols > kMaxGeneratedCells)
    throw InvalidArgument(fmt::format("terrain generator '{}': grid of {} x {} cells exceeds the limit of {} cells",
                                      method, spec.rows, spec.cols, kMaxGeneratedCells));
  if (!(spec.cell_size_m > 0.0 && spec.cell_size_m <= kMaxLength))
    throw InvalidArgument(fmt::format("terrain generator '{}': cell size must be in (0, {}] m, got {}", method,
                                      kMaxLength, spec.cell_size_m));
}

// Cell-centre coordinates with the lower-left corner at (0, 0) [m].
double cell_x(const Frame& f, int col) { return (col + 0.5) * f.cs; }
double cell_y(const Frame& f, int row) { return (f.rows - row - 0.5) * f.cs; }

// Cells whose squares meet the world interval [a, b] along an axis of n cells, plus one cell of margin,
// clamped to [0, n - 1]; empty (first > second) when the interval misses the grid.
std::pair<int, int> index_range(double a_cells, double b_cells, int n) {
  const double lo = std::clamp(std::floor(a_cells) - 1.0, 0.0, static_cast<double>(n));
  const double hi = std::clamp(std::floor(b_cells) + 1.0, -1.0, static_cast<double>(n - 1));
  return {static_cast<int>(lo), static_cast<int>(hi)};
}
std::pair<int, int> col_range(const Frame& f, double x_low, double x_high) {
  return index_range(x_low / f.cs, x_high / f.cs, f.cols);
}
std::pair<int, int> row_range(const Frame& f, double y_low, double y_high) {
  // Row r spans y in [(rows - r - 1) cs, (rows - r) cs]: row index from the north is rows - 1 - y / cs.
  return index_range(f.rows - 1 - y_high / f.cs, f.rows - 1 - y_low / f.cs, f.rows);
}

// ---- methods ----

HeightMatrix flat(const Frame& f, const Params& p) { return HeightMatrix::Constant(f.rows, f.cols, p.get("height")); }

HeightMatrix platform(const Frame& f, const Params& p) {
  const double height = p.get("height");
  const double x0 = p.get("centre_x") - 0.5 * p.get("width");
  const double x1 = p.get("centre_x") + 0.5 * p.get("width");
  const double y0 = p.get("centre_y") - 0.5 * p.get("depth");
  const double y1 = p.get("centre_y") + 0.5 * p.get("depth");
  const auto inside = [](double v, double lo, double hi) { return v >= lo - kEdgeTol && v < hi - kEdgeTol; };
  HeightMatrix h = HeightMatrix::Zero(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r) {
    if (!inside(cell_y(f, r), y0, y1)) continue;
    for (int c = 0; c < f.cols; ++c)
      if (inside(cell_x(f, c), x0, x1)) h(r, c) = height;
  }
  return h;
}

HeightMatrix ramp(const Frame& f, const Params& p) {
  const double slope = p.get("slope");
  const double ux = detail::det_sin_deg(p.get("azimuth"));  // east component of the ascent direction
  const double uy = detail::det_cos_deg(p.get("azimuth"));  // north component
  // Offsets from the south-west cell centre as integer multiples of the cell size keep ramps along the axes
  // exact: along azimuth 90, h(r, c) = slope * (c * cs).
  const auto along = [&](int r, int c) { return (c * f.cs) * ux + ((f.rows - 1 - r) * f.cs) * uy; };
  const double lowest =
      std::min({along(f.rows - 1, 0), along(f.rows - 1, f.cols - 1), along(0, 0), along(0, f.cols - 1)});
  HeightMatrix h(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r)
    for (int c = 0; c < f.cols; ++c) h(r, c) = slope * (along(r, c) - lowest);
  return h;
}

HeightMatrix gaussian_hills(const Frame& f, const Params& p) {
  const int count = p.count("count");
  const double amplitude = p.get("amplitude");
  const double sigma = p.get("sigma");
  random::Rng rng(random::derive_seed(f.seed, 0x68696c6c));
  HeightMatrix h = HeightMatrix::Zero(f.rows, f.cols);
  std::vector<double> ex(f.cols), ey(f.rows);
  for (int k = 0; k < count; ++k) {
    const double cx = rng.uniform(0.0, f.width_m);
    const double cy = rng.uniform(0.0, f.depth_m);
    const double a = amplitude * (0.5 + 0.5 * rng.uniform());
    const double s = sigma * (0.6 + 0.8 * rng.uniform());
    // The Gaussian is separable: one exp per row and per column. Beyond 9 sigma it is below 3e-18 of the
    // peak, i.e. below the rounding of any nearby height, so it is cut there.
    const double reach = 9.0 * s;
    const auto [c0, c1] = col_range(f, cx - reach, cx + reach);
    const auto [r0, r1] = row_range(f, cy - reach, cy + reach);
    const double inv2s2 = 1.0 / (2.0 * s * s);
    for (int c = c0; c <= c1; ++c) {
      const double dx = cell_x(f, c) - cx;
      ex[c] = detail::det_exp(-dx * dx * inv2s2);
    }
    for (int r = r0; r <= r1; ++r) {
      const double dy = cell_y(f, r) - cy;
      ey[r] = a * detail::det_exp(-dy * dy * inv2s2);
    }
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) h(r, c) += ey[r] * ex[c];
  }
  return h;
}

HeightMatrix fractal(const Frame& f, const Params& p) {
  const double amplitude = p.get("amplitude");
  const double wavelength = p.get("wavelength");
  if (wavelength < f.cs)
    throw InvalidArgument(
        fmt::format("terrain generator 'fractal': wavelength {} m is shorter than one cell ({} m)", wavelength, f.cs));
  HeightMatrix h = detail::gradient_fbm(f.rows, f.cols, f.cs, random::derive_seed(f.seed, 0x6662), p.count("octaves"),
                                        p.get("persistence"), wavelength);
  const double lo = h.minCoeff();
  const double hi = h.maxCoeff();
  if (!(hi > lo)) return HeightMatrix::Zero(f.rows, f.cols);
  // Stretch to exactly [-amplitude, amplitude]: the relief is what the parameter promises, whatever the noise.
  const double scale = 2.0 * amplitude / (hi - lo);
  for (Eigen::Index i = 0; i < h.size(); ++i)
    h.data()[i] = std::clamp(-amplitude + (h.data()[i] - lo) * scale, -amplitude, amplitude);
  return h;
}

HeightMatrix craters(const Frame& f, const Params& p) {
  const int count = p.count("count");
  const double r_min = p.get("radius_min");
  const double r_max = p.get("radius_max");
  if (r_min > r_max)
    throw InvalidArgument(
        fmt::format("terrain generator 'craters': radius_min {} m exceeds radius_max {} m", r_min, r_max));
  const double depth = p.get("depth");
  const double rim_height = p.get("rim_height");
  random::Rng rng(random::derive_seed(f.seed, 0x63726174));
  HeightMatrix h = HeightMatrix::Zero(f.rows, f.cols);
  for (int k = 0; k < count; ++k) {
    const double cx = rng.uniform(0.0, f.width_m);
    const double cy = rng.uniform(0.0, f.depth_m);
    const double u = rng.uniform();
    const double radius = r_min + (r_max - r_min) * u * u;  // small craters are more common
    const double scale = radius / r_max;                    // depth and rim grow with the radius
    const double d = depth * scale;
    const double rim = rim_height * scale;
    const double reach = 2.0 * radius;
    const auto [c0, c1] = col_range(f, cx - reach, cx + reach);
    const auto [r0, r1] = row_range(f, cy - reach, cy + reach);
    for (int r = r0; r <= r1; ++r) {
      const double dy = cell_y(f, r) - cy;
      for (int c = c0; c <= c1; ++c) {
        const double dx = cell_x(f, c) - cx;
        const double q = std::sqrt(dx * dx + dy * dy) / radius;
        if (q < 1.0) {
          // Bowl: rounded floor, walls steepening up to a sharp rim crest at q = 1.
          h(r, c) += -d + (d + rim) * q * q * q;
        } else if (q < 2.0) {
          // Ejecta blanket: the rim falls off smoothly to nothing at two radii.
          const double t = 2.0 - q;
          h(r, c) += rim * t * t * t;
        }
      }
    }
  }
  return h;
}

HeightMatrix steps(const Frame& f, const Params& p) {
  const int count = p.count("count");
  const double step = p.get("step_height");
  const double jitter = p.get("jitter");
  const double waviness = p.get("waviness");
  const double ux = detail::det_sin_deg(p.get("azimuth"));
  const double uy = detail::det_cos_deg(p.get("azimuth"));
  const double half_span = 0.5 * (f.width_m * std::abs(ux) + f.depth_m * std::abs(uy));
  const double spacing = 2.0 * half_span / (count + 1);
  random::Rng rng(random::derive_seed(f.seed, 0x73746570));
  std::vector<double> base(count);
  std::vector<detail::ValueNoise1d> wave;
  for (int k = 0; k < count; ++k) {
    base[k] = -half_span + spacing * (k + 1) + jitter * spacing * (rng.uniform() - 0.5);
    wave.emplace_back(rng.next(), 0.25 * f.extent_m);
  }
  HeightMatrix h(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r) {
    const double y = cell_y(f, r) - 0.5 * f.depth_m;
    for (int c = 0; c < f.cols; ++c) {
      const double x = cell_x(f, c) - 0.5 * f.width_m;
      const double s = x * ux + y * uy;   // along the ascent
      const double t = -x * uy + y * ux;  // along the cliffs
      int above = 0;
      for (int k = 0; k < count; ++k) above += s >= base[k] + waviness * wave[k](t) ? 1 : 0;
      h(r, c) = step * above;
    }
  }
  return h;
}

const GeneratorRegistry& registry();

HeightMatrix run(const std::string& method, const Frame& f, const ParamValues& given) {
  const GeneratorEntry& entry = registry().find(method);
  return entry.generate(f, Params(resolve(method, entry, f, given)));
}

HeightMatrix mix(const Frame& f, const Params& p) {
  // Each component gets its own seed stream, so changing one count does not reshuffle the others.
  Frame sub = f;
  sub.seed = random::derive_seed(f.seed, 1);
  HeightMatrix h = run("fractal", sub, {{"amplitude", p.get("fractal_amplitude")}});
  sub.seed = random::derive_seed(f.seed, 2);
  h += run("gaussian_hills", sub, {{"count", p.get("hill_count")}, {"amplitude", p.get("hill_amplitude")}});
  sub.seed = random::derive_seed(f.seed, 3);
  h += run("craters", sub,
           {{"count", p.get("crater_count")},
            {"depth", p.get("crater_depth")},
            {"rim_height", p.get("crater_depth") / 3.0}});
  sub.seed = random::derive_seed(f.seed, 4);
  const double azimuth = std::floor(360.0 * random::Rng(random::derive_seed(f.seed, 5)).uniform());
  h += run("steps", sub, {{"count", p.get("step_count")}, {"step_height", p.get("step_height")}, {"azimuth", azimuth}});
  return h;
}

void register_builtins(GeneratorRegistry& reg) {
  const auto height = [](double dflt, const std::string& meaning) {
    return param("height", dflt, -kMaxHeight, kMaxHeight, false, meaning, "m");
  };
  reg.add("flat", {flat, {height(0.0, "height of every cell")}});

  reg.add("platform", {platform,
                       {height(1.5, "height of the box above the ground at 0 m"),
                        {"width", "30% of the map width", [](const Frame& f) { return 0.3 * f.width_m; }, 0.0,
                         kMaxLength, false, "west-east size of the box; cells whose centre lies in it are raised", "m"},
                        {"depth", "30% of the map depth", [](const Frame& f) { return 0.3 * f.depth_m; }, 0.0,
                         kMaxLength, false, "south-north size of the box", "m"},
                        {"centre_x", "map centre", [](const Frame& f) { return 0.5 * f.width_m; }, -kMaxLength,
                         kMaxLength, false, "x of the box centre, east of the lower-left corner", "m"},
                        {"centre_y", "map centre", [](const Frame& f) { return 0.5 * f.depth_m; }, -kMaxLength,
                         kMaxLength, false, "y of the box centre, north of the lower-left corner", "m"}}});

  reg.add("ramp", {ramp,
                   {param("slope", 0.2, 0.0, 100.0, false, "rise over run of the plane", "m/m"),
                    param("azimuth", 90.0, -360.0, 360.0, false,
                          "direction of ascent, clockwise from north (90 = rising to the east)", "deg")}});

  reg.add(
      "gaussian_hills",
      {gaussian_hills,
       {param("count", 12, 0, 10000, true, "number of hills", "count"),
        scaled_param("amplitude", 0.03, 0.0, kMaxHeight, "height of the tallest hills (each gets 50-100%)"),
        scaled_param("sigma", 0.06, 1e-6, kMaxLength, "typical standard deviation of a hill (each gets 60-140%)")}});

  reg.add("fractal",
          {fractal,
           {scaled_param("amplitude", 0.025, 0.0, kMaxHeight, "half the relief: heights span [-amplitude, amplitude]"),
            param("octaves", 6, 1, 16, true, "number of noise octaves (those finer than 2 cells are skipped)", "count"),
            param("persistence", 0.5, 0.0, 1.0, false, "weight ratio of each octave to the previous one", "ratio"),
            {"wavelength", "25% of the map extent, at least 2 cells",
             [](const Frame& f) { return std::max(0.25 * f.extent_m, 2.0 * f.cs); }, 1e-6, kMaxLength, false,
             "wavelength of the coarsest octave, at least one cell", "m"}}});

  reg.add("craters",
          {craters,
           {param("count", 8, 0, 10000, true, "number of craters", "count"),
            scaled_param("radius_min", 0.03, 1e-6, kMaxLength, "smallest rim radius"),
            scaled_param("radius_max", 0.12, 1e-6, kMaxLength, "largest rim radius"),
            scaled_param("depth", 0.03, 0.0, kMaxHeight,
                         "floor depth below the ground of the largest crater (smaller ones scale with the radius)"),
            scaled_param("rim_height", 0.01, 0.0, kMaxHeight,
                         "rim height above the ground of the largest crater (scales with the radius)")}});

  reg.add(
      "steps",
      {steps,
       {param("count", 3, 0, 1000, true, "number of cliffs across the map", "count"),
        scaled_param("step_height", 0.005, -kMaxHeight, kMaxHeight, "height of each cliff"),
        param("azimuth", 90.0, -360.0, 360.0, false,
              "direction of ascent, clockwise from north (90 = terraces rising to the east)", "deg"),
        param("jitter", 0.25, 0.0, 1.0, false, "random shift of each cliff as a fraction of their spacing", "fraction"),
        scaled_param("waviness", 0.02, 0.0, kMaxLength, "largest sideways excursion of a cliff line")}});

  reg.add("mix", {mix,
                  {scaled_param("fractal_amplitude", 0.015, 0.0, kMaxHeight, "half the relief of the fractal base"),
                   param("hill_count", 6, 0, 10000, true, "number of Gaussian hills", "count"),
                   scaled_param("hill_amplitude", 0.02, 0.0, kMaxHeight, "height of the tallest hills"),
                   param("crater_count", 5, 0, 10000, true, "number of craters", "count"),
                   scaled_param("crater_depth", 0.02, 0.0, kMaxHeight,
                                "floor depth of the largest crater (rims are a third of it)"),
                   param("step_count", 2, 0, 1000, true, "number of cliffs", "count"),
                   scaled_param("step_height", 0.004, -kMaxHeight, kMaxHeight, "height of each cliff")}});
}

const GeneratorRegistry& registry() {
  static const GeneratorRegistry reg = [] {
    GeneratorRegistry r("terrain generator");
    register_builtins(r);
    return r;
  }();
  return reg;
}

}  // namespace

Heightmap generate_terrain(const std::string& method, const GeneratorSpec& spec) {
  const GeneratorEntry& entry = registry().find(method);
  check_spec(method, spec);
  const Frame frame = make_frame(spec);
  HeightMatrix h = entry.generate(frame, Params(resolve(method, entry, frame, spec.params)));
  return Heightmap(GridGeometry{spec.rows, spec.cols, 0.0, 0.0, spec.cell_size_m}, std::move(h));
}

std::vector<std::string> generator_names() { return registry().names(); }

std::vector<std::string> generator_parameter_help(const std::string& method) {
  std::vector<std::string> lines;
  for (const auto& d : registry().find(method).params) {
    lines.push_back(fmt::format("{} (default {}): {}; valid {}[{}, {}] [{}]", d.key, d.default_text, d.meaning,
                                d.integer ? "whole numbers in " : "", d.min, d.max, d.unit));
  }
  return lines;
}

}  // namespace marsala::terrain
