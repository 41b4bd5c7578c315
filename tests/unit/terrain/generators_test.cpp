#include "marsala/terrain/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <set>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::terrain {
namespace {

const std::vector<std::string> kMethods = {"craters", "flat",     "fractal", "gaussian_hills",
                                           "mix",     "platform", "ramp",    "steps"};

GeneratorSpec spec(int rows, int cols, double cs, std::uint64_t seed, std::map<std::string, double> params = {}) {
  GeneratorSpec s;
  s.rows = rows;
  s.cols = cols;
  s.cell_size_m = cs;
  s.seed = seed;
  s.params = std::move(params);
  return s;
}

bool bitwise_equal(const Heightmap& a, const Heightmap& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// FNV-1a over the bit patterns of the heights: a compact fingerprint for reproducibility anchors.
std::uint64_t fingerprint(const Heightmap& m) {
  std::uint64_t h = 1469598103934665603ULL;
  for (long long i = 0; i < m.size(); ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, m.data() + i, sizeof bits);
    for (int k = 0; k < 8; ++k) {
      h ^= (bits >> (8 * k)) & 0xffu;
      h *= 1099511628211ULL;
    }
  }
  return h;
}

std::string message_of(const std::string& method, const GeneratorSpec& s) {
  try {
    generate_terrain(method, s);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(Generators, NamesAreSortedAndCoverTheBuiltins) {
  const auto names = generator_names();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  for (const auto& m : kMethods) EXPECT_NE(std::find(names.begin(), names.end(), m), names.end()) << m;
}

TEST(Generators, GeometryHasLowerLeftCornerAtOrigin) {
  for (const auto& m : kMethods) {
    const Heightmap h = generate_terrain(m, spec(7, 11, 0.25, 3));
    EXPECT_EQ(h.rows(), 7) << m;
    EXPECT_EQ(h.cols(), 11) << m;
    EXPECT_EQ(h.geometry().xll_m, 0.0) << m;
    EXPECT_EQ(h.geometry().yll_m, 0.0) << m;
    EXPECT_EQ(h.cell_size_m(), 0.25) << m;
  }
}

TEST(Generators, SameSpecGivesIdenticalHeights) {
  for (const auto& m : kMethods) {
    const auto a = generate_terrain(m, spec(40, 53, 0.1, 12345));
    const auto b = generate_terrain(m, spec(40, 53, 0.1, 12345));
    EXPECT_TRUE(bitwise_equal(a, b)) << m;
  }
}

TEST(Generators, SeedChangesRandomMethodsOnly) {
  for (const std::string m : {"craters", "fractal", "gaussian_hills", "mix", "steps"}) {
    const auto a = generate_terrain(m, spec(64, 64, 0.1, 1));
    const auto b = generate_terrain(m, spec(64, 64, 0.1, 2));
    EXPECT_FALSE(bitwise_equal(a, b)) << m;
  }
  for (const std::string m : {"flat", "platform", "ramp"}) {
    const auto a = generate_terrain(m, spec(16, 9, 0.1, 1));
    const auto b = generate_terrain(m, spec(16, 9, 0.1, 987654321));
    EXPECT_TRUE(bitwise_equal(a, b)) << m;
  }
}

TEST(Generators, ReproducibilityAnchors) {
  // Fingerprints of this implementation's output. They pin the exact numbers a scenario seed stands for: a
  // change here means saved scenarios would regenerate different terrain (on this or another platform).
  EXPECT_EQ(fingerprint(generate_terrain("fractal", spec(33, 47, 0.1, 123))), 0x5171b3f8bdc87eecULL);
  EXPECT_EQ(fingerprint(generate_terrain("gaussian_hills", spec(33, 47, 0.1, 123))), 0x674d1c41a1510b68ULL);
  EXPECT_EQ(fingerprint(generate_terrain("craters", spec(33, 47, 0.1, 123))), 0x1223188ade558f1cULL);
  EXPECT_EQ(fingerprint(generate_terrain("steps", spec(33, 47, 0.1, 123))), 0xab86f7f4dfb035d2ULL);
  EXPECT_EQ(fingerprint(generate_terrain("mix", spec(33, 47, 0.1, 123))), 0x1d7547d488f29a1cULL);
  EXPECT_EQ(fingerprint(generate_terrain("ramp", spec(33, 47, 0.1, 123, {{"azimuth", 33.0}}))), 0x7cae6518bec7bf8dULL);
}

// Documented height range of each method with default parameters; E is the longer side [m].
struct Range {
  double lo;
  double hi;
};
Range documented_range(const std::string& m, const GeneratorSpec& s) {
  const double e = std::max(s.rows, s.cols) * s.cell_size_m;
  if (m == "flat") return {0.0, 0.0};
  if (m == "platform") return {0.0, 1.5};
  if (m == "ramp") return {0.0, 0.2 * (s.cols - 1) * s.cell_size_m};
  if (m == "gaussian_hills") return {0.0, 12 * 0.03 * e};
  if (m == "fractal") return {-0.025 * e, 0.025 * e};
  if (m == "craters") return {-8 * 0.03 * e, 8 * 0.01 * e};
  if (m == "steps") return {0.0, 3 * 0.005 * e};
  if (m == "mix") return {-(0.015 * e + 5 * 0.02 * e), 0.015 * e + 6 * 0.02 * e + 5 * 0.02 * e / 3.0 + 2 * 0.004 * e};
  ADD_FAILURE() << "no documented range for " << m;
  return {0.0, 0.0};
}

TEST(Generators, FiniteAndWithinDocumentedRange) {
  const std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 37}, {29, 1}, {2, 2}, {17, 23}, {64, 64}};
  for (const auto& m : kMethods)
    for (const auto& [rows, cols] : sizes)
      for (const std::uint64_t seed : {1ULL, 2ULL, 99ULL, 0xdeadbeefULL})
        for (const double cs : {0.1, 1.0}) {
          const GeneratorSpec s = spec(rows, cols, cs, seed);
          const Heightmap h = generate_terrain(m, s);
          const Range range = documented_range(m, s);
          const double tol = 1e-12 * std::max(1.0, std::abs(range.hi) + std::abs(range.lo));
          for (long long i = 0; i < h.size(); ++i) {
            const double v = h.data()[i];
            ASSERT_TRUE(std::isfinite(v)) << m << " " << rows << "x" << cols << " seed " << seed;
            ASSERT_GE(v, range.lo - tol) << m << " " << rows << "x" << cols << " seed " << seed;
            ASSERT_LE(v, range.hi + tol) << m << " " << rows << "x" << cols << " seed " << seed;
          }
        }
}

TEST(Generators, FractalSpansExactlyPlusMinusAmplitude) {
  for (const std::uint64_t seed : {1ULL, 7ULL, 1234ULL}) {
    const auto h = generate_terrain("fractal", spec(50, 80, 0.1, seed, {{"amplitude", 1.25}}));
    EXPECT_EQ(h.min_height(), -1.25);
    EXPECT_EQ(h.max_height(), 1.25);
  }
  // A single cell has no relief.
  EXPECT_EQ(generate_terrain("fractal", spec(1, 1, 0.1, 5)).max_height(), 0.0);
}

TEST(Generators, FractalDefaultsGiveMetresOfReliefOnLargeGrids) {
  // 1024 x 1024 cells of 0.1 m: extent 102.4 m, amplitude 2.56 m.
  const auto h = generate_terrain("fractal", spec(1024, 1024, 0.1, 11));
  EXPECT_DOUBLE_EQ(h.max_height() - h.min_height(), 2 * 0.025 * 102.4);
}

TEST(Generators, FlatGolden) {
  const auto h = generate_terrain("flat", spec(3, 4, 0.5, 1, {{"height", 2.5}}));
  for (long long i = 0; i < h.size(); ++i) EXPECT_EQ(h.data()[i], 2.5);
  EXPECT_EQ(generate_terrain("flat", spec(2, 2, 0.5, 1)).max_height(), 0.0);
}

// Cells at `height` exactly in rows [r0, r1] x cols [c0, c1], 0 elsewhere.
void expect_box(const Heightmap& h, int r0, int r1, int c0, int c1, double height) {
  int raised = 0;
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const bool in = r >= r0 && r <= r1 && c >= c0 && c <= c1;
      EXPECT_EQ(h(r, c), in ? height : 0.0) << "cell (" << r << ", " << c << ")";
      raised += in;
    }
  EXPECT_EQ(raised, (r1 - r0 + 1) * (c1 - c0 + 1));
}

