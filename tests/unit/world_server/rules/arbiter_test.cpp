#include "marsala/world_server/rules/arbiter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/robot_body.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::move_to;
using testing::request_for;
using testing::small_scenario;

protocol::Deposition dep(int row, int col, double h) { return {row, col, h}; }

/// Row and column of the cell whose centre is (x, y) on the 40 x 40 test grid.
CellIndex cell_of(double x, double y) {
  return {40 - 1 - static_cast<int>(std::floor(y / 0.1)), static_cast<int>(std::floor(x / 0.1))};
}

class ArbiterTest : public ::testing::Test {
 protected:
  ArbiterTest() : scenario_(small_scenario()), state_(admitted_state(scenario_, flat_terrain(), 2)) {}
  Verdict check(const protocol::ActionRequest& r, std::uint32_t channel = 0) {
    return validate_request(state_, channel == 0 ? r.agent_id : channel, r);
  }
  void expect_rejected(const protocol::ActionRequest& r, const std::string& words, std::uint32_t channel = 0) {
    const Verdict v = check(r, channel);
    EXPECT_FALSE(v.accepted) << "expected a rejection mentioning '" << words << "'";
    EXPECT_NE(v.reason.find(words), std::string::npos) << v.reason;
  }
  scenario::Scenario scenario_;
  WorldState state_;
};

TEST_F(ArbiterTest, AcceptsAMoveWithDepositionsAndBooksThemExactly) {
  protocol::ActionRequest r = move_to(state_, 1, 1.25, 1.05);        // 0.2 m east
  const CellIndex a = cell_of(1.25, 1.95), b = cell_of(0.45, 1.05);  // 0.9 m north, 0.8 m west of the new position
  r.depositions = {dep(a.row, a.col, kLayer), dep(b.row, b.col, 2 * kLayer)};
  const Verdict v = check(r);
  ASSERT_TRUE(v.accepted) << v.reason;
  EXPECT_EQ(v.volume_m3, kLayer * 0.1 * 0.1 + 2 * kLayer * 0.1 * 0.1);

  std::vector<CellIndex> changed;
  apply_request(state_, r, v, changed);
  const AgentRecord& me = state_.agent(1);
  EXPECT_EQ(me.position.x, 1.25);
  EXPECT_EQ(me.position.y, 1.05);
  EXPECT_EQ(me.z_m, 0.0);
  EXPECT_EQ(state_.terrain(a), kLayer);
  EXPECT_EQ(state_.terrain(b), 2 * kLayer);
  EXPECT_DOUBLE_EQ(state_.terrain.heights().sum(), 3 * kLayer);  // nothing else moved
  EXPECT_EQ(me.material_m3, 0.05 - v.volume_m3);
  EXPECT_EQ(me.deposited_m3, v.volume_m3);
  EXPECT_EQ(state_.deposited_volume_m3, v.volume_m3);
  EXPECT_EQ(me.accepted, 1u);
  ASSERT_EQ(changed.size(), 2u);
  EXPECT_EQ(changed[0], a);
  EXPECT_EQ(changed[1], b);
}

TEST_F(ArbiterTest, EnvelopeRules) {
  // Spoofed id: agent 1's request on agent 2's partition.
  expect_rejected(request_for(state_, 1), "arrived on the partition of agent 2", 2);
  protocol::ActionRequest r = request_for(state_, 1);
  r.session += 1;
  expect_rejected(r, "session");
  r = request_for(state_, 1);
  r.step = 1;
  expect_rejected(r, "current step is 0");
  state_.step = 5;
  r.step = 4;
  expect_rejected(r, "current step is 5");
  r.step = 5;
  EXPECT_TRUE(check(r).accepted);
  // An agent of no slot, and one that was dropped.
  r.agent_id = 7;
  expect_rejected(r, "not admitted and alive");
  state_.agent(2).alive = false;
  r = request_for(state_, 2);
  expect_rejected(r, "not admitted and alive");
  // Slot 3 exists in the scenario but not in this two-agent run.
  WorldState three = admitted_state(scenario_, flat_terrain(), 3);
  three.agent(3).alive = false;
  three.agent(3).admitted = false;
  EXPECT_FALSE(validate_request(three, 3, request_for(three, 3)).accepted);
}

