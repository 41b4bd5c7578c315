// The admit deadline on a clock the test moves: a timeout from the start, again from each sign of progress, never
// earlier, and kAdmitProgressCap timeouts from the start at the most.

#include "marsala/protocol/admit_deadline.hpp"

#include <gtest/gtest.h>

namespace marsala::protocol {
namespace {

using namespace std::chrono_literals;
using Clock = AdmitDeadline::Clock;

const Clock::time_point kT0 = Clock::time_point{} + 1h;

TEST(AdmitDeadline, ATimeoutFromTheLatestProgressUpToTheCap) {
  AdmitDeadline wait(kT0, 10s);
  EXPECT_EQ(wait.deadline(), kT0 + 10s);
  wait.progress(kT0 + 4s);
  EXPECT_EQ(wait.deadline(), kT0 + 14s);
  wait.progress(kT0 + 2s);  // older news: the deadline never moves back
  EXPECT_EQ(wait.deadline(), kT0 + 14s);
  for (auto t = 10s; t <= 120s; t += 10s) wait.progress(kT0 + t);  // progress for ever
  EXPECT_EQ(wait.deadline(), kT0 + kAdmitProgressCap * 10s);
}

}  // namespace
}  // namespace marsala::protocol
