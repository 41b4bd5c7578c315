// The path builder (agent/reactive/path_builder.hpp): every state and transition of its state machine, on a flat
// 6 x 10 m world with a platform, frame by frame (the pipeline role set by the neighbours in the frame) and closed
// loop with the mini world.

#include "marsala/agent/reactive/path_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/core/sensor_spec.hpp"
#include "unit/agent/agent_test_support.hpp"
#include "unit/agent/mini_world.hpp"

namespace marsala::agent::reactive {
namespace {

/// A path builder's context: the Husky body, building for its own kappa (0.5) and width, 2 m separation.
AgentContext context(std::uint32_t id = 3, RobotBody body = test::husky()) {
  AgentContext c = test::agent_context(id, body);
  c.type.pipeline.separation_m = 2.0;
  return c;
}

protocol::Admission admission(const AgentContext& c, Position target, Position base = {0.55, 3.05}) {
  return test::admission_on(c, test::platform_world().geometry(), target, base);
}

/// A frame at `pose` carrying every tile of the world, with `neighbours`.
protocol::SensorFrame frame(const AgentContext& c, std::uint64_t step, Position pose, double material_m3,
                            std::vector<protocol::Neighbour> neighbours = {}) {
  protocol::SensorFrame f = test::full_frame(c, step, pose, material_m3, test::platform_world());
  f.neighbours = std::move(neighbours);
  return f;
}

// The target lies on the platform, due east of the robots; a robot at x = 5.05 m has the gap at the platform's foot
// (x > 4 m at kappa 0.5) within its 1.5 m reach.
constexpr Position kTarget{8.55, 3.05};
constexpr Position kAtFoot{5.05, 3.05};

TEST(PathState, NamesRoundTrip) {
  const std::vector<std::pair<PathState, std::string>> names{{PathState::kWaitAdmission, "wait_admission"},
                                                             {PathState::kSurvey, "survey"},
                                                             {PathState::kAdvance, "advance"},
                                                             {PathState::kBuild, "build"},
                                                             {PathState::kRetreat, "retreat"},
                                                             {PathState::kReturnToBase, "return_to_base"},
                                                             {PathState::kFollow, "follow"},
                                                             {PathState::kHold, "hold"},
                                                             {PathState::kBackOff, "back_off"},
                                                             {PathState::kDone, "done"},
                                                             {PathState::kYield, "yield"}};
  for (const auto& [state, name] : names) {
    EXPECT_EQ(to_string(state), name);
    EXPECT_EQ(path_state_from_string(name), state);
  }
  try {
    path_state_from_string("at_goal");  // the ramp builder's: at the target a path builder goes back to the base
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown path builder state 'at_goal'; valid: wait_admission, survey, "
                                         "advance, build, retreat, return_to_base, follow, hold, back_off, done, yield"),
              std::string::npos)
        << e.what();
  }
}

TEST(PathBuilder, PipelineParamsFollowTheSeparation) {
  Pipeline pipeline;
  pipeline.separation_m = 4.0;
  RobotBody body = test::husky();  // reach 1.5 m, delta 1 m, step 0.2 m
  const PipelineParams p = pipeline_params(pipeline, body);
  EXPECT_EQ(p.separation_m, 4.0);
  EXPECT_EQ(p.back_off_margin_m, 1.0);
  EXPECT_EQ(p.return_detect_m, 3.0);  // three quarters of the separation: longer than a retreat (2.7 m)
  body.reach_m = 3.0;
  EXPECT_DOUBLE_EQ(pipeline_params(pipeline, body).return_detect_m, 4.2);  // a retreat of 3 + 1 + 0.2 m
  EXPECT_EQ(PathBuilder(context()).pipeline().params().separation_m, 2.0);
}

