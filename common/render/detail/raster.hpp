#pragma once
// Small drawing primitives on Image: pixels, rectangles, lines, alpha blending and bitmap text.

#include <cstdint>
#include <string>

#include "marsala/render/image.hpp"

namespace marsala::render::detail {

/// An 8-bit sRGB colour (the public render::Rgb).
using Rgb = render::Rgb;

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

/// Paints every pixel whose centre (x + 0.5, y + 0.5) lies within width / 2 of the segment (x0, y0)-(x1, y1), in
/// continuous pixel coordinates (a pixel covers [x, x + 1) x [y, y + 1)); width >= 1 [px].
void draw_segment(Image& image, double x0, double y0, double x1, double y1, double width, Rgb colour);
/// Paints every pixel whose centre lies inside the triangle (a, b, c) (either orientation, edges included).
void fill_triangle(Image& image, double ax, double ay, double bx, double by, double cx, double cy, Rgb colour);
/// Paints every pixel whose centre lies within `radius` of (cx, cy) [px].
void fill_disc(Image& image, double cx, double cy, double radius, Rgb colour);
/// Paints every pixel whose centre lies within width / 2 of the circle of `radius` around (cx, cy) [px].
void draw_ring(Image& image, double cx, double cy, double radius, double width, Rgb colour);

/// Width of `text` drawn at integer `scale` [px] (no trailing spacing).
int text_width(const std::string& text, int scale);
/// Height of a text line at `scale`, descender included [px].
int text_height(int scale);
/// Draws `text` with its top-left at (x, y), each font pixel a scale x scale square.
void draw_text(Image& image, int x, int y, const std::string& text, int scale, Rgb colour);

}  // namespace marsala::render::detail
