#include "marsala/bus/detail/sample_conversion.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace marsala::bus::detail {
namespace {

// A batch of wire values, one of them malformed (negative): only that one is lost.
TEST(SampleConversion, AMalformedSampleNeverCostsTheOthersOfItsBatch) {
  const std::vector<int> batch{1, 2, -3, 4, 5};
  std::vector<int> out;
  MalformedSamples malformed;
  std::vector<std::string> logged;
  for (const int v : batch)
    convert_sample(
        [&] {
          if (v < 0) throw std::invalid_argument("malformed sample: " + std::to_string(v));
          return v * 10;
        },
        out, malformed,
        [&](const std::string& what, std::uint64_t total) { logged.push_back(what + " #" + std::to_string(total)); });
  EXPECT_EQ(out, (std::vector<int>{10, 20, 40, 50}));
  EXPECT_EQ(malformed.total(), 1u);
  EXPECT_EQ(logged, (std::vector<std::string>{"malformed sample: -3 #1"}));
}

TEST(SampleConversion, AFloodOfMalformedSamplesLogsAFewLinesWithTheCount) {
  MalformedSamples malformed;
  std::vector<std::uint64_t> logged_at;
  std::vector<int> out;
  for (int i = 0; i < 12345; ++i)
    convert_sample([]() -> int { throw 42; }, out, malformed,
                   [&](const std::string& what, std::uint64_t total) {
                     EXPECT_EQ(what, "unknown error");
                     logged_at.push_back(total);
                   });
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(malformed.total(), 12345u);
  EXPECT_EQ(logged_at, (std::vector<std::uint64_t>{1, 10, 100, 1000, 10000}));
}

}  // namespace
}  // namespace marsala::bus::detail
