#include "marsala/agent/reactive/right_of_way.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace marsala::agent::reactive {
namespace {

Neighbour at(std::uint32_t id, double x, double y) { return {id, {x, y}, 0.0, 0.3}; }

// Lane::contains() skips the points beyond the segment's box widened by the radius: it agrees with the capsule's
// own test (the nearest point of the segment within the radius, within()) on points all round lanes of every
// direction, zero length included, and on the capsule's rim.
TEST(Lane, ContainsIsTheCapsuleTest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  long long inside = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Position from{20.0 + 3.0 * u(rng), -7.0 + 3.0 * u(rng)};
    const Position to = trial % 10 == 0 ? from : Position{from.x + 2.0 * u(rng), from.y + 2.0 * u(rng)};
    const Lane lane{from, to, 0.3 + 0.4 * (u(rng) + 1.0)};
    for (int k = 0; k < 200; ++k) {
      Position p{std::min(from.x, to.x) - 1.5 + (std::abs(to.x - from.x) + 3.0) * 0.5 * (u(rng) + 1.0),
                 std::min(from.y, to.y) - 1.5 + (std::abs(to.y - from.y) + 3.0) * 0.5 * (u(rng) + 1.0)};
      if (k % 4 == 0) {  // on the rim round an end
        const double a = 3.14159 * u(rng);
        p = {to.x + lane.radius_m * std::cos(a), to.y + lane.radius_m * std::sin(a)};
      }
      const double dx = to.x - from.x, dy = to.y - from.y, l2 = dx * dx + dy * dy;
      const double t = l2 > 0.0 ? std::clamp(((p.x - from.x) * dx + (p.y - from.y) * dy) / l2, 0.0, 1.0) : 0.0;
      const bool capsule = within(p.x - (from.x + t * dx), p.y - (from.y + t * dy), lane.radius_m);
      EXPECT_EQ(lane.contains(p), capsule) << trial << " " << k;
      inside += capsule;
    }
  }
  EXPECT_GT(inside, 1000);
}

TEST(RightOfWay, ARobotAtItsGoalGivesWayOnceToOneThatWaitsBesideIt) {
  RightOfWay parked(1, 1.6, 0.9, 6);
  int first = -1, episodes = 0;
  bool was_giving = false;
  for (int frame = 0; frame < 300; ++frame) {
    // The other robot drives along y = 4 (out of contact, 0.2 m a frame) until frame 100, then stands beside the
    // parked one for good (it waits for it: the way it wants runs through it).
    const Neighbour other = frame < 100 ? at(2, 0.2 * frame - 10.0, 4.0) : at(2, 2.1, 2.3);
    parked.observe({2.7, 1.7}, {other}, true, 0.0, 0.1);
    const bool giving = parked.giving_way().has_value();
    if (giving && first < 0) first = frame;
    if (giving && !was_giving) ++episodes;
    was_giving = giving;
  }
  // It has waited kStillFrames frames after arriving in frame 100; one episode only: where the other still waits
  // after it, it waits for something else.
  EXPECT_EQ(first, 100 + kStillFrames);
  EXPECT_EQ(episodes, 1);
}

// Robot 2 beside a robot parked at its goal at (2.7, 1.7): it holds (stands still kStillFrames + an episode = 22
// frames) at (2.1, 2.3), tries for 10 frames (0.2 m back and forth) and holds there again, four times.
Neighbour holder_at(int frame) {
  const int cycle = frame % 32;
  return cycle < 22 ? at(2, 2.1, 2.3) : at(2, 2.1 - (cycle < 27 ? 0.04 * (cycle - 21) : 0.04 * (32 - cycle)), 2.3);
}

TEST(RightOfWay, ARobotAtItsGoalGivesWayEveryTimeAWaitingRobotHolds) {
  RightOfWay parked(1, 1.6, 0.9, 6);
  int episodes = 0;
  bool was_giving = false;
  for (int frame = 0; frame < 4 * 32; ++frame) {
    // Parked: on its goal, except while it gives way (it does not move here: the episode counts all the same).
    parked.observe({2.7, 1.7}, {holder_at(frame)}, !parked.giving_way() && !parked.standing_aside(), 0.0, 0.1);
    const bool giving = parked.giving_way().has_value();
    if (giving && !was_giving) ++episodes;
    was_giving = giving;
  }
  // Each hold is seen from its kStillFrames-th frame to its last: one episode per hold after the first, whose
  // first frames the parked robot spends loitering (it has to have stood still kStillFrames itself). An episode from
  // the goal lasts three episodes (18 frames) plus its standing aside, within one 32-frame cycle.
  EXPECT_GE(episodes, 3);
}

