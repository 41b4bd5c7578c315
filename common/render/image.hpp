#pragma once
// Raster images produced by the renderers.

#include <cstdint>
#include <vector>

namespace marsala::render {

/// An 8-bit sRGB colour.
struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
  friend bool operator==(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
  friend bool operator!=(Rgb a, Rgb b) { return !(a == b); }
};

/// An 8-bit RGB raster, row-major, top row first.
struct Image {
  int width = 0;                  ///< [px]
  int height = 0;                 ///< [px]
  std::vector<std::uint8_t> rgb;  ///< 3 * width * height bytes: R, G, B of pixel (x, y) at 3 * (y * width + x)
};

}  // namespace marsala::render
