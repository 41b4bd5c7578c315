#include "marsala/terrain/geotiff_import.hpp"

#include <gtest/gtest.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::terrain {
namespace {

constexpr uint32_t kModelPixelScaleTag = 33550;
constexpr uint32_t kModelTransformationTag = 34264;
constexpr uint32_t kGdalNodataTag = 42113;

// How a test raster is laid out in the file.
struct TiffLayout {
  uint32_t width = 0;
  uint32_t height = 0;
  uint16_t bits = 32;
  uint16_t format = SAMPLEFORMAT_IEEEFP;
  uint16_t samples = 1;
  uint16_t photometric = PHOTOMETRIC_MINISBLACK;
  uint16_t compression = COMPRESSION_NONE;
  uint32_t rows_per_strip = 3;
  uint32_t tile = 0;  ///< tile width and length; 0 = strips
  bool big_endian = false;
  std::optional<std::vector<double>> pixel_scale;     ///< ModelPixelScaleTag (3 values)
  std::optional<std::vector<double>> transformation;  ///< ModelTransformationTag (16 values)
  std::optional<std::string> nodata;                  ///< GDAL_NODATA text
};

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "marsala_geotiff_" + name; }

// Writes `samples` (row-major, `samples_per_pixel` interleaved, already of the layout's type) with libtiff.
template <typename T>
std::string write_tiff(const std::string& name, const TiffLayout& layout, const std::vector<T>& samples) {
  EXPECT_EQ(sizeof(T) * 8, layout.bits);
  EXPECT_EQ(samples.size(), static_cast<std::size_t>(layout.width) * layout.height * layout.samples);
  const std::string path = temp_path(name);
  TIFF* tif = TIFFOpen(path.c_str(), layout.big_endian ? "wb" : "wl");
  if (!tif) {
    ADD_FAILURE() << "cannot create " << path;
    return path;
  }
  static const TIFFFieldInfo kGeoFields[] = {
      {kModelPixelScaleTag, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelPixelScaleTag")},
      {kModelTransformationTag, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelTransformationTag")},
      {kGdalNodataTag, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALNoDataValue")},
  };
  TIFFMergeFieldInfo(tif, kGeoFields, 3);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, layout.width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, layout.height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, layout.bits);
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, layout.format);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, layout.samples);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, layout.photometric);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, layout.compression);
  if (layout.compression == COMPRESSION_ADOBE_DEFLATE)
    TIFFSetField(tif, TIFFTAG_PREDICTOR,
                 layout.format == SAMPLEFORMAT_IEEEFP ? PREDICTOR_FLOATINGPOINT : PREDICTOR_HORIZONTAL);
  if (layout.pixel_scale) TIFFSetField(tif, kModelPixelScaleTag, 3, layout.pixel_scale->data());
  if (layout.transformation) TIFFSetField(tif, kModelTransformationTag, 16, layout.transformation->data());
  if (layout.nodata) TIFFSetField(tif, kGdalNodataTag, layout.nodata->c_str());
  const std::size_t pixel_bytes = sizeof(T) * layout.samples;
  if (layout.tile > 0) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, layout.tile);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, layout.tile);
    std::vector<T> tile(static_cast<std::size_t>(layout.tile) * layout.tile * layout.samples);
    for (uint32_t y = 0; y < layout.height; y += layout.tile)
      for (uint32_t x = 0; x < layout.width; x += layout.tile) {
        // Padding beyond the raster is filled with a marker the reader must never return.
        std::fill(tile.begin(), tile.end(), static_cast<T>(77));
        for (uint32_t r = 0; r < layout.tile && y + r < layout.height; ++r)
          for (uint32_t c = 0; c < layout.tile && x + c < layout.width; ++c)
            std::memcpy(&tile[(static_cast<std::size_t>(r) * layout.tile + c) * layout.samples],
                        &samples[(static_cast<std::size_t>(y + r) * layout.width + x + c) * layout.samples],
                        pixel_bytes);
        EXPECT_GE(TIFFWriteTile(tif, tile.data(), x, y, 0, 0), 0);
      }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, layout.rows_per_strip);
    for (uint32_t r = 0; r < layout.height; ++r)
      EXPECT_EQ(TIFFWriteScanline(
                    tif, const_cast<T*>(&samples[static_cast<std::size_t>(r) * layout.width * layout.samples]), r, 0),
                1);
  }
  TIFFClose(tif);
  return path;
}

