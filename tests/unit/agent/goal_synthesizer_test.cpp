#include "agent/deliberative/goal_synthesizer.hpp"

#include <gtest/gtest.h>

#include "common/error.hpp"

namespace marsala::agent::deliberative {
namespace {

TEST(GoalSynthesizer, FixedTargetIsTheAdmissionsTargetWhereverTheRobotIs) {
  AgentContext context;
  context.admission.target_x_m = 12.5;
  context.admission.target_y_m = -3.25;
  const auto goal = make_goal_synthesizer("fixed_target", context);
  EXPECT_EQ(goal->name(), "fixed_target");
  for (const Position robot : {Position{0.0, 0.0}, Position{12.5, -3.25}, Position{-100.0, 7.0}}) {
    const std::optional<Position> t = goal->target({robot, {}});
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->x, 12.5);
    EXPECT_EQ(t->y, -3.25);
  }
}

TEST(GoalSynthesizer, RegistryListsValidNamesOnAnUnknownOne) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  EXPECT_TRUE(registry.names().empty());
  register_builtins(registry);
  EXPECT_EQ(registry.names(), (std::vector<std::string>{"fixed_target", "goal_vector_map"}));
  EXPECT_TRUE(registry.contains("fixed_target"));
  try {
    make_goal_synthesizer("spiral", AgentContext{});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown goal synthesizer 'spiral'"), std::string::npos) << what;
    EXPECT_NE(what.find("fixed_target"), std::string::npos) << what;
  }
  EXPECT_THROW(register_builtins(registry), InvalidArgument);  // registered twice
  EXPECT_THROW(registry.add("", [](const AgentContext& c) { return std::make_unique<FixedTarget>(c); }),
               InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::deliberative
