// The ramp builder (agent/reactive/ramp_builder.hpp): every state and transition of its state machine, on a flat
// 6 x 10 m world with a platform, frame by frame and closed loop with the mini world.

#include "marsala/agent/reactive/ramp_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "unit/agent/agent_test_support.hpp"
#include "unit/agent/mini_world.hpp"

namespace marsala::agent::reactive {
namespace {

AgentContext context(std::uint32_t id = 3, RobotBody body = test::husky()) { return test::agent_context(id, body); }

protocol::Admission admission(const AgentContext& c, Position target, Position base = {0.55, 3.05}) {
  return test::admission_on(c, test::platform_world().geometry(), target, base);
}

/// A frame at `pose` carrying every tile of `h`.
protocol::SensorFrame frame(const AgentContext& c, std::uint64_t step, Position pose, double material_m3,
                            const Heightmap& h = test::platform_world()) {
  return test::full_frame(c, step, pose, material_m3, h);
}

TEST(RampState, NamesRoundTrip) {
  const std::vector<std::pair<RampState, std::string>> names{{RampState::kWaitAdmission, "wait_admission"},
                                                             {RampState::kSurvey, "survey"},
                                                             {RampState::kAdvance, "advance"},
                                                             {RampState::kBuild, "build"},
                                                             {RampState::kRetreat, "retreat"},
                                                             {RampState::kReturnToBase, "return_to_base"},
                                                             {RampState::kAtGoal, "at_goal"},
                                                             {RampState::kDone, "done"}};
  for (const auto& [state, name] : names) {
    EXPECT_EQ(to_string(state), name);
    EXPECT_EQ(ramp_state_from_string(name), state);
  }
  try {
    ramp_state_from_string("dancing");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("valid: wait_admission, survey, advance, build, retreat, return_to_base, "
                                         "at_goal, done"),
              std::string::npos)
        << e.what();
  }
  // The pipeline's states are the path builder's alone.
  for (const char* name : {"follow", "hold", "back_off"}) EXPECT_THROW(ramp_state_from_string(name), InvalidArgument);
}

TEST(RampBuilder, AdmissionIsCheckedAndFramesBeforeItAreRefused) {
  const AgentContext c = context();
  RampBuilder rb(c);
  EXPECT_EQ(rb.state(), RampState::kWaitAdmission);
  EXPECT_THROW(rb.decide(frame(c, 0, {1.05, 3.05}, 1.0)), InvalidArgument);
  protocol::Admission other = admission(c, {8.0, 3.0});
  other.agent_id = 4;
  EXPECT_THROW(rb.on_admission(other), InvalidArgument);
  other = admission(c, {8.0, 3.0});
  other.session = 1;
  EXPECT_THROW(rb.on_admission(other), InvalidArgument);
  other = admission(c, {8.0, 3.0});
  other.accepted = false;
  EXPECT_THROW(rb.on_admission(other), InvalidArgument);
  other = admission(c, {8.0, 3.0});
  other.assignment.world.cell_size_m = 0.0;
  EXPECT_THROW(rb.on_admission(other), InvalidArgument);
  EXPECT_EQ(rb.state(), RampState::kWaitAdmission);
  rb.on_admission(admission(c, {8.0, 3.0}));
  EXPECT_EQ(rb.state(), RampState::kSurvey);
  protocol::SensorFrame stranger = frame(c, 0, {1.05, 3.05}, 1.0);
  stranger.agent_id = 9;
  EXPECT_THROW(rb.decide(stranger), InvalidArgument);
}

TEST(RampBuilder, SurveyThenAdvanceOnFlatGround) {
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.0}));
  const protocol::ActionRequest q = rb.decide(frame(c, 5, {1.05, 3.05}, 1.0));
  EXPECT_EQ(rb.last_trace().before, RampState::kSurvey);
  EXPECT_EQ(rb.state(), RampState::kAdvance);
  EXPECT_EQ(q.state, "advance");
  EXPECT_EQ(q.step, 5u);
  EXPECT_EQ(q.agent_id, 3u);
  EXPECT_EQ(q.session, 77u);
  // Two cells east along the robot's row: 0.2 m, the whole step.
  ASSERT_TRUE(q.move);
  EXPECT_NEAR(q.target_x_m, 1.25, 1e-12);
  EXPECT_NEAR(q.target_y_m, 3.05, 1e-12);
  EXPECT_TRUE(q.depositions.empty());  // the platform is 6 m away: no gap within reach
  EXPECT_EQ(rb.map().known_cells(), 6000);
}

