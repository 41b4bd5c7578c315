#include "marsala/core/types.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace marsala {
namespace {

TEST(Within, AnswersAsTheDistanceDoesOnRandomAndEdgeOffsets) {
  // Offsets on and next to the radius along an axis, at powers of two, near the diagonal, and random; the shortcut
  // must never change what hypot(dx, dy) <= r says.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> at(-4.0, 4.0), radius(0.01, 4.0);
  std::uniform_int_distribution<int> kind(0, 4), exponent(-6, 2);
  long long inside = 0, outside = 0;
  for (int trial = 0; trial < 500000; ++trial) {
    double r = radius(rng), dx = at(rng), dy = at(rng);
    switch (kind(rng)) {
      case 0: dx = r, dy = dy * 1e-9; break;
      case 1: r = std::ldexp(1.0, exponent(rng)), dx = 0.0, dy = -r; break;
      case 2: dx = std::nextafter(r, 0.0), dy = 1e-8; break;
      case 3: dx = r / std::sqrt(2.0), dy = r / std::sqrt(2.0); break;
      default: break;
    }
    const bool expected = std::hypot(dx, dy) <= r;
    ASSERT_EQ(within(dx, dy, r), expected) << dx << " " << dy << " " << r;
    (expected ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 100000);
  EXPECT_GT(outside, 50000);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(within(nan, 0.0, 1.0));
  EXPECT_FALSE(within(0.0, nan, 1.0));
  EXPECT_FALSE(within(inf, nan, 1.0));
  EXPECT_TRUE(within(0.0, 0.0, 0.0));
}

}  // namespace
}  // namespace marsala
