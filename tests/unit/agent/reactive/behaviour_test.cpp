// The reactive layer: the behaviour registry and the idle behaviour (the ramp and path builders have their own tests).

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/agent/reactive/idle_behaviour.hpp"
#include "marsala/agent/reactive/path_builder.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/core/error.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::reactive {
namespace {

AgentContext context(std::uint32_t id = 3, RobotBody body = test::husky()) { return test::agent_context(id, body); }

protocol::Admission admission(const AgentContext& c, Position target, Position base = {0.55, 3.05}) {
  return test::admission_on(c, test::platform_world().geometry(), target, base);
}

/// A frame at `pose` carrying every tile of the world.
protocol::SensorFrame frame(const AgentContext& c, std::uint64_t step, Position pose, double material_m3) {
  return test::full_frame(c, step, pose, material_m3, test::platform_world());
}

TEST(BehaviourRegistry, MakesBuiltinsByNameAndListsThemOnAnUnknownOne) {
  // Each name makes its own class, with its own states.
  const auto ramp = make_behaviour("ramp_builder", context());
  EXPECT_EQ(ramp->name(), "ramp_builder");
  ASSERT_NE(dynamic_cast<RampBuilder*>(ramp.get()), nullptr);
  EXPECT_EQ(ramp->state_name(), to_string(RampState::kWaitAdmission));
  const auto path = make_behaviour("path_builder", context());
  EXPECT_EQ(path->name(), "path_builder");
  ASSERT_NE(dynamic_cast<PathBuilder*>(path.get()), nullptr);
  EXPECT_EQ(path->state_name(), to_string(PathState::kWaitAdmission));
  EXPECT_EQ(make_behaviour("idle", context())->name(), "idle");
  BehaviourRegistry registry = make_behaviour_registry();
  register_builtins(registry);
  EXPECT_EQ(registry.names(), (std::vector<std::string>{"idle", "path_builder", "ramp_builder"}));
  try {
    make_behaviour("leveller", context());
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown behaviour 'leveller'; valid: idle, path_builder, ramp_builder"),
              std::string::npos)
        << e.what();
  }
  RobotBody bad = test::husky();
  bad.navigability.kappa = -1.0;
  EXPECT_THROW(make_behaviour("ramp_builder", context(3, bad)), InvalidArgument);
  EXPECT_THROW(make_behaviour("path_builder", context(3, bad)), InvalidArgument);
  // The pipeline's separation is the path builder's alone.
  AgentContext no_separation = context();
  no_separation.type.pipeline.separation_m = 0.0;
  EXPECT_THROW(make_behaviour("path_builder", no_separation), InvalidArgument);
  EXPECT_EQ(make_behaviour("ramp_builder", no_separation)->name(), "ramp_builder");
}

TEST(IdleBehaviour, AnswersEveryFrameWithAnEmptyRequest) {
  const AgentContext c = context();
  IdleBehaviour idle(c);
  EXPECT_EQ(idle.state_name(), "wait_admission");
  EXPECT_THROW(idle.decide(frame(c, 0, {1.05, 3.05}, 1.0)), InvalidArgument);
  idle.on_admission(admission(c, {8.0, 3.0}));
  for (std::uint64_t step = 0; step < 3; ++step) {
    const protocol::ActionRequest q = idle.decide(frame(c, step, {1.05, 3.05}, 1.0));
    EXPECT_EQ(q.agent_id, 3u);
    EXPECT_EQ(q.session, 77u);
    EXPECT_EQ(q.step, step);
    EXPECT_FALSE(q.move);
    EXPECT_FALSE(q.refill);
    EXPECT_TRUE(q.depositions.empty());
    EXPECT_EQ(q.state, "idle");
  }
  protocol::SensorFrame over = frame(c, 3, {1.05, 3.05}, 1.0);
  over.run_over = true;
  EXPECT_EQ(idle.decide(over).state, "done");
}

}  // namespace
}  // namespace marsala::agent::reactive
