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

TEST(NumberWithin, PositiveAndNonNegativeRefuseWhatIsNotAFiniteNumber) {
  const CLI::Validator positive = positive_number(), non_negative = non_negative_number();
  for (const char* ok : {"1e-9", "0.25", "3", "1e300"}) {
    EXPECT_EQ(check(positive, ok), "") << ok;
    EXPECT_EQ(check(non_negative, ok), "") << ok;
  }
  EXPECT_NE(check(positive, "0"), "");
  EXPECT_EQ(check(non_negative, "0"), "");
  for (const char* bad : {"nan", "-nan", "inf", "-inf", "-0.1", "1e999", "0x", "two"}) {
    EXPECT_NE(check(positive, bad).find(fmt::format("not '{}'", bad)), std::string::npos) << bad;
    EXPECT_NE(check(non_negative, bad).find(fmt::format("not '{}'", bad)), std::string::npos) << bad;
  }
}

TEST(NumberWithin, NamesWhatAndTheRange) {
  const CLI::Validator pace = number_within(1e-3, 1e9, "a pace in steps/s");
  EXPECT_EQ(check(pace, "10"), "");
  EXPECT_EQ(check(pace, "nan"), "must be a pace in steps/s from 0.001 to 1000000000, not 'nan'");
  EXPECT_EQ(check(positive_number(), "0"), "must be a finite number above 0, not '0'");
  EXPECT_EQ(check(non_negative_number(), "-1"), "must be a finite number of at least 0, not '-1'");
}

}  // namespace
}  // namespace marsala::cli
