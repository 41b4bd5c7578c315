// The world watch on a clock the test moves: liveliness, the silence said after the grace, the silence limit, pauses of
// the process and the hellos of a silence, each against times worked out from docs/runtime.md's rules.

#include "marsala/agent/runtime/world_watch.hpp"

#include <gtest/gtest.h>

namespace marsala::agent::runtime {
namespace {

using namespace std::chrono_literals;
using Clock = WorldWatch::Clock;

const Clock::time_point kT0 = Clock::time_point{} + 1h;
const auto kAlive = [] { return true; };
const auto kNotAlive = [] { return false; };

WorldWatch watch_from_t0() { return WorldWatch(kT0, 20s, 200ms); }

TEST(WorldWatch, NeverSeenWorldIsNeverGoneButTimesOut) {
  WorldWatch watch = watch_from_t0();
  // Turns every 100 ms without any sign: the world was never seen, so only the silence limit (20 s) ends the watch.
  for (auto t = 100ms; t < 20s; t += 100ms)
    ASSERT_EQ(watch.turn(kT0 + t, kNotAlive).state, WorldState::kWatching) << t.count() << " ms";
  EXPECT_EQ(watch.turn(kT0 + 20s, kNotAlive).state, WorldState::kWorldTimeout);
}

TEST(WorldWatch, ASeenWorldSilentForTheGraceIsSaidOnceAndNeverGivenUp) {
  WorldWatch watch = watch_from_t0();
  ASSERT_EQ(watch.turn(kT0 + 100ms, kAlive).state, WorldState::kWatching);  // the last sign, at 0.1 s
  int said = 0;
  for (auto t = 200ms; t < 100ms + kWorldGrace; t += 100ms) {
    const WatchTurn turn = watch.turn(kT0 + t, kNotAlive);
    ASSERT_EQ(turn.state, WorldState::kWatching) << t.count() << " ms";
    said += turn.silent_s.has_value();
  }
  EXPECT_EQ(said, 0);
  const WatchTurn silent = watch.turn(kT0 + 100ms + kWorldGrace, kNotAlive);
  EXPECT_EQ(silent.state, WorldState::kWatching);
  ASSERT_TRUE(silent.silent_s.has_value());
  EXPECT_DOUBLE_EQ(*silent.silent_s, 6.0);
  // Silent on: never said again, and only the silence limit (20 s after the start: no frame ever came) ends it.
  for (auto t = 200ms + kWorldGrace; t < 20s; t += 100ms) {
    const WatchTurn turn = watch.turn(kT0 + t, kNotAlive);
    ASSERT_EQ(turn.state, WorldState::kWatching) << t.count() << " ms";
    ASSERT_FALSE(turn.silent_s.has_value()) << t.count() << " ms";
  }
  // Heard again at 19.9 s: the silence lasted from the last sign at 0.1 s.
  const WatchTurn heard = watch.turn(kT0 + 19900ms, kAlive);
  ASSERT_TRUE(heard.heard_s.has_value());
  EXPECT_DOUBLE_EQ(*heard.heard_s, 19.8);
  EXPECT_EQ(watch.turn(kT0 + 20s, kAlive).state, WorldState::kWorldTimeout);
}

TEST(WorldWatch, ZeroWorldTimeoutWaitsForEver) {
  WorldWatch watch(kT0, 0ms, 200ms);
  ASSERT_EQ(watch.turn(kT0 + 100ms, kAlive).state, WorldState::kWatching);
  // A day of silence, a turn every 100 ms: no limit ends it, and the next wake-up is the next hello (200 ms on).
  for (auto t = 200ms; t < 24h; t += 100ms)
    ASSERT_EQ(watch.turn(kT0 + t, kNotAlive).state, WorldState::kWatching) << t.count() << " ms";
  const auto last = kT0 + 24h - 100ms;
  EXPECT_GT(watch.wake_by(), last);
  EXPECT_LE(watch.wake_by(), last + 200ms);
}

TEST(WorldWatch, FramesAndAnswersAreSignsWithoutAskingLiveliness) {
  WorldWatch watch = watch_from_t0();
  int queries = 0;
  const auto counted = [&] { return ++queries, false; };
  watch.frame(kT0 + 50ms);
  ASSERT_EQ(watch.turn(kT0 + 100ms, counted).state, WorldState::kWatching);
  EXPECT_EQ(queries, 0);  // a frame since the last turn spares the status query
  // From then on only answers to hellos: each spares the query and keeps the world alive past the grace.
  for (auto t = 200ms; t <= 10s; t += 100ms) {
    watch.answered();
    ASSERT_EQ(watch.turn(kT0 + t, counted).state, WorldState::kWatching) << t.count() << " ms";
  }
  EXPECT_EQ(queries, 0);
  // No sign since: the query is made every turn, and the world is said silent a grace after the last answer.
  for (auto t = 10100ms; t < 10s + kWorldGrace; t += 100ms)
    ASSERT_FALSE(watch.turn(kT0 + t, counted).silent_s.has_value()) << t.count() << " ms";
  EXPECT_EQ(queries, 59);
  EXPECT_TRUE(watch.turn(kT0 + 10s + kWorldGrace, counted).silent_s.has_value());
}

TEST(WorldWatch, APauseOfTheProcessGivesAFreshGraceAndAsksAtOnce) {
  WorldWatch watch = watch_from_t0();
  ASSERT_EQ(watch.turn(kT0 + 100ms, kAlive).state, WorldState::kWatching);
  // The process did not run from 0.1 s to 5.5 s: no conclusion from what it could not see, and a hello at once.
  const WatchTurn after_pause = watch.turn(kT0 + 5500ms, kNotAlive);
  EXPECT_EQ(after_pause.state, WorldState::kWatching);
  ASSERT_TRUE(after_pause.paused_s.has_value());
  EXPECT_DOUBLE_EQ(*after_pause.paused_s, 5.4);
  EXPECT_TRUE(after_pause.hello);
  EXPECT_FALSE(after_pause.no_frame_s.has_value());  // the pause's hello, not a silence's first
  EXPECT_TRUE(watch.asked());
  for (auto t = 5600ms; t < 5500ms + kWorldGrace; t += 100ms)
    ASSERT_FALSE(watch.turn(kT0 + t, kNotAlive).silent_s.has_value()) << t.count() << " ms";
  EXPECT_TRUE(watch.turn(kT0 + 5500ms + kWorldGrace, kNotAlive).silent_s.has_value());
}

TEST(WorldWatch, ASilenceAsksEveryHelloPeriodUntilAFrame) {
  WorldWatch watch = watch_from_t0();
  int hellos = 0;
  for (auto t = 100ms; t < kRehelloAfter; t += 100ms) hellos += watch.turn(kT0 + t, kAlive).hello;
  EXPECT_EQ(hellos, 0);
  EXPECT_FALSE(watch.asked());
  EXPECT_EQ(watch.wake_by(), kT0 + 20s);  // not asking: only the silence limit
  const WatchTurn first = watch.turn(kT0 + kRehelloAfter, kAlive);
  EXPECT_TRUE(first.hello);
  ASSERT_TRUE(first.no_frame_s.has_value());
  EXPECT_DOUBLE_EQ(*first.no_frame_s, 2.0);
  EXPECT_EQ(watch.wake_by(), kT0 + kRehelloAfter + 200ms);  // asking: the next hello
  const WatchTurn early = watch.turn(kT0 + kRehelloAfter + 100ms, kAlive);
  EXPECT_FALSE(early.hello);
  const WatchTurn second = watch.turn(kT0 + kRehelloAfter + 200ms, kAlive);
  EXPECT_TRUE(second.hello);
  EXPECT_FALSE(second.no_frame_s.has_value());  // the silence was said once
  EXPECT_TRUE(watch.frame(kT0 + 2300ms));       // frames again after asking
  EXPECT_FALSE(watch.asked());
  EXPECT_FALSE(watch.frame(kT0 + 2400ms));
  for (auto t = 2500ms; t < 4400ms; t += 100ms) EXPECT_FALSE(watch.turn(kT0 + t, kAlive).hello) << t.count() << " ms";
  EXPECT_TRUE(watch.turn(kT0 + 4400ms, kAlive).hello);
}

TEST(WorldWatch, AFrameRestartsTheSilenceLimit) {
  WorldWatch watch = watch_from_t0();
  watch.frame(kT0 + 15s);
  EXPECT_EQ(watch.turn(kT0 + 15s + 100ms, kAlive).state, WorldState::kWatching);
  for (auto t = 15200ms; t < 35s; t += 100ms) watch.answered(), (void)watch.turn(kT0 + t, kAlive);
  EXPECT_EQ(watch.turn(kT0 + 35s - 1ms, kAlive).state, WorldState::kWatching);
  EXPECT_EQ(watch.turn(kT0 + 35s, kAlive).state, WorldState::kWorldTimeout);
}

}  // namespace
}  // namespace marsala::agent::runtime
