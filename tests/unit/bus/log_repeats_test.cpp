#include "marsala/bus/detail/log_repeats.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace marsala::bus::detail {
namespace {

TEST(LogRepeats, TheKindOfAMessageIsItsTextWithoutItsNumbers) {
  EXPECT_EQ(message_kind("recvUC: data(application, vendor 1.15): 10f7f01:645b7305:0:103 #17: deserialization failed"),
            "recvUC: data(application, vendor #.#): #f#f#:#b#:#:# ##: deserialization failed");
  EXPECT_EQ(message_kind("#1"), message_kind("#123456"));
  EXPECT_NE(message_kind("a 1"), message_kind("b 1"));
  EXPECT_EQ(message_kind(""), "");
}

TEST(LogRepeats, EachKindIsWrittenAtItsFirstTenthHundredthMessage) {
  RepeatedMessages repeats;
  std::vector<std::uint64_t> written;
  for (int i = 1; i <= 1000; ++i) {
    if (const std::uint64_t n = repeats.count("flood")) written.push_back(n);
    if (i == 5) {
      EXPECT_EQ(repeats.count("other"), 1u);  // another kind keeps its own count
    }
  }
  EXPECT_EQ(written, (std::vector<std::uint64_t>{1, 10, 100, 1000}));
}

TEST(LogRepeats, TheKindsRememberedAreBounded) {
  RepeatedMessages repeats;
  for (std::size_t i = 0; i < 10 * RepeatedMessages::kMaxKinds; ++i) repeats.count(std::string(i + 1, 'x'));
  EXPECT_LE(repeats.kinds(), RepeatedMessages::kMaxKinds + 1);
  // The kinds beyond the bound share one count: still 1st, 10th, 100th ... of them all.
  std::uint64_t last = 0;
  for (int i = 0; i < 100000; ++i)
    if (const std::uint64_t n = repeats.count("new kind " + std::to_string(i) + "x")) last = n;
  EXPECT_GE(last, 10000u);
}

}  // namespace
}  // namespace marsala::bus::detail
