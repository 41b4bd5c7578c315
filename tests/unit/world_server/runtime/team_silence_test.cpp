// The team-silence rule on a clock the test moves, against docs/runtime.md#silence: a silent team holds the step
// until an agent is heard, for up to the limit; then the drop rules apply.

#include "marsala/world_server/runtime/team_silence.hpp"

#include <gtest/gtest.h>

namespace marsala::world_server {
namespace {

using namespace std::chrono_literals;
const TeamSilence::Clock::time_point t0 = TeamSilence::Clock::time_point{} + 5000h;

TEST(TeamSilence, AHeardTeamIsNeverHeld) {
  TeamSilence silence(600s);
  for (auto t = 0s; t < 60s; t += 1s) EXPECT_EQ(silence.observe(true, t0 + t), SilenceVerdict::kHeard);
  EXPECT_FALSE(silence.held());
  EXPECT_EQ(silence.silent_s(t0 + 60s), 0.0);
}

TEST(TeamSilence, HoldsUntilHeardAgain) {
  TeamSilence silence(600s);
  EXPECT_EQ(silence.observe(false, t0), SilenceVerdict::kStarted);
  EXPECT_TRUE(silence.held());
  for (auto t = 1s; t < 60s; t += 1s) ASSERT_EQ(silence.observe(false, t0 + t), SilenceVerdict::kHeld) << t.count();
  EXPECT_TRUE(silence.held());
  EXPECT_DOUBLE_EQ(silence.silent_s(t0 + 60s), 60.0);
  EXPECT_EQ(silence.observe(true, t0 + 60s), SilenceVerdict::kEnded);
  EXPECT_FALSE(silence.held());
  EXPECT_EQ(silence.observe(true, t0 + 61s), SilenceVerdict::kHeard);
  EXPECT_EQ(silence.observe(false, t0 + 62s), SilenceVerdict::kStarted);  // a new silence, a new hold
}

TEST(TeamSilence, GivesUpAtTheLimitOnceThenTheDropRulesApply) {
  TeamSilence silence(10s);
  EXPECT_EQ(silence.observe(false, t0), SilenceVerdict::kStarted);
  EXPECT_EQ(silence.observe(false, t0 + 9999ms), SilenceVerdict::kHeld);
  EXPECT_EQ(silence.observe(false, t0 + 10s), SilenceVerdict::kGivenUp);
  EXPECT_FALSE(silence.held());
  EXPECT_EQ(silence.observe(false, t0 + 11s), SilenceVerdict::kUnheld);
  EXPECT_FALSE(silence.held());
  EXPECT_EQ(silence.observe(true, t0 + 12s), SilenceVerdict::kEnded);  // heard again: a later silence is held anew
  EXPECT_EQ(silence.observe(false, t0 + 13s), SilenceVerdict::kStarted);
  EXPECT_TRUE(silence.held());
}

TEST(TeamSilence, ZeroLimitHoldsForEver) {
  TeamSilence silence(0ms);
  EXPECT_EQ(silence.observe(false, t0), SilenceVerdict::kStarted);
  for (auto t = 1h; t < 1000h; t += 1h) ASSERT_EQ(silence.observe(false, t0 + t), SilenceVerdict::kHeld);
  EXPECT_TRUE(silence.held());
}

}  // namespace
}  // namespace marsala::world_server