TEST(PathBuilder, AdmissionIsCheckedAndFramesBeforeItAreRefused) {
  const AgentContext c = context();
  PathBuilder pb(c);
  EXPECT_EQ(pb.state(), PathState::kWaitAdmission);
  EXPECT_THROW(pb.decide(frame(c, 0, {1.05, 3.05}, 1.0)), InvalidArgument);
  EXPECT_THROW(pb.map(), InvalidArgument);
  protocol::Admission other = admission(c, kTarget);
  other.agent_id = 4;
  EXPECT_THROW(pb.on_admission(other), InvalidArgument);
  other = admission(c, kTarget);
  other.assignment.world.cell_size_m = 0.0;
  EXPECT_THROW(pb.on_admission(other), InvalidArgument);
  EXPECT_EQ(pb.state(), PathState::kWaitAdmission);
  pb.on_admission(admission(c, kTarget));
  EXPECT_EQ(pb.state(), PathState::kSurvey);
  EXPECT_EQ(pb.state_name(), "survey");
  protocol::SensorFrame stranger = frame(c, 0, {1.05, 3.05}, 1.0);
  stranger.agent_id = 9;
  EXPECT_THROW(pb.decide(stranger), InvalidArgument);
}

TEST(PathBuilder, AloneItIsTheActiveRobotSurveysThenAdvances) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  const protocol::ActionRequest q = pb.decide(frame(c, 5, {1.05, 3.05}, 1.0));
  EXPECT_EQ(pb.last_trace().before, PathState::kSurvey);
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive);
  EXPECT_EQ(pb.state(), PathState::kAdvance);
  EXPECT_EQ(q.state, "advance");
  EXPECT_EQ(q.step, 5u);
  ASSERT_TRUE(q.move);
  EXPECT_NEAR(q.target_x_m, 1.25, 1e-12);
  EXPECT_NEAR(q.target_y_m, 3.05, 1e-12);
  EXPECT_TRUE(q.depositions.empty());  // the gap is out of reach
  EXPECT_EQ(pb.map().known_cells(), 6000);
}

TEST(PathBuilder, ActiveAtTheFootOfThePlatformItDeposits) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  const protocol::ActionRequest q = pb.decide(frame(c, 0, kAtFoot, 1.0));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive);
  EXPECT_EQ(pb.state(), PathState::kAdvance);
  EXPECT_TRUE(q.move);
  EXPECT_FALSE(q.depositions.empty());
}

TEST(PathBuilder, FollowsAFrontNeighbourBeyondTheSeparationWithoutDepositing) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  const protocol::Neighbour front = test::neighbour_at(5, 7.65, 3.05);  // 2.6 m ahead, on the platform
  const protocol::ActionRequest q = pb.decide(frame(c, 0, kAtFoot, 1.0, {front}));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kFollow);
  EXPECT_EQ(pb.state(), PathState::kFollow);
  EXPECT_EQ(q.state, "follow");
  ASSERT_TRUE(q.move);
  EXPECT_GT(q.target_x_m, kAtFoot.x);  // along the path to the target
  EXPECT_GE(distance({q.target_x_m, q.target_y_m}, front.position), 2.0);
  EXPECT_TRUE(q.depositions.empty());  // the gap within reach is the front robot's work
  EXPECT_FALSE(q.refill);
}

TEST(PathBuilder, AFollowerTakesTheWayToItsFrontNeighbourNotItsOwnLineToTheTarget) {
  // Wherever the front neighbour stands ahead (bearings up to 40 degrees off the line to the target, 2.5-3 m away),
  // the follower's path leads to the front neighbour's cell and its step brings it nearer: it goes where the front
  // builds, so the front that follows on builds on the same way (docs/runtime.md#the-construction-band).
  const AgentContext c = context();
  const Position at{1.05, 3.05};
  int cases = 0;
  for (int deg = -40; deg <= 40; deg += 10)
    for (const double r : {2.5, 3.0}) {
      PathBuilder pb(c);
      pb.on_admission(admission(c, kTarget));
      const double a = deg * std::acos(-1.0) / 180.0;
      const protocol::Neighbour front = test::neighbour_at(5, at.x + r * std::cos(a), at.y + r * std::sin(a));
      const protocol::ActionRequest q = pb.decide(frame(c, 0, at, 1.0, {front}));
      ASSERT_EQ(pb.last_trace().role, PipelineRole::kFollow) << deg << " deg, " << r << " m";
      const PathBuilderTrace& t = pb.last_trace();
      ASSERT_TRUE(t.planned && t.plan.found) << deg << " deg, " << r << " m";
      const CellIndex front_cell = *test::platform_world().geometry().cell_at(front.position);
      const CellIndex end{t.plan.path.back().row + t.window_offset.row, t.plan.path.back().col + t.window_offset.col};
      EXPECT_EQ(end, front_cell) << deg << " deg, " << r << " m";
      ASSERT_TRUE(q.move) << deg << " deg, " << r << " m";
      EXPECT_LT(distance({q.target_x_m, q.target_y_m}, front.position), distance(at, front.position) - 0.1)
          << deg << " deg, " << r << " m";
      EXPECT_TRUE(q.depositions.empty());
      ++cases;
    }
  EXPECT_EQ(cases, 18);
}