TEST(RampBuilder, SurveyStraightToAtGoalAndBackToAdvanceWhenMovedOff) {
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.02, 3.03}));  // inside cell (29, 80)
  protocol::ActionRequest q = rb.decide(frame(c, 0, {8.05, 3.05}, 1.0));
  EXPECT_EQ(rb.state(), RampState::kAtGoal);
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
  q = rb.decide(frame(c, 1, {8.05, 3.05}, 1.0));
  EXPECT_EQ(rb.state(), RampState::kAtGoal);
  q = rb.decide(frame(c, 2, {8.35, 3.05}, 1.0));  // pushed off the target cell
  EXPECT_EQ(rb.last_trace().before, RampState::kAtGoal);
  EXPECT_EQ(rb.state(), RampState::kAdvance);
  EXPECT_TRUE(q.move);
}

TEST(RampBuilder, ReturnsToBaseWhenOutOfMaterialAndRefillsThere) {
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.0}, {0.55, 3.05}));
  // Less than one cube (1.25e-4 m^3) on board, 1 m from the base: head west.
  protocol::ActionRequest q = rb.decide(frame(c, 0, {1.55, 3.05}, 1e-4));
  EXPECT_EQ(rb.state(), RampState::kReturnToBase);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, 1.55);
  EXPECT_FALSE(q.refill);
  EXPECT_TRUE(q.depositions.empty());
  // Within the base radius (0.5 m): refill, and back to work.
  q = rb.decide(frame(c, 1, {0.85, 3.05}, 1e-4));
  EXPECT_EQ(rb.last_trace().before, RampState::kReturnToBase);
  EXPECT_TRUE(q.refill);
  EXPECT_EQ(rb.state(), RampState::kAdvance);
}

TEST(RampBuilder, RunOverEndsInDone) {
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.0}));
  rb.decide(frame(c, 0, {1.05, 3.05}, 1.0));
  protocol::SensorFrame over = frame(c, 1, {1.25, 3.05}, 1.0);
  over.run_over = true;
  const protocol::ActionRequest q = rb.decide(over);
  EXPECT_EQ(rb.state(), RampState::kDone);
  EXPECT_EQ(q.state, "done");
  EXPECT_FALSE(q.move);
  EXPECT_EQ(q.step, 1u);
}

TEST(RampBuilder, BlockedWithNothingInReachRetreats) {
  // A body that can place material only in a ring it never reaches (reach = delta / 2): at the foot of the
  // platform it is blocked and has nothing to deposit, so it backs off the way it came.
  RobotBody body = test::husky();
  body.reach_m = 0.5;
  const AgentContext c = context(3, body);
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.05}));
  rb.decide(frame(c, 0, {5.95, 3.05}, 1.0));                                    // came from the west...
  const protocol::ActionRequest q = rb.decide(frame(c, 1, {6.45, 3.05}, 1.0));  // ... to the foot of the platform
  EXPECT_EQ(rb.last_trace().before, RampState::kAdvance);
  EXPECT_EQ(rb.state(), RampState::kRetreat);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, 6.45);
  EXPECT_TRUE(q.depositions.empty());
}

/// Every transition the ramp builder takes on the way up the platform, driven by the mini world.
TEST(RampBuilder, ClimbingThePlatformExercisesTheBuildingTransitions) {
  const AgentContext c = context(1, test::husky(0.3));
  test::MiniWorld world(test::platform_world(), 16, {0.55, 3.05}, 0.5);
  RampBuilder rb(c);
  rb.on_admission(world.admit(1, c.session, c.type.body, {1.05, 3.05}, {8.5, 3.05}));
  std::set<std::pair<RampState, RampState>> seen;
  for (int step = 0; step < 800 && rb.state() != RampState::kAtGoal; ++step) {
    const protocol::ActionRequest q = rb.decide(world.frame_for(1));
    seen.insert({rb.last_trace().before, rb.last_trace().after});
    ASSERT_EQ(world.validate(q), "") << "step " << step << " in " << q.state;
    world.apply_step({q});
  }
  EXPECT_EQ(rb.state(), RampState::kAtGoal);
  // kappa 0.3: the ramp is longer than the robot sees when it first meets the platform, so it has to back off.
  for (const auto& t : std::vector<std::pair<RampState, RampState>>{{RampState::kSurvey, RampState::kAdvance},
                                                                    {RampState::kAdvance, RampState::kBuild},
                                                                    {RampState::kBuild, RampState::kAdvance},
                                                                    {RampState::kBuild, RampState::kRetreat},
                                                                    {RampState::kRetreat, RampState::kRetreat},
                                                                    {RampState::kRetreat, RampState::kAdvance},
                                                                    {RampState::kAdvance, RampState::kAtGoal}})
    EXPECT_EQ(seen.count(t), 1u) << to_string(t.first) << " -> " << to_string(t.second);
  rb.decide(world.frame_for(1, true));
  EXPECT_EQ(rb.state(), RampState::kDone);
}

