// The initial state in two layers: world_state_at() takes its starts as given and sets up no completion check;
// make_world_state() (initial_state.hpp) decides the starts (jitter) and evaluates the check once.
#include "marsala/world_server/rules/initial_state.hpp"

#include <gtest/gtest.h>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/start_jitter.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::flat_terrain;
using testing::small_scenario;

TEST(WorldStateAt, PlacesEachSlotAtTheStartGivenAndChecksNothingYet) {
  const scenario::Scenario s =
      scenario::parse_scenario(testing::small_scenario_text_completing(testing::payload_block()), "small.pbtxt");
  const WorldState w = world_state_at(s, flat_terrain(), {{1.25, 2.5}, {3.0, 0.75}});
  ASSERT_EQ(w.agents.size(), 2u);
  EXPECT_EQ(w.agent(1).start.x, 1.25);
  EXPECT_EQ(w.agent(1).position.y, 2.5);
  EXPECT_EQ(w.agent(2).position.x, 3.0);
  EXPECT_EQ(w.agent(2).start.y, 0.75);
  EXPECT_FALSE(w.agent(1).admitted);
  EXPECT_EQ(w.check.evaluations, 0u);  // the check is set up above this layer
  EXPECT_THROW(world_state_at(s, flat_terrain(), {}), InvalidArgument);
  EXPECT_THROW(world_state_at(s, flat_terrain(), std::vector<Position>(4, Position{1.0, 1.0})), InvalidArgument);
}

TEST(MakeWorldState, JittersTheStartsAndEvaluatesTheCheckOnce) {
  const scenario::Scenario s = scenario::parse_scenario(
      testing::small_scenario_text_completing(testing::payload_block(), "start_jitter_m: 0.3\nseed: 5\n"),
      "small.pbtxt");
  const WorldState w = make_world_state(s, flat_terrain(), 2);
  EXPECT_EQ(w.check.evaluations, 1u);
  EXPECT_TRUE(w.check.met);  // a flat terrain is navigable from the start
  for (std::uint32_t id = 1; id <= 2; ++id) {
    const Position p = jittered_start(w.terrain, s.slots[id - 1], s.robot_for(id).body, 0.3, 5);
    EXPECT_EQ(w.agent(id).start.x, p.x);
    EXPECT_EQ(w.agent(id).start.y, p.y);
  }
  EXPECT_THROW(make_world_state(s, flat_terrain(), 0), InvalidArgument);
  EXPECT_THROW(make_world_state(s, flat_terrain(), 4), InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
