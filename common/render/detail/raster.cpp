#include "marsala/render/detail/raster.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/render/detail/bitmap_font.hpp"

namespace marsala::render::detail {
namespace {

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

}  // namespace

Rgb to_rgb(Colour c) { return {to_byte(c.r), to_byte(c.g), to_byte(c.b)}; }

Colour to_colour(Rgb c) { return {double(c.r), double(c.g), double(c.b)}; }

Colour mix(Colour a, Colour b, double alpha) {
  return {a.r + alpha * (b.r - a.r), a.g + alpha * (b.g - a.g), a.b + alpha * (b.b - a.b)};
}

Image make_image(int width, int height, Rgb fill) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(3u * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
    image.rgb[i] = fill.r;
    image.rgb[i + 1] = fill.g;
    image.rgb[i + 2] = fill.b;
  }
  return image;
}

Rgb get_pixel(const Image& image, int x, int y) {
  const std::size_t i = 3u * (static_cast<std::size_t>(y) * image.width + x);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

void set_pixel(Image& image, int x, int y, Rgb colour) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
  const std::size_t i = 3u * (static_cast<std::size_t>(y) * image.width + x);
  image.rgb[i] = colour.r;
  image.rgb[i + 1] = colour.g;
  image.rgb[i + 2] = colour.b;
}

void fill_rect(Image& image, int x, int y, int w, int h, Rgb colour) {
  const int x0 = std::max(x, 0), x1 = std::min(x + w, image.width);
  const int y0 = std::max(y, 0), y1 = std::min(y + h, image.height);
  for (int yy = y0; yy < y1; ++yy)
    for (int xx = x0; xx < x1; ++xx) set_pixel(image, xx, yy, colour);
}

void draw_rect_outline(Image& image, int x, int y, int w, int h, Rgb colour) {
  fill_rect(image, x, y, w, 1, colour);
  fill_rect(image, x, y + h - 1, w, 1, colour);
  fill_rect(image, x, y, 1, h, colour);
  fill_rect(image, x + w - 1, y, 1, h, colour);
}

void blit(Image& dst, const Image& src, int x, int y) {
  for (int yy = 0; yy < src.height; ++yy)
    for (int xx = 0; xx < src.width; ++xx) set_pixel(dst, x + xx, y + yy, get_pixel(src, xx, yy));
}

void draw_segment(Image& image, double x0, double y0, double x1, double y1, double width, Rgb colour) {
  const double half = 0.5 * std::max(1.0, width);
  const double dx = x1 - x0, dy = y1 - y0, length2 = dx * dx + dy * dy;
  const int xa = std::max(0, static_cast<int>(std::floor(std::min(x0, x1) - half)));
  const int xb = std::min(image.width - 1, static_cast<int>(std::ceil(std::max(x0, x1) + half)));
  const int ya = std::max(0, static_cast<int>(std::floor(std::min(y0, y1) - half)));
  const int yb = std::min(image.height - 1, static_cast<int>(std::ceil(std::max(y0, y1) + half)));
  for (int y = ya; y <= yb; ++y)
    for (int x = xa; x <= xb; ++x) {
      const double px = x + 0.5 - x0, py = y + 0.5 - y0;
      const double t = length2 > 0.0 ? std::clamp((px * dx + py * dy) / length2, 0.0, 1.0) : 0.0;
      const double ex = px - t * dx, ey = py - t * dy;
      if (ex * ex + ey * ey <= half * half) set_pixel(image, x, y, colour);
    }
}

void fill_triangle(Image& image, double ax, double ay, double bx, double by, double cx, double cy, Rgb colour) {
  const auto side = [](double ux, double uy, double vx, double vy, double px, double py) {
    return (vx - ux) * (py - uy) - (vy - uy) * (px - ux);
  };
  const int xa = std::max(0, static_cast<int>(std::floor(std::min({ax, bx, cx}))));
  const int xb = std::min(image.width - 1, static_cast<int>(std::ceil(std::max({ax, bx, cx}))));
  const int ya = std::max(0, static_cast<int>(std::floor(std::min({ay, by, cy}))));
  const int yb = std::min(image.height - 1, static_cast<int>(std::ceil(std::max({ay, by, cy}))));
  for (int y = ya; y <= yb; ++y)
    for (int x = xa; x <= xb; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const double s1 = side(ax, ay, bx, by, px, py), s2 = side(bx, by, cx, cy, px, py),
                   s3 = side(cx, cy, ax, ay, px, py);
      if ((s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0))
        set_pixel(image, x, y, colour);
    }
}

void fill_disc(Image& image, double cx, double cy, double radius, Rgb colour) {
  draw_ring(image, cx, cy, 0.5 * radius, radius, colour);
}

void draw_ring(Image& image, double cx, double cy, double radius, double width, Rgb colour) {
  const double half = 0.5 * width, outer = radius + half, inner = std::max(0.0, radius - half);
  const int xa = std::max(0, static_cast<int>(std::floor(cx - outer)));
  const int xb = std::min(image.width - 1, static_cast<int>(std::ceil(cx + outer)));
  const int ya = std::max(0, static_cast<int>(std::floor(cy - outer)));
  const int yb = std::min(image.height - 1, static_cast<int>(std::ceil(cy + outer)));
  for (int y = ya; y <= yb; ++y)
    for (int x = xa; x <= xb; ++x) {
      const double px = x + 0.5 - cx, py = y + 0.5 - cy, d2 = px * px + py * py;
      if (d2 <= outer * outer && d2 >= inner * inner) set_pixel(image, x, y, colour);
    }
}

int text_width(const std::string& text, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * kGlyphAdvance - 1) * scale;
}

int text_height(int scale) { return kGlyphHeight * scale; }

void draw_text(Image& image, int x, int y, const std::string& text, int scale, Rgb colour) {
  int pen = x;
  for (char ch : text) {
    const auto rows = glyph_rows(ch);
    for (int r = 0; r < kGlyphHeight; ++r)
      for (int c = 0; c < kGlyphWidth; ++c)
        if (rows[r] & (1u << (kGlyphWidth - 1 - c)))
          fill_rect(image, pen + c * scale, y + r * scale, scale, scale, colour);
    pen += kGlyphAdvance * scale;
  }
}

}  // namespace marsala::render::detail
