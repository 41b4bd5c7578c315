// Fuzzes the ESRI ASCII grid reader (common/terrain/asc_io.hpp) with seeded mutations of small grids: every input
// loads or throws a ParseError naming the source; a loaded grid is what its text says (an independent reading of
// header and values) and survives write -> read bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "marsala/core/error.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::terrain {
namespace {

constexpr const char* kSource = "fuzz.asc";

/// The grid a loaded text describes, read independently of asc_io.cpp (strtod, plain splitting); only meaningful
/// for texts the reader accepted, which are strict.
struct ExpectedGrid {
  std::map<std::string, double> header;  ///< lower-case key -> value
  std::vector<std::string> tokens;       ///< data values in file order
};

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

std::vector<std::string> split_blanks(const std::string& line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t e = i;
    while (e < line.size() && line[e] != ' ' && line[e] != '\t') ++e;
    if (e > i) out.push_back(line.substr(i, e - i));
    i = e;
  }
  return out;
}

ExpectedGrid read_independently(const std::string& text) {
  ExpectedGrid grid;
  std::istringstream in(text);
  std::string line;
  bool in_header = true;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> tokens = split_blanks(line);
    if (in_header && !tokens.empty() && std::isalpha(static_cast<unsigned char>(tokens[0][0]))) {
      grid.header[lower(tokens[0])] = tokens.size() > 1 ? std::strtod(tokens[1].c_str(), nullptr) : 0.0;
      continue;
    }
    in_header = false;
    grid.tokens.insert(grid.tokens.end(), tokens.begin(), tokens.end());
  }
  return grid;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

using Report = std::function<std::string()>;

/// Checks a grid the reader accepted against its text.
void check_loaded(const Heightmap& map, const std::string& text, bool fill, const Report& report) {
  const ExpectedGrid expected = read_independently(text);
  const auto value = [&](const char* key) {
    const auto it = expected.header.find(key);
    return it == expected.header.end() ? std::optional<double>() : std::optional<double>(it->second);
  };
  ASSERT_TRUE(value("ncols") && value("nrows") && value("cellsize")) << report();
  ASSERT_EQ(map.rows(), static_cast<int>(*value("nrows"))) << report();
  ASSERT_EQ(map.cols(), static_cast<int>(*value("ncols"))) << report();
  const GridGeometry& g = map.geometry();
  ASSERT_TRUE(std::isfinite(g.cell_size_m) && g.cell_size_m > 0.0) << g.cell_size_m << "\n" << report();
  ASSERT_TRUE(same_bits(g.cell_size_m, *value("cellsize"))) << report();
  ASSERT_TRUE(std::isfinite(g.xll_m) && std::isfinite(g.yll_m)) << g.xll_m << ", " << g.yll_m << "\n" << report();
  const double xll = value("xllcorner") ? *value("xllcorner") : *value("xllcenter") - 0.5 * g.cell_size_m;
  const double yll = value("yllcorner") ? *value("yllcorner") : *value("yllcenter") - 0.5 * g.cell_size_m;
  ASSERT_TRUE(same_bits(g.xll_m, xll) && same_bits(g.yll_m, yll)) << report();

  ASSERT_EQ(static_cast<long long>(expected.tokens.size()), map.size()) << report();
  const std::optional<double> nodata = value("nodata_value");
  double lowest = HUGE_VAL, highest = -HUGE_VAL;
  std::vector<bool> missing(expected.tokens.size(), false);
  for (std::size_t i = 0; i < expected.tokens.size(); ++i) {
    const double v = std::strtod(expected.tokens[i].c_str(), nullptr);
    missing[i] = nodata && v == *nodata;
    if (missing[i]) continue;
    lowest = std::min(lowest, v);
    highest = std::max(highest, v);
    ASSERT_TRUE(same_bits(map.data()[i], v))
        << "cell " << i << ": " << map.data()[i] << " read from '" << expected.tokens[i] << "'\n"
        << report();
  }
  for (std::size_t i = 0; i < missing.size(); ++i) {
    const double h = map.data()[i];
    ASSERT_TRUE(std::isfinite(h)) << "cell " << i << " is " << h << "\n" << report();
    if (!missing[i]) continue;
    ASSERT_TRUE(fill) << "NODATA cell " << i << " accepted without fill_nodata\n" << report();
    // fill_nodata's documented promise: the filled heights stay within [min, max] of the valid ones.
    ASSERT_TRUE(h >= lowest && h <= highest)
        << "filled cell " << i << " = " << h << " outside [" << lowest << ", " << highest << "]\n"
        << report();
  }
}

/// write -> read gives the same grid, bit for bit, and writing that again gives the same text.
void check_round_trip(const Heightmap& map, const Report& report) {
  std::ostringstream first;
  try {
    write_asc(map, first);
  } catch (const InvalidArgument& e) {
    // Documented: a finite height of -9999 m cannot be written (it would read back as NODATA).
    bool has_nodata_height = false;
    for (long long i = 0; i < map.size(); ++i) has_nodata_height |= map.data()[i] == -9999.0;
    ASSERT_TRUE(has_nodata_height) << "write_asc refused a loaded grid: " << e.what() << "\n" << report();
    return;
  }
  std::istringstream in(first.str());
  const Heightmap again = parse_asc(in, "round-trip.asc");
  ASSERT_EQ(again.geometry(), map.geometry()) << report();
  ASSERT_EQ(std::memcmp(again.data(), map.data(), sizeof(double) * static_cast<std::size_t>(map.size())), 0)
      << report();
  std::ostringstream second;
  write_asc(again, second);
  ASSERT_EQ(second.str(), first.str()) << report();
}