TEST(PathBuilder, HoldsWhenFollowingWouldComeWithinTheSeparation) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  // 2.05 m ahead: a follower, but its step east along the path would leave less than 2 m.
  const protocol::ActionRequest q = pb.decide(frame(c, 0, kAtFoot, 1.0, {test::neighbour_at(5, 7.1, 3.05)}));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kFollow);
  EXPECT_EQ(pb.last_trace().before, PathState::kSurvey);
  EXPECT_EQ(pb.state(), PathState::kHold);
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
}

TEST(PathBuilder, HoldsWithinTheSeparationAndFollowsAgainOnceTheFrontMovesOn) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  protocol::ActionRequest q = pb.decide(frame(c, 0, kAtFoot, 1.0, {test::neighbour_at(5, 6.9, 3.05)}));  // 1.85 m
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kHold);
  EXPECT_EQ(pb.state(), PathState::kHold);
  EXPECT_FALSE(pb.last_trace().planned);  // standing still needs no path
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
  q = pb.decide(frame(c, 1, kAtFoot, 1.0, {test::neighbour_at(5, 7.65, 3.05)}));
  EXPECT_EQ(pb.last_trace().before, PathState::kHold);
  EXPECT_EQ(pb.state(), PathState::kFollow);
  EXPECT_TRUE(q.move);
}

TEST(PathBuilder, OnItsWayOutARobotNeverHoldsForTheRightOfWay) {
  const AgentContext c = context();  // keeps the right of way (the default)
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  // 1.85 m behind robot 5 (in contact) for kPatienceSteps frames (then it steps aside on its own): it makes no way,
  // but it waits as the pipeline says; were it on its way back it would hold after kStuckFrames of them (below).
  static_assert(kStuckFrames < kPatienceSteps);
  for (std::uint64_t step = 0; step < kPatienceSteps; ++step) {
    const protocol::ActionRequest q = pb.decide(frame(c, step, kAtFoot, 1.0, {test::neighbour_at(5, 6.9, 3.05)}));
    EXPECT_EQ(q.waiting_for.find("right of way"), std::string::npos) << step << ": " << q.waiting_for;
  }
}

TEST(PathBuilder, OnItsWayBackARobotThatMakesNoWayBesideAnotherHolds) {
  for (const bool keeps : {true, false}) {
    AgentContext c = context();
    c.right_of_way = keeps;
    PathBuilder pb(c);
    pb.on_admission(admission(c, kTarget));
    // Out of material at the platform's foot, robot 5 1.5 m nearer the base; the frames keep it where it is (its
    // motions come to nothing): after kStuckFrames frames without way towards the base it holds still.
    int first_hold = -1;
    for (int step = 0; step < 40 && first_hold < 0; ++step) {
      const protocol::ActionRequest q = pb.decide(frame(c, static_cast<std::uint64_t>(step), kAtFoot, 0.0,
                                                      {test::neighbour_at(5, kAtFoot.x - 1.5, 3.05)}));
      if (pb.state() == PathState::kYield) {
        first_hold = step;
        EXPECT_FALSE(q.move);
        EXPECT_NE(q.waiting_for.find("right of way: holding still"), std::string::npos) << q.waiting_for;
      }
    }
    // Frame 0 still heads for the target (it turns back after the protocol's look), frame 1 for the base: its way
    // is measured afresh there, and kStuckFrames frames without way end with frame kStuckFrames + 1.
    EXPECT_EQ(first_hold, keeps ? kStuckFrames + 1 : -1) << keeps;
  }
}

