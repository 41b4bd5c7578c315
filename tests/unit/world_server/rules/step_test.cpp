#include "marsala/world_server/rules/step.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "marsala/core/error.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::move_to;
using testing::request_for;
using testing::small_scenario;

CellIndex cell_of(double x, double y) {
  return {40 - 1 - static_cast<int>(std::floor(y / 0.1)), static_cast<int>(std::floor(x / 0.1))};
}

protocol::ActionRequest with_deposition(protocol::ActionRequest r, double x, double y, double h) {
  const CellIndex c = cell_of(x, y);
  r.depositions.push_back({c.row, c.col, h});
  return r;
}

int count(const StepOutcome& o, protocol::EventKind kind) {
  return static_cast<int>(
      std::count_if(o.events.begin(), o.events.end(), [&](const auto& e) { return e.kind == kind; }));
}

TEST(ApplyStep, IdOrderDecidesConflictsWhateverTheArrivalOrder) {
  // Agent 1 moves next to the cell agent 2 deposits on: processed first, its new position wins.
  const scenario::Scenario s = small_scenario();
  WorldState base = admitted_state(s, flat_terrain(), 2);  // agent 1 at (1.05, 1.05), agent 2 at (2.55, 1.05)
  const protocol::ActionRequest one = move_to(base, 1, 1.25, 1.05);
  const protocol::ActionRequest two =
      with_deposition(request_for(base, 2), 1.65, 1.05, kLayer);  // 0.4 m from (1.25, 1.05)

  WorldState a = base, b = base;
  const StepOutcome oa = apply_step(a, std::vector<protocol::ActionRequest>{one, two});
  const StepOutcome ob = apply_step(b, std::vector<protocol::ActionRequest>{two, one});
  for (const WorldState* w : {&a, &b}) {
    EXPECT_EQ(w->agent(1).position.x, 1.25);
    EXPECT_EQ(w->agent(2).last_result, protocol::ActionResult::kRejected);
    EXPECT_NE(w->agent(2).last_reason.find("under agent 1"), std::string::npos) << w->agent(2).last_reason;
    EXPECT_EQ(w->terrain.heights().cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(w->step, 1u);
  }
  EXPECT_EQ(oa.accepted, 1u);
  EXPECT_EQ(oa.rejected, 1u);
  ASSERT_EQ(oa.events.size(), ob.events.size());
  for (std::size_t i = 0; i < oa.events.size(); ++i) EXPECT_EQ(oa.events[i].detail, ob.events[i].detail);

  // Alone (no motion of agent 1), agent 2's deposition is fine: the conflict above came from the order.
  WorldState c = base;
  apply_step(c, std::vector<protocol::ActionRequest>{two});
  EXPECT_EQ(c.terrain(cell_of(1.65, 1.05)), kLayer);
}

TEST(ApplyStep, ADepositionOfALowerIdCanBlockAMotionOfAHigherId) {
  const scenario::Scenario s = small_scenario();
  WorldState base = admitted_state(s, flat_terrain(), 2);
  base.agent(2).position.x = 2.45;
  base.agent(2).position.y = 1.15;
  // A 1 m column at (2.05, 1.55): 1.118 m from agent 1, 0.566 m from agent 2, 0.424 m from agent 2's target.
  const protocol::ActionRequest column = with_deposition(request_for(base, 1), 2.05, 1.55, 80 * kLayer);
  const protocol::ActionRequest step_in = move_to(base, 2, 2.35, 1.25);
  for (const auto& order :
       {std::vector<protocol::ActionRequest>{column, step_in}, std::vector<protocol::ActionRequest>{step_in, column}}) {
    WorldState w = base;
    apply_step(w, order);
    EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kAccepted);
    EXPECT_EQ(w.terrain(cell_of(2.05, 1.55)), 80 * kLayer);
    EXPECT_EQ(w.agent(2).last_result, protocol::ActionResult::kRejected);
    EXPECT_NE(w.agent(2).last_reason.find("not occupiable"), std::string::npos) << w.agent(2).last_reason;
    EXPECT_EQ(w.agent(2).position.x, 2.45);
  }
}

