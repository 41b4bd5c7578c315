// Fuzzes the GeoTIFF importer (common/terrain/geotiff_import.hpp) with seeded byte mutations of small TIFFs written by
// libtiff here (strips and tiles, five sample formats, compression, geo and NODATA tags): every file loads or throws
// the project's error family naming the file; a loaded grid has the raster's declared size, a positive finite cell
// size, the local frame at (0, 0) and finite heights within its sample type's range.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <tiffio.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <typeinfo>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "marsala/core/error.hpp"
#include "marsala/terrain/geotiff_import.hpp"

namespace marsala::terrain {
namespace {

constexpr uint32_t kModelPixelScaleTag = 33550;
constexpr uint32_t kModelTransformationTag = 34264;
constexpr uint32_t kGdalNodataTag = 42113;

/// A seed raster: its layout in the file and its samples.
struct SeedTiff {
  uint32_t width = 5;
  uint32_t height = 4;
  uint16_t bits = 32;
  uint16_t format = SAMPLEFORMAT_IEEEFP;
  uint16_t compression = COMPRESSION_NONE;
  uint32_t rows_per_strip = 2;
  uint32_t tile = 0;  ///< tile width and length; 0 = strips
  bool big_endian = false;
  std::vector<double> pixel_scale;     ///< ModelPixelScaleTag when not empty
  std::vector<double> transformation;  ///< ModelTransformationTag when not empty
  std::string nodata;                  ///< GDAL_NODATA when not empty
};

template <typename T>
void put_sample(std::vector<unsigned char>& bytes, double value) {
  const T v = static_cast<T>(value);
  const auto* p = reinterpret_cast<const unsigned char*>(&v);
  bytes.insert(bytes.end(), p, p + sizeof v);
}

std::vector<unsigned char> samples_of(const SeedTiff& seed, uint32_t rows, uint32_t cols, uint32_t row0,
                                      uint32_t col0) {
  std::vector<unsigned char> bytes;
  for (uint32_t r = 0; r < rows; ++r)
    for (uint32_t c = 0; c < cols; ++c) {
      double v = 10.0 * (row0 + r) - 3.0 * (col0 + c) + 7.0;
      if (!seed.nodata.empty() && r == 1 && c == 1) v = std::strtod(seed.nodata.c_str(), nullptr);
      if (seed.format == SAMPLEFORMAT_IEEEFP && seed.bits == 32) put_sample<float>(bytes, v + 0.25);
      if (seed.format == SAMPLEFORMAT_IEEEFP && seed.bits == 64) put_sample<double>(bytes, v + 0.125);
      if (seed.format == SAMPLEFORMAT_INT && seed.bits == 16) put_sample<int16_t>(bytes, v);
      if (seed.format == SAMPLEFORMAT_UINT && seed.bits == 16) put_sample<uint16_t>(bytes, v + 100);
      if (seed.format == SAMPLEFORMAT_INT && seed.bits == 32) put_sample<int32_t>(bytes, v * 1000);
    }
  return bytes;
}

/// The seed written by libtiff, as bytes.
std::string write_seed(const SeedTiff& seed, const std::string& path) {
  TIFF* tif = TIFFOpen(path.c_str(), seed.big_endian ? "wb" : "wl");
  if (!tif) {
    ADD_FAILURE() << "cannot create " << path;
    return {};
  }
  static const TIFFFieldInfo kGeoFields[] = {
      {kModelPixelScaleTag, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelPixelScaleTag")},
      {kModelTransformationTag, -1, -1, TIFF_DOUBLE, FIELD_CUSTOM, 1, 1, const_cast<char*>("ModelTransformationTag")},
      {kGdalNodataTag, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALNoDataValue")},
  };
  TIFFMergeFieldInfo(tif, kGeoFields, 3);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, seed.width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, seed.height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, seed.bits);
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, seed.format);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, seed.compression);
  if (seed.compression == COMPRESSION_ADOBE_DEFLATE || seed.compression == COMPRESSION_LZW)
    TIFFSetField(tif, TIFFTAG_PREDICTOR,
                 seed.format == SAMPLEFORMAT_IEEEFP ? PREDICTOR_FLOATINGPOINT : PREDICTOR_HORIZONTAL);
  if (!seed.pixel_scale.empty()) TIFFSetField(tif, kModelPixelScaleTag, 3, seed.pixel_scale.data());
  if (!seed.transformation.empty()) TIFFSetField(tif, kModelTransformationTag, 16, seed.transformation.data());
  if (!seed.nodata.empty()) TIFFSetField(tif, kGdalNodataTag, seed.nodata.c_str());
  if (seed.tile > 0) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, seed.tile);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, seed.tile);
    for (uint32_t y = 0; y < seed.height; y += seed.tile)
      for (uint32_t x = 0; x < seed.width; x += seed.tile) {
        std::vector<unsigned char> tile = samples_of(seed, seed.tile, seed.tile, y, x);
        EXPECT_GE(TIFFWriteTile(tif, tile.data(), x, y, 0, 0), 0);
      }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, seed.rows_per_strip);
    for (uint32_t r = 0; r < seed.height; ++r) {
      std::vector<unsigned char> row = samples_of(seed, 1, seed.width, r, 0);
      EXPECT_EQ(TIFFWriteScanline(tif, row.data(), r, 0), 1);
    }
  }
  TIFFClose(tif);
  return fuzz::read_file(path);
}

