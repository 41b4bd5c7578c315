#include "marsala/world_server/runtime/metrics_snapshot.hpp"

#include <gtest/gtest.h>

#include "marsala/world_server/rules/admission.hpp"
#include "marsala/world_server/rules/initial_state.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::flat_terrain;
using testing::hello_for;
using testing::move_to;
using testing::request_for;
using testing::small_scenario;

// The state's numbers, as summary.json counts them: two of three slots admitted, one of them dropped after three
// missed deadlines, one rejected request, one forged one.
TEST(MetricsSnapshot, TakesTheStatesCountsAsTheSummaryDoes) {
  WorldState w = make_world_state(small_scenario(), flat_terrain(), 3);
  admit(w, hello_for(w, 1, 1001));
  admit(w, hello_for(w, 2, 1002));  // slot 3 never admitted
  protocol::ActionRequest forged = request_for(w, 1);
  forged.session += 1;
  apply_step(w, std::vector<Submission>{{1, forged}, {1, move_to(w, 1, 1.25, 1.05)}});  // 2 misses its first
  apply_step(w, std::vector<protocol::ActionRequest>{move_to(w, 1, 3.0, 1.05)});  // rejected: 1.75 m in one step
  apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1)});          // 2 dropped: third miss
  w.surplus_requests = 4;

  MetricsSnapshot s;
  s.run_id = "kept";
  take_state(s, w, {true, true, true});
  EXPECT_EQ(s.run_id, "kept");
  EXPECT_EQ(s.steps, 3u);
  EXPECT_EQ(s.agents_expected, 3u);
  EXPECT_EQ(s.agents_admitted, 2u);
  EXPECT_EQ(s.agents_live, 1u);
  EXPECT_EQ(s.agents_connected, 1u);  // a dropped agent is not connected, whatever its writer does
  EXPECT_EQ(s.agents_dropped, 1u);
  EXPECT_EQ(s.deadline_misses, 3u);
  EXPECT_EQ(s.rejected_requests, 1u);
  EXPECT_EQ(s.unattributed_rejections, 1u);
  EXPECT_EQ(s.surplus_requests, 4u);
  EXPECT_EQ(s.deposited_m3, 0.0);
  ASSERT_EQ(s.agents.size(), 3u);
  EXPECT_EQ(s.agents[0].accepted, 2u);
  EXPECT_EQ(s.agents[0].rejected, 1u);
  EXPECT_TRUE(s.agents[0].connected);
  EXPECT_EQ(s.agents[1].missed, 3u);
  EXPECT_FALSE(s.agents[1].alive);
  EXPECT_FALSE(s.agents[2].admitted);
  EXPECT_EQ(s.agents[0].material_m3, 0.05);

  take_state(s, w, {false});  // entries missing: not connected
  EXPECT_EQ(s.agents_connected, 0u);
  EXPECT_EQ(s.agents.size(), 3u);  // taken afresh, not appended
}

}  // namespace
}  // namespace marsala::world_server
