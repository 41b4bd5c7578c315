#pragma once
// ESRI ASCII grid (.asc) files: a strict reader and a bit-exact writer.
//
// File layout (ARCHITECTURE.md, grid conventions):
//   ncols 3            header keys, case-insensitive, one per line, each exactly once;
//   nrows 2            xllcenter / yllcenter may replace xllcorner / yllcorner;
//   xllcorner 0        NODATA_value is optional
//   yllcorner 0
//   cellsize 1
//   NODATA_value -9999
//   1 2 3              then nrows lines of ncols heights [m], first line = northmost row (row 0)
//   4 5 6
// Anything else (unknown or repeated keys, ragged rows, extra rows, NaN/inf, trailing garbage) is a
// ParseError naming the file, the line and the problem; a grid is never guessed.

#include <iosfwd>
#include <string>

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain {

/// How to treat NODATA cells: the policy is an error (naming file, line, column) unless fill_nodata or keep_nodata
/// is set.
struct AscReadOptions {
  bool fill_nodata = false;  ///< fill NODATA cells with fill_nodata() instead of refusing the file
  bool keep_nodata = false;  ///< read NODATA cells as NaN (a map with unknown cells; every cell may be NODATA)
};

/// Reads an ESRI ASCII grid [m] (NODATA cells as `options` say); throws ParseError("file:line: problem") or IoError
/// (cannot open/read).
Heightmap read_asc(const std::string& path, const AscReadOptions& options = {});

/// Same as read_asc from a stream; `source_name` is used in messages.
Heightmap parse_asc(std::istream& in, const std::string& source_name, const AscReadOptions& options = {});

/// Writes an ESRI ASCII grid with the shortest decimals that read back bit for bit (std::to_chars);
/// NaN heights are written as NODATA_value -9999. Throws InvalidArgument for an empty map, a non-finite
/// geometry, an infinite height or a finite height equal to -9999 [m] (it would read back as NODATA),
/// checked before anything is written; throws IoError when the file cannot be written.
void write_asc(const Heightmap& map, const std::string& path);

/// Same as write_asc(map, path) into a stream; throws IoError when the stream fails.
void write_asc(const Heightmap& map, std::ostream& out);

/// Fills NODATA cells (given as NaN) in place by onion peeling: layer by layer outwards from the valid data,
/// each missing cell that touches a known cell (8-neighbourhood) takes the mean of its known 8-neighbours
/// (cells filled in earlier layers count, cells of the same layer do not), so the result is deterministic
/// and stays within [min, max] of the valid heights [m]. Throws InvalidArgument when no valid cell exists.
void fill_nodata(Heightmap& map);

}  // namespace marsala::terrain