std::vector<std::string> seeds(const std::string& path) {
  std::vector<SeedTiff> layouts(8);
  layouts[0].pixel_scale = {0.5, 0.5, 0.0};
  layouts[1].bits = 64;
  layouts[1].nodata = "-9999";
  layouts[1].big_endian = true;
  layouts[1].pixel_scale = {2.0, 2.0, 0.0};
  layouts[2].format = SAMPLEFORMAT_INT;
  layouts[2].bits = 16;
  layouts[2].tile = 16;
  layouts[2].width = 20;
  layouts[2].height = 17;
  layouts[3].format = SAMPLEFORMAT_UINT;
  layouts[3].bits = 16;
  layouts[3].compression = COMPRESSION_ADOBE_DEFLATE;
  layouts[3].transformation = {0.25, 0, 0, 100, 0, -0.25, 0, 200, 0, 0, 0, 0, 0, 0, 0, 1};
  layouts[4].format = SAMPLEFORMAT_INT;
  layouts[4].bits = 32;
  layouts[4].compression = COMPRESSION_LZW;
  layouts[4].nodata = "-3";
  layouts[5].compression = COMPRESSION_PACKBITS;
  layouts[5].rows_per_strip = 1;
  layouts[5].nodata = "nan";
  layouts[6].width = 1;
  layouts[6].height = 1;
  layouts[6].rows_per_strip = 1;
  layouts[7].bits = 64;
  layouts[7].tile = 16;
  layouts[7].width = 16;
  layouts[7].height = 16;
  layouts[7].compression = COMPRESSION_ADOBE_DEFLATE;
  layouts[7].pixel_scale = {1e-3, 1e-3, 0.0};
  std::vector<std::string> out;
  for (const SeedTiff& layout : layouts)
    if (TIFFIsCODECConfigured(layout.compression)) out.push_back(write_seed(layout, path));
  const std::filesystem::path corpus = std::filesystem::path(fuzz::source_dir()) / "tests/fuzz/corpus/geotiff";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(corpus, ec))
    out.push_back(fuzz::read_file(entry.path()));
  return out;
}

/// A mutation that knows the TIFF layout: one field (value, count or type) of one entry of the first directory set
/// to a value that breaks careless readers (sizes, offsets, counts near the limits). Byte mutations rarely hit them.
void mutate_directory_entry(std::string& tiff, fuzz::Mutator& mutator) {
  if (tiff.size() < 8 || (tiff.compare(0, 2, "II") != 0 && tiff.compare(0, 2, "MM") != 0)) return;
  const bool big = tiff[0] == 'M';
  const auto get = [&](std::size_t at, int bytes) {
    uint32_t v = 0;
    for (int i = 0; i < bytes; ++i) {
      const uint32_t byte = static_cast<unsigned char>(tiff[at + i]);
      v |= byte << (8 * (big ? bytes - 1 - i : i));
    }
    return v;
  };
  const auto put = [&](std::size_t at, int bytes, uint32_t v) {
    for (int i = 0; i < bytes && at + i < tiff.size(); ++i)
      tiff[at + i] = static_cast<char>((v >> (8 * (big ? bytes - 1 - i : i))) & 0xff);
  };
  const std::size_t directory = get(4, 4);
  if (directory + 2 > tiff.size()) return;
  const std::size_t entries = get(directory, 2);
  if (entries == 0) return;
  const std::size_t entry = directory + 2 + 12 * mutator.below(entries);
  if (entry + 12 > tiff.size()) return;
  static const std::vector<uint32_t> kValues = {0,     1,     2,          3,          8,          16,
                                                20000, 40000, 0x7fff,     0x8000,     0xffff,     0x10000,
                                                46340, 65537, 0x7fffffff, 0x80000000, 0xffffffff, 0x40000000};
  const uint32_t value =
      mutator.chance(0.2) ? static_cast<uint32_t>(tiff.size() + mutator.below(64)) : mutator.pick(kValues);
  switch (mutator.below(4)) {
    case 0: put(entry + 4, 4, value); break;                         // count
    case 1: put(entry + 2, 2, 1 + mutator.below(18)); break;         // type
    default: put(entry + 8, get(entry + 2, 2) == 3 ? 2 : 4, value);  // value or offset (SHORT values are 2 bytes)
  }
}

/// What libtiff itself says the raster is: width, length, sample format and bits.
struct Declared {
  uint32_t width = 0, height = 0;
  uint16_t format = SAMPLEFORMAT_UINT, bits = 0;
};

std::optional<Declared> declared(const std::string& path) {
  TIFF* tif = TIFFOpen(path.c_str(), "r");
  if (!tif) return std::nullopt;
  Declared d;
  TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &d.width);
  TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &d.height);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &d.format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &d.bits);
  TIFFClose(tif);
  return d;
}