TEST(Generators, PlatformGolden) {
  // 10 x 10 cells of 1 m, box 4 m (west-east) by 2 m centred at (5, 5): x in [3, 7) holds the centres
  // 3.5 .. 6.5 (cols 3..6); y in [4, 6) holds y = 4.5 (row 5) and 5.5 (row 4).
  expect_box(generate_terrain("platform", spec(10, 10, 1.0, 1, {{"width", 4.0}, {"depth", 2.0}})), 4, 5, 3, 6, 1.5);
  // Odd grid, edges through cell centres: west/south edges inclusive, east/north exclusive -> 3 x 3 cells.
  expect_box(generate_terrain("platform", spec(9, 9, 1.0, 1, {{"width", 3.0}, {"depth", 3.0}, {"height", 2.0}})), 3, 5,
             3, 5, 2.0);
  // Non-dyadic cells, explicit centre: x in [0.75, 1.25) -> cols 7..11; y in [0.35, 0.65) -> rows 14..16.
  expect_box(generate_terrain("platform", spec(20, 30, 0.1, 1,
                                               {{"width", 0.5}, {"centre_x", 1.0}, {"depth", 0.3}, {"centre_y", 0.5}})),
             14, 16, 7, 11, 1.5);
  // Default: 1.5 m high, 30% of each side, centred: 20 x 20 cells -> 6 x 6 box at rows/cols 7..12.
  expect_box(generate_terrain("platform", spec(20, 20, 0.1, 1)), 7, 12, 7, 12, 1.5);
  // A box entirely off the map leaves flat ground.
  EXPECT_EQ(generate_terrain("platform", spec(5, 5, 1.0, 1, {{"centre_x", -10.0}})).max_height(), 0.0);
}

