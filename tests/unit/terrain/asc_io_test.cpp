#include "marsala/terrain/asc_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::terrain {
namespace {

const char* const kHeader3x2 = "ncols 3\nnrows 2\nxllcorner 10\nyllcorner 20\ncellsize 0.5\n";

Heightmap parse(const std::string& text, AscReadOptions options = {}) {
  std::istringstream in(text);
  return parse_asc(in, "mem.asc", options);
}

// Parses `text` expecting a ParseError on `line` whose message contains `problem`.
void expect_parse_error(const std::string& text, int line, const std::string& problem, AscReadOptions options = {}) {
  try {
    parse(text, options);
    ADD_FAILURE() << "no ParseError for:\n" << text;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "mem.asc");
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << "message: " << e.what();
    if (line > 0) {
      const std::string prefix = "mem.asc:" + std::to_string(line) + ": ";
      EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
    }
  }
}

std::uint64_t bits_of(double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "marsala_asc_io_" + name; }

std::string gale_asc_path() {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  if (!root) return {};
  const std::string path = std::string(root) + "/../shared/data/terrains/gale_crater_1m.asc";
  return std::filesystem::exists(path) ? path : std::string();
}

TEST(AscRead, ReadsHeaderAndRowsNorthFirst) {
  const Heightmap map = parse(std::string(kHeader3x2) + "NODATA_value -9999\n1 2 3\n4 5 6.25\n");
  ASSERT_EQ(map.rows(), 2);
  ASSERT_EQ(map.cols(), 3);
  EXPECT_EQ(map.geometry().xll_m, 10.0);
  EXPECT_EQ(map.geometry().yll_m, 20.0);
  EXPECT_EQ(map.cell_size_m(), 0.5);
  // First data line is row 0, the northmost row.
  EXPECT_EQ(map(0, 0), 1.0);
  EXPECT_EQ(map(0, 2), 3.0);
  EXPECT_EQ(map(1, 0), 4.0);
  EXPECT_EQ(map(1, 2), 6.25);
  EXPECT_DOUBLE_EQ(map.cell_center({0, 0}).y, 20.75);
}

TEST(AscRead, KeysAreCaseInsensitiveAndNodataIsOptional) {
  const Heightmap map = parse("NCOLS 2\nNRows 1\nXLLCORNER -3\nyllCorner 4\nCellSize 2\n7 8\n");
  EXPECT_EQ(map.cols(), 2);
  EXPECT_EQ(map.geometry().xll_m, -3.0);
  EXPECT_EQ(map(0, 1), 8.0);
  // Without NODATA_value, -9999 is an ordinary height.
  const Heightmap deep = parse("ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n-9999\n");
  EXPECT_EQ(deep(0, 0), -9999.0);
}

TEST(AscRead, CentreKeysBecomeCorners) {
  const Heightmap map = parse("ncols 2\nnrows 2\nxllcenter 0.5\nyllcenter 10.25\ncellsize 0.5\n1 2\n3 4\n");
  EXPECT_EQ(map.geometry().xll_m, 0.25);
  EXPECT_EQ(map.geometry().yll_m, 10.0);
  EXPECT_DOUBLE_EQ(map.cell_center({1, 0}).x, 0.5);
  EXPECT_DOUBLE_EQ(map.cell_center({1, 0}).y, 10.25);
}

TEST(AscRead, AcceptsCrlfTabsLeadingBlanksAndTrailingEmptyLines) {
  const Heightmap lf = parse(std::string(kHeader3x2) + "1 2 3\n4 5 6\n");
  const Heightmap crlf =
      parse("ncols 3\r\nnrows 2\r\nxllcorner 10\r\nyllcorner 20\r\ncellsize 0.5\r\n 1\t2 3 \r\n\t4 5  6\r\n\r\n\n");
  EXPECT_EQ(crlf.geometry(), lf.geometry());
  EXPECT_EQ(crlf.heights(), lf.heights());
  const Heightmap no_final_newline = parse(std::string(kHeader3x2) + "1 2 3\n4 5 6");
  EXPECT_EQ(no_final_newline.heights(), lf.heights());
}

