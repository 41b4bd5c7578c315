#include "marsala/core/format.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>

namespace marsala {
namespace {

// The spellings format.hpp documents, on its own examples.
TEST(Format, VocabularyTypesSpellTheirDocumentedText) {
  EXPECT_EQ(fmt::format("{}", CellIndex{3, 7}), "(3, 7)");
  EXPECT_EQ(fmt::format("{}", Position{1.5, -0.25}), "(1.5, -0.25) m");
  Rect r;
  r.x0 = 0.0;
  r.y0 = -1.0;
  r.x1 = 4.5;
  r.y1 = 1.0;
  EXPECT_EQ(fmt::format("{}", r), "[0, 4.5] x [-1, 1] m");
  CellRect cells;
  cells.first = {3, 7};
  cells.rows = 10;
  cells.cols = 20;
  EXPECT_EQ(fmt::format("{}", cells), "rows 10, cols 20 from (3, 7)");
  NavigabilityParams p;
  p.kappa = 0.3;
  p.delta_m = 1.0;
  p.eps_m = 0.05;
  EXPECT_EQ(fmt::format("{}", p), "kappa 0.3, delta 1 m, eps 0.05 m");
}

// Doubles in a message read back to the very same double (the bit that decided a tie stays visible).
TEST(Format, PositionCoordinatesReadBackExactly) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coordinate(-1e4, 1e4);
  for (int i = 0; i < 1000; ++i) {
    const Position p{coordinate(rng), coordinate(rng) * 1e-7};
    const std::string text = fmt::format("{}", p);
    ASSERT_EQ(text.front(), '(') << text;
    ASSERT_EQ(text.substr(text.size() - 3), ") m") << text;
    const std::size_t comma = text.find(", ");
    ASSERT_NE(comma, std::string::npos) << text;
    EXPECT_EQ(std::strtod(text.substr(1, comma - 1).c_str(), nullptr), p.x) << text;
    EXPECT_EQ(std::strtod(text.substr(comma + 2, text.size() - comma - 5).c_str(), nullptr), p.y) << text;
  }
}

}  // namespace
}  // namespace marsala