// A value per cell that identifies its row and column.
double pattern(uint32_t r, uint32_t c) { return 100.0 * r + 0.5 * c - 7.0; }

template <typename T>
std::vector<T> pattern_samples(uint32_t width, uint32_t height) {
  std::vector<T> samples;
  for (uint32_t r = 0; r < height; ++r)
    for (uint32_t c = 0; c < width; ++c) samples.push_back(static_cast<T>(pattern(r, c)));
  return samples;
}

template <typename T>
void expect_pattern(const Heightmap& map, uint32_t width, uint32_t height) {
  ASSERT_EQ(map.cols(), static_cast<int>(width));
  ASSERT_EQ(map.rows(), static_cast<int>(height));
  for (uint32_t r = 0; r < height; ++r)
    for (uint32_t c = 0; c < width; ++c)
      ASSERT_EQ(map(r, c), static_cast<double>(static_cast<T>(pattern(r, c)))) << "(" << r << ", " << c << ")";
}

// Reads `path` expecting a ParseError whose message names the file and contains `problem`.
void expect_parse_error(const std::string& path, const std::string& problem, GeoTiffOptions options = {}) {
  try {
    read_geotiff(path, options);
    ADD_FAILURE() << "no ParseError for " << path;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << "message: " << e.what();
  }
}

std::string shared_terrain(const std::string& name) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  if (!root) return {};
  const std::string path = std::string(root) + "/../shared/data/terrains/" + name;
  return std::filesystem::exists(path) ? path : std::string();
}

TEST(GeoTiff, Float32StripsWithPixelScale) {
  TiffLayout layout;
  layout.width = 7;
  layout.height = 5;
  layout.rows_per_strip = 2;  // the last strip holds a single row
  layout.pixel_scale = std::vector<double>{0.5, 0.5, 0.0};
  const std::string path = write_tiff("f32_strips.tif", layout, pattern_samples<float>(7, 5));
  const Heightmap map = read_geotiff(path);
  expect_pattern<float>(map, 7, 5);
  EXPECT_EQ(map.cell_size_m(), 0.5);
  EXPECT_EQ(map.geometry().xll_m, 0.0);
  EXPECT_EQ(map.geometry().yll_m, 0.0);
  // The first TIFF row is the northmost: its centre is half a cell below the top edge 5 * 0.5 m.
  EXPECT_DOUBLE_EQ(map.cell_center({0, 0}).y, 2.25);
  std::filesystem::remove(path);
}

TEST(GeoTiff, Int16TilesWithPaddedEdgeTiles) {
  TiffLayout layout;
  layout.width = 37;  // 3 x 2 tiles of 16, the right and bottom ones padded
  layout.height = 21;
  layout.bits = 16;
  layout.format = SAMPLEFORMAT_INT;
  layout.tile = 16;
  layout.pixel_scale = std::vector<double>{2.0, 2.0, 0.0};
  std::vector<int16_t> samples;
  for (uint32_t r = 0; r < 21; ++r)
    for (uint32_t c = 0; c < 37; ++c) samples.push_back(static_cast<int16_t>(-1000 + 50 * r + c));
  const std::string path = write_tiff("i16_tiles.tif", layout, samples);
  const Heightmap map = read_geotiff(path);
  ASSERT_EQ(map.rows(), 21);
  ASSERT_EQ(map.cols(), 37);
  EXPECT_EQ(map.cell_size_m(), 2.0);
  for (int r = 0; r < 21; ++r)
    for (int c = 0; c < 37; ++c) ASSERT_EQ(map(r, c), -1000.0 + 50 * r + c) << r << ", " << c;
  std::filesystem::remove(path);
}

TEST(GeoTiff, Float64BigEndianWithoutScaleIsOneMetre) {
  TiffLayout layout;
  layout.width = 4;
  layout.height = 3;
  layout.bits = 64;
  layout.big_endian = true;
  std::vector<double> samples = pattern_samples<double>(4, 3);
  samples[5] = 0.1;  // a double that float32 could not hold
  const std::string path = write_tiff("f64_be.tif", layout, samples);
  const Heightmap map = read_geotiff(path);
  EXPECT_EQ(map.cell_size_m(), 1.0);
  EXPECT_EQ(map(1, 1), 0.1);
  EXPECT_EQ(map(2, 3), pattern(2, 3));
  std::filesystem::remove(path);
}