TEST(Generators, RampGoldenAlongTheAxes) {
  // slope 0.25, cells 0.5 m: 0.125 m per cell, exact in binary.
  const std::map<double, std::function<double(int, int)>> expected = {
      {90.0, [](int, int c) { return 0.125 * c; }},         // rising to the east
      {0.0, [](int r, int) { return 0.125 * (3 - r); }},    // rising to the north (row 0 highest)
      {180.0, [](int r, int) { return 0.125 * r; }},        // rising to the south
      {270.0, [](int, int c) { return 0.125 * (5 - c); }},  // rising to the west
      {-90.0, [](int, int c) { return 0.125 * (5 - c); }},
  };
  for (const auto& [azimuth, height] : expected) {
    const auto h = generate_terrain("ramp", spec(4, 6, 0.5, 1, {{"slope", 0.25}, {"azimuth", azimuth}}));
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 6; ++c)
        EXPECT_EQ(h(r, c), height(r, c)) << "azimuth " << azimuth << " (" << r << ", " << c << ")";
  }
}

TEST(Generators, RampSlopeBetweenCellsIsTheSlope) {
  // Non-dyadic slope and cell size: the slope between neighbours along the azimuth is kappa to rounding.
  const auto east = generate_terrain("ramp", spec(5, 9, 0.1, 1, {{"slope", 0.3}, {"azimuth", 90.0}}));
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c + 1 < 9; ++c) {
      EXPECT_NEAR((east(r, c + 1) - east(r, c)) / 0.1, 0.3, 1e-12);
      EXPECT_EQ(east(r, c), east(0, c));  // level across the slope
    }
  EXPECT_EQ(east.min_height(), 0.0);
  // Azimuth 45 (north-east): along the diagonal the rise over the diagonal run is the slope; across it, level.
  const auto ne = generate_terrain("ramp", spec(6, 6, 0.2, 1, {{"slope", 0.3}, {"azimuth", 45.0}}));
  for (int r = 1; r < 6; ++r)
    for (int c = 0; c + 1 < 6; ++c) {
      EXPECT_NEAR((ne(r - 1, c + 1) - ne(r, c)) / (0.2 * std::sqrt(2.0)), 0.3, 1e-12);
      EXPECT_NEAR(ne(r - 1, c), ne(r, c + 1), 1e-12);
    }
  EXPECT_EQ(ne(5, 0), 0.0);  // south-west corner is the lowest
}