TEST(ApplyStep, ArrivalOrderAcrossAgentsNeverChangesTheResult) {
  const scenario::Scenario s = small_scenario();
  const WorldState start = admitted_state(s, flat_terrain(), 3);
  std::mt19937_64 rng(11);
  WorldState in_order = start, shuffled = start;
  for (int step = 0; step < 40; ++step) {
    std::vector<Submission> subs;
    for (std::uint32_t id = 1; id <= 3; ++id) {
      const AgentRecord& a = in_order.agent(id);
      const double angle = std::uniform_real_distribution<double>(0.0, 6.283185307179586)(rng);
      protocol::ActionRequest r = move_to(in_order, id, a.position.x + 0.19 * std::cos(angle), a.position.y + 0.19 * std::sin(angle));
      // Two depositions 0.7-1.1 m away, some of which collide with other robots or cells of other agents.
      for (int k = 0; k < 2; ++k) {
        const double d = std::uniform_real_distribution<double>(0.7, 1.1)(rng);
        const double t = std::uniform_real_distribution<double>(0.0, 6.283185307179586)(rng);
        const double x = r.target_x_m + d * std::cos(t), y = r.target_y_m + d * std::sin(t);
        if (x > 0 && x < 4 && y > 0 && y < 4) r = with_deposition(r, x, y, (1 + k) * kLayer);
      }
      subs.push_back({id, r});
    }
    const StepOutcome a = apply_step(in_order, subs);
    std::shuffle(subs.begin(), subs.end(), rng);
    const StepOutcome b = apply_step(shuffled, subs);
    ASSERT_EQ(a.accepted, b.accepted);
    ASSERT_EQ(a.changed_tiles, b.changed_tiles);
  }
  EXPECT_EQ(runlog::terrain_sha256(in_order.terrain), runlog::terrain_sha256(shuffled.terrain));
  EXPECT_GT(in_order.deposited_volume_m3, 0.0);
  EXPECT_EQ(in_order.deposited_volume_m3, shuffled.deposited_volume_m3);
  for (std::uint32_t id = 1; id <= 3; ++id) {
    EXPECT_EQ(in_order.agent(id).position.x, shuffled.agent(id).position.x);
    EXPECT_EQ(in_order.agent(id).rejected, shuffled.agent(id).rejected);
  }
}

TEST(ApplyStep, TheLowerIdTakesASpotTheHigherIdOnlyOneThatWasLeft) {
  const scenario::Scenario s = small_scenario();
  WorldState base = admitted_state(s, flat_terrain(), 2);
  base.agent(2).position.x = 2.05;  // 1.0 m east of agent 1: touching
  // Agent 2 moves east and agent 1 follows into the space: agent 1 is judged first, agent 2 has not moved yet.
  const protocol::ActionRequest one = move_to(base, 1, 1.2, 1.05), two = move_to(base, 2, 2.2, 1.05);
  WorldState w = base;
  apply_step(w, std::vector<protocol::ActionRequest>{two, one});
  EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kRejected);
  EXPECT_EQ(w.agent(1).position.x, 1.05);
  EXPECT_EQ(w.agent(2).position.x, 2.2);
  EXPECT_EQ(w.rejected_motions, 1u);
  // The other way round: agent 1 moves west and agent 2 follows in the same step.
  w = base;
  apply_step(w, std::vector<protocol::ActionRequest>{move_to(base, 2, 1.9, 1.05), move_to(base, 1, 0.9, 1.05)});
  EXPECT_EQ(w.agent(1).position.x, 0.9);
  EXPECT_EQ(w.agent(2).position.x, 1.9);
  EXPECT_EQ(w.rejected_motions, 0u);
}