/// The range of a sample type [m]: a loaded height never leaves it (filled NODATA cells are means, so they stay too).
std::pair<double, double> sample_range(const Declared& d) {
  if (d.format == SAMPLEFORMAT_INT && d.bits == 16) return {-32768.0, 32767.0};
  if (d.format == SAMPLEFORMAT_UINT && d.bits == 16) return {0.0, 65535.0};
  if (d.format == SAMPLEFORMAT_INT && d.bits == 32) return {-2147483648.0, 2147483647.0};
  if (d.format == SAMPLEFORMAT_IEEEFP && d.bits == 32)
    return {std::numeric_limits<float>::lowest(), std::numeric_limits<float>::max()};
  return {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max()};
}

using Report = std::function<std::string()>;

void check_loaded(const Heightmap& map, const std::string& path, const Report& report) {
  const std::optional<Declared> d = declared(path);
  ASSERT_TRUE(d) << "the importer loaded a file libtiff cannot open\n" << report();
  ASSERT_EQ(map.rows(), static_cast<int>(d->height)) << report();
  ASSERT_EQ(map.cols(), static_cast<int>(d->width)) << report();
  const GridGeometry& g = map.geometry();
  ASSERT_TRUE(std::isfinite(g.cell_size_m) && g.cell_size_m > 0.0) << g.cell_size_m << "\n" << report();
  ASSERT_EQ(g.xll_m, 0.0) << report();
  ASSERT_EQ(g.yll_m, 0.0) << report();
  const auto [lowest, highest] = sample_range(*d);
  for (long long i = 0; i < map.size(); ++i) {
    const double h = map.data()[i];
    ASSERT_TRUE(std::isfinite(h) && h >= lowest && h <= highest)
        << "cell " << i << " = " << h << " outside [" << lowest << ", " << highest << "]\n"
        << report();
  }
}

/// Keeps a damaged header from taking the machine's memory: a huge allocation fails (std::bad_alloc, which the
/// test reports as an untyped error) instead of swapping or waking the OOM killer.
void limit_address_space() {
  constexpr rlim_t kLimit = rlim_t{1} << 30;
  rlimit current{};
  if (getrlimit(RLIMIT_AS, &current) != 0) return;
  if (current.rlim_cur != RLIM_INFINITY && current.rlim_cur <= kLimit) return;
  rlimit limited = current;
  limited.rlim_cur = kLimit;
  setrlimit(RLIMIT_AS, &limited);
}

TEST(GeoTiffFuzz, EveryFileLoadsOrThrowsATypedErrorAndLoadedGridsAreWhatTheFileDeclares) {
  limit_address_space();
  TIFFSetErrorHandler(nullptr);  // this test's own libtiff calls (seeds, declared()) stay quiet
  TIFFSetWarningHandler(nullptr);
  const std::uint64_t seed = fuzz::seed(0x6E071FF);
  const int iterations = fuzz::iterations(8000);
  const std::string path = ::testing::TempDir() + "marsala_fuzz_geotiff_input.tif";
  fuzz::Mutator mutator(seed, {});
  std::vector<std::string> corpus = seeds(path);
  ASSERT_GE(corpus.size(), 4u);
  const std::size_t fixed_seeds = corpus.size();
  const std::size_t kMaxCorpus = 64;
  fuzz::Watchdog watchdog;
  int loaded = 0;
  for (int i = 0; i < iterations; ++i) {
    // The seeds themselves first (regressions in corpus/ replay as they are), then mutants.
    std::string input =
        i < static_cast<int>(fixed_seeds) ? corpus[i] : mutator.mutate_binary(mutator.pick(corpus), corpus);
    if (i >= static_cast<int>(fixed_seeds) && mutator.chance(0.3)) mutate_directory_entry(input, mutator);
    fuzz::write_file(path, input);
    GeoTiffOptions options;
    options.fill_nodata = i < static_cast<int>(fixed_seeds) || mutator.chance(0.5);
    const Report report = [&] { return fuzz::failure_report("geotiff", seed, i, input, ".tif"); };
    watchdog.arm(std::chrono::seconds(5), "geotiff seed " + std::to_string(seed) + " iteration " + std::to_string(i),
                 input, fuzz::failure_path("geotiff", seed, i, ".tif"));
    const std::optional<Heightmap> map = fuzz::load_or_refuse<Error>(
        [&] { return read_geotiff(path, options); },
        [&](const Error& e) {
          const std::string what = e.what();
          EXPECT_NE(what.find(path), std::string::npos) << "the message does not name the file: " << what << "\n"
                                                        << report();
        },
        "marsala::Error", report);
    watchdog.disarm();
    if (::testing::Test::HasFailure()) return;
    if (!map) continue;
    ++loaded;
    check_loaded(*map, path, report);
    if (::testing::Test::HasFailure()) return;
    if (input.size() > 16384 || map->size() > 100000) continue;  // small seeds keep the budget
    mutator.keep(corpus, input, fixed_seeds, kMaxCorpus);
  }
  std::filesystem::remove(path);
  EXPECT_GT(loaded, iterations / 50) << "only " << loaded << " of " << iterations << " files loaded";
  RecordProperty("loaded", loaded);
}

}  // namespace
}  // namespace marsala::terrain
