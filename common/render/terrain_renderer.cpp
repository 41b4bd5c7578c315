#include "marsala/render/terrain_renderer.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/render/detail/colormap.hpp"
#include "marsala/render/detail/raster.hpp"

namespace marsala::render {
namespace {

using detail::Colour;
using detail::Rgb;

constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kInk{30, 30, 30};
constexpr Rgb kFrame{80, 80, 80};
constexpr Colour kNavigableTint{70, 225, 90};
constexpr Rgb kNavigableOutline{0, 105, 40};
constexpr Rgb kMarkerCore{235, 0, 175};
constexpr Rgb kMarkerHalo{255, 255, 255};
constexpr double kNavigableAlpha = 0.38;
constexpr double kGapAlpha = 0.72;
constexpr double kGapThresholdM = 1e-9;
constexpr int kMaxSizePx = 16384;

// Sun from the north-west (azimuth 315 deg), 45 deg above the horizon, in (east, north, up) coordinates.
constexpr double kSinAltitude = 0.70710678118654752;
constexpr double kSunEast = -0.5;
constexpr double kSunNorth = 0.5;
// Vertical exaggeration of the shading only (colours use true heights): gentle 0.1-0.3 slopes stay readable.
constexpr double kShadeExaggeration = 2.0;

constexpr Rgb kHalo{30, 30, 30};

// Twelve colours that stay apart from each other and from the terrain colour map's blues and sands when blended.
const std::vector<Rgb> kPalette{{228, 26, 28},  {40, 100, 220},  {60, 170, 60},  {255, 127, 0},
                                {150, 70, 170}, {0, 200, 220},   {235, 50, 190}, {170, 230, 40},
                                {150, 85, 35},  {250, 160, 200}, {0, 120, 120},  {180, 160, 255}};

/// How grid cells map to pixels: `factor` x `factor` cells are averaged into one display cell, which is drawn
/// as a `scale` x `scale` pixel square (one of the two is 1).
struct Sampling {
  int factor;
  int scale;
  int rows;  // display cells
  int cols;
};

Sampling choose_sampling(int rows, int cols, int max_px) {
  const int n = std::max(rows, cols);
  if (n > max_px) {
    const int f = (n + max_px - 1) / max_px;
    return {f, 1, (rows + f - 1) / f, (cols + f - 1) / f};
  }
  return {1, max_px / n, rows, cols};
}

template <class Matrix>
std::vector<double> block_mean(const Matrix& m, const Sampling& s) {
  std::vector<double> out(static_cast<std::size_t>(s.rows) * s.cols);
  const int rows = static_cast<int>(m.rows()), cols = static_cast<int>(m.cols());
  for (int i = 0; i < s.rows; ++i)
    for (int j = 0; j < s.cols; ++j) {
      const int r1 = std::min(rows, (i + 1) * s.factor), c1 = std::min(cols, (j + 1) * s.factor);
      double sum = 0.0;
      for (int r = i * s.factor; r < r1; ++r)
        for (int c = j * s.factor; c < c1; ++c) sum += static_cast<double>(m(r, c));
      out[static_cast<std::size_t>(i) * s.cols + j] = sum / ((r1 - i * s.factor) * (c1 - j * s.factor));
    }
  return out;
}

// Illumination relative to flat ground (1 on flat ground, 0 facing away from the sun), Horn's 3 x 3 gradient
// with one-sided differences at the borders.
std::vector<double> hillshade(const std::vector<double>& h, int rows, int cols, double cell_m) {
  std::vector<double> out(h.size());
  const auto at = [&](int r, int c) { return h[static_cast<std::size_t>(r) * cols + c]; };
  for (int r = 0; r < rows; ++r) {
    const int rn = std::max(r - 1, 0), rs = std::min(r + 1, rows - 1);  // north, south neighbours
    for (int c = 0; c < cols; ++c) {
      const int cw = std::max(c - 1, 0), ce = std::min(c + 1, cols - 1);
      double dzdx = 0.0, dzdy = 0.0;
      if (ce > cw)
        dzdx = ((at(rn, ce) - at(rn, cw)) + 2.0 * (at(r, ce) - at(r, cw)) + (at(rs, ce) - at(rs, cw))) /
               (4.0 * (ce - cw) * cell_m);
      if (rs > rn)
        dzdy = ((at(rn, cw) - at(rs, cw)) + 2.0 * (at(rn, c) - at(rs, c)) + (at(rn, ce) - at(rs, ce))) /
               (4.0 * (rs - rn) * cell_m);
      dzdx *= kShadeExaggeration;
      dzdy *= kShadeExaggeration;
      const double lit =
          (kSinAltitude - kSunEast * dzdx - kSunNorth * dzdy) / std::sqrt(1.0 + dzdx * dzdx + dzdy * dzdy);
      out[static_cast<std::size_t>(r) * cols + c] = std::max(0.0, lit) / kSinAltitude;
    }
  }
  return out;
}

// Scales the colour with the illumination: slopes facing away from the sun darken (down to 40%), sunlit ones
// brighten (up to 133%); brightening that would clip a channel turns into a lift toward white instead, so
// hues do not shift. Flat ground keeps its colour-map colour exactly.
Colour shade(Colour c, double light) {
  const double d = light - 1.0;
  if (d <= 0.0) {
    const double k = 1.0 + 0.6 * d;
    return {c.r * k, c.g * k, c.b * k};
  }
  const double k = 1.0 + 0.8 * d;
  const double brightest = std::max({c.r, c.g, c.b, 1.0});
  const double k_fit = std::min(k, 255.0 / brightest);
  const Colour scaled{c.r * k_fit, c.g * k_fit, c.b * k_fit};
  return detail::mix(scaled, {255.0, 255.0, 255.0}, std::min(1.0, 0.6 * (k - k_fit)));
}

void validate(const Heightmap& map, const RenderOptions& o) {
  if (map.rows() <= 0 || map.cols() <= 0 || map.heights().size() != map.size())
    throw InvalidArgument("render_terrain: the heightmap is empty");
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c)
      if (!std::isfinite(map(r, c)))
        throw InvalidArgument(fmt::format("render_terrain: height at cell {} is not finite", CellIndex{r, c}));
  if (o.max_size_px < 1 || o.max_size_px > kMaxSizePx)
    throw InvalidArgument(
        fmt::format("render_terrain: max_size_px = {} is outside [1, {}]", o.max_size_px, kMaxSizePx));
  if (o.navigable && (o.navigable->rows() != map.rows() || o.navigable->cols() != map.cols()))
    throw InvalidArgument(fmt::format("render_terrain: navigable mask is {} x {} but the heightmap is {} x {}",
                                      o.navigable->rows(), o.navigable->cols(), map.rows(), map.cols()));
  if (o.gap) {
    if (o.gap->rows() != map.rows() || o.gap->cols() != map.cols())
      throw InvalidArgument(fmt::format("render_terrain: gap map is {} x {} but the heightmap is {} x {}",
                                        o.gap->rows(), o.gap->cols(), map.rows(), map.cols()));
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (!std::isfinite((*o.gap)(r, c)))
          throw InvalidArgument(fmt::format("render_terrain: gap at cell {} is not finite", CellIndex{r, c}));
  }
  for (const CellIndex m : o.markers)
    if (!map.contains(m))
      throw InvalidArgument(
          fmt::format("render_terrain: marker {} is off the {} x {} grid", m, map.rows(), map.cols()));
  if (o.labels && (o.labels->rows() != map.rows() || o.labels->cols() != map.cols()))
    throw InvalidArgument(fmt::format("render_terrain: label grid is {} x {} but the heightmap is {} x {}",
                                      o.labels->rows(), o.labels->cols(), map.rows(), map.cols()));
  if (!(o.label_alpha >= 0.0 && o.label_alpha <= 1.0))
    throw InvalidArgument(fmt::format("render_terrain: label_alpha = {} is outside [0, 1]", o.label_alpha));
  const auto check = [](bool ok, const char* what, std::size_t i) {
    if (!ok) throw InvalidArgument(fmt::format("render_terrain: {} {} has a non-finite or negative value", what, i));
  };
  const auto finite = [](Position p) { return std::isfinite(p.x) && std::isfinite(p.y); };
  const auto width_ok = [](double w) { return std::isfinite(w) && w >= 0.0; };
  for (std::size_t i = 0; i < o.polylines.size(); ++i) {
    bool ok = width_ok(o.polylines[i].width_px);
    for (const Position& p : o.polylines[i].points) ok = ok && finite(p);
    check(ok, "polyline", i);
  }
  for (std::size_t i = 0; i < o.arrows.size(); ++i)
    check(finite(o.arrows[i].tail) && finite(o.arrows[i].head) && width_ok(o.arrows[i].width_px), "arrow", i);
  for (std::size_t i = 0; i < o.rectangles.size(); ++i)
    check(finite(o.rectangles[i].a) && finite(o.rectangles[i].b) && width_ok(o.rectangles[i].width_px), "rectangle", i);
  for (std::size_t i = 0; i < o.circles.size(); ++i)
    check(finite(o.circles[i].centre) && width_ok(o.circles[i].radius_m) && width_ok(o.circles[i].width_px), "circle",
          i);
  for (std::size_t i = 0; i < o.points.size(); ++i)
    check(finite(o.points[i].at) && width_ok(o.points[i].radius_px), "point", i);
}

/// Per display cell: the most frequent non-zero label of its block (ties: the smallest) and the labelled fraction.
void block_labels(const CellLabels& labels, const Sampling& s, std::vector<std::uint32_t>& label,
                  std::vector<double>& fraction) {
  label.assign(static_cast<std::size_t>(s.rows) * s.cols, 0);
  fraction.assign(label.size(), 0.0);
  const int rows = static_cast<int>(labels.rows()), cols = static_cast<int>(labels.cols());
  std::vector<std::uint32_t> seen;
  for (int i = 0; i < s.rows; ++i)
    for (int j = 0; j < s.cols; ++j) {
      const int r1 = std::min(rows, (i + 1) * s.factor), c1 = std::min(cols, (j + 1) * s.factor);
      seen.clear();
      for (int r = i * s.factor; r < r1; ++r)
        for (int c = j * s.factor; c < c1; ++c)
          if (labels(r, c) != 0) seen.push_back(labels(r, c));
      if (seen.empty()) continue;
      std::sort(seen.begin(), seen.end());
      std::uint32_t best = seen.front();
      std::size_t best_run = 0;
      for (std::size_t a = 0; a < seen.size();) {
        std::size_t b = a;
        while (b < seen.size() && seen[b] == seen[a]) ++b;
        if (b - a > best_run) {
          best_run = b - a;
          best = seen[a];
        }
        a = b;
      }
      const std::size_t k = static_cast<std::size_t>(i) * s.cols + j;
      label[k] = best;
      fraction[k] = static_cast<double>(seen.size()) / ((r1 - i * s.factor) * (c1 - j * s.factor));
    }
}

/// World [m] to continuous pixel coordinates of the terrain area.
struct PixelMapper {
  double x0, y_top, per_m;  // per_m = pixels per metre
  double x(const Position& p) const { return (p.x - x0) * per_m; }
  double y(const Position& p) const { return (y_top - p.y) * per_m; }
};

PixelMapper pixel_mapper(const Heightmap& map, const Sampling& s) {
  const GridGeometry& g = map.geometry();
  return {g.xll_m, g.yll_m + g.rows * g.cell_size_m, static_cast<double>(s.scale) / (s.factor * g.cell_size_m)};
}

double automatic(double width, double value) { return width > 0.0 ? width : value; }

/// An arrow in pixel coordinates: the halo pass or the colour pass.
void draw_arrow_px(Image& img, double tx, double ty, double hx, double hy, double w, Rgb colour, bool halo) {
  const double dx = hx - tx, dy = hy - ty, length = std::sqrt(dx * dx + dy * dy);
  if (!(length > 0.0)) return;
  const double head = std::min(0.5 * length, 3.0 * w + 4.0), half = 0.6 * head;
  const double ux = dx / length, uy = dy / length;
  const double bx = hx - head * ux, by = hy - head * uy;  // middle of the head's base
  const double lx = bx - half * uy, ly = by + half * ux, rx = bx + half * uy, ry = by - half * ux;
  if (halo) {
    detail::draw_segment(img, tx, ty, bx, by, w + 2.0, kHalo);
    detail::draw_segment(img, hx, hy, lx, ly, 2.0, kHalo);
    detail::draw_segment(img, lx, ly, rx, ry, 2.0, kHalo);
    detail::draw_segment(img, rx, ry, hx, hy, 2.0, kHalo);
    return;
  }
  detail::draw_segment(img, tx, ty, bx, by, w, colour);
  detail::fill_triangle(img, hx, hy, lx, ly, rx, ry, colour);
}

void draw_arrow(Image& img, const PixelMapper& px, const Arrow& a, double auto_width, bool halo) {
  draw_arrow_px(img, px.x(a.tail), px.y(a.tail), px.x(a.head), px.y(a.head), automatic(a.width_px, auto_width),
                a.colour, halo);
}

void draw_point(Image& img, double x, double y, PointShape shape, double r, Rgb colour) {
  switch (shape) {
    case PointShape::kDisc: detail::fill_disc(img, x, y, r, colour); break;
    case PointShape::kSquare: {
      const int x0 = static_cast<int>(std::floor(x - r)), y0 = static_cast<int>(std::floor(y - r));
      const int side = static_cast<int>(std::floor(x + r)) - x0 + 1;
      detail::fill_rect(img, x0, y0, side, side, colour);
      break;
    }
    case PointShape::kDiamond:
      detail::fill_triangle(img, x - r, y, x, y - r, x + r, y, colour);
      detail::fill_triangle(img, x - r, y, x, y + r, x + r, y, colour);
      break;
  }
}

/// Rectangles, circles, polylines and arrows, each kind with its halo under it.
void draw_overlays(Image& img, const Heightmap& map, const RenderOptions& o, const Sampling& s) {
  const PixelMapper px = pixel_mapper(map, s);
  const double longest = std::max(img.width, img.height);
  const double thin = std::clamp(longest / 400.0, 1.0, 4.0);
  const double line = std::clamp(longest / 200.0, 2.0, 8.0);
  for (const RectangleOutline& r : o.rectangles) {
    const double xa = px.x(r.a), ya = px.y(r.a), xb = px.x(r.b), yb = px.y(r.b);
    const double w = automatic(r.width_px, thin);
    for (const auto& [pass_w, colour] : {std::pair<double, Rgb>{w + 2.0, kHalo}, {w, r.colour}}) {
      detail::draw_segment(img, xa, ya, xb, ya, pass_w, colour);
      detail::draw_segment(img, xb, ya, xb, yb, pass_w, colour);
      detail::draw_segment(img, xb, yb, xa, yb, pass_w, colour);
      detail::draw_segment(img, xa, yb, xa, ya, pass_w, colour);
    }
  }
  for (const CircleOutline& c : o.circles) {
    const double w = automatic(c.width_px, thin), r = c.radius_m * px.per_m;
    detail::draw_ring(img, px.x(c.centre), px.y(c.centre), r, w + 2.0, kHalo);
    detail::draw_ring(img, px.x(c.centre), px.y(c.centre), r, w, c.colour);
  }
  for (bool halo : {true, false})
    for (const Polyline& p : o.polylines) {
      const double w = automatic(p.width_px, line);
      for (std::size_t i = 1; i < p.points.size(); ++i)
        detail::draw_segment(img, px.x(p.points[i - 1]), px.y(p.points[i - 1]), px.x(p.points[i]), px.y(p.points[i]),
                             halo ? w + 2.0 : w, halo ? kHalo : p.colour);
    }
  for (bool halo : {true, false})
    for (const Arrow& a : o.arrows) draw_arrow(img, px, a, thin, halo);
}

void draw_points(Image& img, const Heightmap& map, const RenderOptions& o, const Sampling& s) {
  const PixelMapper px = pixel_mapper(map, s);
  const double auto_r = std::clamp(std::max(img.width, img.height) / 120.0, 3.0, 10.0);
  for (const PointMark& p : o.points) {
    const double r = automatic(p.radius_px, auto_r);
    draw_point(img, px.x(p.at), px.y(p.at), p.shape, r + 1.5, kHalo);
    draw_point(img, px.x(p.at), px.y(p.at), p.shape, r, p.colour);
  }
}

/// The terrain area: colours, overlays and markers, one pixel per display pixel.
struct TerrainLayer {
  Image image;
  double min_height;
  double max_height;
  double max_gap;  // 0 when there is no gap above the threshold
};

TerrainLayer draw_terrain(const Heightmap& map, const RenderOptions& o, const Sampling& s) {
  TerrainLayer layer{{}, map.min_height(), map.max_height(), 0.0};
  const std::vector<double> heights = block_mean(map.heights(), s);
  const std::vector<double> light = hillshade(heights, s.rows, s.cols, map.cell_size_m() * s.factor);
  std::vector<double> navigable, gap, label_fraction;
  std::vector<std::uint32_t> label;
  if (o.labels) block_labels(*o.labels, s, label, label_fraction);
  if (o.navigable) navigable = block_mean(*o.navigable, s);
  if (o.gap) {
    gap = block_mean(o.gap->heights(), s);
    layer.max_gap = std::max(0.0, o.gap->max_height());
    if (layer.max_gap <= kGapThresholdM) layer.max_gap = 0.0;
  }
  const double range = layer.max_height - layer.min_height;

  const int width = s.cols * s.scale, height = s.rows * s.scale;
  layer.image = detail::make_image(width, height, kBackground);
  for (int i = 0; i < s.rows; ++i)
    for (int j = 0; j < s.cols; ++j) {
      const std::size_t k = static_cast<std::size_t>(i) * s.cols + j;
      const double t = range > 0.0 ? (heights[k] - layer.min_height) / range : 0.5;
      Colour c = shade(detail::terrain_colour(t), light[k]);
      if (!label.empty() && label[k] != 0)
        c = detail::mix(c, detail::to_colour(label_colour(label[k], o.palette)), o.label_alpha * label_fraction[k]);
      if (!navigable.empty()) c = detail::mix(c, kNavigableTint, kNavigableAlpha * navigable[k]);
      if (!gap.empty() && layer.max_gap > 0.0 && gap[k] > kGapThresholdM)
        c = detail::mix(c, detail::heat_colour(gap[k] / layer.max_gap), kGapAlpha);
      detail::fill_rect(layer.image, j * s.scale, i * s.scale, s.scale, s.scale, detail::to_rgb(c));
    }

  const int longest = std::max(width, height);
  if (!navigable.empty()) {
    // Outline: navigable pixels within `reach` pixels of a non-navigable one (the image edge is no border).
    const int reach = std::clamp(longest / 512, 1, 3);
    const auto inside = [&](int x, int y) {
      return navigable[static_cast<std::size_t>(y / s.scale) * s.cols + x / s.scale] >= 0.5;
    };
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        if (!inside(x, y)) continue;
        bool border = false;
        for (int dy = -reach; dy <= reach && !border; ++dy)
          for (int dx = -reach; dx <= reach && !border; ++dx) {
            const int xx = x + dx, yy = y + dy;
            border = xx >= 0 && yy >= 0 && xx < width && yy < height && !inside(xx, yy);
          }
        if (border) detail::set_pixel(layer.image, x, y, kNavigableOutline);
      }
  }