TEST(AscRead, ParsesNumberSyntaxes) {
  const Heightmap map = parse("ncols 5\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1e3 -2.5E-1 .5 +4 -0\n");
  EXPECT_EQ(map(0, 0), 1000.0);
  EXPECT_EQ(map(0, 1), -0.25);
  EXPECT_EQ(map(0, 2), 0.5);
  EXPECT_EQ(map(0, 3), 4.0);
  EXPECT_EQ(map(0, 4), 0.0);
  EXPECT_TRUE(std::signbit(map(0, 4)));
}

TEST(AscReadErrors, EmptyFile) {
  expect_parse_error("", 1, "empty file");
  expect_parse_error(" \n\r\n", 1, "empty file");
}

TEST(AscReadErrors, MissingKey) {
  expect_parse_error("ncols 3\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n", 5, "missing header key 'yllcorner");
  expect_parse_error("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\n", 5, "missing header key 'cellsize'");
}

TEST(AscReadErrors, DuplicateKey) {
  expect_parse_error("ncols 3\nnrows 2\nNCOLS 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n", 3,
                     "duplicate header key 'NCOLS'");
  // A corner and a centre for the same axis are a duplicate as well.
  expect_parse_error("ncols 3\nnrows 2\nxllcorner 0\nxllcenter 0.5\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n", 4,
                     "already given as 'xllcorner' on line 3");
}

TEST(AscReadErrors, UnknownKey) {
  expect_parse_error("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\ndx 1\n1 2 3\n4 5 6\n", 6,
                     "unknown header key 'dx'");
}

TEST(AscReadErrors, NonNumericOrMissingHeaderValue) {
  expect_parse_error("ncols three\nnrows 2\n", 1, "not a number: 'three'");
  expect_parse_error("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0x\ncellsize 1\n", 4, "not a number: '0x'");
  expect_parse_error("ncols 3\nnrows\n", 2, "has no value");
  expect_parse_error("ncols 3 4\nnrows 2\n", 1, "trailing garbage after the value of header key 'ncols'");
  expect_parse_error("ncols 3\nnrows 2\nxllcorner inf\n", 3, "must be finite");
}

TEST(AscReadErrors, BadNcolsNrows) {
  expect_parse_error("ncols 3.5\nnrows 2\n", 1, "must be a positive integer");
  expect_parse_error("ncols 3\nnrows 2.0\n", 2, "must be a positive integer");
  expect_parse_error("ncols 0\nnrows 2\n", 1, "must be positive");
  expect_parse_error("ncols 3\nnrows -2\n", 2, "must be positive");
  expect_parse_error("ncols 99999999999\nnrows 2\n", 1, "too large");
}

TEST(AscReadErrors, BadCellsize) {
  const std::string head = "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\n";
  expect_parse_error(head + "cellsize 0\n1\n", 5, "must be positive");
  expect_parse_error(head + "cellsize -1\n1\n", 5, "must be positive");
  expect_parse_error(head + "cellsize nan\n1\n", 5, "must be finite");
  expect_parse_error(head + "cellsize inf\n1\n", 5, "must be finite");
  expect_parse_error(head + "cellsize 1e999\n1\n", 5, "out of range");
}

TEST(AscReadErrors, CornerBeyondTheDoubles) {
  // Found by tests/fuzz/asc_fuzz_test.cpp: a finite centre half a cell from the double limits made an infinite
  // corner, and the Heightmap's InvalidArgument ("grid corner must be finite") escaped without the file's name.
  expect_parse_error("ncols 1\nnrows 1\nxllcenter -1.7976931348623157e308\nyllcorner 0\ncellsize 1e308\n5\n", 3,
                     "'xllcenter' puts the grid's lower-left corner half a cell beyond the range of doubles");
  expect_parse_error("ncols 1\nnrows 1\nxllcorner 0\nyllcenter -1.7e308\ncellsize 1e308\n5\n", 4, "'yllcenter'");
  // The same corner as a corner is fine, and so is a centre with a cell that keeps it in range.
  EXPECT_EQ(parse("ncols 1\nnrows 1\nxllcorner -1.7e308\nyllcenter 0\ncellsize 1e308\n5\n").geometry().xll_m, -1.7e308);
  EXPECT_EQ(parse("ncols 1\nnrows 1\nxllcenter -1.7e308\nyllcorner 0\ncellsize 2\n5\n").geometry().xll_m,
            -1.7e308 - 1.0);
}

