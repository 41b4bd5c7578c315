// The resend rule on a clock the test moves, against docs/runtime.md#resends: no copy while one is in flight or no
// reader is matched, a late reader at once, one repair per step after an interval that doubles up to 4 s and halves
// after 16 quiet steps. The schedules below are written out from the rule, not read from the code.

#include "marsala/world_server/runtime/resend_policy.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace marsala::world_server {
namespace {

using namespace std::chrono_literals;
using Clock = ResendPolicy::Clock;
const Clock::time_point t0 = Clock::time_point{} + 5000h;
constexpr CopyState kDelivered{1, true};
constexpr CopyState kInFlight{1, false};
constexpr CopyState kNoReader{0, true};

// Looks every 100 ms for `length` after a first copy at `start`, writing whatever the rule asks; returns when
// copies were written, as offsets from `start` [ms].
std::vector<long> copies_in_step(ResendPolicy& policy, Clock::time_point start, std::chrono::milliseconds length,
                                 const CopyState& copy) {
  policy.first_copy(start, copy.readers);
  std::vector<long> written;
  for (auto t = 0ms; t <= length; t += 100ms) {
    const Resend what = policy.look(start + t, copy);
    if (what == Resend::kNone) continue;
    policy.copied(what, start + t, copy.readers);
    written.push_back(static_cast<long>(t.count()));
  }
  return written;
}

TEST(ResendPolicy, NothingWhileACopyIsInFlightHoweverLong) {
  ResendPolicy policy;
  EXPECT_TRUE(copies_in_step(policy, t0, 60s, kInFlight).empty());
  EXPECT_EQ(policy.resends(), 0u);
}

TEST(ResendPolicy, NothingWithoutAReader) {
  ResendPolicy policy;
  EXPECT_TRUE(copies_in_step(policy, t0, 60s, kNoReader).empty());
}

TEST(ResendPolicy, ADeliveredFrameIsRepairedOncePerStep) {
  ResendPolicy policy;
  EXPECT_EQ(copies_in_step(policy, t0, 10s, kDelivered), (std::vector<long>{500}));
  EXPECT_EQ(policy.resends(), 1u);
}

TEST(ResendPolicy, TheRepairIntervalDoublesUpToFourSeconds) {
  ResendPolicy policy;
  const std::vector<long> expected{500, 1000, 2000, 4000, 4000, 4000};
  for (std::size_t step = 0; step < expected.size(); ++step) {
    const auto start = t0 + std::chrono::hours(step);
    EXPECT_EQ(copies_in_step(policy, start, 10s, kDelivered), (std::vector<long>{expected[step]})) << step;
  }
  EXPECT_EQ(policy.interval(), 4000ms);
}

TEST(ResendPolicy, SixteenQuietStepsHalveTheInterval) {
  ResendPolicy policy;
  for (int step = 0; step < 4; ++step) copies_in_step(policy, t0 + std::chrono::hours(step), 10s, kDelivered);
  ASSERT_EQ(policy.interval(), 4000ms);
  // Answered at once: a first copy and no look.
  for (int step = 0; step < 16; ++step) policy.first_copy(t0 + std::chrono::hours(10 + step), 1);
  EXPECT_EQ(policy.interval(), 4000ms);  // the 16th quiet step is counted when the 17th begins
  policy.first_copy(t0 + 30h, 1);
  EXPECT_EQ(policy.interval(), 2000ms);
  for (int step = 0; step < 64; ++step) policy.first_copy(t0 + std::chrono::hours(40 + step), 1);
  EXPECT_EQ(policy.interval(), kFirstRepairInterval);
}

// An agent that took the step's copies while it did not trust this world yet (a resumed world answers from a new
// participant) asks again after its repair: each ask is one copy at the next look, never one while a copy is in flight,
// and the ask is spent by the copy.
TEST(ResendPolicy, AnAgentThatAsksAgainGetsOneCopyPerAsk) {
  ResendPolicy policy;
  policy.first_copy(t0, 1);
  EXPECT_EQ(policy.look(t0 + 500ms, kDelivered), Resend::kRepair);
  policy.copied(Resend::kRepair, t0 + 500ms, 1);
  EXPECT_EQ(policy.look(t0 + 2000ms, kDelivered), Resend::kNone);  // the step's one repair is spent
  policy.asked();
  EXPECT_EQ(policy.look(t0 + 2100ms, kInFlight), Resend::kNone);  // a copy on its way answers the ask
  EXPECT_EQ(policy.look(t0 + 2200ms, kDelivered), Resend::kAsked);
  policy.copied(Resend::kAsked, t0 + 2200ms, 1);
  EXPECT_EQ(policy.look(t0 + 2300ms, kDelivered), Resend::kNone);
  EXPECT_EQ(policy.interval(), 1000ms);  // an ask is no repair: the back-off stays where the repair left it
  policy.asked();
  EXPECT_EQ(policy.look(t0 + 4300ms, kDelivered), Resend::kAsked);
  EXPECT_EQ(policy.resends(), 2u);  // the repair and the first ask's copy
}

TEST(ResendPolicy, AReaderMatchedAfterTheCopyGetsOneAtOnce) {
  ResendPolicy policy;
  policy.first_copy(t0, 0);  // written before the agent's reader matched: nobody got it
  EXPECT_EQ(policy.look(t0 + 100ms, kNoReader), Resend::kNone);
  EXPECT_EQ(policy.look(t0 + 200ms, kDelivered), Resend::kLateReader);
  policy.copied(Resend::kLateReader, t0 + 200ms, 1);
  EXPECT_EQ(policy.look(t0 + 300ms, kInFlight), Resend::kNone);
  // Its repair comes an interval after that copy, and only once.
  EXPECT_EQ(policy.look(t0 + 600ms, kDelivered), Resend::kNone);
  EXPECT_EQ(policy.look(t0 + 700ms, kDelivered), Resend::kRepair);
  policy.copied(Resend::kRepair, t0 + 700ms, 1);
  EXPECT_EQ(policy.look(t0 + 5s, kDelivered), Resend::kNone);
  EXPECT_EQ(policy.resends(), 2u);
}

TEST(ResendPolicy, AReaderThatLeftAndMatchedAgainIsLate) {
  ResendPolicy policy;
  policy.first_copy(t0, 1);
  EXPECT_EQ(policy.look(t0 + 100ms, kInFlight), Resend::kNone);
  EXPECT_EQ(policy.look(t0 + 200ms, kNoReader), Resend::kNone);  // its participant's lease ran out
  EXPECT_EQ(policy.look(t0 + 300ms, kDelivered), Resend::kLateReader);
}

TEST(ResendPolicy, ASlowLinkGetsOneCopyPerStep) {
  // The frame is in flight for 3 s, then acknowledged; the agent answers 1 s later: no copy besides the first.
  ResendPolicy policy;
  policy.first_copy(t0, 1);
  int written = 0;
  for (auto t = 0ms; t < 4s; t += 100ms) {
    const Resend what = policy.look(t0 + t, t < 3s ? kInFlight : kDelivered);
    // A repair may come only once the copy was delivered and the interval has passed since it was written.
    if (what != Resend::kNone) {
      EXPECT_GE(t, 3s);
      ++written;
      policy.copied(what, t0 + t, 1);
    }
  }
  EXPECT_LE(written, 1);
  EXPECT_LE(policy.resends(), 1u);
}

}  // namespace
}  // namespace marsala::world_server
