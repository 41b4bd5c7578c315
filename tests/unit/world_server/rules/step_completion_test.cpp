// apply_step with payload_path and level_site completion: the check's schedule ((step + 1) % every == 0 and a
// change since the previous evaluation), completion from the start, progress; per-cell depositors; idle steps.

#include <gtest/gtest.h>

#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::payload_block;
using testing::request_for;
using testing::site_block;
using testing::small_scenario_text_completing;

scenario::Scenario scenario_with(const std::string& completion) {
  return scenario::parse_scenario(small_scenario_text_completing(completion), "small.pbtxt");
}

protocol::ActionRequest deposit(const WorldState& s, std::uint32_t id, CellIndex cell, double height_m) {
  protocol::ActionRequest r = request_for(s, id);
  r.depositions.push_back({cell.row, cell.col, height_m});
  return r;
}

/// Steps with every live agent idle (requests that do nothing).
void idle_steps(WorldState& s, int n) {
  for (int i = 0; i < n; ++i) {
    std::vector<protocol::ActionRequest> requests;
    for (std::uint32_t id : s.live_ids()) requests.push_back(request_for(s, id));
    apply_step(s, requests);
  }
}

TEST(PayloadCompletion, AnAlreadyNavigablePayloadIsCompleteFromTheStart) {
  const WorldState s = admitted_state(scenario_with(payload_block()), flat_terrain(), 1);
  EXPECT_EQ(s.completion, scenario::CompletionKind::kPayloadPath);
  EXPECT_TRUE(is_completed(s));
  EXPECT_EQ(progress(s), 1.0);
  EXPECT_EQ(s.check.evaluations, 1u);
  // Without any agent live it still is: completion is about the terrain.
  const WorldState none = make_world_state(scenario_with(payload_block()), flat_terrain(), 1);
  EXPECT_TRUE(is_completed(none));
}

TEST(PayloadCompletion, TheCheckRunsOnItsScheduleOnlyAfterChanges) {
  // A 0.1 m hole beside `to` (row 9, col 30), in its ball, spoils it for the payload (ball 3 x 3, eps 0.05, kappa
  // 0.2). Beside, not under: filling a hole under `to` would raise the target's cell (next test).
  Heightmap terrain = flat_terrain();
  const CellIndex hole{9, 29};
  terrain(hole) = -8 * kLayer;
  WorldState s = admitted_state(scenario_with(payload_block(3)), terrain, 2);
  EXPECT_FALSE(is_completed(s));
  EXPECT_EQ(progress(s), 0.0);
  EXPECT_EQ(s.check.evaluations, 1u);
  s.agent(1).position.x = 2.15;  // 0.8 m west of the hole: within reach, not over it
  s.agent(1).position.y = 3.05;

  // Step 0 fills the hole; no check at steps 0 and 1, the check at step 2 finds the path.
  StepOutcome o =
      apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, hole, 8 * kLayer), request_for(s, 2)});
  ASSERT_EQ(s.agent(1).last_result, protocol::ActionResult::kAccepted) << s.agent(1).last_reason;
  EXPECT_EQ(s.terrain(hole), 0.0);
  EXPECT_FALSE(o.completion_checked);
  EXPECT_FALSE(o.completed);
  EXPECT_TRUE(payload_path_navigable(s.terrain, s.payload_path));  // true already, not yet checked
  idle_steps(s, 1);
  EXPECT_FALSE(is_completed(s));
  EXPECT_EQ(s.check.evaluations, 1u);
  o = apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1), request_for(s, 2)});
  EXPECT_EQ(o.step, 2u);
  EXPECT_TRUE(o.completion_checked);
  EXPECT_TRUE(o.completed);
  EXPECT_TRUE(is_completed(s));
  EXPECT_EQ(progress(s), 1.0);
  EXPECT_EQ(s.check.evaluations, 2u);

  // Steps 5, 8, ... would check, but nothing changes: no evaluation.
  idle_steps(s, 7);
  EXPECT_EQ(s.check.evaluations, 2u);
}

TEST(PayloadCompletion, APathOverARaisedTargetIsNoCompletion) {
  // The payload has its path from the start (flat ground), so the check is met; then the target's cell is raised.
  WorldState s = admitted_state(scenario_with(payload_block(3)), flat_terrain(), 2);
  ASSERT_TRUE(is_completed(s));
  const CellIndex to = s.check.to;
  EXPECT_EQ(to, (CellIndex{9, 30}));
  EXPECT_EQ(s.check.target_initial_m, 0.0);
  EXPECT_EQ(s.check.max_target_rise_m, kLayer);  // one cube layer of the scenario's robot type
  s.agent(1).position.x = 2.25;  // 0.8 m west of `to`
  s.agent(1).position.y = 3.05;
  // Two layers on the target's cell (0.025 m, less than eps: the payload still drives over it): a path, no completion.
  StepOutcome o = apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, to, 2 * kLayer), request_for(s, 2)});
  ASSERT_EQ(s.agent(1).last_result, protocol::ActionResult::kAccepted) << s.agent(1).last_reason;
  idle_steps(s, 2);  // step 2 checks (every 3 steps)
  EXPECT_TRUE(payload_path_navigable(s.terrain, s.payload_path));
  EXPECT_TRUE(s.check.path_found);
  EXPECT_FALSE(s.check.met);
  EXPECT_FALSE(is_completed(s));
  EXPECT_EQ(progress(s), 0.0);
  EXPECT_DOUBLE_EQ(target_rise_m(s), 2 * kLayer);
  EXPECT_EQ(payload_completion_detail(s, true),
            "payload path found, but the target's cell stands 0.025 m above its initial height (at most 0.0125 m "
            "allowed)");
  EXPECT_EQ(payload_completion_detail(s, false), "no payload path from base to target");
  // One layer is within the allowance: the same with a single layer completes.
  WorldState t = admitted_state(scenario_with(payload_block(3)), flat_terrain(), 2);
  t.agent(1).position.x = 2.25;
  t.agent(1).position.y = 3.05;
  o = apply_step(t, std::vector<protocol::ActionRequest>{deposit(t, 1, to, kLayer), request_for(t, 2)});
  idle_steps(t, 2);
  EXPECT_EQ(t.check.evaluations, 2u);
  EXPECT_TRUE(is_completed(t));
  EXPECT_EQ(payload_completion_detail(t, true), "payload path found, target's cell within 0.0125 m of its initial height");
}

