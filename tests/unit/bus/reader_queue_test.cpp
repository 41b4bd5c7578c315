#include "marsala/bus/detail/reader_queue.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>

namespace marsala::bus::detail {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A volatile reader drops what a transient-local writer wrote before the reader existed, and takes what came after.
TEST(VolatileFilter, AVolatileReaderDropsSamplesWrittenBeforeItWasCreated) {
  const std::int64_t before = now_ns() - 1'000'000'000;  // a second before the reader
  const VolatileFilter filter(Durability::kVolatile);
  EXPECT_FALSE(filter.passes(before));
  EXPECT_TRUE(filter.passes(now_ns() + 1'000'000));
}

// A sample reassembled by Fast DDS from fragments whose first came without INFO_TS has no source timestamp (0); its
// age is unknown, so it passes: dropping it lost genuine frames of a Cyclone writer under loss for good.
TEST(VolatileFilter, ASampleWithoutSourceTimestampPasses) {
  const VolatileFilter filter(Durability::kVolatile);
  EXPECT_TRUE(filter.passes(0));
  EXPECT_TRUE(filter.passes(-1));  // an invalid time (Fast DDS's c_TimeInvalid is negative)
}

TEST(VolatileFilter, ATransientLocalReaderPassesEverything) {
  const VolatileFilter filter(Durability::kTransientLocal);
  EXPECT_TRUE(filter.passes(1));
  EXPECT_TRUE(filter.passes(0));
  EXPECT_TRUE(filter.passes(now_ns()));
}

}  // namespace
}  // namespace marsala::bus::detail
