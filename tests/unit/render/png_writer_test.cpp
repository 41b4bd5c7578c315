#include "marsala/render/png_writer.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/render/terrain_renderer.hpp"

namespace marsala::render {
namespace {

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "/marsala_png_writer_" + name; }

// Decodes PNG bytes with libpng (independent of the encoder) as 8-bit RGB.
Image decode_png(const std::vector<std::uint8_t>& bytes) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
    ADD_FAILURE() << "cannot read the bytes: " << png.message;
    return {};
  }
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr)) {
    ADD_FAILURE() << "cannot decode the bytes: " << png.message;
    png_image_free(&png);
    return {};
  }
  return image;
}

std::vector<std::uint8_t> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Reads a PNG file back with libpng (independent of the writer) as 8-bit RGB.
Image read_png(const std::string& path) { return decode_png(file_bytes(path)); }

// A rendered terrain of rows x cols cells of 0.5 m, rising in steps of varied slope.
Image terrain_picture(int rows, int cols) {
  Heightmap map(GridGeometry{rows, cols, 0.0, 0.0, 0.5});
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) map(r, c) = 0.1 * r * c - 0.3 * c;
  return render_terrain(map);
}

Image pattern(int width, int height) {
  Image image{width, height, std::vector<std::uint8_t>(3u * width * height)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = 3u * (y * width + x);
      image.rgb[i] = static_cast<std::uint8_t>(40 * x + 1);
      image.rgb[i + 1] = static_cast<std::uint8_t>(90 * y + 2);
      image.rgb[i + 2] = static_cast<std::uint8_t>(7 * (x + y) + 200);
    }
  return image;
}

TEST(PngWriter, RoundTripKeepsSizeAndEveryPixel) {
  const Image image = pattern(3, 2);
  const std::string path = temp_path("pattern.png");
  write_png(image, path);
  const Image back = read_png(path);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_EQ(back.rgb, image.rgb);
  // Spot checks by hand: pixel (x = 2, y = 1) is (81, 92, 221); (0, 0) is (1, 2, 200).
  EXPECT_EQ(back.rgb[3 * (1 * 3 + 2) + 0], 81);
  EXPECT_EQ(back.rgb[3 * (1 * 3 + 2) + 1], 92);
  EXPECT_EQ(back.rgb[3 * (1 * 3 + 2) + 2], 221);
  EXPECT_EQ(back.rgb[0], 1);
  EXPECT_EQ(back.rgb[1], 2);
  EXPECT_EQ(back.rgb[2], 200);
}

TEST(PngWriter, FileStartsWithThePngSignature) {
  const std::string path = temp_path("signature.png");
  write_png(pattern(1, 1), path);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  unsigned char head[8] = {};
  EXPECT_EQ(std::fread(head, 1, 8, f), 8u);
  std::fclose(f);
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_EQ(std::memcmp(head, signature, 8), 0);
}

TEST(PngWriter, RenderedTerrainRoundTrips) {
  const Image image = terrain_picture(9, 13);
  const std::string path = temp_path("terrain.png");
  write_png(image, path);
  const Image back = read_png(path);
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.rgb, image.rgb);
}

TEST(PngWriter, OverwritesAnExistingFile) {
  const std::string path = temp_path("overwrite.png");
  write_png(pattern(4, 4), path);
  write_png(pattern(2, 5), path);
  const Image back = read_png(path);
  EXPECT_EQ(back.width, 2);
  EXPECT_EQ(back.height, 5);
}

TEST(PngWriter, UnwritablePathThrowsIoErrorNamingIt) {
  const std::string path = ::testing::TempDir() + "/no_such_directory_for_marsala/x.png";
  try {
    write_png(pattern(2, 2), path);
    FAIL() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(PngWriter, MalformedImagesAreRejected) {
  EXPECT_THROW(write_png(Image{}, temp_path("empty.png")), InvalidArgument);
  Image short_buffer = pattern(3, 3);
  short_buffer.rgb.pop_back();
  EXPECT_THROW(write_png(short_buffer, temp_path("short.png")), InvalidArgument);
  Image negative{-2, 3, {}};
  EXPECT_THROW(write_png(negative, temp_path("negative.png")), InvalidArgument);
}

TEST(PngWriter, EncodedBytesDecodeToEveryPixelAtBothSpeeds) {
  for (const Image& image : {pattern(3, 2), terrain_picture(9, 13)})
    for (const PngSpeed speed : {PngSpeed::kSmall, PngSpeed::kFast}) {
      const std::vector<std::uint8_t> bytes = encode_png(image, speed);
      const Image back = decode_png(bytes);
      EXPECT_EQ(back.width, image.width);
      EXPECT_EQ(back.height, image.height);
      EXPECT_EQ(back.rgb, image.rgb);
    }
}

TEST(PngWriter, FileHoldsTheEncodedBytesAsLibpngsFileWriterWritesThem) {
  const Image image = terrain_picture(20, 30);
  const std::string path = temp_path("same_bytes.png");
  write_png(image, path);
  // The reference: libpng's own file writer with default settings, as the pictures of a run were always written.
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  const std::string reference = temp_path("reference.png");
  ASSERT_TRUE(png_image_write_to_file(&png, reference.c_str(), 0, image.rgb.data(), 3 * image.width, nullptr));
  EXPECT_EQ(file_bytes(path), file_bytes(reference));
  EXPECT_EQ(file_bytes(path), encode_png(image));
}

TEST(PngWriter, EncodingMalformedImagesThrows) {
  EXPECT_THROW(encode_png(Image{}), InvalidArgument);
  Image short_buffer = pattern(3, 3);
  short_buffer.rgb.pop_back();
  EXPECT_THROW(encode_png(short_buffer, PngSpeed::kFast), InvalidArgument);
}

}  // namespace
}  // namespace marsala::render