std::vector<std::string> seeds() {
  std::vector<std::string> out = {
      "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 2 3\n4 5 6\n",
      "NCOLS 2\r\nNROWS 2\r\nXLLCENTER 10.5\r\nYLLCENTER -3.25\r\nCELLSIZE 0.5\r\n0.125 -1e-3\r\n2.5e2 7\r\n",
      "ncols 4\nnrows 3\nxllcorner -1\nyllcorner 2\ncellsize 0.1\nnodata_value -1\n"
      "1 -1 2 3\n-1 -1 4 5\n6 7 8 9\n",
      "ncols\t1\nnrows\t1\nxllcorner\t0\nyllcorner\t0\ncellsize\t2\n\t42\t\n",
      "ncols 5\nnrows 1\nxllcorner 1e5\nyllcorner 1e5\ncellsize 1e-4\n-0 0 +1 1. .5\n\n",
  };
  // A written grid, and whatever tiny files tests/fuzz/corpus/asc holds (inputs that once found a bug).
  GridGeometry g;
  g.rows = 6;
  g.cols = 7;
  g.xll_m = 3.5;
  g.yll_m = -2.0;
  g.cell_size_m = 0.25;
  Heightmap map(g);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) map(r, c) = 0.1 * r - 0.03 * c + (r == c ? 1e-7 : 0.0);
  std::ostringstream written;
  write_asc(map, written);
  out.push_back(written.str());
  const std::filesystem::path corpus = std::filesystem::path(fuzz::source_dir()) / "tests/fuzz/corpus/asc";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(corpus, ec))
    out.push_back(fuzz::read_file(entry.path()));
  return out;
}

TEST(AscFuzz, EveryInputLoadsOrThrowsAParseErrorAndLoadedGridsRoundTrip) {
  const std::uint64_t seed = fuzz::seed(0xA5C0001);
  const int iterations = fuzz::iterations(40000);
  fuzz::Mutator mutator(seed, {"ncols", "nrows", "xllcorner", "yllcorner", "xllcenter", "yllcenter", "cellsize",
                               "NODATA_value", "nodata_value", "NCOLS", "dx", "\n", "\r\n", "\t", " ", "\n\n"});
  std::vector<std::string> corpus = seeds();
  const std::size_t fixed_seeds = corpus.size();
  const std::size_t kMaxCorpus = 256;
  const std::string file = ::testing::TempDir() + "marsala_fuzz_asc_input.asc";
  fuzz::Watchdog watchdog;
  int loaded = 0;
  for (int i = 0; i < iterations; ++i) {
    // The seeds themselves first (regressions in corpus/ replay as they are), then mutants.
    const std::string input =
        i < static_cast<int>(fixed_seeds) ? corpus[i] : mutator.mutate_text(mutator.pick(corpus), corpus);
    AscReadOptions options;
    options.fill_nodata = i < static_cast<int>(fixed_seeds) || mutator.chance(0.5);
    const bool from_file = i % 64 == 0;  // read_asc's own file reading, now and then
    if (from_file) fuzz::write_file(file, input);
    const std::string source = from_file ? file : kSource;
    const Report report = [&] { return fuzz::failure_report("asc", seed, i, input, ".asc"); };
    watchdog.arm(std::chrono::seconds(5), "asc seed " + std::to_string(seed) + " iteration " + std::to_string(i), input,
                 fuzz::failure_path("asc", seed, i, ".asc"));
    const std::optional<Heightmap> map = fuzz::load_or_refuse<ParseError>(
        [&] {
          if (from_file) return read_asc(file, options);
          std::istringstream in(input);
          return parse_asc(in, source, options);
        },
        [&](const ParseError& e) {
          const std::string what = e.what();
          EXPECT_EQ(what.rfind(source + ":", 0), 0u) << "the message does not start with the source: " << what << "\n"
                                                     << report();
          EXPECT_GT(what.size(), source.size() + 2) << report();
        },
        "ParseError", report);
    watchdog.disarm();
    if (::testing::Test::HasFailure()) return;
    if (!map) continue;
    ++loaded;
    try {
      check_loaded(*map, input, options.fill_nodata, report);
      check_round_trip(*map, report);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "a loaded grid does not round-trip: " << e.what() << "\n" << report();
    }
    if (::testing::Test::HasFailure()) return;
    // Accepted mutants are kept as seeds, so later mutations reach beyond the header checks.
    if (input.size() < 4096) mutator.keep(corpus, input, fixed_seeds, kMaxCorpus);
  }
  std::filesystem::remove(file);
  // The fuzzer must reach the data: a run where (almost) nothing loads tests only the header checks.
  EXPECT_GT(loaded, iterations / 50) << "only " << loaded << " of " << iterations << " inputs loaded";
  RecordProperty("loaded", loaded);
}

}  // namespace
}  // namespace marsala::terrain
