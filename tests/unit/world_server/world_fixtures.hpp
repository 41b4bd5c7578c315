#pragma once
// Hand-made worlds for the world server's unit tests: a small scenario in text, states with admitted agents, and
// requests with their envelope filled in.

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "marsala/core/heightmap.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/rules/admission.hpp"
#include "marsala/world_server/rules/initial_state.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server::testing {

/// The body every test robot has: layer of one cube on a 0.1 m cell = 0.05^3 / 0.01 = 0.0125 m, cube 1.25e-4 m^3.
inline const char* const kTestRobotType = R"(
robot_type {
  name: "tester"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
}
)";

/// The small scenario with another completion block (`goal { ... }`, `payload_path { ... }` or `site { ... }`).
inline std::string small_scenario_text_completing(const std::string& completion, const std::string& extra = "") {
  return std::string(R"(
name: "small"
terrain { generator: "flat" rows: 40 cols: 40 cell_size_m: 0.1 }
)") + kTestRobotType +
         R"(
agent { robot_type: "tester" start { x_m: 1.05 y_m: 1.05 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "tester" start { x_m: 2.55 y_m: 1.05 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "tester" start { x_m: 1.05 y_m: 3.05 } target { x_m: 3.05 y_m: 2.05 } }
)" + completion +
         R"(
base { x_m: 0.55 y_m: 0.55 radius_m: 0.5 }
tile_size: 16
)" + extra;
}

/// A flat 40 x 40 grid of 0.1 m cells (4 x 4 m), three slots, base at (0.55, 0.55) r 0.5, goal [2.9, 3.2] x [1.9, 2.2].
inline std::string small_scenario_text(const std::string& extra = "") {
  return small_scenario_text_completing("goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }", extra);
}

/// A payload path from the base (0.55, 0.55) to (3.05, 3.05) for a payload of kappa 0.2, delta 0.3 m, eps 0.05 m
/// (its ball: the 3 x 3 cells around it), checked every `every` steps.
inline std::string payload_block(int every = 3) {
  return "payload_path { body { kappa: 0.2 delta_m: 0.3 eps_m: 0.05 } from { x_m: 0.55 y_m: 0.55 } "
         "to { x_m: 3.05 y_m: 3.05 } check_every_steps: " +
         std::to_string(every) + " }";
}

/// A level site [2.0, 3.0] x [2.0, 3.0] (the 10 x 10 cells rows 10..19, cols 20..29) for kappa 0.1, delta 0.3 m,
/// eps 0.05 m, checked every `every` steps.
inline std::string site_block(int every = 3, double min_fraction = 1.0) {
  return "site { x0_m: 2.0 y0_m: 2.0 x1_m: 3.0 y1_m: 3.0 kappa: 0.1 delta_m: 0.3 eps_m: 0.05 min_fraction: " +
         std::to_string(min_fraction) + " check_every_steps: " + std::to_string(every) + " }";
}

/// small_scenario_text() parsed.
inline scenario::Scenario small_scenario(const std::string& extra = "") {
  return scenario::parse_scenario(small_scenario_text(extra), "small.pbtxt");
}

/// A hello that matches slot `id` of `state`.
inline protocol::AgentHello hello_for(const WorldState& state, std::uint32_t id, std::uint64_t session) {
  protocol::AgentHello h;
  h.agent_id = id;
  h.session = session;
  h.name = "tester-" + std::to_string(id);
  h.behaviour = state.agent(id).type.behaviour;
  h.body = state.agent(id).type.body;
  return h;
}

/// A state on `terrain` with agents 1..agents admitted (session 1000 + id).
inline WorldState admitted_state(const scenario::Scenario& s, Heightmap terrain, std::uint32_t agents) {
  WorldState state = make_world_state(s, std::move(terrain), agents);
  for (std::uint32_t id = 1; id <= agents; ++id) admit(state, hello_for(state, id, 1000 + id));
  return state;
}

/// A flat terrain of the small scenario's geometry.
inline Heightmap flat_terrain(double height = 0.0) {
  GridGeometry g;
  g.rows = 40;
  g.cols = 40;
  g.cell_size_m = 0.1;
  return Heightmap(g, height);
}

/// A request of agent `id` for the state's current step, doing nothing yet.
inline protocol::ActionRequest request_for(const WorldState& state, std::uint32_t id) {
  protocol::ActionRequest r;
  r.agent_id = id;
  r.session = state.agent(id).session;
  r.step = state.step;
  return r;
}

/// A request that moves agent `id` to (x, y).
inline protocol::ActionRequest move_to(const WorldState& state, std::uint32_t id, double x, double y) {
  protocol::ActionRequest r = request_for(state, id);
  r.move = true;
  r.target_x_m = x;
  r.target_y_m = y;
  return r;
}

/// Cube layer of the test robot on 0.1 m cells [m].
inline constexpr double kLayer = 0.05 * 0.05 * 0.05 / (0.1 * 0.1);

/// A test with a folder of its own under the temporary directory (made empty before it, removed after it) and the
/// small scenario that completes on a level site: the fixture of the tests that record a run and read it back.
class RecordedRunTest : public ::testing::Test {
 protected:
  /// prefix: the start of the folder's name (the process id and the test's name follow).
  explicit RecordedRunTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    scenario_ = scenario::parse_scenario(small_scenario_text_completing(site_block(4, 1.0)), "small.pbtxt");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string log_path() const { return (dir_ / kRunLogFile).string(); }
  /// Opens run.log for `state` (run id small-d1, 3 agents) and admits agents 1..admitted into both, as a run starts.
  runlog::RunLogWriter start_log(WorldState& state, std::uint32_t admitted = 3) const {
    LogStart start;
    start.run_id = "small-d1";
    start.agents = 3;
    runlog::RunLogWriter log = runlog::RunLogWriter::create(log_path(), log_header(scenario_, start, state.terrain));
    for (std::uint32_t id = 1; id <= admitted; ++id) {
      admit(state, hello_for(state, id, 100 + id), AdmissionKind::kFirst);
      log.append(admitted_record(state, id, AdmissionKind::kFirst));
    }
    return log;
  }

  scenario::Scenario scenario_;
  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace marsala::world_server::testing