TEST(AscReadErrors, TooFewOrTooManyValuesOnARow) {
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5\n", 7, "too few values on data row 2: got 2, expected 3");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3 4\n5 6 7\n", 6, "too many values on data row 1");
  // One row per line: a grid's values wrapped over lines are refused, not reflowed.
  expect_parse_error("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3 4\n", 6, "too many values");
  expect_parse_error("ncols 4\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n", 6, "too few values");
}

TEST(AscReadErrors, TooFewOrTooManyRows) {
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n", 7, "too few data rows: got 1, expected 2");
  expect_parse_error(std::string(kHeader3x2), 6, "too few data rows: got 0, expected 2");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 6\n7 8 9\n", 8, "too many data rows: expected 2");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n\n4 5 6\n", 7, "empty line where data row 2 of 2");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n\n", 7, "too few data rows: got 1");
}

TEST(AscReadErrors, TrailingGarbage) {
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 6\nend of grid\n", 8, "trailing garbage");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 6\n\n\n#\n", 10, "trailing garbage after the last data row");
}

TEST(AscReadErrors, NonNumericTokens) {
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 1.2x 6\n", 7, "not a number: '1.2x' at data row 2, column 2");
  expect_parse_error(std::string(kHeader3x2) + "1,5 2 3\n4 5 6\n", 6, "not a number: '1,5'");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 - 6\n", 7, "not a number: '-'");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 1e999\n", 7, "out of range");
  // A header key among the data rows is garbage, not a header.
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\ncellsize 1\n", 7, "not a number: 'cellsize'");
  // Binary junk is reported, escaped.
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 \x01\x02\n", 7, "not a number: '\\x01\\x02'");
}

TEST(AscReadErrors, NanAndInfTokens) {
  expect_parse_error(std::string(kHeader3x2) + "1 nan 3\n4 5 6\n", 6,
                     "non-finite height 'nan' at data row 1, column 2");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 -inf\n", 7, "non-finite height '-inf'");
  expect_parse_error(std::string(kHeader3x2) + "1 2 3\n4 5 Infinity\n", 7, "non-finite height");
  // A row that starts with "NaN" is still a data row, not a header key.
  expect_parse_error(std::string(kHeader3x2) + "NaN 2 3\n4 5 6\n", 6, "non-finite height 'NaN'");
  // Filling NODATA does not make NaN tokens acceptable.
  expect_parse_error(std::string(kHeader3x2) + "NODATA_value -9999\n1 nan 3\n4 5 6\n", 7, "non-finite", {true});
}

TEST(AscReadErrors, NodataCellsNeedExplicitFill) {
  const std::string text = std::string(kHeader3x2) + "NODATA_value -9999\n1 2 3\n4 -9999.0 6\n";
  expect_parse_error(text, 8, "NODATA value '-9999.0' at data row 2, column 2");
  expect_parse_error(text, 8, "--fill-nodata");
  // All-NODATA files cannot be filled.
  expect_parse_error(std::string(kHeader3x2) + "NODATA_value -1\n-1 -1 -1\n-1 -1.0 -1e0\n", 0, "every cell is NODATA",
                     {true});
}

