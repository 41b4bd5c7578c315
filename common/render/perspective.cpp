#include "marsala/render/perspective.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/render/detail/colormap.hpp"
#include "marsala/render/detail/raster.hpp"

namespace marsala::render {
namespace {

using detail::Colour;
using Vec3 = Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxVertexSide = 800;  // grids with more cells a side are block-averaged down to this many vertices
constexpr double kMarginFraction = 0.04;

/// The grid to draw: heights and deposits block-averaged by `factor`, with the cell size grown to match.
struct Surface {
  int rows = 0, cols = 0;
  double cell_m = 0.0;
  std::vector<double> height;   // [row * cols + col]
  std::vector<double> deposit;  // same layout; empty without deposits
};

Surface reduce(const Heightmap& map, const std::optional<Heightmap>& deposit) {
  const int factor = std::max(1, (std::max(map.rows(), map.cols()) + kMaxVertexSide - 1) / kMaxVertexSide);
  Surface s;
  s.rows = (map.rows() + factor - 1) / factor;
  s.cols = (map.cols() + factor - 1) / factor;
  s.cell_m = map.cell_size_m() * factor;
  s.height.assign(static_cast<std::size_t>(s.rows) * s.cols, 0.0);
  if (deposit) s.deposit.assign(s.height.size(), 0.0);
  for (int r = 0; r < s.rows; ++r)
    for (int c = 0; c < s.cols; ++c) {
      double h = 0.0, d = 0.0;
      int n = 0;
      for (int i = r * factor; i < std::min(map.rows(), (r + 1) * factor); ++i)
        for (int j = c * factor; j < std::min(map.cols(), (c + 1) * factor); ++j) {
          h += map(i, j);
          if (deposit) d += (*deposit)(i, j);
          ++n;
        }
      s.height[static_cast<std::size_t>(r) * s.cols + c] = h / n;
      if (deposit) s.deposit[static_cast<std::size_t>(r) * s.cols + c] = d / n;
    }
  return s;
}

void check(const Heightmap& map, const PerspectiveOptions& o) {
  if (map.rows() == 0 || map.cols() == 0) throw InvalidArgument("render_perspective: empty heightmap");
  if (!(o.elevation_deg > 0.0 && o.elevation_deg <= 90.0))
    throw InvalidArgument(fmt::format("render_perspective: elevation_deg must be in (0, 90], got {}", o.elevation_deg));
  if (!(o.vertical_exaggeration > 0.0) || !std::isfinite(o.vertical_exaggeration))
    throw InvalidArgument("render_perspective: vertical_exaggeration must be a finite number > 0");
  if (!std::isfinite(o.azimuth_deg)) throw InvalidArgument("render_perspective: azimuth_deg must be finite");
  if (o.width_px < 16 || o.width_px > 8192 || o.height_px < 16 || o.height_px > 8192)
    throw InvalidArgument(fmt::format("render_perspective: picture size must be within [16, 8192] px, got {} x {}",
                                      o.width_px, o.height_px));
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c)
      if (!std::isfinite(map(r, c)))
        throw InvalidArgument(fmt::format("render_perspective: height of cell {} is not finite", CellIndex{r, c}));
  if (o.deposit) {
    if (o.deposit->rows() != map.rows() || o.deposit->cols() != map.cols())
      throw InvalidArgument(fmt::format("render_perspective: the deposit grid is {} x {}, the terrain {} x {}",
                                        o.deposit->rows(), o.deposit->cols(), map.rows(), map.cols()));
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (!std::isfinite((*o.deposit)(r, c)))
          throw InvalidArgument(fmt::format("render_perspective: deposit of cell {} is not finite", CellIndex{r, c}));
  }
}

/// A vertex on screen: pixel position and depth along the view direction.
struct Projected {
  double x = 0.0, y = 0.0, depth = 0.0;
};

/// Fills the triangle into `image` where it is nearer than `zbuffer`.
void raster_triangle(Image& image, std::vector<double>& zbuffer, const Projected& a, const Projected& b,
                     const Projected& c, Rgb colour) {
  const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
  const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
  const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const double wa = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
      const double wb = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
      const double wc = 1.0 - wa - wb;
      if (wa < -1e-9 || wb < -1e-9 || wc < -1e-9) continue;
      const double depth = wa * a.depth + wb * b.depth + wc * c.depth;
      double& z = zbuffer[static_cast<std::size_t>(y) * image.width + x];
      if (depth >= z) continue;
      z = depth;
      detail::set_pixel(image, x, y, colour);
    }
}

}  // namespace

