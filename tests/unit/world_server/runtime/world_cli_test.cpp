#include "marsala/world_server/runtime/world_cli.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "support/busy_port.hpp"
#include "unit/world_server/fake_agent.hpp"
#include "unit/world_server/world_cli_fixture.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;

/// The command-line fixture.
class WorldCliTest : public testing::WorldCliFixture {};

TEST_F(WorldCliTest, UsageErrorsExitWith2) {
  EXPECT_EQ(run({}), 2);
  EXPECT_NE(err_.str().find("--scenario (or --resume DIR, --fork DIR) is required"), std::string::npos) << err_.str();
  const std::string ok = write("ok.pbtxt", testing::small_scenario_text());
  EXPECT_EQ(run({"--scenario", ok, "--frobnicate"}), 2);
  EXPECT_EQ(run({"--scenario", ok, "--agents", "0"}), 2);
  EXPECT_EQ(run({"--scenario", ok, "--dds", "opensplice"}), 2);
  EXPECT_EQ(run({"--scenario", ok, "--domain", "300"}), 2);
  EXPECT_EQ(run({"--scenario", ok, "--step-deadline", "0"}), 2);
  EXPECT_EQ(run({"--resume", "somewhere", "--scenario", ok}), 2);  // a resume takes its scenario from the log
  EXPECT_EQ(run({"--help"}), 0);
  EXPECT_NE(out_.str().find("--admit-timeout"), std::string::npos);
}

// A metrics port that cannot be listened on is refused with one line naming it, exit 2, before the run's folder is
// made; --check refuses it too (spawn.sh checks with the run's arguments before it starts anything).
TEST_F(WorldCliTest, AMetricsPortInUseIsRefusedBeforeAnythingIsWritten) {
  marsala::testing::BusyPort busy;
  const std::string port = std::to_string(busy.port());
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text());
  const fs::path out = dir_ / "out";
  EXPECT_EQ(run({"--scenario", scenario, "--out", out.string(), "--dds", "inprocess", "--metrics-port", port}), 2);
  EXPECT_EQ(err_.str(), "marsala-world: error: --metrics-port " + port + ": cannot listen on 127.0.0.1 port " + port +
                            ": the port is in use (another server listens there)\n");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run({"--check", scenario, "--metrics-port", port}), 2);
  EXPECT_NE(err_.str().find("--metrics-port " + port), std::string::npos) << err_.str();
  busy.release();
  EXPECT_EQ(run({"--check", scenario, "--metrics-port", port}), 0) << err_.str();
  EXPECT_EQ(run({"--scenario", scenario, "--metrics-port", "0"}), 2);
  EXPECT_EQ(run({"--scenario", scenario, "--metrics-linger", "1"}), 2);  // needs --metrics-port
}

// --step-deadline overrides the scenario's, as the world's own start-up check reports it.
TEST_F(WorldCliTest, StepDeadlineOverridesTheScenarios) {
  const std::string ok = write("ok.pbtxt", testing::small_scenario_text());
  EXPECT_EQ(run({"--check", "--json", "--step-deadline", "2.5", ok}), 0) << err_.str();
  EXPECT_NE(out_.str().find("\"step_deadline_s\": 2.5"), std::string::npos) << out_.str();
}

// --resume of a folder without a run log: one line naming it, exit 1.
TEST_F(WorldCliTest, ResumingAFolderWithoutARunLogIsAnError) {
  const std::string folder = std::filesystem::path(write("readme.txt", "no run here")).parent_path().string();
  EXPECT_EQ(run({"--resume", folder}), 1);
  EXPECT_NE(err_.str().find("no run.log there"), std::string::npos) << err_.str();
}

TEST_F(WorldCliTest, BadScenariosExitWith2OnOneLineNamingFileAndLine) {
  const std::string bad = write("bad.pbtxt", "name: \"x\"\nterrain { generator: \"flat\" }\nagent { robot_type: }\n");
  EXPECT_EQ(run({"--scenario", bad}), 2);
  const std::string message = err_.str();
  EXPECT_EQ(message.rfind("marsala-world: error: " + bad + ":3:", 0), 0u) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1);
  EXPECT_EQ(run({"--scenario", (dir_ / "missing.pbtxt").string()}), 2);
  EXPECT_NE(err_.str().find("cannot open scenario file"), std::string::npos) << err_.str();
  const std::string ok = write("ok.pbtxt", testing::small_scenario_text());
  EXPECT_EQ(run({"--scenario", ok, "--agents", "5", "--dds", "inprocess"}), 2);
  EXPECT_NE(err_.str().find("exceeds the 3 agent slots"), std::string::npos) << err_.str();
  EXPECT_EQ(run({"--scenario", ok, "--dds", "inprocess", "--domain", "49", "--admit-timeout", "0.1", "--quiet", "--out",
                 (dir_ / "none").string()}),
            1);
  EXPECT_NE(err_.str().find("no agent admitted"), std::string::npos) << err_.str();
}

