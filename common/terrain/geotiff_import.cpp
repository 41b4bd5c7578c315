#include "marsala/terrain/geotiff_import.hpp"

#include <tiffio.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "marsala/core/error.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::terrain {
namespace {

// GeoTIFF and GDAL tags; libtiff does not know them, so it reads them as anonymous fields.
constexpr uint32_t kModelPixelScaleTag = 33550;
constexpr uint32_t kModelTransformationTag = 34264;
constexpr uint32_t kGdalNodataTag = 42113;
// Guard against absurd sizes in a damaged header before allocating [cells].
constexpr long long kMaxHeaderCells = 1LL << 31;

enum class SampleKind { kFloat32, kFloat64, kInt16, kUInt16, kInt32 };

int sample_bytes(SampleKind kind) {
  switch (kind) {
    case SampleKind::kFloat32: return 4;
    case SampleKind::kFloat64: return 8;
    case SampleKind::kInt16: return 2;
    case SampleKind::kUInt16: return 2;
    case SampleKind::kInt32: return 4;
  }
  return 0;
}

template <typename T>
void convert_as(const unsigned char* src, std::size_t count, double* dst) {
  for (std::size_t i = 0; i < count; ++i) {
    T value;
    std::memcpy(&value, src + i * sizeof(T), sizeof(T));
    dst[i] = static_cast<double>(value);
  }
}

// Converts `count` decoded samples (native byte order: libtiff swaps them) to doubles.
void convert(SampleKind kind, const unsigned char* src, std::size_t count, double* dst) {
  switch (kind) {
    case SampleKind::kFloat32: convert_as<float>(src, count, dst); break;
    case SampleKind::kFloat64: convert_as<double>(src, count, dst); break;
    case SampleKind::kInt16: convert_as<int16_t>(src, count, dst); break;
    case SampleKind::kUInt16: convert_as<uint16_t>(src, count, dst); break;
    case SampleKind::kInt32: convert_as<int32_t>(src, count, dst); break;
  }
}

// libtiff reports through per-handle callbacks: keep the first error for our message, drop warnings
// (every GeoTIFF triggers "unknown field" warnings for its geo tags).
struct TiffMessages {
  std::string first_error;
};

int on_tiff_error(TIFF*, void* user_data, const char* module, const char* fmt, va_list ap) {
  auto* messages = static_cast<TiffMessages*>(user_data);
  if (messages->first_error.empty()) {
    // libtiff hands over a printf format and its va_list: only vsnprintf can expand them.
    char text[512];
    std::vsnprintf(text, sizeof text, fmt, ap);
    messages->first_error = module && *module ? fmt::format("{}: {}", module, text) : std::string(text);
  }
  return 1;
}

int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};
struct OptionsFreer {
  void operator()(TIFFOpenOptions* options) const { TIFFOpenOptionsFree(options); }
};

class GeoTiffReader {
 public:
  GeoTiffReader(const std::string& path, const GeoTiffOptions& options) : path_(path), options_(options) {}