  draw_overlays(layer.image, map, o, s);

  const int arm = std::max(3, longest / 64);
  const int thick = std::clamp(longest / 320, 1, 4);
  for (const CellIndex m : o.markers) {
    const int x = (m.col / s.factor) * s.scale + s.scale / 2;
    const int y = (m.row / s.factor) * s.scale + s.scale / 2;
    const int lo = thick / 2;
    detail::fill_rect(layer.image, x - arm - 1, y - lo - 1, 2 * arm + 3, thick + 2, kMarkerHalo);
    detail::fill_rect(layer.image, x - lo - 1, y - arm - 1, thick + 2, 2 * arm + 3, kMarkerHalo);
    detail::fill_rect(layer.image, x - arm, y - lo, 2 * arm + 1, thick, kMarkerCore);
    detail::fill_rect(layer.image, x - lo, y - arm, thick, 2 * arm + 1, kMarkerCore);
  }
  draw_points(layer.image, map, o, s);
  return layer;
}

// ---- legend ----

// Largest 1, 2 or 5 times a power of ten not above x (x > 0).
double nice_floor(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= x * (1.0 + 1e-9)) return m * p;
  return p;
}

// Smallest 1, 2 or 5 times a power of ten not below x (x > 0).
double nice_ceil(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= x * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

// Legend numbers with a fixed count of decimals (fmt's fixed form prints what printf's "%.*f" printed, so the
// pictures keep their pixels).
std::string format_fixed(double v, int decimals) {
  std::string s = fmt::format("{:.{}f}", v, decimals);
  if (s == "-0" || s.rfind("-0.", 0) == 0) {
    if (s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // no "-0.00"
  }
  return s;
}

std::string format_length(double metres) { return fmt::format("{:g} m", metres); }

struct Tick {
  double value;
  std::string label;
};

// Values at multiples of a nice step within [lo, hi], about `target` of them.
std::vector<Tick> nice_ticks(double lo, double hi, int target) {
  // A range lost in the rounding of its bounds reads as one value.
  if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi)))) return {{lo, format_fixed(lo, 2)}};
  const double step = nice_ceil((hi - lo) / target);
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 12);
  std::vector<Tick> ticks;
  const double first = std::ceil(lo / step - 1e-9);
  for (int k = 0; k <= 4 * target && (first + k) * step <= hi + 1e-9 * step; ++k)
    ticks.push_back({(first + k) * step, format_fixed((first + k) * step, decimals)});
  return ticks;
}

