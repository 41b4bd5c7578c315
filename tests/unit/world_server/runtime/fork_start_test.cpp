#include "marsala/world_server/runtime/fork_start.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::hello_for;
using testing::request_for;
using testing::site_block;
using testing::small_scenario_text_completing;

/// What an agent learns of its scenario, from its own file (agent/main.cpp: the bodies of every slot, its seed, its
/// goal vector map, right of way) and from the world (core/assignment.hpp: grid, tiles, start, target, base; the
/// terrain in its frames): an independent list of what a fork may not change.
std::string agent_view(const scenario::Scenario& s) {
  std::string out = fmt::format("terrain {} {} {} {} {} | tiles {} | seed {} | jitter {} | base {} {} {} | row {} | "
                                "gvm {}\n",
                                s.terrain.method, s.terrain.rows, s.terrain.cols, s.terrain.cell_size_m,
                                s.terrain.seed, s.tile_size, s.seed, s.start_jitter_m, s.base.centre.x,
                                s.base.centre.y, s.base.radius_m, s.right_of_way, s.has_goal_vector_map);
  for (const scenario::AgentSlot& slot : s.slots) {
    const RobotType& t = s.robot_for(slot.id);
    const RobotBody& b = t.body;
    out += fmt::format("slot {} {} {} start {} {} target {} {} body {} {} {} {} {} {} {} {} {}\n", slot.id, t.name,
                       t.behaviour, slot.start.x, slot.start.y, slot.target.x, slot.target.y, b.navigability.kappa,
                       b.navigability.delta_m, b.navigability.eps_m, b.max_step_m, b.max_deposit_m3,
                       b.material_capacity_m3, b.reach_m, b.sensing_range_m, b.proximity_range_m);
  }
  return out;
}

scenario::Scenario parsed(const std::string& completion, const std::vector<std::string>& overrides = {}) {
  return scenario::parse_scenario(small_scenario_text_completing(completion), "small.pbtxt", overrides);
}

const std::string kGoal = "goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }";

TEST(ForkOverrides, WorldOnlyFieldsMayChangeFieldsTheAgentsSeeMayNot) {
  struct Case {
    std::string completion, override_text;
    bool allowed;
  };
  const std::vector<Case> cases = {
      {site_block(), "max_steps=300", true},
      {site_block(), "stall_steps=7", true},
      {site_block(), "step_deadline_s=2.5", true},
      {site_block(), "site.min_fraction=0.5", true},
      {site_block(), "site.check_every_steps=2", true},
      {kGoal, "goal.min_height_m=0.1", true},
      {kGoal, "goal.target_radius_m=0.5", true},
      {testing::payload_block(), "payload_path.check_every_steps=1", true},
      {site_block(), "seed=5", false},
      {site_block(), "tile_size=8", false},
      {site_block(), "robot_type.body.kappa=0.2", false},
      {site_block(), "robot_type[0].body.sensing_range_m=2", false},
      {site_block(), "agent[0].start.x_m=1.15", false},
      {site_block(), "base.radius_m=0.6", false},
      {site_block(), "right_of_way=false", false},
      {site_block(), "terrain.seed=3", false},
  };
  for (const Case& c : cases) {
    // The independent expectation: the agents' view of the scenario is unchanged exactly for the allowed ones.
    const bool agents_see_it = agent_view(parsed(c.completion)) != agent_view(parsed(c.completion, {c.override_text}));
    ASSERT_EQ(agents_see_it, !c.allowed) << c.override_text << " (check the case, not the code)";
    const std::string problem = fork_override_problem(c.override_text);
    EXPECT_EQ(problem.empty(), c.allowed) << c.override_text << ": " << problem;
    if (c.allowed) continue;
    EXPECT_NE(problem.find(fmt::format("--set {}: the agents read", c.override_text)), std::string::npos) << problem;
    EXPECT_NE(problem.find("max_steps, step_deadline_s, stall_steps, goal, payload_path, site"), std::string::npos);
    EXPECT_EQ(problem.find('\n'), std::string::npos);
  }
}

/// A parent run of 6 steps (agents idle) whose run.log holds its scenario text, as marsala-world writes it.
class ForkStartTest : public testing::RecordedRunTest {
 protected:
  ForkStartTest() : RecordedRunTest("marsala_fork_start_") {}

  /// Records the parent; `text` (default: the fixture's scenario) becomes the fixture's scenario and the header's.
  void record(int steps, std::uint32_t team = 3, std::string text = small_scenario_text_completing(site_block(4, 1.0))) {
    scenario_ = scenario::parse_scenario(text, "small.pbtxt");
    WorldState state = make_world_state(scenario_, scenario::build_terrain(scenario_), team);
    LogStart start;
    start.run_id = "small-d1";
    start.agents = team;
    start.max_steps = 500;
    start.step_deadline_s = 10.0;
    start.scenario_text = text;
    runlog::RunLogWriter log =
        runlog::RunLogWriter::create(log_path(), log_header(scenario_, start, state.terrain));
    for (std::uint32_t id = 1; id <= team; ++id) {
      admit(state, hello_for(state, id, 100 + id), AdmissionKind::kFirst);
      log.append(admitted_record(state, id, AdmissionKind::kFirst));
    }
    for (int k = 0; k < steps; ++k) {
      std::vector<Submission> idle;
      for (std::uint32_t id = 1; id <= team; ++id) idle.push_back({id, request_for(state, id)});
      const StepOutcome outcome = apply_step(state, idle);
      log.append(step_record(idle, outcome, state));
    }
  }