TEST(PathBuilder, BacksOffAwayFromAFrontNeighbourTooNear) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  pb.decide(frame(c, 0, {4.85, 3.05}, 1.0, {test::neighbour_at(5, 7.65, 3.05)}));  // came from the west, following
  ASSERT_EQ(pb.state(), PathState::kFollow);
  // Another robot cuts in 0.95 m ahead: nearer than separation - margin (1.5 m). (Robot 5 out of range is forgotten;
  // had it come back this far itself, it would count as returning.)
  const Position front{6.0, 3.05};
  const protocol::ActionRequest q = pb.decide(frame(c, 1, kAtFoot, 1.0, {test::neighbour_at(6, front.x, front.y)}));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kBackOff);
  EXPECT_EQ(pb.last_trace().before, PathState::kFollow);
  EXPECT_EQ(pb.state(), PathState::kBackOff);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, kAtFoot.x);
  EXPECT_GT(distance({q.target_x_m, q.target_y_m}, front), distance(kAtFoot, front));
  EXPECT_TRUE(q.depositions.empty());
}

TEST(PathBuilder, ANeighbourTurnedBackIsNoLongerFollowedAndPassesBy) {
  const AgentContext c = context();  // return detection: reach 1.5 + delta 1 + step 0.2 = 2.7 m
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  const Neighbour front = test::neighbour_at(6, 8.0, 1.5);  // 3.33 m ahead: this robot follows it
  pb.decide(frame(c, 0, kAtFoot, 1.0, {test::neighbour_at(5, 8.55, 3.05), front}));
  ASSERT_EQ(pb.state(), PathState::kFollow);
  // It moved 2.75 m away from the target: it is heading for the base, still nearer the target than this robot and
  // 1.63 m from it, within the separation. This robot makes way: a step off the line from it to the base
  // (x = 0.55, y = 3.05), no deposition.
  const Position oncoming{6.1, 4.3};
  protocol::ActionRequest q =
      pb.decide(frame(c, 1, kAtFoot, 1.0, {test::neighbour_at(5, oncoming.x, oncoming.y), front}));
  EXPECT_TRUE(pb.pipeline().returning(5));
  EXPECT_EQ(pb.state(), PathState::kYield);
  EXPECT_TRUE(q.depositions.empty());
  ASSERT_TRUE(q.move);
  const auto off_line = [&](Position p) {
    const double dx = 0.55 - oncoming.x, dy = 3.05 - oncoming.y;
    return std::abs((p.x - oncoming.x) * dy - (p.y - oncoming.y) * dx) / std::hypot(dx, dy);
  };
  EXPECT_GT(off_line({q.target_x_m, q.target_y_m}), off_line(kAtFoot));
  // Once it has passed (farther from the target than this robot) and robot 6 has gone out of range, nobody ahead is
  // in sight: having made way, it keeps robot 6's way to where it was last seen (3.33 m off), no deposition...
  q = pb.decide(frame(c, 2, kAtFoot, 1.0, {test::neighbour_at(5, 4.0, 4.3)}));
  EXPECT_TRUE(pb.pipeline().returning(5));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive);
  EXPECT_EQ(pb.state(), PathState::kFollow);
  EXPECT_TRUE(q.depositions.empty());
  // ... and within the separation of that place this robot is the front of the pipeline.
  q = pb.decide(frame(c, 3, {6.55, 2.05}, 1.0, {test::neighbour_at(5, 3.0, 4.3)}));
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive);
  EXPECT_TRUE(pb.state() == PathState::kAdvance || pb.state() == PathState::kBuild) << to_string(pb.state());
  EXPECT_FALSE(q.depositions.empty());
}

