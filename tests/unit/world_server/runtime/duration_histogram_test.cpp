#include "marsala/world_server/runtime/duration_histogram.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "marsala/core/error.hpp"

namespace marsala::world_server {
namespace {

using Counts = std::vector<std::uint64_t>;

TEST(DurationHistogram, ABoundCountsInItsOwnBucketAsPrometheusLeSays) {
  DurationHistogram h({0.01, 0.1});
  for (double s : {0.0, 0.01, 0.010001, 0.1, 0.5, 7.0}) h.observe(s);
  EXPECT_EQ(h.bucket_counts(), (Counts{2, 2, 2}));  // <= 0.01: 0 and 0.01; <= 0.1: 0.010001 and 0.1; above: 0.5, 7
  EXPECT_EQ(h.count(), 6u);
  EXPECT_DOUBLE_EQ(h.sum_s(), 0.0 + 0.01 + 0.010001 + 0.1 + 0.5 + 7.0);
}

TEST(DurationHistogram, ANaNIsNotCounted) {
  DurationHistogram h({1.0});
  h.observe(std::numeric_limits<double>::quiet_NaN());
  h.observe(std::numeric_limits<double>::infinity());
  EXPECT_EQ(h.bucket_counts(), (Counts{0, 1}));
  EXPECT_EQ(h.count(), 1u);
}

TEST(DurationHistogram, BoundsMustBeFiniteAndAscending) {
  EXPECT_THROW(DurationHistogram({0.1, 0.1}), InvalidArgument);
  EXPECT_THROW(DurationHistogram({0.2, 0.1}), InvalidArgument);
  EXPECT_THROW(DurationHistogram({0.1, std::numeric_limits<double>::infinity()}), InvalidArgument);
  EXPECT_NO_THROW(DurationHistogram(std::vector<double>{}));
}

TEST(DurationHistogram, StepBoundsSpanHalfAMillisecondToTenSeconds) {
  const std::vector<double>& b = step_duration_bounds_s();
  ASSERT_FALSE(b.empty());
  EXPECT_EQ(b.front(), 0.0005);
  EXPECT_EQ(b.back(), 10.0);
  EXPECT_EQ(DurationHistogram().bucket_counts().size(), b.size() + 1);
}

}  // namespace
}  // namespace marsala::world_server
