// The world watch on a clock the test moves: liveliness, the silence said after the grace, the silence limit, pauses of
// the process and the hellos of a silence, each against times worked out from docs/runtime.md's rules.

#include "marsala/agent/runtime/world_watch.hpp"

#include <gtest/gtest.h>

#include <vector>

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

/// The times (from kT0) of the hellos `watch` asks for on turns every 100 ms in [from, to), the world answering each
/// one at once when `answer` (a world still admitting its team: it counts this agent in and sends no frame yet).
std::vector<Clock::duration> hellos_between(WorldWatch& watch, Clock::duration from, Clock::duration to, bool answer) {
  std::vector<Clock::duration> at;
  for (Clock::duration t = from; t < to; t += 100ms) {
    if (!watch.turn(kT0 + t, kAlive).hello) continue;
    at.push_back(t);
    if (answer) watch.answered();
  }
  return at;
}

TEST(WorldWatch, EachAnswerThatTheWorldStillCountsTheAgentInDoublesTheGapUpToTheRecheck) {
  WorldWatch watch(kT0, 60s, 200ms);  // a silence limit beyond the test's minute
  // First hello at 2 s, then gaps 0.2, 0.4, 0.8, 1.6, 3.2, 6.4 s, then kStillInRecheck (8 s).
  const std::vector<Clock::duration> expected = {2000ms, 2200ms, 2600ms, 3400ms, 5000ms,
                                                 8200ms, 14600ms, 22600ms, 30600ms};
  EXPECT_EQ(hellos_between(watch, 100ms, 31s, true), expected);
  // A frame ends the silence: the next one starts over at the hello period.
  watch.frame(kT0 + 31s);
  const std::vector<Clock::duration> again = {33000ms, 33200ms};  // 2 s after the frame, then the hello period
  EXPECT_EQ(hellos_between(watch, 31100ms, 33500ms, true), again);
  // Unanswered hellos (the world silent) keep the hello period.
  WorldWatch unanswered = watch_from_t0();
  EXPECT_EQ(hellos_between(unanswered, 100ms, 3s, false).size(), 5u);  // 2.0, 2.2, 2.4, 2.6, 2.8 s
}

TEST(WorldWatch, AWorldSteppingSlowlyIsAskedOnlyAfterThreeTimesItsRecentPace) {
  WorldWatch watch = watch_from_t0();
  // Frames 3 s apart (a crowd on a loaded host): no hello between them; before, one went 2 s after each frame. The
  // pace needs a gap first: 1 s, then 2.5 s (under 3 x 1 s), then 3 s (under 3 x 2.5 s).
  const std::vector<Clock::duration> frames = {1000ms, 2000ms, 4500ms, 7500ms, 10500ms, 13500ms};
  Clock::duration last{0};
  for (const Clock::duration f : frames) {
    EXPECT_TRUE(hellos_between(watch, last + 100ms, f, true).empty()) << "before the frame at " << f.count();
    watch.frame(kT0 + f);
    last = f;
  }
  EXPECT_EQ(watch.quiet_limit(), Clock::duration(kPaceMultiple * 3s));
  // Silent after the frame at 13.5 s: asked at 13.5 + 9 s.
  const std::vector<Clock::duration> first = hellos_between(watch, 13600ms, 25s, true);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front(), 22500ms);
  // The pace follows the latest kPaceFrames gaps: fast frames again bring it back to kRehelloAfter.
  for (std::size_t k = 1; k <= kPaceFrames + 1; ++k) watch.frame(kT0 + 25s + 100ms * k);
  EXPECT_EQ(watch.quiet_limit(), Clock::duration(kRehelloAfter));
  // And a world pausing for minutes is still asked after kLongestPace at the latest.
  WorldWatch paused = watch_from_t0();
  paused.frame(kT0 + 1s);
  paused.frame(kT0 + 1s + 10min);
  EXPECT_EQ(paused.quiet_limit(), Clock::duration(kLongestPace));
}