TEST_F(ArbiterTest, NonFiniteOrHugeValuesAreRejected) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expect_rejected(move_to(state_, 1, nan, 1.05), "not finite");
  expect_rejected(move_to(state_, 1, 1.05, inf), "not finite");
  expect_rejected(move_to(state_, 1, 1e7, 1.05), "too large");
  protocol::ActionRequest r = request_for(state_, 1);
  r.target_x_m = nan;  // checked even without a motion: every double must be sane
  expect_rejected(r, "not finite");
  r = request_for(state_, 1);
  r.depositions = {dep(0, 0, inf)};
  expect_rejected(r, "not finite");
  r.depositions = {dep(0, 0, -nan)};
  expect_rejected(r, "not finite");
}

TEST_F(ArbiterTest, MotionLongerThanTheStepIsRejectedTheStepItselfPasses) {
  EXPECT_TRUE(check(move_to(state_, 1, 1.25, 1.05)).accepted);
  // The diagonal of 0.2 m: (0.2 / sqrt 2) on both axes.
  const double d = 0.2 / std::sqrt(2.0);
  EXPECT_TRUE(check(move_to(state_, 1, 1.05 + d, 1.05 + d)).accepted);
  expect_rejected(move_to(state_, 1, 1.05 + 0.2 + 1e-6, 1.05), "exceeds max_step_m");
  expect_rejected(move_to(state_, 1, 1.35, 1.05), "exceeds max_step_m");
}

TEST_F(ArbiterTest, MotionOffTheGridIsRejected) {
  state_.agent(1).position.x = 0.05;
  state_.agent(1).position.y = 2.05;
  expect_rejected(move_to(state_, 1, -0.1, 2.05), "off the grid");
  state_.agent(1).position.x = 3.95;
  expect_rejected(move_to(state_, 1, 4.05, 2.05), "off the grid");
  EXPECT_TRUE(check(move_to(state_, 1, 3.99, 2.05)).accepted);
}

TEST_F(ArbiterTest, MotionOntoANonOccupiableCellIsRejected) {
  // A 1 m cliff: every cell with x >= 3.0 m is at 1 m.
  for (int r = 0; r < 40; ++r)
    for (int c = 30; c < 40; ++c) state_.terrain(r, c) = 1.0;
  state_.agent(1).position.x = 2.35;
  state_.agent(1).position.y = 2.05;
  // (2.55, 2.05): its ball (radius 0.5 m) reaches x = 3.05, a cell on the cliff 0.5 m from ground cells.
  expect_rejected(move_to(state_, 1, 2.55, 2.05), "not occupiable");
  // (2.45, 2.05): the ball stops at x = 2.95, all ground.
  EXPECT_TRUE(check(move_to(state_, 1, 2.45, 2.05)).accepted);
  EXPECT_TRUE(check(move_to(state_, 1, 2.15, 2.05)).accepted);
}

