#pragma once
// Raster images produced by the renderers.

#include <cstdint>
#include <vector>

namespace marsala::render {

/// An 8-bit RGB raster, row-major, top row first.
struct Image {
  int width = 0;                   ///< [px]
  int height = 0;                  ///< [px]
  std::vector<std::uint8_t> rgb;   ///< 3 * width * height bytes: R, G, B of pixel (x, y) at 3 * (y * width + x)
};

}  // namespace marsala::render