struct ColourBar {
  std::string label;
  double lo, hi;
  bool heat;
};

int bar_label_width(const ColourBar& bar, int scale) {
  int w = detail::text_width(bar.label, scale);
  for (const Tick& t : nice_ticks(bar.lo, bar.hi, 5)) w = std::max(w, detail::text_width(t.label, scale) + 14 * scale);
  return w;
}

// Draws a vertical colour bar (top = hi) with ticks; returns the height used [px].
int draw_colour_bar(Image& img, int x, int y, int bar_w, int bar_h, const ColourBar& bar, int scale) {
  detail::draw_text(img, x, y, bar.label, scale, kInk);
  const int top = y + detail::text_height(scale) * 3 / 2 + 4 * scale;
  for (int k = 0; k < bar_h; ++k) {
    const double t = bar_h > 1 ? 1.0 - static_cast<double>(k) / (bar_h - 1) : 0.5;
    const Colour c = bar.heat ? detail::heat_colour(t) : detail::terrain_colour(t);
    detail::fill_rect(img, x, top + k, bar_w, 1, detail::to_rgb(c));
  }
  detail::draw_rect_outline(img, x - 1, top - 1, bar_w + 2, bar_h + 2, kFrame);
  for (const Tick& t : nice_ticks(bar.lo, bar.hi, 5)) {
    const double f = bar.hi > bar.lo ? (t.value - bar.lo) / (bar.hi - bar.lo) : 0.5;
    const int ty = top + static_cast<int>(std::lround((1.0 - f) * (bar_h - 1)));
    detail::fill_rect(img, x + bar_w, ty, 4 * scale, std::max(1, scale / 2), kFrame);
    detail::draw_text(img, x + bar_w + 6 * scale, ty - detail::text_height(scale) / 2 + scale / 2, t.label, scale,
                      kInk);
  }
  return top - y + bar_h;
}