TEST_F(ArbiterTest, MotionAcrossANonOccupiableCellIsRejected) {
  // A thin wall: a slope of 0.353 m/m over columns 15..25 and flat ground either side. Only column 20's ball spans
  // the whole slope: its end cells, 1.0 m apart, differ by 0.353 m > eps + kappa 1.0 m = 0.35 m; the balls of
  // columns 19 and 21 span 0.9 m of it (0.318 m <= 0.35 m).
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) state_.terrain(r, c) = 0.0353 * std::clamp(c - 15, 0, 10);
  const NavigabilityParams body{0.3, 1.0, 0.05};
  ASSERT_TRUE(cell_occupiable(state_.terrain, {20, 19}, body));
  ASSERT_FALSE(cell_occupiable(state_.terrain, {20, 20}, body));
  ASSERT_TRUE(cell_occupiable(state_.terrain, {20, 21}, body));
  state_.agent(1).position.x = 1.95;  // column 19
  state_.agent(1).position.y = 1.95;  // row 20
  state_.agent(2).position.x = 3.55;  // out of the way
  state_.agent(2).position.y = 0.35;
  // 0.2 m east, from column 19 to column 21, across column 20: its end cell is occupiable, its way is not.
  expect_rejected(move_to(state_, 1, 2.15, 1.95), "motion passes through cell (20, 20), not occupiable");
  // Onto the wall, named as the target, with the drop a body there finds: the ball's end cells on the slope's foot and
  // top (the only pairs that differ by more than the rule allows).
  expect_rejected(move_to(state_, 1, 2.05, 1.95), "target cell (20, 20) is not occupiable");
  const Verdict onto = check(move_to(state_, 1, 2.05, 1.95));
  // With the heights the body found there, to the last bit (the robot takes the lower one as a fact).
  EXPECT_NE(onto.reason.find(fmt::format(": cell (20, 15) at {} m lies too far below cell (20, 25) at {} m",
                                         state_.terrain(20, 15), state_.terrain(20, 25))),
            std::string::npos)
      << onto.reason;
  // Along it (north, in column 19), fine.
  EXPECT_TRUE(check(move_to(state_, 1, 1.95, 2.15)).accepted);
  // A robot standing on the wall may leave it: its own cell is not part of the way.
  state_.agent(1).position.x = 2.05;
  EXPECT_TRUE(check(move_to(state_, 1, 2.15, 1.95)).accepted);
  EXPECT_TRUE(check(move_to(state_, 1, 1.95, 1.95)).accepted);
}

TEST_F(ArbiterTest, ATerrainRefusalNamesEveryDropUnderTheBody) {
  // A platform 0.4 m high from column 22 on, flat ground before it: the ball of the cell at (2.05, 2.05) m (column
  // 20, radius 0.5 m) holds ground cells that lie too far below platform cells, more than a reason names. The reason
  // names each low cell once, with the cell it breaks the rule against by the most and both heights, the worst first,
  // in occupancy_breaches() order: what the robot learns from one refusal.
  for (int r = 0; r < 40; ++r)
    for (int c = 22; c < 40; ++c) state_.terrain(r, c) = 0.4;
  const NavigabilityParams body = state_.agent(1).type.body.navigability;
  state_.agent(1).position = {1.95, 2.05};  // column 19, beside the target
  state_.agent(2).position = {3.55, 0.35};  // out of the way
  const Verdict onto = check(move_to(state_, 1, 2.05, 2.05));
  ASSERT_FALSE(onto.accepted);
  const CellIndex target = *state_.terrain.cell_at({2.05, 2.05});
  const std::vector<OccupancyBreach> breaches = occupancy_breaches(state_.terrain, target, body);
  ASSERT_GT(breaches.size(), kMaxNamedDrops);  // more than a reason names: the list is cut after the worst
  std::string expected = fmt::format("target cell {} is not occupiable for this body", target);
  for (std::size_t i = 0; i < breaches.size() && i < kMaxNamedDrops; ++i)
    expected += fmt::format("{} cell {} at {} m lies too far below cell {} at {} m", i == 0 ? ":" : ";",
                            breaches[i].low, state_.terrain(breaches[i].low), breaches[i].high,
                            state_.terrain(breaches[i].high));
  EXPECT_EQ(onto.reason, expected);
  // The first is the pair of the ball the rule is broken by the most (brute force over the ball's pairs).
  const auto excess = [&](CellIndex low, CellIndex high) {
    const double d = state_.terrain.cell_size_m() * std::hypot(low.row - high.row, low.col - high.col);
    return state_.terrain(high) - state_.terrain(low) - (body.eps_m + body.kappa * d);
  };
  const std::vector<CellIndex> ball = disc_offsets(body.delta_m / (2.0 * state_.terrain.cell_size_m()));
  double worst = 0.0;
  for (const CellIndex& a : ball)
    for (const CellIndex& b : ball)
      worst = std::max(worst,
                       excess({target.row + a.row, target.col + a.col}, {target.row + b.row, target.col + b.col}));
  EXPECT_NEAR(excess(breaches.front().low, breaches.front().high), worst, 1e-12);
}