TEST(PathBuilder, AfterMakingWayItKeepsTheWayOfAFrontOutOfSightNotALineOfItsOwn) {
  // Robot 5 stands 1.85 m ahead and this robot holds behind it for kPatienceSteps frames, then steps aside. Robot 5
  // drives on out of sight. Wherever this robot then stands beside robot 5's last place (farther than the separation
  // from it, with the platform's foot in reach, where the front robot deposits), it plans its way to that place and
  // drives it, depositing nothing; a robot that never made way is the front at once. (Its own
  // line to the target passes robot 5's place 1.4-1.6 m off, more than half the band.)
  const AgentContext c = context();
  const Position held{3.05, 3.05}, last_seen{4.9, 3.05};
  int cases = 0;
  for (const Position aside : {Position{4.05, 0.85}, Position{4.05, 5.25}, Position{3.55, 0.95}, Position{3.55, 5.15}})
    for (const bool made_way : {true, false}) {
      PathBuilder pb(c);
      pb.on_admission(admission(c, kTarget));
      std::uint64_t step = 0;
      if (made_way) {
        for (; step <= kPatienceSteps; ++step)
          pb.decide(frame(c, step, held, 1.0, {test::neighbour_at(5, last_seen.x, last_seen.y)}));
        ASSERT_EQ(pb.state(), PathState::kYield);
      } else {
        pb.decide(frame(c, step++, held, 1.0, {test::neighbour_at(5, last_seen.x + 0.5, last_seen.y)}));
        ASSERT_EQ(pb.state(), PathState::kFollow);
      }
      ASSERT_GT(distance(aside, last_seen), c.type.pipeline.separation_m);
      const protocol::ActionRequest q = pb.decide(frame(c, step, aside, 1.0));
      const PathBuilderTrace& t = pb.last_trace();
      EXPECT_EQ(t.role, PipelineRole::kActive);
      if (!made_way) {
        EXPECT_TRUE(pb.state() == PathState::kAdvance || pb.state() == PathState::kBuild) << to_string(pb.state());
        EXPECT_FALSE(q.depositions.empty()) << aside.x << ", " << aside.y;
        ++cases;
        continue;
      }
      EXPECT_EQ(pb.state(), PathState::kFollow) << aside.x << ", " << aside.y;
      EXPECT_TRUE(q.depositions.empty()) << aside.x << ", " << aside.y;
      ASSERT_TRUE(t.planned && t.plan.found);
      const CellIndex end{t.plan.path.back().row + t.window_offset.row, t.plan.path.back().col + t.window_offset.col};
      EXPECT_EQ(end, *test::platform_world().geometry().cell_at(last_seen)) << aside.x << ", " << aside.y;
      EXPECT_TRUE(q.move);  // along that way, in its lane
      ++cases;
    }
  EXPECT_EQ(cases, 8);
}

TEST(PathBuilder, AFrontOutOfSightIsKeptForABoundedTime) {
  // Made way as above, then robot 5 out of sight: the robot cannot move (the frames keep it where it is) and never
  // gets nearer robot 5's last place. It keeps that place for at most 2 x proximity range / step + kPatienceSteps
  // frames, then it is the front and deposits.
  const AgentContext c = context();
  const Position held{3.05, 3.05}, last_seen{4.9, 3.05}, aside{4.05, 0.85};
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  std::uint64_t step = 0;
  for (; step <= kPatienceSteps; ++step)
    pb.decide(frame(c, step, held, 1.0, {test::neighbour_at(5, last_seen.x, last_seen.y)}));
  ASSERT_EQ(pb.state(), PathState::kYield);
  // The frames keep the robot at `aside`: every motion it asks for comes to nothing, as if blocked.
  int followed = 0;
  for (int i = 0; i < 3 * kPatienceSteps && pb.state() != PathState::kAdvance && pb.state() != PathState::kBuild;
       ++i, ++step) {
    const protocol::ActionRequest q = pb.decide(frame(c, step, aside, 1.0));
    if (pb.state() != PathState::kFollow) continue;
    ++followed;
    EXPECT_TRUE(q.depositions.empty());
  }
  const RobotBody& body = c.type.body;
  EXPECT_GT(followed, 0);
  EXPECT_LE(followed, std::ceil(2.0 * body.proximity_range_m / body.max_step_m) + kPatienceSteps);
  EXPECT_TRUE(pb.state() == PathState::kAdvance || pb.state() == PathState::kBuild) << to_string(pb.state());
}

