#pragma once
// Small drawing primitives on Image: pixels, rectangles, lines, alpha blending and bitmap text.

#include <cstdint>
#include <string>

#include "common/render/image.hpp"

namespace marsala::render::detail {

/// An 8-bit sRGB colour.
struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
  friend bool operator==(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
};

/// A colour with double channels on the 0..255 scale, for blending before rounding.
struct Colour {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
};

/// Rounds and clamps to 8 bits.
Rgb to_rgb(Colour c);
/// Widens to doubles.
Colour to_colour(Rgb c);
/// (1 - alpha) * a + alpha * b, alpha in [0, 1].
Colour mix(Colour a, Colour b, double alpha);

/// A width x height image filled with one colour [px].
Image make_image(int width, int height, Rgb fill);
/// Pixel (x, y) [px]; unchecked.
Rgb get_pixel(const Image& image, int x, int y);
/// Sets pixel (x, y) when it lies on the image.
void set_pixel(Image& image, int x, int y, Rgb colour);
/// Fills the rectangle with top-left (x, y) and size w x h [px], clipped to the image.
void fill_rect(Image& image, int x, int y, int w, int h, Rgb colour);
/// One-pixel outline of the rectangle with top-left (x, y) and size w x h [px].
void draw_rect_outline(Image& image, int x, int y, int w, int h, Rgb colour);
/// Copies `src` into `dst` with its top-left at (x, y) [px], clipped.
void blit(Image& dst, const Image& src, int x, int y);

/// Width of `text` drawn at integer `scale` [px] (no trailing spacing).
int text_width(const std::string& text, int scale);
/// Height of a text line at `scale`, descender included [px].
int text_height(int scale);
/// Draws `text` with its top-left at (x, y), each font pixel a scale x scale square.
void draw_text(Image& image, int x, int y, const std::string& text, int scale, Rgb colour);

}  // namespace marsala::render::detail