TEST_F(ArbiterTest, ALongStepCannotJumpAWall) {
  // A 1 m wall over x in [2.0, 2.5): cells within delta/2 of it are not occupiable, x in [1.5, 3.0).
  for (int r = 0; r < 40; ++r)
    for (int c = 20; c < 25; ++c) state_.terrain(r, c) = 1.0;
  // A body the scenario validator would refuse (max_step_m 3 > delta/2), put into the state by hand: the world
  // still judges its way cell by cell.
  state_.agent(1).type.body.max_step_m = 3.0;
  state_.agent(1).position.x = 0.55;
  state_.agent(1).position.y = 1.95;
  ASSERT_TRUE(cell_occupiable(state_.terrain, *state_.terrain.cell_at({3.55, 1.95}), {0.3, 1.0, 0.05}));
  expect_rejected(move_to(state_, 1, 3.55, 1.95), "motion passes through cell (20, 15), not occupiable");
  EXPECT_FALSE(body_problem(state_.agent(1).type.body).empty());
}

TEST_F(ArbiterTest, AMotionMayNotEndInsideAnotherRobotsBody) {
  // Agent 1 at (1.05, 1.05), agent 2 at (2.55, 1.05): bodies of 1 m need 1 m between centres.
  state_.agent(2).position.x = 2.15;  // 1.1 m east of agent 1
  // 0.15 m east ends 0.95 m from agent 2: overlap.
  expect_rejected(move_to(state_, 1, 1.20, 1.05), "whose body it would overlap");
  const Verdict v = check(move_to(state_, 1, 1.20, 1.05));
  EXPECT_EQ(v.rule, 2);
  EXPECT_NE(v.reason.find("agent 2"), std::string::npos) << v.reason;
  // 0.1 m east ends exactly 1 m away: bodies touch, allowed.
  EXPECT_TRUE(check(move_to(state_, 1, 1.15, 1.05)).accepted);
  // A dropped robot is off the field.
  state_.agent(2).alive = false;
  EXPECT_TRUE(check(move_to(state_, 1, 1.20, 1.05)).accepted);
}

TEST_F(ArbiterTest, OverlappingBodiesMayMoveApartButNotCloser) {
  state_.agent(2).position.x = 1.65;  // 0.6 m east of agent 1: already overlapping (e.g. jittered starts)
  EXPECT_TRUE(check(move_to(state_, 1, 0.90, 1.05)).accepted);   // away: 0.75 m
  EXPECT_TRUE(check(move_to(state_, 1, 1.05, 1.10)).accepted);   // sideways, a little farther: 0.602 m
  expect_rejected(move_to(state_, 1, 1.15, 1.05), "agent 2");     // closer: 0.5 m
  EXPECT_TRUE(check(move_to(state_, 1, 1.05, 1.05)).accepted);   // a motion of 0 m keeps the distance
}

TEST(BodiesOverlap, IsSymmetricAndUsesBothBodies) {
  AgentRecord a, b;
  a.type.body.navigability.delta_m = 1.0;
  b.type.body.navigability.delta_m = 2.0;
  EXPECT_DOUBLE_EQ(body_clearance_m(a, b), 1.5);
  EXPECT_TRUE(bodies_overlap(a, 0, 0, b, 1.49, 0));
  EXPECT_TRUE(bodies_overlap(b, 1.49, 0, a, 0, 0));
  EXPECT_FALSE(bodies_overlap(a, 0, 0, b, 1.5, 0));
  EXPECT_FALSE(bodies_overlap(a, 0, 0, b, 0.9, 1.2));  // 1.5 m on a diagonal
}

