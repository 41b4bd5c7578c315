#include "common/render/terrain_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/error.hpp"
#include "common/render/detail/colormap.hpp"
#include "common/render/detail/raster.hpp"

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

std::string cell_name(int r, int c) { return "(" + std::to_string(r) + ", " + std::to_string(c) + ")"; }
std::string size_name(long long r, long long c) { return std::to_string(r) + " x " + std::to_string(c); }

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
      const double lit = (kSinAltitude - kSunEast * dzdx - kSunNorth * dzdy) / std::sqrt(1.0 + dzdx * dzdx + dzdy * dzdy);
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

void validate(const grid::Heightmap& map, const RenderOptions& o) {
  if (map.rows() <= 0 || map.cols() <= 0 || map.heights().size() != map.size())
    throw InvalidArgument("render_terrain: the heightmap is empty");
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c)
      if (!std::isfinite(map(r, c)))
        throw InvalidArgument("render_terrain: height at cell " + cell_name(r, c) + " is not finite");
  if (o.max_size_px < 1 || o.max_size_px > kMaxSizePx)
    throw InvalidArgument("render_terrain: max_size_px = " + std::to_string(o.max_size_px) + " is outside [1, " +
                          std::to_string(kMaxSizePx) + "]");
  if (o.navigable && (o.navigable->rows() != map.rows() || o.navigable->cols() != map.cols()))
    throw InvalidArgument("render_terrain: navigable mask is " + size_name(o.navigable->rows(), o.navigable->cols()) +
                          " but the heightmap is " + size_name(map.rows(), map.cols()));
  if (o.gap) {
    if (o.gap->rows() != map.rows() || o.gap->cols() != map.cols())
      throw InvalidArgument("render_terrain: gap map is " + size_name(o.gap->rows(), o.gap->cols()) +
                            " but the heightmap is " + size_name(map.rows(), map.cols()));
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (!std::isfinite((*o.gap)(r, c)))
          throw InvalidArgument("render_terrain: gap at cell " + cell_name(r, c) + " is not finite");
  }
  for (const CellIndex m : o.markers)
    if (!map.contains(m))
      throw InvalidArgument("render_terrain: marker " + cell_name(m.row, m.col) + " is off the " +
                            size_name(map.rows(), map.cols()) + " grid");
}

/// The terrain area: colours, overlays and markers, one pixel per display pixel.
struct TerrainLayer {
  Image image;
  double min_height;
  double max_height;
  double max_gap;  // 0 when there is no gap above the threshold
};

TerrainLayer draw_terrain(const grid::Heightmap& map, const RenderOptions& o, const Sampling& s) {
  TerrainLayer layer{{}, map.min_height(), map.max_height(), 0.0};
  const std::vector<double> heights = block_mean(map.heights(), s);
  const std::vector<double> light = hillshade(heights, s.rows, s.cols, map.cell_size_m() * s.factor);
  std::vector<double> navigable, gap;
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

std::string format_fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s == "-0" || s.rfind("-0.", 0) == 0) {
    if (s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // no "-0.00"
  }
  return s;
}

std::string format_length(double metres) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g m", metres);
  return buf;
}

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

Image compose(const TerrainLayer& layer, const grid::Heightmap& map, const RenderOptions& o, const Sampling& s) {
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
  char caption_buf[96];
  std::snprintf(caption_buf, sizeof caption_buf, "%d x %d cells of %g m", map.rows(), map.cols(), map.cell_size_m());
  const std::string caption = caption_buf;
  const int scale_row_w = scale_px + 6 * font + detail::text_width(scale_label, font);
  const int bottom_h = pad + line + 2 * font + line + pad;

  const int title_h = o.title.empty() ? 0 : detail::text_height(title_font) + pad;
  const int left_w = std::max({tw, scale_row_w, detail::text_width(caption, font)});
  const int width = std::max(pad + left_w + 3 * pad + panel_w + pad, pad + detail::text_width(o.title, title_font) + pad);
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
  for (const auto& k : keys) {
    if (k == "navigable") {
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

Image render_terrain(const grid::Heightmap& map, const RenderOptions& options) {
  validate(map, options);
  const Sampling s = choose_sampling(map.rows(), map.cols(), options.max_size_px);
  TerrainLayer layer = draw_terrain(map, options, s);
  if (!options.legend) return std::move(layer.image);
  return compose(layer, map, options, s);
}

}  // namespace marsala::render