TEST(ApplyStep, RandomMotionsNeverMakeBodiesOverlap) {
  // Three robots wander in a 4 x 4 m yard with 1 m bodies; whatever they ask, no pair that was apart ever overlaps
  // after a step, and a pair that overlapped at the start (jittered starts) only moves apart.
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 3);
  w.agent(2).position.x = 1.6;  // 0.55 m from agent 1: the only overlap at the start
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  std::uint64_t rejected = 0;
  for (int step = 0; step < 400; ++step) {
    const WorldState before = w;
    std::vector<protocol::ActionRequest> requests;
    for (std::uint32_t id = 1; id <= 3; ++id) {
      const double t = angle(rng);
      const double x = std::clamp(w.agent(id).position.x + 0.19 * std::cos(t), 0.01, 3.99);
      const double y = std::clamp(w.agent(id).position.y + 0.19 * std::sin(t), 0.01, 3.99);
      requests.push_back(move_to(w, id, x, y));
    }
    apply_step(w, requests);
    for (std::uint32_t a = 1; a <= 3; ++a)
      for (std::uint32_t b = a + 1; b <= 3; ++b) {
        const auto gap = [&](const WorldState& st) {
          return std::hypot(st.agent(a).position.x - st.agent(b).position.x, st.agent(a).position.y - st.agent(b).position.y);
        };
        if (gap(w) < 1.0 - 1e-9) {
          ASSERT_LT(gap(before), 1.0 - 1e-9) << "agents " << a << ", " << b << " came to overlap at step " << step;
          ASSERT_GE(gap(w), gap(before) - 1e-12) << "agents " << a << ", " << b << " came closer at step " << step;
        }
      }
  }
  rejected = w.rejected_motions;
  EXPECT_GT(rejected, 0u);  // the yard is small: some motions were refused
  EXPECT_EQ(w.close_passes, 0u);
  EXPECT_GE(w.overlap_pair_steps, 1u);  // the starting overlap lasted at least its first step
}

TEST(ApplyStep, CountsOverlappingPairSteps) {
  // On a state the rule cannot produce (positions set directly); close passes cannot happen under rule 2.5 at all
  // (RandomMotionsNeverMakeBodiesOverlap), they are counted for runs of worlds without it.
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 3);  // 1 (1.05, 1.05), 2 (2.55, 1.05), 3 (1.05, 3.05)
  const auto stand_still = [&] {
    apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1), request_for(w, 2), request_for(w, 3)});
  };
  stand_still();
  EXPECT_EQ(w.overlap_pair_steps, 0u);
  w.agent(2).position.x = 1.55;  // overlaps agent 1 from now on
  for (int i = 0; i < 3; ++i) stand_still();
  EXPECT_EQ(w.overlap_pair_steps, 3u);
  EXPECT_EQ(w.close_passes, 0u);  // the overlap was there before each step: no new pass
  // A dropped robot is off the field: its overlap stops counting.
  w.agent(1).alive = false;
  apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 2), request_for(w, 3)});
  EXPECT_EQ(w.overlap_pair_steps, 3u);
}

TEST(ApplyStep, DuplicatesPastAndFutureRequests) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 2);
  apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1), request_for(w, 2)});
  ASSERT_EQ(w.step, 1u);

  protocol::ActionRequest past = request_for(w, 1);
  past.step = 0;
  const protocol::ActionRequest first = move_to(w, 1, 1.25, 1.05);
  const protocol::ActionRequest second = move_to(w, 1, 0.85, 1.05);
  protocol::ActionRequest future = request_for(w, 1);
  future.step = 2;
  protocol::ActionRequest future_of_2 = request_for(w, 2);
  future_of_2.step = 2;
  const StepOutcome o =
      apply_step(w, std::vector<Submission>{{1, past}, {1, first}, {2, future_of_2}, {1, second}, {1, future}});

  EXPECT_EQ(w.agent(1).position.x, 1.25);  // the first stands
  EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kAccepted);
  EXPECT_EQ(w.agent(1).accepted, 2u);
  EXPECT_EQ(w.agent(1).rejected, 2u);  // the duplicate and the future one
  EXPECT_EQ(w.agent(1).missed, 0u);
  EXPECT_EQ(w.agent(2).rejected, 1u);
  EXPECT_EQ(w.agent(2).missed, 1u);  // a request for another step does not answer this one
  EXPECT_EQ(w.agent(2).last_result, protocol::ActionResult::kMissed);
  EXPECT_EQ(o.accepted, 1u);
  EXPECT_EQ(o.rejected, 3u);
  EXPECT_EQ(o.missed, 1u);
  EXPECT_EQ(count(o, protocol::EventKind::kRejected), 3);
  EXPECT_EQ(count(o, protocol::EventKind::kMissed), 1);
  ASSERT_EQ(o.notes.size(), 1u);
  EXPECT_NE(o.notes[0].find("past step 0"), std::string::npos);
}