TEST(PathBuilder, ReturnsToBaseBelowOneDepositionThresholdAndRefillsThere) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget, {0.55, 3.05}));
  // Half a deposition threshold (0.02 m^3) on board: too little for a deposition task (a ramp builder would go on).
  protocol::ActionRequest q = pb.decide(frame(c, 0, {1.55, 3.05}, 0.01));
  EXPECT_EQ(pb.state(), PathState::kReturnToBase);
  EXPECT_FALSE(pb.last_trace().role.has_value());  // going back, the pipeline does not decide
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, 1.55);
  EXPECT_FALSE(q.refill);
  EXPECT_TRUE(q.depositions.empty());
  // Within the base radius (0.5 m): refill, then the next frame's role decides.
  q = pb.decide(frame(c, 1, {0.85, 3.05}, 0.01));
  EXPECT_EQ(pb.last_trace().before, PathState::kReturnToBase);
  EXPECT_TRUE(q.refill);
  EXPECT_TRUE(pb.last_trace().refill);
  EXPECT_EQ(pb.state(), PathState::kAdvance);
  q = pb.decide(frame(c, 2, {0.85, 3.05}, 1.0, {test::neighbour_at(5, 3.0, 3.05)}));
  EXPECT_EQ(pb.last_trace().before, PathState::kAdvance);
  EXPECT_EQ(pb.state(), PathState::kFollow);
}

TEST(PathBuilder, AtTheTargetGoesBackToTheBaseToComeAgain) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, {8.02, 3.03}));  // inside cell (29, 80), on the platform
  protocol::ActionRequest q = pb.decide(frame(c, 0, {8.05, 3.05}, 1.0));
  EXPECT_EQ(pb.last_trace().before, PathState::kSurvey);
  EXPECT_EQ(pb.state(), PathState::kReturnToBase);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, 8.05);  // westwards, towards the base
  EXPECT_TRUE(q.depositions.empty());
  q = pb.decide(frame(c, 1, {q.target_x_m, q.target_y_m}, 1.0));
  EXPECT_EQ(pb.last_trace().before, PathState::kReturnToBase);
  EXPECT_EQ(pb.state(), PathState::kReturnToBase);
}

TEST(PathBuilder, NoDepositionPathThroughKnownCellsRequestsNothingAndKeepsTheState) {
  // The robot has seen only its own tile: the local goal is unknown, so no deposition path leads there yet.
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  const Position at{1.05, 2.05};
  const auto own_tile = [&](protocol::SensorFrame f) {
    return test::keep_tile_at(f, test::platform_world().geometry(), at);
  };
  pb.decide(own_tile(frame(c, 0, at, 1.0, {test::neighbour_at(5, 2.9, 2.05)})));  // 1.85 m ahead
  ASSERT_EQ(pb.state(), PathState::kHold);
  const protocol::ActionRequest q = pb.decide(own_tile(frame(c, 1, at, 1.0)));  // alone: the active robot
  EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive);
  EXPECT_TRUE(pb.last_trace().planned);
  EXPECT_FALSE(pb.last_trace().plan.found);
  EXPECT_EQ(pb.state(), PathState::kHold);
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
}

TEST(PathBuilder, RunOverEndsInDone) {
  const AgentContext c = context();
  PathBuilder pb(c);
  pb.on_admission(admission(c, kTarget));
  pb.decide(frame(c, 0, {1.05, 3.05}, 1.0));
  protocol::SensorFrame over = frame(c, 1, {1.25, 3.05}, 1.0);
  over.run_over = true;
  const protocol::ActionRequest q = pb.decide(over);
  EXPECT_EQ(pb.last_trace().before, PathState::kAdvance);
  EXPECT_EQ(pb.state(), PathState::kDone);
  EXPECT_EQ(q.state, "done");
  EXPECT_FALSE(q.move);
  EXPECT_EQ(q.step, 1u);
  pb.decide(frame(c, 2, {1.25, 3.05}, 1.0));  // done stays done
  EXPECT_EQ(pb.state(), PathState::kDone);
}

