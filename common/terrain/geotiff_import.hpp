#pragma once
// GeoTIFF import: band 1 of an elevation raster into a Heightmap in a local frame.

#include <string>

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain {

/// How to treat NODATA (GDAL_NODATA tag) and NaN cells: an error unless fill_nodata is set.
struct GeoTiffOptions {
  bool fill_nodata = false;  ///< fill such cells with fill_nodata() (asc_io.hpp) instead of refusing the file
};

/// Reads band 1 of a GeoTIFF (float32, float64, int16, uint16, int32; strips or tiles; any compression this
/// libtiff decodes) into a local frame whose lower-left corner is (0, 0) [m] and whose cell size is the pixel
/// size [m] (ModelPixelScaleTag, else an unrotated ModelTransformationTag; 1 m if both are absent; square
/// pixels required). The first TIFF row is the northmost row. NODATA (GDAL_NODATA tag 42113) cells and NaN:
/// error unless options.fill_nodata; infinite samples are always an error. Throws IoError when the file cannot
/// be opened and ParseError naming the file and the problem (not a TIFF, unsupported sample format, several
/// bands, non-square or rotated pixels, truncated data, ...).
Heightmap read_geotiff(const std::string& path, const GeoTiffOptions& options = {});

}  // namespace marsala::terrain