TEST(GeoTiff, UInt16AndInt32) {
  TiffLayout u16;
  u16.width = 3;
  u16.height = 2;
  u16.bits = 16;
  u16.format = SAMPLEFORMAT_UINT;
  const std::string path16 = write_tiff("u16.tif", u16, std::vector<uint16_t>{0, 1, 2, 65535, 40000, 7});
  const Heightmap m16 = read_geotiff(path16);
  EXPECT_EQ(m16(1, 0), 65535.0);
  EXPECT_EQ(m16(1, 1), 40000.0);
  TiffLayout i32 = u16;
  i32.bits = 32;
  i32.format = SAMPLEFORMAT_INT;
  i32.tile = 16;
  const std::string path32 = write_tiff("i32.tif", i32, std::vector<int32_t>{-2000000000, 1, 2, 3, 4, 2000000000});
  const Heightmap m32 = read_geotiff(path32);
  EXPECT_EQ(m32(0, 0), -2000000000.0);
  EXPECT_EQ(m32(1, 2), 2000000000.0);
  std::filesystem::remove(path16);
  std::filesystem::remove(path32);
}

TEST(GeoTiff, DeflateWithPredictor) {
  if (!TIFFIsCODECConfigured(COMPRESSION_ADOBE_DEFLATE)) GTEST_SKIP() << "this libtiff has no deflate codec";
  TiffLayout layout;
  layout.width = 40;
  layout.height = 9;
  layout.compression = COMPRESSION_ADOBE_DEFLATE;
  layout.rows_per_strip = 4;
  const std::string path = write_tiff("deflate.tif", layout, pattern_samples<float>(40, 9));
  expect_pattern<float>(read_geotiff(path), 40, 9);
  std::filesystem::remove(path);
}

TEST(GeoTiff, TransformationMatrixGivesTheCellSize) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  layout.transformation = std::vector<double>{0.25, 0, 0, 500, 0, -0.25, 0, 900, 0, 0, 0, 0, 0, 0, 0, 1};
  const std::string path = write_tiff("matrix.tif", layout, std::vector<float>{1, 2, 3, 4});
  EXPECT_EQ(read_geotiff(path).cell_size_m(), 0.25);
  std::filesystem::remove(path);

  layout.transformation = std::vector<double>{0.25, 0.1, 0, 500, 0.1, -0.25, 0, 900, 0, 0, 0, 0, 0, 0, 0, 1};
  const std::string rotated = write_tiff("rotated.tif", layout, std::vector<float>{1, 2, 3, 4});
  expect_parse_error(rotated, "rotated");
  std::filesystem::remove(rotated);
}

TEST(GeoTiff, NodataIsAnErrorUnlessFilled) {
  TiffLayout layout;
  layout.width = 3;
  layout.height = 3;
  layout.nodata = "-32767";
  std::vector<float> samples{1, 2, 3, 4, -32767, 6, 7, 8, 9};
  const std::string path = write_tiff("nodata.tif", layout, samples);
  expect_parse_error(path, "NODATA cell at row 1, column 1");
  expect_parse_error(path, "--fill-nodata");
  const Heightmap filled = read_geotiff(path, {true});
  EXPECT_EQ(filled(1, 1), 5.0);  // mean of 1, 2, 3, 4, 6, 7, 8, 9
  EXPECT_EQ(filled(0, 0), 1.0);
  std::filesystem::remove(path);

  // Without the tag, -32767 is a height.
  layout.nodata.reset();
  const std::string plain = write_tiff("no_nodata_tag.tif", layout, samples);
  EXPECT_EQ(read_geotiff(plain)(1, 1), -32767.0);
  std::filesystem::remove(plain);
}

TEST(GeoTiff, Float32NodataComparesInFloat) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 1;
  // -9999.9 has no exact float: the file stores the float nearest to it, which differs from the double.
  layout.nodata = "-9999.9";
  ASSERT_NE(static_cast<double>(-9999.9f), -9999.9);
  const std::string path = write_tiff("nodata_float.tif", layout, std::vector<float>{-9999.9f, 2.5f});
  expect_parse_error(path, "NODATA cell at row 0, column 0");
  const Heightmap map = read_geotiff(path, {true});
  EXPECT_EQ(map(0, 0), 2.5);
  std::filesystem::remove(path);
}