TEST(Generators, StepsGoldenWithStraightCliffs) {
  // 40 cells of 1 m rising to the east, 3 cliffs evenly spaced at x = 10, 20, 30 (no jitter, no waviness).
  const auto h = generate_terrain(
      "steps", spec(6, 40, 1.0, 3, {{"count", 3}, {"step_height", 0.5}, {"jitter", 0.0}, {"waviness", 0.0}}));
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 40; ++c) EXPECT_EQ(h(r, c), 0.5 * (c / 10)) << "(" << r << ", " << c << ")";
  // Rising to the north: row 0 (northmost) is on the top terrace.
  const auto n = generate_terrain(
      "steps",
      spec(40, 3, 1.0, 3, {{"count", 3}, {"step_height", 0.5}, {"azimuth", 0.0}, {"jitter", 0.0}, {"waviness", 0.0}}));
  for (int r = 0; r < 40; ++r) EXPECT_EQ(n(r, 1), 0.5 * ((39 - r) / 10)) << r;
}

TEST(Generators, StepsAreWholeMultiplesOfTheStepHeight) {
  const auto h = generate_terrain("steps", spec(80, 60, 0.1, 17, {{"count", 4}, {"step_height", 0.25}}));
  std::set<double> levels;
  for (long long i = 0; i < h.size(); ++i) levels.insert(h.data()[i]);
  for (double v : levels) EXPECT_EQ(v, 0.25 * std::round(v / 0.25));
  EXPECT_GE(levels.size(), 2u);
  EXPECT_LE(levels.size(), 5u);
}

TEST(Generators, HillsPeakNearTheirAmplitude) {
  // One hill of sigma >= 0.6 * 3.84 m on 1 m cells: its peak lies within 0.71 m of a cell centre, so the
  // highest cell holds at least 0.5 * exp(-0.71^2 / (2 * 2.3^2)) > 0.47 of the amplitude.
  for (const std::uint64_t seed : {1ULL, 2ULL, 3ULL}) {
    const auto h = generate_terrain("gaussian_hills", spec(64, 64, 1.0, seed, {{"count", 1}, {"amplitude", 2.0}}));
    EXPECT_LE(h.max_height(), 2.0);
    EXPECT_GE(h.max_height(), 0.47 * 2.0);
    EXPECT_GE(h.min_height(), 0.0);
  }
}

TEST(Generators, CratersDigBelowAndRimAboveTheGround) {
  const auto h = generate_terrain("craters", spec(100, 100, 0.5, 4, {{"count", 3}}));
  EXPECT_LT(h.min_height(), 0.0);
  EXPECT_GT(h.max_height(), 0.0);
  EXPECT_EQ(generate_terrain("craters", spec(20, 20, 0.5, 4, {{"count", 0}})).max_height(), 0.0);
}

TEST(Generators, MixIsTheSumOfItsParts) {
  const std::map<std::string, double> nothing = {
      {"fractal_amplitude", 0.0}, {"hill_count", 0}, {"crater_count", 0}, {"step_count", 0}};
  const auto zero = generate_terrain("mix", spec(30, 40, 0.1, 8, nothing));
  EXPECT_EQ(zero.min_height(), 0.0);
  EXPECT_EQ(zero.max_height(), 0.0);
  auto only_fractal = nothing;
  only_fractal["fractal_amplitude"] = 0.75;
  const auto f = generate_terrain("mix", spec(30, 40, 0.1, 8, only_fractal));
  EXPECT_EQ(f.min_height(), -0.75);
  EXPECT_EQ(f.max_height(), 0.75);
}

TEST(Generators, UnknownMethodListsTheValidNames) {
  try {
    generate_terrain("perlin", spec(4, 4, 0.1, 1));
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("perlin"), std::string::npos) << what;
    for (const auto& m : kMethods) EXPECT_NE(what.find(m), std::string::npos) << what;
  }
  EXPECT_THROW(generator_parameter_help("perlin"), InvalidArgument);
}

