#include "marsala/world_server/runtime/liveliness.hpp"

#include <gtest/gtest.h>

#include <chrono>

namespace marsala::world_server {
namespace {

using namespace std::chrono_literals;
const LivelinessWatch::Clock::time_point t0 = LivelinessWatch::Clock::time_point{} + 5000h;

TEST(Liveliness, AWriterNeverSeenAliveIsNeverDropped) {
  LivelinessWatch watch;
  for (auto t = 0s; t < 60s; t += 1s) EXPECT_EQ(watch.observe(false, t0 + t), LivelinessVerdict::kSteady);
  EXPECT_FALSE(watch.seen());
}

TEST(Liveliness, DropsOnlyAfterSixSecondsNotAliveOnceSeenAlive) {
  LivelinessWatch watch;
  EXPECT_EQ(watch.observe(true, t0), LivelinessVerdict::kSteady);
  EXPECT_TRUE(watch.seen());
  EXPECT_EQ(watch.observe(false, t0 + 1s), LivelinessVerdict::kLost);
  EXPECT_EQ(watch.observe(false, t0 + 4s), LivelinessVerdict::kSteady);
  EXPECT_EQ(watch.observe(false, t0 + 6999ms), LivelinessVerdict::kSteady);
  EXPECT_EQ(watch.observe(false, t0 + 7s), LivelinessVerdict::kDrop);  // 6 s after it was found not alive
}

TEST(Liveliness, AliveAgainResetsTheGrace) {
  LivelinessWatch watch;
  watch.observe(true, t0);
  EXPECT_EQ(watch.observe(false, t0 + 1s), LivelinessVerdict::kLost);
  EXPECT_EQ(watch.observe(true, t0 + 5s), LivelinessVerdict::kBack);  // a process paused for 4 s comes back
  EXPECT_EQ(watch.observe(true, t0 + 6s), LivelinessVerdict::kSteady);
  EXPECT_EQ(watch.observe(false, t0 + 8s), LivelinessVerdict::kLost);  // a new grace from here
  EXPECT_EQ(watch.observe(false, t0 + 13s), LivelinessVerdict::kSteady);
  EXPECT_EQ(watch.observe(false, t0 + 14s), LivelinessVerdict::kDrop);
}

TEST(Liveliness, ForgivingARunningGraceKeepsThatTheWriterWasSeen) {
  LivelinessWatch watch;
  watch.observe(true, t0);
  watch.observe(false, t0 + 1s);
  watch.forgive();  // re-admitted
  EXPECT_TRUE(watch.seen());
  EXPECT_EQ(watch.observe(false, t0 + 10s), LivelinessVerdict::kLost);
  EXPECT_EQ(watch.observe(false, t0 + 16s), LivelinessVerdict::kDrop);
}

}  // namespace
}  // namespace marsala::world_server