TEST(AscRead, FillsNodataWhenAllowed) {
  // "-9999.0" equals NODATA_value -9999, so it is NODATA too.
  const Heightmap map = parse(std::string(kHeader3x2) + "NODATA_value -9999\n1 -9999 3\n4 -9999.0 6\n", {true});
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_FALSE(std::isnan(map(r, c)));
  // Both missing cells touch known cells only: (0,1) sees 1, 3, 4, 6 -> 3.5; (1,1) sees 1, 3, 4, 6 -> 3.5.
  EXPECT_DOUBLE_EQ(map(0, 1), 3.5);
  EXPECT_DOUBLE_EQ(map(1, 1), 3.5);
  EXPECT_EQ(map(1, 2), 6.0);
}

TEST(AscRead, KeepsNodataAsNanWhenAsked) {
  AscReadOptions keep;
  keep.keep_nodata = true;
  const Heightmap map = parse(std::string(kHeader3x2) + "NODATA_value -9999\n1 -9999 3\n4 5 -9999.0\n", keep);
  EXPECT_TRUE(std::isnan(map(0, 1)));
  EXPECT_TRUE(std::isnan(map(1, 2)));
  EXPECT_EQ(map(0, 0), 1.0);
  EXPECT_EQ(map(1, 1), 5.0);
  // A map that knows nothing is still a map; NaN tokens stay an error.
  const Heightmap none = parse(std::string(kHeader3x2) + "NODATA_value -1\n-1 -1 -1\n-1 -1 -1\n", keep);
  EXPECT_TRUE(none.heights().array().isNaN().all());
  expect_parse_error(std::string(kHeader3x2) + "NODATA_value -9999\n1 nan 3\n4 5 6\n", 7, "non-finite", keep);
  // What write_asc writes for NaN reads back as NaN.
  std::ostringstream out;
  write_asc(map, out);
  std::istringstream in(out.str());
  const Heightmap back = parse_asc(in, "back.asc", keep);
  EXPECT_TRUE(std::isnan(back(0, 1)));
  EXPECT_EQ(back(1, 1), 5.0);
}

TEST(AscRead, HeaderPromisingMoreThanTheDataDoesNotAllocateIt) {
  expect_parse_error("ncols 2000000000\nnrows 2000000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n", 6,
                     "too few values on data row 1");
}

TEST(AscRead, MissingFileIsAnIoError) {
  EXPECT_THROW(read_asc(temp_path("does_not_exist.asc")), IoError);
  EXPECT_THROW(read_asc(::testing::TempDir()), IoError);
}

TEST(AscRead, FileErrorsNameThePath) {
  const std::string path = temp_path("bad.asc");
  {
    std::ofstream out(path, std::ios::binary);
    out << kHeader3x2 << "1 2 3\n4 5\n";
  }
  try {
    read_asc(path);
    ADD_FAILURE() << "no ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 7);
    EXPECT_EQ(std::string(e.what()).rfind(path + ":7: too few values", 0), 0u) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(AscWrite, WritesTheDocumentedHeader) {
  GridGeometry g{2, 2, 0.25, -3.0, 0.1};
  Heightmap map(g);
  map(0, 0) = 1.5;
  map(0, 1) = std::numeric_limits<double>::quiet_NaN();
  map(1, 0) = -0.0;
  map(1, 1) = 0.1;
  std::ostringstream out;
  write_asc(map, out);
  EXPECT_EQ(out.str(),
            "ncols 2\nnrows 2\nxllcorner 0.25\nyllcorner -3\ncellsize 0.1\nNODATA_value -9999\n"
            "1.5 -9999\n-0 0.1\n");
}

TEST(AscWrite, RoundTripIsBitExact) {
  std::mt19937_64 rng(20240611);
  GridGeometry g{17, 23, 1234.5678901234567, -0.1, 0.1};
  Heightmap map(g);
  const double specials[] = {0.0,
                             -0.0,
                             1e-300,
                             -1e-300,
                             1e300,
                             -1e300,
                             std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(),
                             0.1,
                             1.0 / 3.0,
                             -9999.000000000002};
  std::uniform_real_distribution<double> ordinary(-5000.0, 5000.0);
  long long i = 0;
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c, ++i) {
      double value = 0.0;
      if (i < static_cast<long long>(std::size(specials))) {
        value = specials[i];
      } else if (i % 2 == 0) {
        value = ordinary(rng);
      } else {
        // Random bit patterns over the whole double range, skipping NaN, inf and subnormals.
        do {
          const std::uint64_t bits = rng();
          std::memcpy(&value, &bits, sizeof value);
        } while (!std::isnormal(value) && value != 0.0);
      }
      map(r, c) = value;
    }
  const std::string path = temp_path("round_trip.asc");
  write_asc(map, path);
  const Heightmap back = read_asc(path);
  EXPECT_EQ(back.geometry(), map.geometry());
  EXPECT_EQ(bits_of(back.geometry().xll_m), bits_of(map.geometry().xll_m));
  EXPECT_EQ(bits_of(back.cell_size_m()), bits_of(map.cell_size_m()));
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c)
      ASSERT_EQ(bits_of(back(r, c)), bits_of(map(r, c))) << "cell (" << r << ", " << c << ") = " << map(r, c);
  std::filesystem::remove(path);
}

