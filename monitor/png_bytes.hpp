#pragma once
// PNG encoding into memory, for pictures served over HTTP (render::write_png writes files).

#include <string>

#include "marsala/render/image.hpp"

namespace marsala::monitor {

/// The bytes of an 8-bit RGB PNG of `image` (zlib level 3: fast, for pictures redrawn while a run goes on).
/// Throws InvalidArgument for an empty image or a buffer that does not hold 3 * width * height bytes.
std::string encode_png(const render::Image& image);

}  // namespace marsala::monitor