/// Every transition one path builder takes building up to the platform, going back and coming again, driven by the
/// mini world.
TEST(PathBuilder, AloneItBuildsToTheTargetGoesBackRefillsAndComesAgain) {
  const AgentContext c = context(1, test::husky(0.3));
  test::MiniWorld world(test::platform_world(), 16, {0.55, 3.05}, 0.5);
  PathBuilder pb(c);
  pb.on_admission(world.admit(1, c.session, c.type.body, {1.05, 3.05}, {8.5, 3.05}));
  std::set<std::pair<PathState, PathState>> seen;
  int refills = 0;
  for (int step = 0; step < 1500 && refills == 0; ++step) {
    const protocol::ActionRequest q = pb.decide(world.frame_for(1));
    seen.insert({pb.last_trace().before, pb.last_trace().after});
    refills += q.refill ? 1 : 0;
    ASSERT_EQ(world.validate(q), "") << "step " << step << " in " << q.state;
    world.apply_step({q});
  }
  EXPECT_EQ(refills, 1);
  for (const auto& t :
       std::vector<std::pair<PathState, PathState>>{{PathState::kSurvey, PathState::kAdvance},
                                                    {PathState::kAdvance, PathState::kBuild},
                                                    {PathState::kBuild, PathState::kAdvance},
                                                    {PathState::kBuild, PathState::kRetreat},
                                                    {PathState::kRetreat, PathState::kRetreat},
                                                    {PathState::kRetreat, PathState::kAdvance},
                                                    {PathState::kAdvance, PathState::kReturnToBase},
                                                    {PathState::kReturnToBase, PathState::kReturnToBase},
                                                    {PathState::kReturnToBase, PathState::kAdvance}})
    EXPECT_EQ(seen.count(t), 1u) << to_string(t.first) << " -> " << to_string(t.second);
  for (const auto& [before, after] : seen)
    for (PathState s : {before, after})
      EXPECT_TRUE(s != PathState::kFollow && s != PathState::kHold && s != PathState::kBackOff)
          << "alone, yet " << to_string(s);
  pb.decide(world.frame_for(1, true));
  EXPECT_EQ(pb.state(), PathState::kDone);
}

/// A pipeline of path builders from the base: the front robot alone deposits; the others follow, hold and back off,
/// and take over the front when it goes back to refill.
TEST(PathBuilder, InAPipelineOnlyTheActiveRobotDeposits) {
  RobotBody body = test::husky(0.3);
  body.material_capacity_m3 = 0.6;
  test::MiniWorld world(test::platform_world(), 16, {1.0, 3.05}, 1.2);
  std::vector<std::unique_ptr<PathBuilder>> robots;
  const std::vector<Position> starts{{1.5, 3.05}, {1.0, 2.4}, {0.5, 3.7}};
  for (std::uint32_t id = 1; id <= starts.size(); ++id) {
    AgentContext c = context(id, body);
    c.session = 100 + id;
    robots.push_back(std::make_unique<PathBuilder>(c));
    robots.back()->on_admission(world.admit(id, c.session, body, starts[id - 1], {8.5, 3.05}));
  }
  std::set<PathState> states;
  std::set<std::uint32_t> builders;
  const std::vector<PathState> expected{PathState::kAdvance,      PathState::kBuild,  PathState::kRetreat,
                                        PathState::kReturnToBase, PathState::kFollow, PathState::kHold,
                                        PathState::kBackOff};
  const auto all_seen = [&] {
    return builders.size() == robots.size() &&
           std::all_of(expected.begin(), expected.end(), [&](PathState s) { return states.count(s) == 1; });
  };
  for (int step = 0; step < 2000 && !all_seen(); ++step) {
    std::vector<protocol::ActionRequest> requests;
    for (std::uint32_t id = 1; id <= robots.size(); ++id) {
      PathBuilder& pb = *robots[id - 1];
      requests.push_back(pb.decide(world.frame_for(id)));
      states.insert(pb.state());
      if (!requests.back().depositions.empty()) {
        builders.insert(id);
        EXPECT_EQ(pb.last_trace().role, PipelineRole::kActive) << "step " << step << ": robot " << id;
      }
    }
    const auto reasons = world.apply_step(requests);
    for (std::size_t i = 0; i < reasons.size(); ++i)
      ASSERT_EQ(reasons[i], "") << "step " << step << ": robot " << i + 1 << " in " << requests[i].state;
  }
  EXPECT_EQ(builders.size(), robots.size());
  for (PathState s : expected) EXPECT_EQ(states.count(s), 1u) << to_string(s);
}