TEST(WorldWatch, BeforeTheFirstFrameTheWorldAdmittingOthersPutsTheQuestionOffByTheAgentsStagger) {
  EXPECT_EQ(admitting_stagger(16), 0ms);
  EXPECT_EQ(admitting_stagger(1), 250ms);
  EXPECT_EQ(admitting_stagger(15), 3750ms);
  // Admitted at kT0, no frame yet; the world admits or answers another agent every 1.5 s until 9 s: this agent (stagger
  // 500 ms) does not ask meanwhile, where it asked at 2 s before; then it asks 2.5 s after the last of them.
  WorldWatch watch = watch_from_t0();
  std::vector<Clock::duration> hellos;
  for (Clock::duration t = 100ms; t < 15s; t += 100ms) {
    if (t <= 9s && t % 1500ms == 0ms) watch.answered_another(kT0 + t, 500ms);
    const WatchTurn turn = watch.turn(kT0 + t, kNotAlive);
    EXPECT_FALSE(turn.silent_s.has_value()) << "the world admitting others is heard, at " << t.count() << " ms";
    if (turn.hello) hellos.push_back(t);
  }
  ASSERT_FALSE(hellos.empty());
  EXPECT_EQ(hellos.front(), 11500ms);  // the last admission of another at 9 s, + kRehelloAfter + 500 ms
  // Once frames come, the world admitting others puts nothing off: asked kRehelloAfter after the last frame.
  WorldWatch running = watch_from_t0();
  for (Clock::duration t = 100ms; t < 3s; t += 100ms) {
    if (t == 1s) running.frame(kT0 + t);
    if (t == 2500ms) running.answered_another(kT0 + t, 500ms);
    EXPECT_FALSE(running.turn(kT0 + t, kAlive).hello) << t.count() << " ms";
  }
  EXPECT_TRUE(running.turn(kT0 + 3s, kAlive).hello);
}

// docs/runtime.md#standing-answers: while the agent's answer stands the world writes no frame. A live world's signs
// keep the silence limit away however long; the agent asks whether it is still counted in only kStandingRecheck after
// its last frame (and again after the next frame, which answers); a world whose writer is gone times out 20 s after
// its last sign; the held-back gap sets no pace for the frames after.
TEST(WorldWatch, WhileTheAnswerStandsALiveWorldIsAskedOnlyAtTheRecheckAndNeverTimedOut) {
  WorldWatch watch = watch_from_t0();
  watch.frame(kT0 + 100ms);
  watch.standing(true);
  std::vector<Clock::duration> hellos;
  for (Clock::duration t = 200ms; t < 100ms + kStandingRecheck + 1s; t += 100ms) {
    const WatchTurn turn = watch.turn(kT0 + t, kAlive);
    ASSERT_EQ(turn.state, WorldState::kWatching) << t.count();
    if (turn.hello) hellos.push_back(t);
  }
  ASSERT_EQ(hellos.size(), 5u) << "from the recheck on, every hello period (200 ms) until answered";
  EXPECT_EQ(hellos.front(), 100ms + kStandingRecheck);
  // The world answers with the next frame; the answer stands again: no question for another kStandingRecheck, and
  // a live world is not timed out (20 s) in between.
  EXPECT_TRUE(watch.frame(kT0 + 31200ms));
  for (Clock::duration t = 31300ms; t < 31200ms + kStandingRecheck; t += 100ms) {
    const WatchTurn turn = watch.turn(kT0 + t, kAlive);
    ASSERT_EQ(turn.state, WorldState::kWatching) << t.count();
    ASSERT_FALSE(turn.hello) << t.count();
  }
  // The world's writer goes: timed out 20 s after its last sign.
  WorldState end = WorldState::kWatching;
  Clock::duration ended{};
  for (Clock::duration t = 61200ms; t <= 90s && end == WorldState::kWatching; t += 100ms) {
    end = watch.turn(kT0 + t, kNotAlive).state;
    ended = t;
  }
  EXPECT_EQ(end, WorldState::kWorldTimeout);
  EXPECT_EQ(ended, 61100ms + 20s);
  // Frames every 100 ms after the answer stood no longer: the long gap set no pace (asked kRehelloAfter after them).
  WorldWatch after = watch_from_t0();
  after.frame(kT0 + 100ms);
  after.standing(true);
  for (Clock::duration t = 200ms; t < 20s; t += 100ms) (void)after.turn(kT0 + t, kAlive);
  after.frame(kT0 + 20s);
  after.standing(false);
  after.frame(kT0 + 20100ms);
  Clock::duration asked{};
  for (Clock::duration t = 20200ms; t < 40s && asked == Clock::duration{}; t += 100ms)
    if (after.turn(kT0 + t, kAlive).hello) asked = t;
  EXPECT_EQ(asked, 20100ms + kRehelloAfter);
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