TEST(ApplyStep, AForgedRequestOnAnAgentsPartitionDoesNotTakeItsSlot) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 2);
  // Another process writes on agent 1's partition first: once claiming agent 1 with a wrong session, once
  // claiming agent 2. Agent 1's own request, arriving after them, must still be the one that counts.
  protocol::ActionRequest forged = move_to(w, 1, 0.85, 1.05);
  forged.session += 1;
  protocol::ActionRequest claims_2 = request_for(w, 2);
  const protocol::ActionRequest real = move_to(w, 1, 1.25, 1.05);
  const StepOutcome o =
      apply_step(w, std::vector<Submission>{{1, forged}, {1, claims_2}, {1, real}, {2, request_for(w, 2)}});
  EXPECT_EQ(w.agent(1).position.x, 1.25);
  EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kAccepted);
  EXPECT_EQ(w.agent(1).missed, 0u);
  // Rejections are charged to the sender, never to the victim: the request with agent 2's admitted identity to
  // agent 2, the one with no admitted identity to no agent.
  EXPECT_EQ(w.agent(1).rejected, 0u);
  EXPECT_EQ(w.agent(2).accepted, 1u);
  EXPECT_EQ(w.agent(2).rejected, 1u);
  EXPECT_EQ(w.unattributed_rejections, 1u);
  EXPECT_EQ(o.accepted, 2u);
  EXPECT_EQ(o.rejected, 2u);
  std::vector<std::uint32_t> charged;
  for (const protocol::WorldEvent& e : o.events)
    if (e.kind == protocol::EventKind::kRejected) charged.push_back(e.agent_id);
  EXPECT_EQ(charged, (std::vector<std::uint32_t>{0, 2}));
}

// An agent that got its frame twice sends the same request twice: the repeat is ignored, not a rejection.
TEST(ApplyStep, ARepeatedIdenticalRequestIsIgnored) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 1);
  const protocol::ActionRequest r = move_to(w, 1, 1.25, 1.05);
  protocol::ActionRequest other = r;
  other.target_x_m = 1.15;
  const StepOutcome o = apply_step(w, std::vector<protocol::ActionRequest>{r, r, other});
  EXPECT_EQ(w.agent(1).accepted, 1u);
  EXPECT_EQ(w.agent(1).rejected, 1u);  // only the different one
  EXPECT_EQ(w.agent(1).position.x, 1.25);
  EXPECT_EQ(o.rejected, 1u);
  ASSERT_EQ(o.notes.size(), 1u);
  EXPECT_NE(o.notes[0].find("repeated; the first stands"), std::string::npos) << o.notes[0];
}

TEST(ApplyStep, ARejectedRequestChangesNothingAndIsReportedInTheNextFrame) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 1);
  const std::string before = runlog::terrain_sha256(w.terrain);
  protocol::ActionRequest r = with_deposition(move_to(w, 1, 1.25, 1.05), 1.25, 2.05, kLayer);
  r = with_deposition(r, 1.25, 2.55, kLayer);  // 1.5 m away: out of reach, so nothing of it happens
  const StepOutcome o = apply_step(w, std::vector<protocol::ActionRequest>{r});
  EXPECT_EQ(runlog::terrain_sha256(w.terrain), before);
  EXPECT_EQ(w.agent(1).position.x, 1.05);
  EXPECT_EQ(w.agent(1).material_m3, 0.05);
  EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kRejected);
  EXPECT_NE(w.agent(1).last_reason.find("beyond reach_m"), std::string::npos);
  EXPECT_TRUE(o.changed_tiles.empty());
  apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1)});
  EXPECT_EQ(w.agent(1).last_result, protocol::ActionResult::kAccepted);
  EXPECT_TRUE(w.agent(1).last_reason.empty());
}

