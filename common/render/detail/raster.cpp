#include "common/render/detail/raster.hpp"

#include <algorithm>
#include <cmath>

#include "common/render/detail/bitmap_font.hpp"

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
        if (rows[r] & (1u << (kGlyphWidth - 1 - c))) fill_rect(image, pen + c * scale, y + r * scale, scale, scale, colour);
    pen += kGlyphAdvance * scale;
  }
}

}  // namespace marsala::render::detail
