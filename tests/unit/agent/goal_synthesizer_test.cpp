#include "agent/deliberative/goal_synthesizer.hpp"

#include <gtest/gtest.h>

#include "common/error.hpp"

namespace marsala::agent::deliberative {
namespace {

TEST(GoalSynthesizer, FixedTargetIsTheAdmissionsTargetWhereverTheRobotIs) {
  bus::Admission a;
  a.target_x_m = 12.5;
  a.target_y_m = -3.25;
  const auto goal = make_goal_synthesizer("fixed_target");
  EXPECT_EQ(goal->name(), "fixed_target");
  for (const Position robot : {Position{0.0, 0.0}, Position{12.5, -3.25}, Position{-100.0, 7.0}}) {
    const Position t = goal->target(a, robot);
    EXPECT_EQ(t.x, 12.5);
    EXPECT_EQ(t.y, -3.25);
  }
}

TEST(GoalSynthesizer, RegistryListsValidNamesOnAnUnknownOne) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  EXPECT_TRUE(registry.names().empty());
  register_builtins(registry);
  EXPECT_EQ(registry.names(), std::vector<std::string>{"fixed_target"});
  EXPECT_TRUE(registry.contains("fixed_target"));
  try {
    make_goal_synthesizer("goal_vector_map");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown goal synthesizer 'goal_vector_map'"), std::string::npos) << what;
    EXPECT_NE(what.find("fixed_target"), std::string::npos) << what;
  }
  EXPECT_THROW(register_builtins(registry), InvalidArgument);  // registered twice
  EXPECT_THROW(registry.add("", [] { return std::make_unique<FixedTarget>(); }), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::deliberative