TEST(ApplyStep, ThreeConsecutiveMissesDropAnAgent) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 2);
  // Two misses, an answer, two misses: never three in a row.
  for (int k = 0; k < 2; ++k) apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1)});
  apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1), request_for(w, 2)});
  for (int k = 0; k < 2; ++k) {
    const StepOutcome o = apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1)});
    EXPECT_TRUE(o.dropped.empty());
  }
  EXPECT_EQ(w.agent(2).missed, 4u);
  EXPECT_TRUE(w.agent(2).alive);
  const StepOutcome third = apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1)});
  EXPECT_EQ(third.dropped, std::vector<std::uint32_t>{2});
  EXPECT_EQ(count(third, protocol::EventKind::kDropped), 1);
  EXPECT_FALSE(w.agent(2).alive);
  EXPECT_TRUE(w.agent(2).dropped);
  EXPECT_NE(w.agent(2).drop_reason.find("3 consecutive missed"), std::string::npos);
  EXPECT_EQ(w.live_ids(), std::vector<std::uint32_t>{1});
  // Later requests on its partition are ignored, and it is no longer expected.
  protocol::ActionRequest late = request_for(w, 2);
  const StepOutcome after = apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1), late});
  EXPECT_EQ(after.missed, 0u);
  EXPECT_EQ(after.accepted, 1u);
  ASSERT_EQ(after.notes.size(), 1u);
  EXPECT_NE(after.notes[0].find("not in the run"), std::string::npos);
  EXPECT_EQ(w.agent(2).missed, 5u);
}

TEST(ApplyStep, AChronicallyLateAgentIsDropped) {
  const scenario::Scenario s = small_scenario();
  WorldState w = admitted_state(s, flat_terrain(), 2);
  // Agent 2 misses two deadlines in every three, never three in a row: its misses fall on steps 0, 1, 3, 4, 6, 7,
  // 9, 10, 12, ...; the 9th, at step 12, is more than half of its last 16 steps.
  for (int step = 0; step <= 12; ++step) {
    std::vector<protocol::ActionRequest> requests{request_for(w, 1)};
    if (step % 3 == 2) requests.push_back(request_for(w, 2));
    const StepOutcome o = apply_step(w, requests);
    if (step < 12) {
      EXPECT_TRUE(o.dropped.empty()) << "step " << step;
    } else {
      EXPECT_EQ(o.dropped, std::vector<std::uint32_t>{2});
    }
  }
  EXPECT_FALSE(w.agent(2).alive);
  EXPECT_EQ(w.agent(2).missed, 9u);
  EXPECT_NE(w.agent(2).drop_reason.find("9 missed deadlines in its last 16 steps"), std::string::npos)
      << w.agent(2).drop_reason;
  // One miss in every two is tolerated for good: 8 of every 16.
  WorldState half = admitted_state(s, flat_terrain(), 2);
  for (int step = 0; step < 64; ++step) {
    std::vector<protocol::ActionRequest> requests{request_for(half, 1)};
    if (step % 2 == 1) requests.push_back(request_for(half, 2));
    EXPECT_TRUE(apply_step(half, requests).dropped.empty()) << "step " << step;
  }
  EXPECT_TRUE(half.agent(2).alive);
  EXPECT_EQ(half.agent(2).missed, 32u);
}

TEST(ApplyStep, OnlyChangedTilesGetANewVersion) {
  const scenario::Scenario s = small_scenario();  // 40 x 40 cells, tiles of 16: 3 x 3 tiles
  WorldState w = admitted_state(s, flat_terrain(), 1);
  ASSERT_EQ(w.tile_versions.size(), 9u);
  // (1.05, 2.05) is cell (19, 10): tile (1, 0).
  const StepOutcome o =
      apply_step(w, std::vector<protocol::ActionRequest>{with_deposition(request_for(w, 1), 1.05, 2.05, kLayer)});
  EXPECT_EQ(o.changed_tiles, std::vector<int>{3});
  EXPECT_EQ(w.tile_versions, (std::vector<std::uint64_t>{0, 0, 0, 1, 0, 0, 0, 0, 0}));
  ASSERT_EQ(count(o, protocol::EventKind::kDeposited), 1);
  EXPECT_EQ(o.events[0].volume_m3, kLayer * 0.1 * 0.1);
}