TEST(GeoTiff, NanCellsAreNodataAndInfinityIsAnError) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  const std::string path =
      write_tiff("nan.tif", layout, std::vector<float>{1, std::numeric_limits<float>::quiet_NaN(), 3, 5});
  expect_parse_error(path, "NODATA cell at row 0, column 1");
  EXPECT_EQ(read_geotiff(path, {true})(0, 1), 3.0);  // mean of 1, 3, 5
  const std::string all_nan = write_tiff("all_nan.tif", layout, std::vector<float>(4, std::nanf("")));
  expect_parse_error(all_nan, "every cell is NODATA", {true});
  const std::string inf =
      write_tiff("inf.tif", layout, std::vector<float>{1, 2, std::numeric_limits<float>::infinity(), 4});
  expect_parse_error(inf, "infinite sample at row 1, column 0", {true});
  for (const auto& p : {path, all_nan, inf}) std::filesystem::remove(p);
}

TEST(GeoTiffErrors, SeveralBands) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  layout.samples = 2;
  const std::string path = write_tiff("two_bands.tif", layout, std::vector<float>(8, 1.0f));
  expect_parse_error(path, "2 bands");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, EightBitRgb) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  layout.samples = 3;
  layout.bits = 8;
  layout.format = SAMPLEFORMAT_UINT;
  layout.photometric = PHOTOMETRIC_RGB;
  const std::string path = write_tiff("rgb.tif", layout, std::vector<uint8_t>(12, 200));
  expect_parse_error(path, "3 bands");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, UnsupportedSampleFormat) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  layout.bits = 8;
  layout.format = SAMPLEFORMAT_UINT;
  const std::string path = write_tiff("gray8.tif", layout, std::vector<uint8_t>(4, 9));
  expect_parse_error(path, "unsupported sample format: 8-bit unsigned integer");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, NonSquarePixels) {
  TiffLayout layout;
  layout.width = 2;
  layout.height = 2;
  layout.pixel_scale = std::vector<double>{1.0, 2.0, 0.0};
  const std::string path = write_tiff("non_square.tif", layout, std::vector<float>(4, 1.0f));
  expect_parse_error(path, "not square");
  layout.pixel_scale = std::vector<double>{-1.0, -1.0, 0.0};
  const std::string negative = write_tiff("negative_scale.tif", layout, std::vector<float>(4, 1.0f));
  expect_parse_error(negative, "pixel size must be positive");
  std::filesystem::remove(path);
  std::filesystem::remove(negative);
}

TEST(GeoTiffErrors, BadNodataText) {
  TiffLayout layout;
  layout.width = 1;
  layout.height = 1;
  layout.nodata = "none";
  const std::string path = write_tiff("bad_nodata.tif", layout, std::vector<float>{1.0f});
  expect_parse_error(path, "GDAL_NODATA tag is not a number: 'none'");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, NotATiff) {
  const std::string path = temp_path("not_a_tiff.tif");
  {
    std::ofstream out(path, std::ios::binary);
    out << "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5\n";
  }
  expect_parse_error(path, "not a readable TIFF file");
  std::filesystem::remove(path);
}