TEST(RightOfWay, AfterGivingWayFromItsGoalARobotStandsAsideWhileTheOtherDrivesPast) {
  RightOfWay parked(1, 1.6, 0.9, 6);
  // Robot 2 holds beside it until the parked robot gives way.
  for (int frame = 0; frame < 100 && !parked.giving_way(); ++frame)
    parked.observe({2.7, 1.7}, {at(2, 2.1, 2.3)}, true, 0.0, 0.1);
  ASSERT_TRUE(parked.giving_way());
  // The episode lasts three episodes of frames (it stays where it is here); robot 2 ends its hold after 5 of them
  // and drives on, 0.03 m a frame, in contact.
  const auto other = [](int k) { return at(2, 2.1 + 0.03 * std::max(0, k - 5), 2.3); };
  int k = 0;
  for (; k < 3 * 6; ++k) parked.observe({3.5, 1.0}, {other(k)}, false, 1.0, 0.1);
  EXPECT_FALSE(parked.giving_way());
  // After the episode the robot stands aside while robot 2 still drives (it does not cut back in) ...
  int aside = 0;
  for (; k < 30; ++k) {
    parked.observe({3.5, 1.0}, {other(k)}, false, 1.0, 0.1);
    aside += parked.standing_aside() ? 1 : 0;
  }
  EXPECT_EQ(aside, 30 - 3 * 6);
  // ... until robot 2 stands still (one last motion, then kMovingFrames frames).
  for (int still = 0; still <= kMovingFrames; ++still) parked.observe({3.5, 1.0}, {other(30)}, false, 1.0, 0.1);
  EXPECT_FALSE(parked.standing_aside());
}

TEST(RightOfWay, ARobotOffItsGoalToGiveWayKeepsOutOfEveryLaneUntilItIsBack) {
  RightOfWay parked(1, 1.6, 0.9, 6);
  for (int frame = 0; frame < 100 && !parked.giving_way(); ++frame)
    parked.observe({2.7, 1.7}, {at(2, 2.1, 2.3)}, true, 0.0, 0.1);
  ASSERT_TRUE(parked.giving_way());
  // Robot 2 (a higher id) drives on: off its goal, robot 1 keeps out of robot 2's lane ...
  parked.observe({3.5, 1.0}, {at(2, 2.2, 2.3)}, false, 1.0, 0.1);
  EXPECT_EQ(parked.lanes(3.0, 0.5).size(), 1u);
  // ... and once back on its goal it has the lowest priority there anyway: no lanes of higher ids.
  RightOfWay fresh(1, 1.6, 0.9, 6);
  fresh.observe({3.5, 1.0}, {at(2, 2.1, 2.3)}, false, 1.0, 0.1);
  fresh.observe({3.5, 1.0}, {at(2, 2.2, 2.3)}, false, 1.0, 0.1);
  EXPECT_TRUE(fresh.lanes(3.0, 0.5).empty());  // a robot that never gave way from its goal: lower ids' lanes only
  parked.observe({2.7, 1.7}, {at(2, 2.3, 2.3)}, true, 0.0, 0.1);
  EXPECT_TRUE(parked.lanes(3.0, 0.5).empty());
}

TEST(RightOfWay, ARobotParkedOutOfRangeForAWhileDoesNotHoldAgainWhenSeenAgain) {
  RightOfWay r(2, 1.6, 0.9, 6);
  // Robot 1 is parked at (2, 1); robot 2 stands beside it, goes out of range for 30 frames and comes back: robot 1
  // has stood still all along (more than a hold lasts), so it holds for no one and robot 2 never gives way to it.
  for (int frame = 0; frame < 200; ++frame) {
    const bool away = frame >= 60 && frame < 90;
    r.observe(away ? Position{9.0, 1.0} : Position{3.0, 1.0}, away ? std::vector<Neighbour>{} : std::vector{at(1, 2.0, 1.0)},
              false, 5.0, 0.1);
    if (frame >= 2 * (kStillFrames + 6)) {
      EXPECT_FALSE(r.giving_way().has_value()) << frame;
    }
  }
}

TEST(RightOfWay, ARobotThatMakesNoWayHoldsUnlessItBuilds) {
  RightOfWay idle(2, 1.6, 0.9, 6), builder(2, 1.6, 0.9, 6);
  int idle_first = -1;
  for (int frame = 0; frame < 100; ++frame) {
    // Both stand 1 m from robot 3, 5 m from where they go, and come no nearer; the builder deposits every frame.
    idle.observe({1.0, 1.0}, {at(3, 2.0, 1.0)}, false, 5.0, 0.1);
    builder.observe({1.0, 1.0}, {at(3, 2.0, 1.0)}, false, 5.0, 0.1, true);
    if (idle.holding() && idle_first < 0) idle_first = frame;
    EXPECT_FALSE(builder.holding()) << frame;
  }
  // The first frame has no distance to beat and counts as a frame without progress: kStuckFrames of them end with
  // frame kStuckFrames - 1.
  EXPECT_EQ(idle_first, kStuckFrames - 1);
}