TEST(ApplyStep, ReachingTheGoalCompletesTheRun) {
  // A goal box [2.0, 3.9] x [1.9, 3.9] that holds both bodies of 1 m side by side.
  const scenario::Scenario s = scenario::parse_scenario(
      testing::small_scenario_text_completing("goal { x0_m: 2.0 y0_m: 1.9 x1_m: 3.9 y1_m: 3.9 }"), "small.pbtxt");
  WorldState w = admitted_state(s, flat_terrain(), 2);
  w.agent(1).position.x = 1.85;
  w.agent(1).position.y = 2.05;
  w.agent(2).position.x = 3.05;
  w.agent(2).position.y = 1.75;
  EXPECT_FALSE(is_completed(w));
  StepOutcome o = apply_step(w, std::vector<protocol::ActionRequest>{move_to(w, 1, 2.05, 2.05), request_for(w, 2)});
  EXPECT_EQ(count(o, protocol::EventKind::kAtGoal), 1);
  EXPECT_TRUE(w.agent(1).at_goal);
  EXPECT_FALSE(o.completed);
  EXPECT_DOUBLE_EQ(progress(w), 0.5);
  o = apply_step(w, std::vector<protocol::ActionRequest>{request_for(w, 1), move_to(w, 2, 3.05, 1.95)});
  EXPECT_EQ(count(o, protocol::EventKind::kAtGoal), 1);  // agent 1 is not reported twice
  EXPECT_TRUE(o.completed);
  EXPECT_DOUBLE_EQ(progress(w), 1.0);
  // A height condition: the flat ground at 0 m is not high enough for 0.5 m.
  w.goal.min_height_m = 0.5;
  EXPECT_FALSE(is_completed(w));
  w.goal.min_height_m = 0.0;
  EXPECT_TRUE(is_completed(w));
  // No live agent: never completed.
  drop_agent(w, 1, "test");
  drop_agent(w, 2, "test");
  EXPECT_FALSE(is_completed(w));
  EXPECT_THROW(drop_agent(w, 9, "test"), InvalidArgument);
}

TEST(ApplyStep, KeepsABoundedPrintableWaitingFor) {
  const scenario::Scenario s = small_scenario();
  WorldState state = admitted_state(s, flat_terrain(), 2);
  protocol::ActionRequest one = request_for(state, 1), two = request_for(state, 2);
  one.waiting_for = "front neighbour 2 at 1.5 m (hold)";
  two.waiting_for = std::string("bell\a tab\t \xff") + std::string(100000, 'x');
  apply_step(state, std::vector<protocol::ActionRequest>{one, two});
  EXPECT_EQ(state.agent(1).waiting_for, "front neighbour 2 at 1.5 m (hold)");
  const std::string& kept = state.agent(2).waiting_for;
  ASSERT_EQ(kept.size(), kMaxWaitingForChars);
  EXPECT_EQ(kept.substr(0, 13), "bell? tab? ?x");
  EXPECT_TRUE(std::all_of(kept.begin(), kept.end(), [](char c) { return c >= 0x20 && c <= 0x7e; }));
  EXPECT_EQ(kept_waiting_for(kept), kept);  // idempotent: run.log keeps what the state keeps
}

TEST(ApplyStep, TheStallDetectorSeesDepositsButNotMotions) {
  const scenario::Scenario s = small_scenario("stall_steps: 3\n");
  WorldState state = admitted_state(s, flat_terrain(), 1);
  EXPECT_EQ(state.stall_steps, 3u);
  apply_step(state, std::vector<protocol::ActionRequest>{move_to(state, 1, 1.25, 1.05)});
  apply_step(state, std::vector<protocol::ActionRequest>{move_to(state, 1, 1.45, 1.05)});
  EXPECT_EQ(quiet_steps(state.stall, state.step), 2u);  // motions are no progress (agents_at_goal: none there)
  apply_step(state, std::vector<protocol::ActionRequest>{with_deposition(request_for(state, 1), 2.15, 1.05, kLayer)});
  EXPECT_EQ(quiet_steps(state.stall, state.step), 0u);
  for (int i = 0; i < 3; ++i) apply_step(state, std::vector<protocol::ActionRequest>{request_for(state, 1)});
  EXPECT_TRUE(stalled(state.stall, state.step, state.stall_steps));
  EXPECT_EQ(state.stall.quiet_since, 3u);
  EXPECT_EQ(state.stall.longest_quiet, 3u);
}

}  // namespace
}  // namespace marsala::world_server
