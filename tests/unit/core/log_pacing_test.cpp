#include "marsala/core/log_pacing.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace marsala {
namespace {

TEST(LogPacing, OnlyPowersOfTenAreLogged) {
  std::uint64_t logged = 0;
  for (std::uint64_t n = 0; n <= 100000; ++n)
    if (power_of_ten(n)) ++logged;
  EXPECT_EQ(logged, 6u);  // 1, 10, 100, 1000, 10000, 100000
  EXPECT_TRUE(power_of_ten(10000000000000000000ull));
  for (std::uint64_t n : {0ull, 2ull, 11ull, 20ull, 110ull, 1000001ull}) EXPECT_FALSE(power_of_ten(n)) << n;
}

}  // namespace
}  // namespace marsala