TEST(AscWrite, LargeGridRoundTrips) {
  // 2048 x 2048 cells of fractional heights: the size the reader must handle quickly.
  GridGeometry g{2048, 2048, 0.0, 0.0, 0.1};
  Heightmap map(g);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> height(0.0, 40.0);
  for (long long i = 0; i < map.size(); ++i) map.data()[i] = height(rng);
  const std::string path = temp_path("large.asc");
  write_asc(map, path);
  const Heightmap back = read_asc(path);
  ASSERT_EQ(back.geometry(), map.geometry());
  EXPECT_TRUE(back.heights() == map.heights());
  std::filesystem::remove(path);
}

TEST(AscWrite, RefusesUnrepresentableMaps) {
  Heightmap map(GridGeometry{1, 2, 0.0, 0.0, 1.0});
  map(0, 1) = std::numeric_limits<double>::infinity();
  std::ostringstream out;
  EXPECT_THROW(write_asc(map, out), InvalidArgument);
  map(0, 1) = -9999.0;  // would read back as NODATA
  EXPECT_THROW(write_asc(map, out), InvalidArgument);
  EXPECT_TRUE(out.str().empty());
  EXPECT_THROW(write_asc(Heightmap(), out), InvalidArgument);
  map(0, 1) = 1.0;
  EXPECT_THROW(write_asc(map, temp_path("no_such_dir/x.asc")), IoError);
}

TEST(FillNodata, OnionPeelingGoldenValues) {
  // 1 x 5: [0, ?, ?, ?, 8]. Layer 1: (0,1) <- 0, (0,3) <- 8. Layer 2: (0,2) <- mean(0, 8) = 4.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Heightmap row(GridGeometry{1, 5, 0.0, 0.0, 1.0});
  const double values[] = {0.0, nan, nan, nan, 8.0};
  for (int c = 0; c < 5; ++c) row(0, c) = values[c];
  fill_nodata(row);
  const double expected[] = {0.0, 0.0, 4.0, 8.0, 8.0};
  for (int c = 0; c < 5; ++c) EXPECT_EQ(row(0, c), expected[c]) << c;

  // 3 x 3 with a missing centre: the mean of its eight neighbours 1..8 is 4.5.
  Heightmap square(GridGeometry{3, 3, 0.0, 0.0, 1.0});
  double next = 1.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) square(r, c) = (r == 1 && c == 1) ? nan : next++;
  fill_nodata(square);
  EXPECT_EQ(square(1, 1), 4.5);
  EXPECT_EQ(square(0, 0), 1.0);
}

