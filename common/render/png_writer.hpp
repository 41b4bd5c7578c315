#pragma once
// PNG encoding of rendered images: into memory (pictures served over HTTP) or into a file.

#include <cstdint>
#include <string>
#include <vector>

#include "marsala/render/image.hpp"

namespace marsala::render {

/// How hard zlib works on a PNG.
enum class PngSpeed {
  kSmall,  ///< libpng's default filters and zlib level: files kept after a run
  kFast,   ///< no row filters, zlib level 3: pictures redrawn while a run goes on
};

/// The bytes of an 8-bit RGB PNG of `image`. Throws InvalidArgument when the image is empty or its buffer does not
/// hold 3 * width * height bytes, IoError when libpng fails.
std::vector<std::uint8_t> encode_png(const Image& image, PngSpeed speed = PngSpeed::kSmall);

/// Writes encode_png(image) to `path`; throws IoError naming the path, InvalidArgument as encode_png (naming it too).
void write_png(const Image& image, const std::string& path);

}  // namespace marsala::render
