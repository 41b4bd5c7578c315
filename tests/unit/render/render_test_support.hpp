#pragma once
// Shared by the renderer tests: pixels read back from an Image, and options for a bare terrain area.

#include <cstddef>

#include "marsala/render/image.hpp"
#include "marsala/render/terrain_renderer.hpp"

namespace marsala::render::test {

/// One pixel's channels, comparable, with the measures the tests judge colours by.
struct Pixel {
  int r, g, b;
  bool operator==(const Pixel& o) const { return r == o.r && g == o.g && b == o.b; }
  bool operator!=(const Pixel& o) const { return !(*this == o); }
  double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
  double greenness() const { return g - 0.5 * (r + b); }
};

/// Pixel (x, y) of `img` (row 0 at the top).
inline Pixel at(const Image& img, int x, int y) {
  const std::size_t i = 3u * (static_cast<std::size_t>(y) * img.width + x);
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

/// No legend: the image is exactly the terrain area, its longest side at most max_size_px.
inline RenderOptions plain(int max_size_px) {
  RenderOptions o;
  o.legend = false;
  o.max_size_px = max_size_px;
  return o;
}

}  // namespace marsala::render::test
