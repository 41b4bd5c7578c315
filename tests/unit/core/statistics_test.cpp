#include "marsala/core/statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace marsala {
namespace {

TEST(Percentile, IsTheNearestRankOfTheSortedValues) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> value(-5.0, 5.0);
  for (std::size_t n = 1; n <= 40; ++n) {
    std::vector<double> values(n);
    for (double& v : values) v = value(rng);
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    for (double q : {0.0, 0.1, 0.5, 0.9, 1.0}) {
      const std::size_t rank = static_cast<std::size_t>(q * static_cast<double>(n - 1) + 0.5);
      EXPECT_EQ(percentile(values, q), sorted[rank]) << "n " << n << " q " << q;
    }
    // The median of an even count is the upper middle value, as the runtimes always reported it.
    EXPECT_EQ(median(values), sorted[n / 2]) << n;
  }
}

TEST(Percentile, OfNothingIsZero) {
  EXPECT_EQ(percentile({}, 0.9), 0.0);
  EXPECT_EQ(median({}), 0.0);
}

}  // namespace
}  // namespace marsala
