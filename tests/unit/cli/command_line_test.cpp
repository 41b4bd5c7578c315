#include <gtest/gtest.h>

#include <string>

#include "marsala/cli/command_line.hpp"

namespace marsala::cli {
namespace {

/// The validator's message for `text`: empty when accepted.
std::string check(const CLI::Validator& v, std::string text) { return v(text); }

TEST(SecondsWithin, TakesFiniteNumbersInTheRangeOnly) {
  const CLI::Validator v = seconds_within(0.0, 600.0, " (0: never)");
  for (const char* ok : {"0", "0.5", "600", "6e2", "1e-3"}) EXPECT_EQ(check(v, ok), "") << ok;
  for (const char* bad : {"nan", "NaN", "inf", "-1", "600.5", "soon", "", "5s", "1e9"}) {
    const std::string message = check(v, bad);
    EXPECT_NE(message, "") << bad;
    EXPECT_NE(message.find(fmt::format("not '{}'", bad)), std::string::npos) << message;
    EXPECT_NE(message.find("(0: never)"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace marsala::cli