  /// A check of the fork (no folder) with these --set and --max-steps.
  WorldStart fork_at(std::uint64_t at, const std::vector<std::string>& overrides, std::uint64_t max_steps = 0,
                     std::uint32_t agents = 0) const {
    RuntimeOptions options;
    options.agents = agents;
    options.out_dir.clear();
    options.overrides = overrides;
    options.max_steps = max_steps;
    return prepare_fork(dir_.string(), at, options, 7);
  }

  /// The one-line refusal of fork_at(), or "accepted".
  std::string refusal(std::uint64_t at, const std::vector<std::string>& overrides, std::uint64_t max_steps = 0) const {
    try {
      fork_at(at, overrides, max_steps);
      return "accepted";
    } catch (const InvalidArgument& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
  }
};

TEST_F(ForkStartTest, ASetOfWorldOnlyFieldsAppliesFromStepZeroAndIsRecordedAsTheForks) {
  record(6);
  const WorldStart plain = fork_at(4, {});
  EXPECT_EQ(plain.options.max_steps, 500u);  // the parent's
  EXPECT_EQ(plain.state.stall_steps, scenario::kDefaultStallSteps);
  const WorldStart changed = fork_at(4, {"stall_steps=7", "max_steps=40", "site.min_fraction=0.5"});
  EXPECT_EQ(changed.state.stall_steps, 7u);
  EXPECT_EQ(changed.options.max_steps, 40u);
  EXPECT_DOUBLE_EQ(changed.state.site.min_fraction, 0.5);
  EXPECT_EQ(changed.options.overrides, (std::vector<std::string>{"stall_steps=7", "max_steps=40", "site.min_fraction=0.5"}));
  EXPECT_EQ(changed.fork->origin().overrides, changed.options.overrides);
  EXPECT_EQ(changed.fork->origin().parent_sha256_at_step, plain.fork->origin().parent_sha256_at_step);
  EXPECT_EQ(fork_at(4, {"max_steps=40"}, 90).options.max_steps, 90u);  // --max-steps wins, as in any run
}

TEST_F(ForkStartTest, AFieldTheAgentsReadOrALimitBeforeKIsRefusedWithOneLine) {
  record(6);
  EXPECT_NE(refusal(4, {"robot_type.body.kappa=0.2"}).find("--set robot_type.body.kappa=0.2: the agents read "
                                                           "robot_type from step 0"),
            std::string::npos);
  EXPECT_NE(refusal(4, {"stall_steps=7", "seed=3"}).find("--set seed=3: the agents read seed"), std::string::npos);
  EXPECT_NE(refusal(4, {"no_such_field=1"}).find("no_such_field"), std::string::npos);
  EXPECT_NE(refusal(5, {"max_steps=4"}).find("max_steps 4 would end the fork before it goes live at 5"),
            std::string::npos);
  EXPECT_NE(refusal(5, {}, 3).find("max_steps 3 would end the fork before it goes live at 5"), std::string::npos);
  EXPECT_EQ(refusal(5, {"max_steps=5"}), "accepted");
}

TEST_F(ForkStartTest, ALargerTeamHoldsItsLateSlotsUnadmittedUntilK) {
  record(6, 2);  // a parent of 2 on the scenario's 3 slots
  const WorldStart grown = fork_at(4, {}, 0, 3);
  ASSERT_EQ(grown.state.agents.size(), 3u);
  EXPECT_FALSE(grown.state.agent(3).admitted);
  EXPECT_EQ(grown.fork->origin().parent_agents, 2u);
  EXPECT_EQ(grown.fork->origin().agents, 3u);
  EXPECT_EQ(grown.fork->origin().parent_sha256_at_step, fork_at(4, {}).fork->origin().parent_sha256_at_step);
  try {
    fork_at(4, {}, 0, 4);
    ADD_FAILURE() << "a team beyond the scenario's slots was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("--agents 4 exceeds the 3 agent slots"), std::string::npos) << e.what();
  }
}

TEST_F(ForkStartTest, LateSlotsThatWouldChangeTheDepositBoundAreRefused) {
  // Slot 3 deposits cubes and builds at kappa 0.2: a team holding it judges deposits against a bound at 0.2 from step
  // 0 (docs/runtime.md#deposit-bound); the parent of 2 layer robots had none.
  std::string text = small_scenario_text_completing(site_block(4, 1.0), R"(
robot_type {
  name: "cuber"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  construction { kappa: 0.2 }
  depositor { name: "cube" cube_size_m: 0.1 }
}
)");
  const std::string third = R"(agent { robot_type: "tester" start { x_m: 1.05 y_m: 3.05 })";
  text.replace(text.find(third), third.size(), R"(agent { robot_type: "cuber" start { x_m: 1.05 y_m: 3.05 })");
  record(6, 2, text);
  EXPECT_EQ(fork_at(4, {}).state.agents.size(), 2u);  // the parent's team forks as it was
  try {
    fork_at(4, {}, 0, 3);
    ADD_FAILURE() << "a late slot changing the deposit bound was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("--agents 3: the late slots' robot types change the world's deposit bound"),
              std::string::npos)
        << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace marsala::world_server