/// A legend entry's swatch in the side x side square at (x, y) [px].
void draw_swatch(Image& img, int x, int y, int side, const LegendEntry& e) {
  const double cx = x + 0.5 * side, cy = y + 0.5 * side, r = 0.5 * side;
  const double w = std::max(2.0, side / 5.0);
  switch (e.swatch) {
    case LegendSwatch::kSquare:
      detail::fill_rect(img, x, y, side, side, e.colour);
      detail::draw_rect_outline(img, x, y, side, side, kFrame);
      break;
    case LegendSwatch::kDisc:
      draw_point(img, cx, cy, PointShape::kDisc, r - 1.0, kHalo);
      draw_point(img, cx, cy, PointShape::kDisc, r - 2.5, e.colour);
      break;
    case LegendSwatch::kDiamond:
      draw_point(img, cx, cy, PointShape::kDiamond, r, kHalo);
      draw_point(img, cx, cy, PointShape::kDiamond, r - 1.5, e.colour);
      break;
    case LegendSwatch::kLine:
      detail::draw_segment(img, x + 1.0, cy, x + side - 1.0, cy, w + 2.0, kHalo);
      detail::draw_segment(img, x + 1.0, cy, x + side - 1.0, cy, w, e.colour);
      break;
    case LegendSwatch::kRing:
    case LegendSwatch::kOutline:
      detail::fill_rect(img, x, y, side, side, detail::to_rgb(detail::terrain_colour(0.15)));
      if (e.swatch == LegendSwatch::kRing) {
        detail::draw_ring(img, cx, cy, r - 3.0, 2.0, e.colour);
      } else {
        detail::draw_rect_outline(img, x + 3, y + 3, side - 6, side - 6, e.colour);
        detail::draw_rect_outline(img, x + 4, y + 4, side - 8, side - 8, e.colour);
      }
      break;
    case LegendSwatch::kArrow:
      for (bool halo : {true, false})
        draw_arrow_px(img, x + 1.0, cy, x + side - 1.0, cy, std::max(1.0, side / 8.0), e.colour, halo);
      break;
  }
}

