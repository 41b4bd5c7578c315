#include "marsala/render/png_writer.hpp"

#include <png.h>

#include <cstring>

#include "marsala/core/error.hpp"

namespace marsala::render {

void write_png(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0)
    throw InvalidArgument("cannot write " + path + ": image is empty (" + std::to_string(image.width) + " x " +
                          std::to_string(image.height) + " px)");
  const std::size_t expected = 3u * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.rgb.size() != expected)
    throw InvalidArgument("cannot write " + path + ": image buffer holds " + std::to_string(image.rgb.size()) +
                          " bytes, expected " + std::to_string(expected) + " for " + std::to_string(image.width) +
                          " x " + std::to_string(image.height) + " RGB");
  // The simplified libpng API reports errors as a return value (no setjmp/longjmp across C++ frames).
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  const int ok = png_image_write_to_file(&png, path.c_str(), 0, image.rgb.data(), 3 * image.width, nullptr);
  if (!ok) {
    const std::string reason = png.message[0] != '\0' ? png.message : "unknown libpng error";
    png_image_free(&png);
    throw IoError("cannot write PNG " + path + ": " + reason);
  }
}

}  // namespace marsala::render