TEST(RightOfWay, ARobotWhoseGoalMovesOnMeasuresItsWayToEachGoalAfresh) {
  RightOfWay fresh(2, 1.6, 0.9, 6), stale(2, 1.6, 0.9, 6);
  int stale_first = -1;
  for (int frame = 0; frame < 100; ++frame) {
    // Both go back and forth along x within 0.8 m of robot 3 (in contact). Their goal is the head of the arrow
    // they are on, 2 m ahead at the start of each 8-frame leg, so each leg ends 0.4 m nearer its own goal (progress),
    // but never nearer than 1.6 m: measured against the best distance of the earlier legs that is no way made.
    const int leg = frame / 8, in_leg = frame % 8;
    const double dir = leg % 2 == 0 ? 1.0 : -1.0;
    const double start = leg % 2 == 0 ? 0.0 : 0.4;
    const Position self{start + dir * 0.05 * in_leg, 1.0};
    const double to_go = 2.0 - 0.05 * in_leg;
    fresh.observe(self, {at(3, 0.2, 1.5)}, false, to_go, 0.1, false, in_leg == 0);
    stale.observe(self, {at(3, 0.2, 1.5)}, false, to_go, 0.1);
    EXPECT_FALSE(fresh.holding()) << frame;
    if (stale.holding() && stale_first < 0) stale_first = frame;
  }
  EXPECT_GE(stale_first, 0);  // the same robot without new goals holds: the test tells the two apart
}

TEST(RightOfWay, TwoRobotsParkedAtTheirGoalsSideBySideStayParked) {
  RightOfWay a(1, 1.6, 0.9, 6), b(2, 1.6, 0.9, 6);
  for (int frame = 0; frame < 300; ++frame) {
    a.observe({1.0, 1.0}, {at(2, 2.0, 1.0)}, true, 0.0, 0.1);
    b.observe({2.0, 1.0}, {at(1, 1.0, 1.0)}, true, 0.0, 0.1);
    // Both stand still from the first frame: each sees the other hold only in frames 16..22, and gives way then
    // (each may be in the other's way); afterwards neither waits for anyone.
    if (frame > kStillFrames + 6) {
      EXPECT_FALSE(a.giving_way().has_value() && frame > 3 * (kStillFrames + 6)) << frame;
    }
  }
}

TEST(RightOfWay, TheLowerIdGoesFirstAndTheHigherGivesWay) {
  RightOfWay low(1, 1.6, 0.9, 6), high(2, 1.6, 0.9, 6);
  bool low_gave = false;
  std::optional<Position> high_gave;
  for (int frame = 0; frame < 40; ++frame) {
    low.observe({1.0, 1.0}, {at(2, 2.0, 1.0)}, false, 5.0, 0.1);
    high.observe({2.0, 1.0}, {at(1, 1.0, 1.0)}, false, 5.0, 0.1);
    low_gave = low_gave || low.giving_way().has_value();
    if (!high_gave) high_gave = high.giving_way();
  }
  EXPECT_FALSE(low_gave);
  ASSERT_TRUE(high_gave);
  EXPECT_DOUBLE_EQ(high_gave->x, 1.0);  // away from the robot it gives way to
}

TEST(RightOfWay, NobodyGivesWayToARobotOutOfContactOrOnItsWay) {
  RightOfWay far(2, 1.6, 0.9, 6), moving(2, 1.6, 0.9, 6);
  for (int frame = 0; frame < 60; ++frame) {
    far.observe({5.0, 1.0}, {at(1, 1.0, 1.0)}, false, 5.0, 0.1);
    moving.observe({2.0, 1.0}, {at(1, 0.1 * frame, 3.0)}, false, 5.0, 0.1);  // passing by, 0.1 m a frame
    EXPECT_FALSE(far.giving_way());
    EXPECT_FALSE(moving.giving_way());
  }
}

TEST(RightOfWay, AMovingLowerIdReservesItsWayAhead) {
  RightOfWay r(3, 1.6, 0.9, 6);
  r.observe({5.0, 1.0}, {at(1, 1.0, 1.0), at(4, 1.0, 2.0)}, false, 5.0, 0.1);
  r.observe({5.0, 1.0}, {at(1, 1.2, 1.0), at(4, 1.2, 2.0)}, false, 5.0, 0.1);
  const auto lanes = r.lanes(3.0, 0.5);
  ASSERT_EQ(lanes.size(), 1u);  // robot 4 has a higher id: no lane
  EXPECT_TRUE(lanes[0].contains({4.0, 1.0}));
  EXPECT_TRUE(lanes[0].contains({4.2, 1.7}));   // 0.7 m off the line: its radius 0.3 + 0.5
  EXPECT_FALSE(lanes[0].contains({4.2, 1.9}));  // 0.9 m off
  EXPECT_FALSE(lanes[0].contains({5.1, 1.0}));  // beyond 3 m ahead and the radius
  for (int frame = 0; frame < kMovingFrames; ++frame) r.observe({5.0, 1.0}, {at(1, 1.2, 1.0)}, false, 5.0, 0.1);
  EXPECT_TRUE(r.lanes(3.0, 0.5).empty());  // it stopped: no longer on its way
}

}  // namespace
}  // namespace marsala::agent::reactive