TEST(FillNodata, StaysWithinTheValidRangeAndReproducesConstants) {
  std::mt19937 rng(3);
  Heightmap map(GridGeometry{30, 40, 0.0, 0.0, 1.0});
  std::uniform_real_distribution<double> height(-2.0, 5.0);
  std::bernoulli_distribution missing(0.7);
  double lo = 1e300, hi = -1e300;
  for (long long i = 0; i < map.size(); ++i) {
    if (missing(rng) && i != 0) {
      map.data()[i] = std::numeric_limits<double>::quiet_NaN();
    } else {
      map.data()[i] = height(rng);
      lo = std::min(lo, map.data()[i]);
      hi = std::max(hi, map.data()[i]);
    }
  }
  const Heightmap before = map;
  fill_nodata(map);
  for (long long i = 0; i < map.size(); ++i) {
    ASSERT_FALSE(std::isnan(map.data()[i])) << i;
    EXPECT_GE(map.data()[i], lo);
    EXPECT_LE(map.data()[i], hi);
    if (!std::isnan(before.data()[i])) {
      EXPECT_EQ(map.data()[i], before.data()[i]);
    }
  }
  Heightmap constant(GridGeometry{9, 9, 0.0, 0.0, 1.0}, std::numeric_limits<double>::quiet_NaN());
  constant(8, 8) = 2.75;
  fill_nodata(constant);
  for (long long i = 0; i < constant.size(); ++i) EXPECT_EQ(constant.data()[i], 2.75);
}

TEST(FillNodata, MeansOfHeightsNearTheDoubleLimitsStayFinite) {
  // Found by tests/fuzz/asc_fuzz_test.cpp: the sum of two neighbours of -1e308 overflowed to -inf, so a file of
  // finite heights loaded with --fill-nodata held an infinite height.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Heightmap row(GridGeometry{1, 3, 0.0, 0.0, 1.0});
  row(0, 0) = -1e308;
  row(0, 1) = nan;
  row(0, 2) = -1e308;
  fill_nodata(row);
  EXPECT_EQ(row(0, 1), -1e308);
  const double max = std::numeric_limits<double>::max();
  Heightmap square(GridGeometry{3, 3, 0.0, 0.0, 1.0}, max);
  square(1, 1) = nan;
  square(0, 0) = 0.0;
  fill_nodata(square);
  EXPECT_DOUBLE_EQ(square(1, 1), 0.875 * max);  // the mean of seven max and one 0
  std::istringstream in(
      "ncols 3\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n"
      "1e308 -9999 1e308\n");
  AscReadOptions fill;
  fill.fill_nodata = true;
  EXPECT_EQ(parse_asc(in, "limits.asc", fill)(0, 1), 1e308);
}

TEST(FillNodata, AllMissingIsInvalid) {
  Heightmap map(GridGeometry{2, 2, 0.0, 0.0, 1.0}, std::numeric_limits<double>::quiet_NaN());
  EXPECT_THROW(fill_nodata(map), InvalidArgument);
  Heightmap empty;
  EXPECT_THROW(fill_nodata(empty), InvalidArgument);
}

TEST(AscGale, ReadsTheRealDem) {
  const std::string path = gale_asc_path();
  if (path.empty()) GTEST_SKIP() << "gale_crater_1m.asc not found under $MARSALA_SOURCE_DIR/../shared/data/terrains";
  const Heightmap map = read_asc(path);
  EXPECT_EQ(map.cols(), 348);
  EXPECT_EQ(map.rows(), 337);
  EXPECT_EQ(map.cell_size_m(), 1.0);
  EXPECT_EQ(map.geometry().xll_m, 0.0);
  EXPECT_EQ(map.geometry().yll_m, 0.0);
  // PROVENANCE.md: heights above the lowest cell, 0 .. 34.787 m; first value of the file is 1.930.
  EXPECT_EQ(map.min_height(), 0.0);
  EXPECT_EQ(map.max_height(), 34.787);
  EXPECT_EQ(map(0, 0), 1.930);
  const std::string copy = temp_path("gale_copy.asc");
  write_asc(map, copy);
  EXPECT_TRUE(read_asc(copy).heights() == map.heights());
  std::filesystem::remove(copy);
}

}  // namespace
}  // namespace marsala::terrain