  Heightmap read() {
    open();
    read_layout();
    const double cell_size = read_cell_size();
    read_nodata();
    GridGeometry geometry;
    geometry.rows = static_cast<int>(height_);
    geometry.cols = static_cast<int>(width_);
    geometry.cell_size_m = cell_size;
    Heightmap map(geometry);
    if (TIFFIsTiled(tif_.get()))
      read_tiles(map.data());
    else
      read_strips(map.data());
    screen_cells(map);
    return map;
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const { throw ParseError(path_, 0, problem); }

  std::string libtiff_says() const {
    return messages_.first_error.empty() ? std::string() : fmt::format(" (libtiff: {})", messages_.first_error);
  }

  void open() {
    std::error_code ec;
    if (std::filesystem::is_directory(path_, ec))
      throw IoError(fmt::format("cannot read '{}': it is a directory", path_));
    {
      std::ifstream probe(path_, std::ios::binary);
      if (!probe) throw IoError(fmt::format("cannot open '{}': {}", path_, std::strerror(errno)));
    }
    std::unique_ptr<TIFFOpenOptions, OptionsFreer> open_options(TIFFOpenOptionsAlloc());
    if (!open_options) throw IoError(fmt::format("cannot allocate libtiff options to read '{}'", path_));
    TIFFOpenOptionsSetErrorHandlerExtR(open_options.get(), on_tiff_error, &messages_);
    TIFFOpenOptionsSetWarningHandlerExtR(open_options.get(), on_tiff_warning, &messages_);
    tif_.reset(TIFFOpenExt(path_.c_str(), "r", open_options.get()));
    if (!tif_) fail(fmt::format("not a readable TIFF file{}", libtiff_says()));
  }

  void read_layout() {
    TIFF* tif = tif_.get();
    uint32_t width = 0, height = 0;
    if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) || !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height))
      fail("TIFF without image width or length");
    if (width == 0 || height == 0) fail(fmt::format("empty raster: {} x {}", width, height));
    if (width > static_cast<uint32_t>(std::numeric_limits<int>::max()) ||
        height > static_cast<uint32_t>(std::numeric_limits<int>::max()) ||
        static_cast<long long>(width) * height > kMaxHeaderCells)
      fail(fmt::format("raster too large: {} x {}", width, height));
    width_ = width;
    height_ = height;

    uint16_t samples = 1, bits = 0, format = SAMPLEFORMAT_UINT, compression = COMPRESSION_NONE;
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
    if (samples != 1)
      fail(fmt::format("the raster has {} bands (samples per pixel); an elevation raster has exactly one", samples));
    if (format == SAMPLEFORMAT_IEEEFP && bits == 32)
      kind_ = SampleKind::kFloat32;
    else if (format == SAMPLEFORMAT_IEEEFP && bits == 64)
      kind_ = SampleKind::kFloat64;
    else if (format == SAMPLEFORMAT_INT && bits == 16)
      kind_ = SampleKind::kInt16;
    else if (format == SAMPLEFORMAT_UINT && bits == 16)
      kind_ = SampleKind::kUInt16;
    else if (format == SAMPLEFORMAT_INT && bits == 32)
      kind_ = SampleKind::kInt32;
    else
      fail(fmt::format("unsupported sample format: {}-bit {} (supported: float32, float64, int16, uint16, int32)", bits,
                       format_name(format)));
    if (!TIFFIsCODECConfigured(compression))
      fail(fmt::format("compression scheme {} is not supported by this libtiff", compression));
    // A damaged header can claim a raster of gigabytes in a file of a few bytes: uncompressed samples must fit in
    // the file before their raster is allocated.
    std::error_code ec;
    const std::uintmax_t file_bytes = std::filesystem::file_size(path_, ec);
    const std::uintmax_t raster_bytes = static_cast<std::uintmax_t>(width_) * height_ * sample_bytes(kind_);
    if (compression == COMPRESSION_NONE && !ec && raster_bytes > file_bytes)
      fail(fmt::format(
          "the header declares {} x {} uncompressed samples ({} bytes) in a file of {} bytes: truncated or damaged",
          width_, height_, raster_bytes, file_bytes));
  }

  static std::string format_name(uint16_t format) {
    switch (format) {
      case SAMPLEFORMAT_UINT: return "unsigned integer";
      case SAMPLEFORMAT_INT: return "signed integer";
      case SAMPLEFORMAT_IEEEFP: return "floating point";
      case SAMPLEFORMAT_COMPLEXINT: return "complex integer";
      case SAMPLEFORMAT_COMPLEXIEEEFP: return "complex floating point";
      default: return fmt::format("sample format {}", format);
    }
  }

  // The values of a custom tag as stored: pointer and count; {nullptr, 0} when absent.
  std::pair<const void*, uint32_t> custom_tag(uint32_t tag, TIFFDataType expected, const char* name) const {
    TIFF* tif = tif_.get();
    const TIFFField* field = TIFFFindField(tif, tag, TIFF_ANY);
    if (!field) return {nullptr, 0};
    if (TIFFFieldDataType(field) != expected)
      fail(fmt::format("{} has TIFF type {}, expected {}", name, static_cast<int>(TIFFFieldDataType(field)),
                       static_cast<int>(expected)));
    void* data = nullptr;
    uint32_t count = 0;
    int found = 0;
    if (TIFFFieldPassCount(field)) {
      if (TIFFFieldReadCount(field) == TIFF_VARIABLE2) {
        found = TIFFGetField(tif, tag, &count, &data);
      } else {
        uint16_t count16 = 0;
        found = TIFFGetField(tif, tag, &count16, &data);
        count = count16;
      }
    } else if (expected == TIFF_ASCII) {
      found = TIFFGetField(tif, tag, &data);
      count = data ? static_cast<uint32_t>(std::strlen(static_cast<const char*>(data)) + 1) : 0;
    } else {
      fail(fmt::format("{} is registered in an unexpected way by this libtiff", name));
    }
    if (!found || !data) return {nullptr, 0};
    return {data, count};
  }

  double read_cell_size() const {
    const auto [scale_data, scale_count] = custom_tag(kModelPixelScaleTag, TIFF_DOUBLE, "ModelPixelScaleTag");
    double sx = 1.0, sy = 1.0;
    if (scale_data) {
      if (scale_count < 2) fail(fmt::format("ModelPixelScaleTag holds {} values, expected 3", scale_count));
      const auto* scale = static_cast<const double*>(scale_data);
      sx = scale[0];
      sy = scale[1];
    } else {
      const auto [matrix_data, matrix_count] =
          custom_tag(kModelTransformationTag, TIFF_DOUBLE, "ModelTransformationTag");
      if (!matrix_data) return 1.0;
      if (matrix_count != 16) fail(fmt::format("ModelTransformationTag holds {} values, expected 16", matrix_count));
      const auto* m = static_cast<const double*>(matrix_data);
      if (m[1] != 0.0 || m[4] != 0.0) fail("rotated or sheared rasters (ModelTransformationTag) are not supported");
      sx = std::abs(m[0]);
      sy = std::abs(m[5]);
    }
    if (!(sx > 0.0) || !(sy > 0.0) || !std::isfinite(sx) || !std::isfinite(sy))
      fail(fmt::format("pixel size must be positive and finite, got {} x {}", sx, sy));
    if (std::abs(sx - sy) > 1e-9 * std::max(sx, sy))
      fail(fmt::format("pixels are not square: {} x {} m; resample first", sx, sy));
    return sx;
  }

  void read_nodata() {
    const auto [data, count] = custom_tag(kGdalNodataTag, TIFF_ASCII, "GDAL_NODATA tag");
    if (!data) return;
    const auto* text = static_cast<const char*>(data);
    const void* nul = std::memchr(text, '\0', count);
    std::string_view value(text, nul ? static_cast<std::size_t>(static_cast<const char*>(nul) - text) : count);
    while (!value.empty() && (value.front() == ' ' || value.front() == '\t')) value.remove_prefix(1);
    while (!value.empty() && (value.back() == ' ' || value.back() == '\t' || value.back() == '\n'))
      value.remove_suffix(1);
    if (!value.empty() && value.front() == '+') value.remove_prefix(1);
    double nodata = 0.0;
    const auto result = std::from_chars(value.data(), value.data() + value.size(), nodata);
    if (value.empty() || result.ec == std::errc::invalid_argument || result.ptr != value.data() + value.size())
      fail(fmt::format("GDAL_NODATA tag is not a number: '{}'", value));
    has_nodata_ = true;
    // NaN here means NaN cells, which are missing anyway. A float32 raster stores its NODATA rounded to
    // float ("-3.40282e+38" names the float nearest to it), so compare in float there, as GDAL does.
    nodata_ = nodata;
    if (kind_ == SampleKind::kFloat32 && std::abs(nodata) <= std::numeric_limits<float>::max())
      nodata_ = static_cast<double>(static_cast<float>(nodata));
  }

  void read_strips(double* out) {
    TIFF* tif = tif_.get();
    uint32_t rows_per_strip = height_;
    TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows_per_strip);
    if (rows_per_strip == 0 || rows_per_strip > height_) rows_per_strip = height_;
    const uint32_t strips_needed = (height_ + rows_per_strip - 1) / rows_per_strip;
    if (TIFFNumberOfStrips(tif) < strips_needed)
      fail(fmt::format("the file holds {} strips, {} are needed", TIFFNumberOfStrips(tif), strips_needed));
    const std::size_t bytes = static_cast<std::size_t>(sample_bytes(kind_));
    std::vector<unsigned char> buffer(static_cast<std::size_t>(rows_per_strip) * width_ * bytes);
    for (uint32_t strip = 0; strip < strips_needed; ++strip) {
      const uint32_t row0 = strip * rows_per_strip;
      const uint32_t rows = std::min(rows_per_strip, height_ - row0);
      const std::size_t samples = static_cast<std::size_t>(rows) * width_;
      const tmsize_t wanted = static_cast<tmsize_t>(samples * bytes);
      const tmsize_t got = TIFFReadEncodedStrip(tif, strip, buffer.data(), wanted);
      if (got < wanted)
        fail(fmt::format("cannot decode strip {} (rows {}..{}): data missing or damaged{}", strip, row0,
                         row0 + rows - 1, libtiff_says()));
      convert(kind_, buffer.data(), samples, out + static_cast<std::size_t>(row0) * width_);
    }
  }

  void read_tiles(double* out) {
    TIFF* tif = tif_.get();
    uint32_t tile_width = 0, tile_length = 0;
    if (!TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_width) || !TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_length) ||
        tile_width == 0 || tile_length == 0)
      fail("tiled TIFF without a valid tile size");
    const std::size_t bytes = static_cast<std::size_t>(sample_bytes(kind_));
    const tmsize_t tile_bytes = static_cast<tmsize_t>(static_cast<std::size_t>(tile_width) * tile_length * bytes);
    std::vector<unsigned char> buffer(static_cast<std::size_t>(tile_bytes));
    for (uint32_t y = 0; y < height_; y += tile_length) {
      for (uint32_t x = 0; x < width_; x += tile_width) {
        const uint32_t rows = std::min(tile_length, height_ - y);
        const uint32_t cols = std::min(tile_width, width_ - x);
        const uint32_t tile = TIFFComputeTile(tif, x, y, 0, 0);
        // Edge tiles are stored padded to the full tile size; only their top-left part is the raster.
        const tmsize_t needed = static_cast<tmsize_t>((static_cast<std::size_t>(rows - 1) * tile_width + cols) * bytes);
        const tmsize_t got = TIFFReadEncodedTile(tif, tile, buffer.data(), tile_bytes);
        if (got < needed)
          fail(fmt::format("cannot decode the tile at row {}, column {}: data missing or damaged{}", y, x,
                           libtiff_says()));
        for (uint32_t r = 0; r < rows; ++r)
          convert(kind_, buffer.data() + static_cast<std::size_t>(r) * tile_width * bytes, cols,
                  out + static_cast<std::size_t>(y + r) * width_ + x);
      }
    }
  }

  // NODATA and NaN cells become NaN (then filled, if allowed); infinite samples are always an error.
  void screen_cells(Heightmap& map) const {
    long long missing = 0;
    double* h = map.data();
    const long long cells = map.size();
    for (long long i = 0; i < cells; ++i) {
      const bool is_missing = std::isnan(h[i]) || (has_nodata_ && h[i] == nodata_);
      if (!is_missing) {
        if (std::isinf(h[i])) fail(fmt::format("infinite sample at row {}, column {}", i / width_, i % width_));
        continue;
      }
      if (!options_.fill_nodata)
        fail(fmt::format(
            "NODATA cell at row {}, column {} (0-based); fill NODATA cells explicitly (--fill-nodata) to accept this "
            "file",
            i / width_, i % width_));
      h[i] = std::numeric_limits<double>::quiet_NaN();
      ++missing;
    }
    if (missing == cells) fail("every cell is NODATA; there is nothing to fill from");
    if (missing > 0) fill_nodata(map);
  }

  const std::string& path_;
  const GeoTiffOptions& options_;
  TiffMessages messages_;
  std::unique_ptr<TIFF, TiffCloser> tif_;
  uint32_t width_ = 0;
  uint32_t height_ = 0;
  SampleKind kind_ = SampleKind::kFloat32;
  bool has_nodata_ = false;
  double nodata_ = 0.0;
};

}  // namespace

Heightmap read_geotiff(const std::string& path, const GeoTiffOptions& options) {
  try {
    return GeoTiffReader(path, options).read();
  } catch (const std::bad_alloc&) {
    // Compressed data can claim more than memory holds too; that is a problem of this file, not of the program.
    throw ParseError(path, 0, "the raster does not fit in memory (damaged header?)");
  }
}

}  // namespace marsala::terrain