// A little-endian float32 4 x 4 TIFF written byte by byte: one strip of 64 bytes right after the
// directory, of which only `data_bytes` are present (a truncated download). `side`: the width and length the
// directory claims (a damaged header when not 4).
std::string write_truncated_tiff(const std::string& name, std::size_t data_bytes, uint32_t side = 4) {
  std::string bytes = std::string("II*\0", 4);
  auto put16 = [&](uint16_t v) { bytes += static_cast<char>(v & 0xff), bytes += static_cast<char>(v >> 8); };
  auto put32 = [&](uint32_t v) { put16(static_cast<uint16_t>(v & 0xffff)), put16(static_cast<uint16_t>(v >> 16)); };
  put32(8);  // first directory right after the header
  const uint16_t kShort = 3, kLong = 4;
  const uint32_t entries = 10;
  const uint32_t data_offset = 8 + 2 + entries * 12 + 4;
  struct Entry {
    uint16_t tag, type;
    uint32_t value;
  };
  const Entry directory[] = {{256, kLong, side}, {257, kLong, side},
                             {258, kShort, 32},  {259, kShort, 1},
                             {262, kShort, 1},   {273, kLong, data_offset},
                             {277, kShort, 1},   {278, kLong, side},
                             {279, kLong, 64},   {339, kShort, SAMPLEFORMAT_IEEEFP}};
  put16(static_cast<uint16_t>(entries));
  for (const Entry& e : directory) {
    put16(e.tag);
    put16(e.type);
    put32(1);
    if (e.type == kShort) {
      put16(static_cast<uint16_t>(e.value));
      put16(0);
    } else {
      put32(e.value);
    }
  }
  put32(0);  // no further directory
  EXPECT_EQ(bytes.size(), data_offset);
  for (std::size_t i = 0; i < data_bytes; ++i) bytes += '\0';
  const std::string path = temp_path(name);
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

TEST(GeoTiffErrors, TruncatedPixelData) {
  // The hand-made file is valid when complete, so the failures below are the truncation's.
  const std::string complete = write_truncated_tiff("complete.tif", 64);
  const Heightmap map = read_geotiff(complete);
  EXPECT_EQ(map.rows(), 4);
  EXPECT_EQ(map(3, 3), 0.0);
  const std::string truncated = write_truncated_tiff("truncated.tif", 20);
  expect_parse_error(truncated, "cannot decode strip 0");
  const std::string no_data = write_truncated_tiff("no_data.tif", 0);
  expect_parse_error(no_data, "cannot decode strip 0");
  for (const auto& p : {complete, truncated, no_data}) std::filesystem::remove(p);
}

TEST(GeoTiffErrors, AHeaderClaimingMoreThanTheFileHoldsIsRefusedBeforeAllocating) {
  // Found while writing tests/fuzz/geotiff_fuzz_test.cpp: a 198-byte file claiming 20000 x 20000 float32 samples made
  // the importer allocate (and zero) a 3.2 GB raster before finding the data missing; 40000 x 40000 threw
  // std::bad_alloc.
  const std::string path = write_truncated_tiff("claims_too_much.tif", 64, 20000);
  expect_parse_error(path, "declares 20000 x 20000 uncompressed samples (1600000000 bytes) in a file of 198 bytes");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, TruncatedBeforeTheDirectory) {
  TiffLayout layout;
  layout.width = 64;
  layout.height = 64;
  layout.rows_per_strip = 64;
  const std::string path = write_tiff("cut.tif", layout, pattern_samples<float>(64, 64));
  // libtiff writes the directory after the pixels: keep the header and some pixels only.
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 64u * 64u * 4u);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), 8 + 1000);
  }
  expect_parse_error(path, "not a readable TIFF file");
  std::filesystem::remove(path);
}

TEST(GeoTiffErrors, MissingFileIsAnIoError) {
  EXPECT_THROW(read_geotiff(temp_path("missing.tif")), IoError);
  EXPECT_THROW(read_geotiff(::testing::TempDir()), IoError);
}

TEST(GeoTiffGale, MatchesTheAscToItsThreeDecimals) {
  const std::string tif = shared_terrain("gale_crater_1m_original.tif");
  const std::string asc = shared_terrain("gale_crater_1m.asc");
  if (tif.empty() || asc.empty())
    GTEST_SKIP() << "Gale crater files not found under $MARSALA_SOURCE_DIR/../shared/data/terrains";
  const Heightmap original = read_geotiff(tif);
  const Heightmap local = read_asc(asc);
  ASSERT_EQ(original.rows(), 337);
  ASSERT_EQ(original.cols(), 348);
  EXPECT_EQ(original.geometry(), local.geometry());
  // PROVENANCE.md: elevation -4472.67 .. -4437.88 m.
  EXPECT_NEAR(original.min_height(), -4472.67, 0.005);
  EXPECT_NEAR(original.max_height(), -4437.88, 0.005);
  const double lowest = original.min_height();
  double worst = 0.0;
  for (int r = 0; r < original.rows(); ++r)
    for (int c = 0; c < original.cols(); ++c) worst = std::max(worst, std::abs(original(r, c) - lowest - local(r, c)));
  // Rounding to 3 decimals errs by at most 0.0005 m; ties such as 32.3125 -> "32.312" reach it exactly,
  // and 32.312 is itself a rounded double, hence the 1e-9 m.
  EXPECT_LE(worst, 0.0005 + 1e-9);
  EXPECT_GT(worst, 0.0);  // the comparison does look at the data
}

}  // namespace
}  // namespace marsala::terrain