TEST_F(ArbiterTest, DepositionRules) {
  const AgentRecord& me = state_.agent(1);  // at (1.05, 1.05); agent 2 at (2.55, 1.05)
  protocol::ActionRequest r = request_for(state_, 1);
  const CellIndex fine = cell_of(1.05, 2.05);  // 1 m north: within reach 1.2, beyond delta/2 of everyone
  r.depositions = {dep(fine.row, fine.col, kLayer)};
  EXPECT_TRUE(check(r).accepted);

  r.depositions = {dep(-1, 3, kLayer)};
  expect_rejected(r, "off the grid");
  r.depositions = {dep(fine.row, 40, kLayer)};
  expect_rejected(r, "off the grid");
  r.depositions = {dep(fine.row, fine.col, kLayer), dep(fine.row, fine.col, kLayer)};
  expect_rejected(r, "listed twice");
  r.depositions = {dep(fine.row, fine.col, 0.0)};
  expect_rejected(r, "not in (0, 1] m");
  r.depositions = {dep(fine.row, fine.col, -kLayer)};
  expect_rejected(r, "not in (0, 1] m");
  r.depositions = {dep(fine.row, fine.col, 81 * kLayer)};  // 1.0125 m: a whole multiple, but above 1 m
  expect_rejected(r, "not in (0, 1] m");
  r.depositions = {dep(fine.row, fine.col, 80 * kLayer)};  // exactly 1 m
  EXPECT_TRUE(check(r).accepted);
  r.depositions = {dep(fine.row, fine.col, 1.5 * kLayer)};
  expect_rejected(r, "whole multiple");
  r.depositions = {dep(fine.row, fine.col, 0.5 * kLayer)};
  expect_rejected(r, "whole multiple");
  r.depositions = {dep(fine.row, fine.col, kLayer * (1 + 2e-6))};
  expect_rejected(r, "whole multiple");
  r.depositions = {dep(fine.row, fine.col, kLayer * (1 + 5e-7))};  // within the 1e-6 tolerance
  EXPECT_TRUE(check(r).accepted);

  // Reach 1.2 m: 1.2 m north passes, 1.3 m does not.
  const CellIndex at_reach = cell_of(1.05, 2.25), beyond = cell_of(1.05, 2.35);
  r.depositions = {dep(at_reach.row, at_reach.col, kLayer)};
  EXPECT_TRUE(check(r).accepted);
  r.depositions = {dep(beyond.row, beyond.col, kLayer)};
  expect_rejected(r, "beyond reach_m");
  // Reach counts from the position after the motion.
  protocol::ActionRequest moved = move_to(state_, 1, 1.05, 1.25);
  moved.depositions = {dep(beyond.row, beyond.col, kLayer)};
  EXPECT_TRUE(check(moved).accepted);
  EXPECT_EQ(me.position.y, 1.05);
}

TEST_F(ArbiterTest, DepositionUnderARobotIsRejected) {
  protocol::ActionRequest r = request_for(state_, 1);
  // Under itself: 0.4 m away, and exactly delta/2 = 0.5 m away (the ball is inclusive).
  CellIndex c = cell_of(1.45, 1.05);
  r.depositions = {dep(c.row, c.col, kLayer)};
  expect_rejected(r, "under agent 1");
  c = cell_of(1.55, 1.05);
  r.depositions = {dep(c.row, c.col, kLayer)};
  expect_rejected(r, "under agent 1");
  c = cell_of(1.65, 1.05);
  r.depositions = {dep(c.row, c.col, kLayer)};
  EXPECT_TRUE(check(r).accepted);
  // Under agent 2 (at 2.55, 1.05): 0.5 m west of it is 1.0 m from agent 1, within reach.
  c = cell_of(2.05, 1.05);
  r.depositions = {dep(c.row, c.col, kLayer)};
  expect_rejected(r, "under agent 2");
  // Under its own new position: the cell it moves next to.
  protocol::ActionRequest moved = move_to(state_, 1, 1.05, 1.25);
  c = cell_of(1.05, 1.65);  // 0.4 m from (1.05, 1.25), 0.6 m from (1.05, 1.05)
  moved.depositions = {dep(c.row, c.col, kLayer)};
  expect_rejected(moved, "under agent 1");
  // A dropped robot is no longer in the world.
  state_.agent(2).alive = false;
  c = cell_of(2.05, 1.05);
  r.depositions = {dep(c.row, c.col, kLayer)};
  EXPECT_TRUE(check(r).accepted);
}