TEST(Generators, UnknownParameterListsTheMethodsKeys) {
  const std::string what = message_of("fractal", spec(8, 8, 0.1, 1, {{"octave", 3}}));
  EXPECT_NE(what.find("'octave'"), std::string::npos) << what;
  for (const std::string key : {"amplitude", "octaves", "persistence", "wavelength"})
    EXPECT_NE(what.find(key), std::string::npos) << what;
  EXPECT_THROW(generate_terrain("flat", spec(2, 2, 0.1, 1, {{"slope", 1.0}})), InvalidArgument);
}

TEST(Generators, OutOfRangeValuesNameTheParameterAndTheRange) {
  const std::string what = message_of("fractal", spec(8, 8, 0.1, 1, {{"octaves", 40}}));
  EXPECT_NE(what.find("octaves"), std::string::npos) << what;
  EXPECT_NE(what.find("[1, 16]"), std::string::npos) << what;
  EXPECT_THROW(generate_terrain("fractal", spec(8, 8, 0.1, 1, {{"persistence", 1.5}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("fractal", spec(8, 8, 0.1, 1, {{"amplitude", std::nan("")}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("fractal", spec(8, 8, 0.1, 1, {{"octaves", 2.5}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("fractal", spec(8, 8, 0.1, 1, {{"wavelength", 0.05}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("gaussian_hills", spec(8, 8, 0.1, 1, {{"count", -1}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("ramp", spec(8, 8, 0.1, 1, {{"slope", -0.1}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("ramp", spec(8, 8, 0.1, 1, {{"azimuth", 400.0}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("platform", spec(8, 8, 0.1, 1, {{"width", -1.0}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("craters", spec(8, 8, 0.1, 1, {{"radius_min", 2.0}, {"radius_max", 1.0}})),
               InvalidArgument);
  EXPECT_THROW(generate_terrain("steps", spec(8, 8, 0.1, 1, {{"jitter", 2.0}})), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(8, 8, 0.1, 1, {{"height", INFINITY}})), InvalidArgument);
}

TEST(Generators, BadGridIsRejected) {
  EXPECT_THROW(generate_terrain("flat", spec(0, 4, 0.1, 1)), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(4, -1, 0.1, 1)), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(4, 4, 0.0, 1)), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(4, 4, -0.1, 1)), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(4, 4, std::nan(""), 1)), InvalidArgument);
  EXPECT_THROW(generate_terrain("flat", spec(1 << 16, 1 << 16, 0.1, 1)), InvalidArgument);
}

// Every key in the help text is accepted with its range's bounds, and every line has the documented shape.
TEST(Generators, HelpListsExactlyTheAcceptedParameters) {
  for (const auto& m : kMethods) {
    const auto lines = generator_parameter_help(m);
    EXPECT_FALSE(lines.empty()) << m;
    for (const auto& line : lines) {
      const auto paren = line.find(" (default ");
      ASSERT_NE(paren, std::string::npos) << line;
      ASSERT_NE(line.find("): "), std::string::npos) << line;
      ASSERT_EQ(line.back(), ']') << line;
      const std::string key = line.substr(0, paren);
      const auto valid = line.find("; valid ");
      ASSERT_NE(valid, std::string::npos) << line;
      double lo = 0, hi = 0;
      ASSERT_EQ(std::sscanf(line.c_str() + line.find('[', valid), "[%lf, %lf]", &lo, &hi), 2) << line;
      ASSERT_LE(lo, hi) << line;
      if (m == "craters" && (key == "radius_min" || key == "radius_max")) continue;  // must stay ordered
      if (m == "fractal" && key == "wavelength") continue;                           // must exceed a cell
      for (const double v : {lo, hi})
        EXPECT_NO_THROW(generate_terrain(m, spec(3, 4, 0.5, 1, {{key, v}}))) << m << " " << key << " = " << v;
    }
  }
  EXPECT_EQ(generator_parameter_help("platform").front(),
            "height (default 1.5): height of the box above the ground at 0 m; valid [-10000, 10000] [m]");
}

}  // namespace
}  // namespace marsala::terrain