Image compose(const TerrainLayer& layer, const Heightmap& map, const RenderOptions& o, const Sampling& s) {
  const int tw = layer.image.width, th = layer.image.height;
  const int font = std::clamp((std::max(tw, th) + 559) / 560, 1, 4);  // font pixel size [px]
  const int title_font = font + 1;
  const int pad = 10 * font;
  const int line = detail::text_height(font);

  // Colour bars and key on the right.
  std::vector<ColourBar> bars{{"height [m]", layer.min_height, layer.max_height, false}};
  if (layer.max_gap > 0.0) bars.push_back({"gap [m]", 0.0, layer.max_gap, true});
  const int bar_w = 14 * font;
  const int bar_h = std::max(80 * font, static_cast<int>(std::min(th, 480 * font) * (bars.size() > 1 ? 0.36 : 0.6)));
  std::vector<std::string> keys;
  if (o.navigable) keys.push_back("navigable");
  if (!o.markers.empty()) keys.push_back(o.markers.size() > 1 ? "markers" : "marker");
  for (const LegendEntry& e : o.legend_entries) keys.push_back(e.text);
  int panel_w = 0;
  for (const auto& b : bars) panel_w = std::max(panel_w, bar_w + bar_label_width(b, font));
  for (const auto& k : keys) panel_w = std::max(panel_w, bar_w + 6 * font + detail::text_width(k, font));
  const int panel_h = static_cast<int>(bars.size()) * (line * 3 / 2 + 4 * font + bar_h + 3 * pad) +
                      static_cast<int>(keys.size()) * (bar_w + pad);

  // Scale bar and caption below the terrain.
  const double metres_per_px = map.cell_size_m() * s.factor / s.scale;
  const double bar_m = nice_floor(0.25 * tw * metres_per_px);
  const int scale_px = std::max(1, static_cast<int>(std::lround(bar_m / metres_per_px)));
  const std::string scale_label = format_length(bar_m);
  // "{:g}" as the scale bar: picture text, six significant digits as ever (the pixels must not change).
  const std::string caption = fmt::format("{} x {} cells of {:g} m", map.rows(), map.cols(), map.cell_size_m());
  const int scale_row_w = scale_px + 6 * font + detail::text_width(scale_label, font);
  const int bottom_h = pad + line + 2 * font + line + pad;

  const int title_h = o.title.empty() ? 0 : detail::text_height(title_font) + pad;
  const int left_w = std::max({tw, scale_row_w, detail::text_width(caption, font)});
  const int width =
      std::max(pad + left_w + 3 * pad + panel_w + pad, pad + detail::text_width(o.title, title_font) + pad);
  const int top = pad + title_h;
  const int height = top + std::max(th + bottom_h, panel_h) + pad;

  Image img = detail::make_image(width, height, kBackground);
  if (!o.title.empty()) detail::draw_text(img, pad, pad, o.title, title_font, kInk);
  detail::blit(img, layer.image, pad, top);
  detail::draw_rect_outline(img, pad - 1, top - 1, tw + 2, th + 2, kFrame);

  // Scale bar: a black bar with end ticks, label to its right; caption on the next line.
  const int sy = top + th + pad;
  detail::fill_rect(img, pad, sy + line / 2 - font, scale_px, 2 * font, kInk);
  detail::fill_rect(img, pad, sy, std::max(1, font), line, kInk);
  detail::fill_rect(img, pad + scale_px - std::max(1, font), sy, std::max(1, font), line, kInk);
  detail::draw_text(img, pad + scale_px + 6 * font, sy, scale_label, font, kInk);
  detail::draw_text(img, pad, sy + line + 2 * font + font, caption, font, {110, 110, 110});

  int y = top;
  const int px = pad + left_w + 3 * pad;
  for (const auto& b : bars) y += draw_colour_bar(img, px, y, bar_w, bar_h, b, font) + 3 * pad;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::string& k = keys[i];
    const std::size_t builtin = keys.size() - o.legend_entries.size();
    if (i >= builtin) {
      draw_swatch(img, px, y, bar_w, o.legend_entries[i - builtin]);
    } else if (k == "navigable") {
      const Colour base = detail::terrain_colour(0.5);
      detail::fill_rect(img, px, y, bar_w, bar_w, detail::to_rgb(detail::mix(base, kNavigableTint, kNavigableAlpha)));
      detail::draw_rect_outline(img, px, y, bar_w, bar_w, kNavigableOutline);
      detail::draw_rect_outline(img, px + 1, y + 1, bar_w - 2, bar_w - 2, kNavigableOutline);
    } else {
      const int cx = px + bar_w / 2, cy = y + bar_w / 2, arm = bar_w / 2 - 1, t = std::max(1, font);
      detail::fill_rect(img, cx - arm, cy - t / 2, 2 * arm + 1, t, kMarkerCore);
      detail::fill_rect(img, cx - t / 2, cy - arm, t, 2 * arm + 1, kMarkerCore);
    }
    detail::draw_text(img, px + bar_w + 6 * font, y + (bar_w - line) / 2 + font / 2, k, font, kInk);
    y += bar_w + pad;
  }
  return img;
}

}  // namespace

const std::vector<Rgb>& default_palette() { return kPalette; }

Rgb label_colour(std::uint32_t label, const std::vector<Rgb>& palette) {
  const std::vector<Rgb>& p = palette.empty() ? kPalette : palette;
  return p[(label == 0 ? 0 : label - 1) % p.size()];
}

Image render_terrain(const Heightmap& map, const RenderOptions& options) {
  validate(map, options);
  const Sampling s = choose_sampling(map.rows(), map.cols(), options.max_size_px);
  TerrainLayer layer = draw_terrain(map, options, s);
  if (!options.legend) return std::move(layer.image);
  return compose(layer, map, options, s);
}

}  // namespace marsala::render