TEST_F(WorldCliTest, ARunThatReachesMaxStepsExitsWith3) {
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text());
  const fs::path out = dir_ / "out";
  // The exit code says how the run ended: max_steps.
  EXPECT_EQ(run_beside_walker(48, {"--scenario", scenario, "--out", out.string(), "--max-steps", "3"}), 3)
      << err_.str();
  EXPECT_NE(out_.str().find("run small-d48: max_steps after 3 steps, 1 agents"), std::string::npos) << out_.str();
  for (const char* name : {"summary.json", "terrain_initial.asc", "terrain_final.asc", "final.png", "events.log"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
}

TEST_F(WorldCliTest, SeedOverridesTheScenariosAndIsReported) {
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text("seed: 5\nstart_jitter_m: 0.3\n"));
  EXPECT_EQ(run({"--scenario", scenario, "--seed", "abc"}), 2);
  EXPECT_NE(out_.str().size() + err_.str().size(), 0u);
  const fs::path out = dir_ / "out";
  EXPECT_EQ(run_beside_walker(52, {"--scenario", scenario, "--out", out.string(), "--max-steps", "2", "--seed", "77"}),
            3)
      << err_.str();  // max_steps
  std::ifstream in(out / "summary.json");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("\"seed\": \"77\""), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("\"start_jitter_m\": 0.3"), std::string::npos) << text.str();
  EXPECT_EQ(run({"--help"}), 0);
  EXPECT_NE(out_.str().find("--seed"), std::string::npos);
}

TEST_F(WorldCliTest, ARunWithoutProgressEndsStalledWith6AndAnAccount) {
  // A walker on the way to a goal it needs 12 steps to reach: its motions are no progress, so with stall_steps 4 the
  // run ends before step 4 is applied.
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text("stall_steps: 4\n"));
  const fs::path out = dir_ / "out";
  EXPECT_EQ(run_beside_walker(53, {"--scenario", scenario, "--out", out.string(), "--max-steps", "50"}), 6)
      << err_.str();
  EXPECT_NE(out_.str().find("run small-d53: stalled after 4 steps"), std::string::npos) << out_.str();
  std::ifstream in(out / "summary.json");
  std::stringstream text;
  text << in.rdbuf();
  for (const char* field : {"\"end_reason\": \"stalled\"", "\"stall_steps\": 4", "\"quiet_since_step\": 0",
                            "\"state\": \"walking\"", "\"waiting_for\": \"its target?\"", "\"material_m3\""})
    EXPECT_NE(text.str().find(field), std::string::npos) << field << " in\n" << text.str();
  std::ifstream events(out / "events.log");
  std::stringstream log;
  log << events.rdbuf();
  EXPECT_NE(log.str().find("stalled: agent 1 walking with"), std::string::npos) << log.str();
}

TEST_F(WorldCliTest, ATeamThatDoesNotFitOnItsBaseIsRefusedWith2) {
  // The small scenario's 1 m robots all start on the base (radius 0.5 m): three do not fit there, two do.
  const std::string text = testing::small_scenario_text();
  std::string crowded = text;
  for (const char* start :
       {"start { x_m: 1.05 y_m: 1.05 }", "start { x_m: 2.55 y_m: 1.05 }", "start { x_m: 1.05 y_m: 3.05 }"})
    crowded.replace(crowded.find(start), std::string(start).size(), "start { x_m: 0.55 y_m: 0.55 }");
  const std::string scenario = write("crowded.pbtxt", crowded);
  EXPECT_EQ(run({"--check", scenario}), 2);
  EXPECT_NE(err_.str().find("the team does not fit on its base: agent (3 robots): only 2 of their bodies"),
            std::string::npos)
      << err_.str();
  EXPECT_EQ(run({"--scenario", scenario, "--dds", "inprocess", "--out", (dir_ / "out").string()}), 2);
  const std::string refused = err_.str();
  EXPECT_EQ(std::count(refused.begin(), refused.end(), '\n'), 1) << refused;
  EXPECT_NE(refused.find("agent (3 robots)"), std::string::npos) << refused;
  EXPECT_EQ(run({"--check", "--agents", "2", scenario}), 0) << err_.str();
  const std::string stall = write("stall.pbtxt", testing::small_scenario_text("stall_steps: -3\n"));
  EXPECT_EQ(run({"--check", stall}), 2);
  EXPECT_NE(err_.str().find("stall_steps: -3 must be 0 (never) or in 1..1000000000"), std::string::npos) << err_.str();
}

}  // namespace
}  // namespace marsala::world_server