TEST(RampBuilder, NoDepositionPathThroughKnownCellsRequestsNothingAndKeepsTheState) {
  // The robot has seen only its own tile: the local goal, 4 m east, is unknown, so no path leads there yet.
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.05}));
  const Position at{1.05, 2.05};
  const protocol::SensorFrame f = test::keep_tile_at(frame(c, 0, at, 1.0), test::platform_world().geometry(), at);
  ASSERT_EQ(f.tiles.size(), 1u);
  const protocol::ActionRequest q = rb.decide(f);
  EXPECT_TRUE(rb.last_trace().planned);
  EXPECT_FALSE(rb.last_trace().plan.found);
  EXPECT_EQ(rb.state(), RampState::kAdvance);  // survey ends on the first frame; nothing else changes it
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
  EXPECT_EQ(q.state, "advance");
}

TEST(RampBuilder, KeepsBuildingWithLessThanADepositionThresholdButAtLeastACubeOnBoard) {
  // One cube is 1.25e-4 m^3 (5 cm cubes on 0.1 m cells); 0.01 m^3 is half a deposition threshold. The ramp builder
  // goes back only below one cube (the path builder already below one threshold).
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.0}));
  protocol::ActionRequest q = rb.decide(frame(c, 0, {1.55, 3.05}, 0.01));
  EXPECT_EQ(rb.state(), RampState::kAdvance);
  ASSERT_TRUE(q.move);
  EXPECT_GT(q.target_x_m, 1.55);
  q = rb.decide(frame(c, 1, {1.75, 3.05}, 1.2e-4));  // below one cube
  EXPECT_EQ(rb.state(), RampState::kReturnToBase);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, 1.75);
}

TEST(RampBuilder, StaysAtTheGoalOutOfMaterial) {
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.02, 3.03}));  // inside cell (29, 80)
  const protocol::ActionRequest q = rb.decide(frame(c, 0, {8.05, 3.05}, 0.0));
  EXPECT_EQ(rb.state(), RampState::kAtGoal);
  EXPECT_FALSE(q.move);
  EXPECT_FALSE(q.refill);
}

TEST(RampBuilder, BuildsOnPastANeighbourButNeverIntoItsBody) {
  // No pipeline here: a neighbour 1.5 m ahead neither holds it back nor makes it step aside.
  const AgentContext c = context();
  RampBuilder rb(c);
  rb.on_admission(admission(c, {8.0, 3.05}));
  protocol::SensorFrame f = frame(c, 0, {3.05, 3.05}, 1.0);
  f.neighbours = {test::neighbour_at(4, 4.55, 3.05)};
  protocol::ActionRequest q = rb.decide(f);
  EXPECT_EQ(rb.state(), RampState::kAdvance);
  ASSERT_TRUE(q.move);
  EXPECT_GT(q.target_x_m, 3.05);
  EXPECT_NEAR(q.target_y_m, 3.05, 1e-12);
  // Touching (1 m ahead, bodies of 1 m): no motion ends nearer to it than 1 m (docs/runtime.md#collisions).
  RampBuilder touching(c);
  touching.on_admission(admission(c, {8.0, 3.05}));
  f.neighbours = {test::neighbour_at(4, 4.05, 3.05)};
  q = touching.decide(f);
  if (q.move) {
    EXPECT_GE(std::hypot(q.target_x_m - 4.05, q.target_y_m - 3.05), 1.0 - 1e-9);
  }
}

}  // namespace
}  // namespace marsala::agent::reactive