Image render_perspective(const Heightmap& map, const PerspectiveOptions& options) {
  check(map, options);
  const Surface s = reduce(map, options.deposit);
  const double exaggeration = options.vertical_exaggeration;
  const auto [lo, hi] = std::minmax_element(s.height.begin(), s.height.end());
  const double h_min = *lo, h_span = std::max(*hi - *lo, 1e-9);

  // World points: x east, y north, z up [m]; row 0 is the north edge.
  const auto point = [&](int r, int c) {
    return Vec3((c + 0.5) * s.cell_m, (s.rows - r - 0.5) * s.cell_m,
                s.height[static_cast<std::size_t>(r) * s.cols + c] * exaggeration);
  };
  const double width_m = s.cols * s.cell_m, depth_m = s.rows * s.cell_m;
  const Vec3 centre(width_m / 2.0, depth_m / 2.0, (h_min + h_span / 2.0) * exaggeration);
  const double az = options.azimuth_deg * kPi / 180.0, el = options.elevation_deg * kPi / 180.0;
  const double distance = 1.6 * std::hypot(width_m, depth_m, h_span * exaggeration);
  const Vec3 camera = centre + distance * Vec3(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  const Vec3 forward = (centre - camera).normalized();
  // Straight down (elevation 90): "up" on the picture is north.
  const Vec3 world_up = options.elevation_deg > 89.999 ? Vec3(0.0, 1.0, 0.0) : Vec3(0.0, 0.0, 1.0);
  const Vec3 right = forward.cross(world_up).normalized();
  const Vec3 up = right.cross(forward);

  // Project every vertex, then fit the projection into the picture.
  std::vector<Projected> vertices(static_cast<std::size_t>(s.rows) * s.cols);
  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x, min_y = min_x, max_y = -min_x;
  for (int r = 0; r < s.rows; ++r)
    for (int c = 0; c < s.cols; ++c) {
      const Vec3 d = point(r, c) - camera;
      const double depth = d.dot(forward);
      Projected& p = vertices[static_cast<std::size_t>(r) * s.cols + c];
      p = {d.dot(right) / depth, d.dot(up) / depth, depth};
      min_x = std::min(min_x, p.x);
      max_x = std::max(max_x, p.x);
      min_y = std::min(min_y, p.y);
      max_y = std::max(max_y, p.y);
    }
  const int w = options.width_px, h = options.height_px;
  const double margin = kMarginFraction * std::min(w, h);
  const double scale = std::min((w - 2.0 * margin) / std::max(max_x - min_x, 1e-12),
                                (h - 2.0 * margin) / std::max(max_y - min_y, 1e-12));
  const double offset_x = (w - (max_x - min_x) * scale) / 2.0, offset_y = (h - (max_y - min_y) * scale) / 2.0;
  for (Projected& p : vertices) {
    p.x = offset_x + (p.x - min_x) * scale;
    p.y = h - (offset_y + (p.y - min_y) * scale);  // picture rows grow downwards
  }

  Image image = detail::make_image(w, h, Rgb{16, 20, 28});
  for (int y = 0; y < h; ++y)  // a dark sky, a little lighter towards the horizon
    for (int x = 0; x < w; ++x) {
      const double t = static_cast<double>(y) / h;
      detail::set_pixel(image, x, y, detail::to_rgb(detail::mix({16, 20, 28}, {44, 52, 68}, t)));
    }
  std::vector<double> zbuffer(static_cast<std::size_t>(w) * h, std::numeric_limits<double>::infinity());
  const Vec3 sun = Vec3(-1.0, 1.0, std::sqrt(2.0)).normalized();  // from the north-west, 45 deg up
  const Colour built{255, 140, 0};
  const auto shade = [&](int ra, int ca, int rb, int cb, int rc, int cc) {
    const Vec3 pa = point(ra, ca), pb = point(rb, cb), pc = point(rc, cc);
    Vec3 normal = (pb - pa).cross(pc - pa).normalized();
    if (normal.z() < 0.0) normal = -normal;
    const double light = 0.35 + 0.65 * std::max(0.0, normal.dot(sun));
    const auto at = [&](int r, int c) { return static_cast<std::size_t>(r) * s.cols + c; };
    const double mean_h = (s.height[at(ra, ca)] + s.height[at(rb, cb)] + s.height[at(rc, cc)]) / 3.0;
    Colour colour = detail::terrain_colour((mean_h - h_min) / h_span);
    if (!s.deposit.empty()) {
      const double d = std::max({s.deposit[at(ra, ca)], s.deposit[at(rb, cb)], s.deposit[at(rc, cc)]});
      if (d > 1e-9) colour = detail::mix(colour, built, std::min(0.9, 0.45 + d / 0.5));
    }
    colour.r *= light;
    colour.g *= light;
    colour.b *= light;
    raster_triangle(image, zbuffer, vertices[at(ra, ca)], vertices[at(rb, cb)], vertices[at(rc, cc)],
                    detail::to_rgb(colour));
  };
  for (int r = 0; r + 1 < s.rows; ++r)
    for (int c = 0; c + 1 < s.cols; ++c) {
      shade(r, c, r, c + 1, r + 1, c);
      shade(r + 1, c, r, c + 1, r + 1, c + 1);
    }
  // Robots: boxes on the cell under their centre, their faces lit like the terrain's.
  const auto project = [&](const Vec3& p) {
    const Vec3 d = p - camera;
    const double depth = d.dot(forward);
    return Projected{offset_x + (d.dot(right) / depth - min_x) * scale,
                     h - (offset_y + (d.dot(up) / depth - min_y) * scale), depth};
  };
  const GridGeometry& g = map.geometry();
  for (const PerspectiveBody& b : options.bodies) {
    const auto cell = map.cell_at({b.x_m, b.y_m});
    if (!cell) continue;
    const double x = b.x_m - g.xll_m, y = b.y_m - g.yll_m, half = b.side_m / 2.0;
    const double z0 = map(cell->row, cell->col) * exaggeration, z1 = z0 + b.height_m * exaggeration;
    const Vec3 corner[8] = {{x - half, y - half, z0}, {x + half, y - half, z0}, {x + half, y + half, z0},
                            {x - half, y + half, z0}, {x - half, y - half, z1}, {x + half, y - half, z1},
                            {x + half, y + half, z1}, {x - half, y + half, z1}};
    // Faces as corner quadruples with their outward normals: bottom is never seen from above.
    const int faces[5][4] = {{4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    const Vec3 normals[5] = {{0, 0, 1}, {0, -1, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
    for (int f = 0; f < 5; ++f) {
      const double light = 0.35 + 0.65 * std::max(0.0, normals[f].dot(sun));
      const Rgb colour = detail::to_rgb(Colour{b.colour.r * light, b.colour.g * light, b.colour.b * light});
      const Projected q[4] = {project(corner[faces[f][0]]), project(corner[faces[f][1]]),
                              project(corner[faces[f][2]]), project(corner[faces[f][3]])};
      raster_triangle(image, zbuffer, q[0], q[1], q[2], colour);
      raster_triangle(image, zbuffer, q[0], q[2], q[3], colour);
    }
  }
  if (!options.title.empty()) detail::draw_text(image, 12, 12, options.title, 2, Rgb{235, 235, 235});
  return image;
}

}  // namespace marsala::render