TEST(PayloadCompletion, EndsOffTheGridAreRefusedWhenTheStateIsMade) {
  const std::string off =
      "payload_path { body { kappa: 0.2 delta_m: 0.3 eps_m: 0.05 } from { x_m: 0.55 y_m: 0.55 } "
      "to { x_m: 4.05 y_m: 3.05 } }";
  EXPECT_THROW(make_world_state(scenario_with(off), flat_terrain(), 1), InvalidArgument);
  EXPECT_THROW(make_world_state(scenario_with("site { x0_m: 5 y0_m: 0 x1_m: 6 y1_m: 1 }"), flat_terrain(), 1),
               InvalidArgument);
}

TEST(SiteCompletion, LevelFractionIsProgressAndCompletesWhenLevel) {
  // Site rows 10..19 x cols 20..29; a 0.1 m hole at (15, 25) spoils its 3 x 3 neighbourhood: 91 of 100 cells.
  Heightmap terrain = flat_terrain();
  const CellIndex hole{15, 25};
  terrain(hole) = -8 * kLayer;
  WorldState s = admitted_state(scenario_with(site_block(2)), terrain, 1);
  EXPECT_EQ(s.completion, scenario::CompletionKind::kLevelSite);
  EXPECT_DOUBLE_EQ(s.check.level_fraction, 0.91);
  EXPECT_DOUBLE_EQ(progress(s), 0.91);
  EXPECT_FALSE(is_completed(s));

  // A deposition outside the site (cell (30, 18), 0.81 m from the agent) is no change for its check.
  s.agent(1).position.x = 1.05;
  s.agent(1).position.y = 1.05;
  apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, {30, 18}, kLayer)});
  StepOutcome o = apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1)});
  EXPECT_FALSE(o.completion_checked);
  EXPECT_EQ(s.check.evaluations, 1u);

  // Filling the hole at step 2 (not a check step), the check at step 3 sees a level site.
  s.agent(1).position.x = 2.55;
  s.agent(1).position.y = 1.65;  // 0.9 m south of the hole
  o = apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, hole, 8 * kLayer)});
  ASSERT_EQ(s.agent(1).last_result, protocol::ActionResult::kAccepted) << s.agent(1).last_reason;
  EXPECT_FALSE(o.completion_checked);
  EXPECT_DOUBLE_EQ(progress(s), 0.91);
  o = apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1)});
  EXPECT_TRUE(o.completion_checked);
  EXPECT_TRUE(o.completed);
  EXPECT_EQ(s.check.level_fraction, 1.0);
  EXPECT_EQ(progress(s), 1.0);
}

TEST(SiteCompletion, MinFractionBelowOneAcceptsAPartlyLevelSite) {
  Heightmap terrain = flat_terrain();
  terrain(15, 25) = -0.1;
  EXPECT_TRUE(is_completed(admitted_state(scenario_with(site_block(2, 0.9)), terrain, 1)));
  EXPECT_FALSE(is_completed(admitted_state(scenario_with(site_block(2, 0.92)), terrain, 1)));
}

TEST(Depositors, EachCellRemembersWhoRaisedItLastAndIdleStepsAreCounted) {
  const scenario::Scenario sc = testing::small_scenario();
  WorldState s = admitted_state(sc, flat_terrain(), 2);  // agent 1 at (1.05, 1.05), agent 2 at (2.55, 1.05)
  ASSERT_EQ(s.depositor.rows(), 40);
  EXPECT_EQ(s.depositor.maxCoeff(), 0u);
  const CellIndex shared{29, 18};  // (1.85, 1.05): 0.8 m from agent 1, 0.7 m from agent 2
  apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, shared, kLayer), request_for(s, 2)});
  EXPECT_EQ(s.depositor(shared.row, shared.col), 1u);
  EXPECT_EQ(s.idle_steps, 0u);
  apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1), request_for(s, 2)});
  EXPECT_EQ(s.idle_steps, 1u);
  apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1), deposit(s, 2, shared, kLayer)});
  EXPECT_EQ(s.depositor(shared.row, shared.col), 2u);
  EXPECT_EQ(s.idle_steps, 1u);
  // A rejected deposition (not a whole cube layer) raises nothing: the step is idle, the cell keeps its depositor.
  apply_step(s, std::vector<protocol::ActionRequest>{deposit(s, 1, shared, 0.5 * kLayer), request_for(s, 2)});
  EXPECT_EQ(s.agent(1).last_result, protocol::ActionResult::kRejected);
  EXPECT_EQ(s.depositor(shared.row, shared.col), 2u);
  EXPECT_EQ(s.idle_steps, 2u);
  // A step where every agent missed is idle too.
  apply_step(s, std::vector<protocol::ActionRequest>{});
  EXPECT_EQ(s.idle_steps, 3u);
  // Only deposited cells have a depositor.
  EXPECT_EQ((s.depositor.array() != 0).count(), 1);
}

}  // namespace
}  // namespace marsala::world_server
