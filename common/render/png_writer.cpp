#include "marsala/render/png_writer.hpp"

#include <fmt/format.h>
#include <png.h>

#include <cstring>
#include <fstream>

#include "marsala/core/error.hpp"

namespace marsala::render {
namespace {

/// Why `image` cannot be encoded, or empty when it can.
std::string malformed(const Image& image) {
  if (image.width <= 0 || image.height <= 0)
    return fmt::format("image is empty ({} x {} px)", image.width, image.height);
  const std::size_t expected = 3u * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.rgb.size() != expected)
    return fmt::format("image buffer holds {} bytes, expected {} for {} x {} RGB", image.rgb.size(), expected,
                       image.width, image.height);
  return {};
}

std::vector<std::uint8_t> encode(const Image& image, PngSpeed speed) {
  // The simplified libpng API reports errors as a return value (no setjmp/longjmp across C++ frames).
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  if (speed == PngSpeed::kFast) png.flags |= PNG_IMAGE_FLAG_FAST;
  const png_int_32 stride = 3 * image.width;
  // A buffer of the largest size the image can take, written once, then cut to what was written.
  std::vector<std::uint8_t> bytes(PNG_IMAGE_PNG_SIZE_MAX(png));
  png_alloc_size_t size = bytes.size();
  const bool ok = png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), stride, nullptr) != 0;
  bytes.resize(ok ? size : 0);
  if (!ok) {
    const std::string reason = png.message[0] != '\0' ? png.message : "unknown libpng error";
    png_image_free(&png);
    throw IoError(reason);
  }
  return bytes;
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image, PngSpeed speed) {
  if (const std::string why = malformed(image); !why.empty()) throw InvalidArgument(fmt::format("encode_png: {}", why));
  try {
    return encode(image, speed);
  } catch (const IoError& e) {
    throw IoError(fmt::format("encode_png: {}", e.what()));
  }
}

void write_png(const Image& image, const std::string& path) {
  if (const std::string why = malformed(image); !why.empty())
    throw InvalidArgument(fmt::format("cannot write {}: {}", path, why));
  std::vector<std::uint8_t> bytes;
  try {
    bytes = encode(image, PngSpeed::kSmall);
  } catch (const IoError& e) {
    throw IoError(fmt::format("cannot write PNG {}: {}", path, e.what()));
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw IoError(fmt::format("cannot write PNG {}: cannot open or write the file", path));
}

}  // namespace marsala::render