TEST_F(ArbiterTest, VolumeAboveTheThresholdOrTheMaterialIsRejected) {
  protocol::ActionRequest r = request_for(state_, 1);
  const CellIndex a = cell_of(1.05, 2.05), b = cell_of(1.15, 2.05), c = cell_of(0.95, 2.05);
  // 160 cubes = 160 * 1.25e-4 = 0.02 m^3: exactly the threshold.
  r.depositions = {dep(a.row, a.col, 53 * kLayer), dep(b.row, b.col, 53 * kLayer), dep(c.row, c.col, 54 * kLayer)};
  const Verdict at_threshold = check(r);
  EXPECT_TRUE(at_threshold.accepted) << at_threshold.reason;
  EXPECT_NEAR(at_threshold.volume_m3, 0.02, 1e-15);
  r.depositions.back().height_m = 55 * kLayer;  // 161 cubes
  expect_rejected(r, "exceeds max_deposit_m3");
  // Material: 0.001 m^3 on board = 8 cubes.
  state_.agent(1).material_m3 = 0.001;
  r.depositions = {dep(a.row, a.col, 8 * kLayer)};
  EXPECT_TRUE(check(r).accepted);
  r.depositions = {dep(a.row, a.col, 9 * kLayer)};
  expect_rejected(r, "exceeds the material on board");
}

TEST_F(ArbiterTest, RefillOnlyAtTheBase) {
  protocol::ActionRequest r = request_for(state_, 1);  // (1.05, 1.05) is 0.707 m from the base centre (0.55, 0.55)
  r.refill = true;
  expect_rejected(r, "from the base station");
  r = move_to(state_, 1, 0.95, 0.95);  // 0.566 m: still outside the 0.5 m radius
  r.refill = true;
  expect_rejected(r, "from the base station");
  state_.agent(1).position.x = 0.75;
  state_.agent(1).position.y = 0.75;
  state_.agent(1).material_m3 = 0.01;
  r = move_to(state_, 1, 0.85, 0.85);  // 0.424 m from the centre
  r.refill = true;
  const CellIndex c = cell_of(0.85, 1.85);
  r.depositions = {dep(c.row, c.col, 4 * kLayer)};
  const Verdict v = check(r);
  ASSERT_TRUE(v.accepted) << v.reason;
  std::vector<CellIndex> changed;
  apply_request(state_, r, v, changed);
  EXPECT_EQ(state_.agent(1).material_m3, 0.05);  // deposited from what it had, then filled to capacity
  EXPECT_EQ(state_.agent(1).deposited_m3, v.volume_m3);
}

TEST_F(ArbiterTest, AllOrNothing) {
  protocol::ActionRequest r = move_to(state_, 1, 1.25, 1.05);
  const CellIndex good = cell_of(1.25, 2.05), bad = cell_of(1.25, 2.55);  // the second is 1.5 m away
  r.depositions = {dep(good.row, good.col, kLayer), dep(bad.row, bad.col, kLayer)};
  EXPECT_FALSE(check(r).accepted);
  EXPECT_EQ(state_.terrain.heights().cwiseAbs().sum(), 0.0);
  EXPECT_EQ(state_.agent(1).position.x, 1.05);
}

}  // namespace
}  // namespace marsala::world_server