// docs/runtime.md#mapping, "Under the rays": an RGB-D path builder (path_generated.pbtxt's builder, 0.25 m cells) at
// the edge of a 3 m cliff, its centre 0.625 m back from the edge (the nearest its body stands on the top), facing
// the basin. The edge hides the cliff's foot from its camera, 0.5 m up, out to 6 x 0.625 = 3.75 m beyond the edge,
// and its hits on the basin floor beyond lie 5.7-6 m away, too noisy to place in a cell: no cell within its 2 m
// reach below the edge is ever read. But the rays that clear the edge pass over those cells: each stands below the
// lowest one that crossed it, so it may be raised by the MARS height of the known cells less that ray's height, and
// it ends no higher than that, whatever its depth. Within a few scans from that pose the robot deposits on such
// cells, unknown on its map, and each deposit leaves its cell under the MARS bound of the true terrain at the
// construction's kappa (brute force here). Before the rule it deposited nothing there and stood at the edge for good.
TEST(PathBuilder, AScanningFrontFillsTheUnseenFootOfACliffUnderItsRays) {
  Heightmap h({40, 80, 0.0, 0.0, 0.25}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < 32; ++c) h(r, c) = 3.0;  // the top: x < 8 m
  RobotBody body = test::husky(0.3);  // a Husky on 0.25 m cells: longer steps and reach, 0.1 m cubes
  body.max_step_m = 0.25;
  body.max_deposit_m3 = 0.05;
  body.material_capacity_m3 = 1.0;
  body.reach_m = 2.0;
  body.sensing_range_m = 5.0;
  body.proximity_range_m = 4.0;
  body.cube_size_m = 0.1;
  AgentContext c = test::agent_context(1, body);
  c.type.construction = NavigabilityParams{0.2, 3.0, 0.05};
  c.type.pipeline.separation_m = 2.0;
  c.type.sensor = sensor_defaults(SensorKind::kRgbd);
  const Position robot{7.375, 5.125};  // col 29: the edge at x = 8 m is 0.625 m east
  PathBuilder b(c);
  b.on_admission(test::admission_on(c, h.geometry(), {18.125, 5.125}, {1.125, 5.125}));
  const Point3 origin = sensor_origin(h, robot.x, robot.y, c.type.sensor);
  const auto bound = [&](CellIndex p) {  // P_0.2 of the true terrain at p
    double best = -std::numeric_limits<double>::infinity();
    const Position at = h.cell_center(p);
    for (int r = 0; r < h.rows(); ++r)
      for (int col = 0; col < h.cols(); ++col) best = std::max(best, h(r, col) - 0.2 * distance(at, h.cell_center({r, col})));
    return best;
  };
  std::vector<Deposition> unseen;
  for (std::uint64_t step = 0; step < 6 && unseen.empty(); ++step) {
    protocol::SensorFrame f = test::scan_frame(1, step, robot, 3.0);
    f.points = cast_scan(h, origin, 0.0, c.type.sensor, step + 1);  // looking east
    const protocol::ActionRequest q = b.decide(f);
    for (const Deposition& d : q.depositions) {
      const CellIndex cell{d.row, d.col};
      EXPECT_LE(h(cell) + d.height_m, bound(cell) + 1e-9) << "step " << step << ": (" << d.row << ", " << d.col << ")";
      if (!b.map().is_known(cell)) unseen.push_back(d);
    }
  }
  ASSERT_FALSE(unseen.empty()) << "no deposit below the edge";
  for (const Deposition& d : unseen) EXPECT_GE(d.col, 32) << "below the edge";
}

}  // namespace
}  // namespace marsala::agent::reactive
