#pragma once
// PNG output for rendered images.

#include <string>

#include "marsala/render/image.hpp"

namespace marsala::render {

/// Writes an 8-bit RGB PNG; throws IoError naming the path, InvalidArgument when the image is empty or its
/// buffer does not hold 3 * width * height bytes.
void write_png(const Image& image, const std::string& path);

}  // namespace marsala::render
