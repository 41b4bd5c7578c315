#include "marsala/world_server/records/run_recorder.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "marsala/runlog/run_log.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using testing::admitted_state;
using testing::flat_terrain;
using testing::small_scenario;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class RunRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("run_recorder_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  RecorderSetup setup(std::uint64_t snapshot_every) const {
    RecorderSetup s;
    s.out_dir = dir_.string();
    s.run_id = "rec";
    s.snapshot_every = snapshot_every;
    return s;
  }
  LogStart log_start() const {
    LogStart start;
    start.scenario_text = testing::small_scenario_text();
    start.run_id = "rec";
    start.agents = 2;
    start.max_steps = 10;
    start.step_deadline_s = 1.0;
    return start;
  }
  fs::path dir_;
};

TEST_F(RunRecorderTest, AFreshRunWritesItsInitialTerrainEventsAndLogHeader) {
  const WorldState state = admitted_state(small_scenario(), flat_terrain(), 2);
  RunRecorder recorder(setup(0));
  recorder.open(small_scenario(), log_start(), state);
  EXPECT_TRUE(fs::exists(dir_ / "terrain_initial.asc"));
  protocol::WorldEvent e;
  e.step = 3;
  e.agent_id = 2;
  e.kind = protocol::EventKind::kAtGoal;
  recorder.event(e);
  recorder.note(4, "a note");
  EXPECT_EQ(read_text(dir_ / "events.log"),
            "{\"step\":3,\"agent\":2,\"kind\":\"at_goal\"}\n{\"step\":4,\"kind\":\"note\",\"detail\":\"a note\"}\n");
  recorder.sync();
  runlog::RunLogReader reader((dir_ / runlog::kRunLogFile).string());
  EXPECT_EQ(reader.header().run_id(), "rec");
  EXPECT_EQ(reader.header().agents(), 2u);
}

TEST_F(RunRecorderTest, SnapshotsOnlyAtMultiplesOfItsPeriod) {
  WorldState state = admitted_state(small_scenario(), flat_terrain(), 2);
  RunRecorder recorder(setup(3));
  recorder.open(small_scenario(), log_start(), state);
  const fs::path snapshot = dir_ / kSnapshotFile;
  for (std::uint64_t step : {1, 2, 4, 5}) {
    state.step = step;
    recorder.after_step(state);
    EXPECT_FALSE(fs::exists(snapshot)) << "step " << step;
  }
  state.step = 6;
  recorder.after_step(state);
  ASSERT_TRUE(fs::exists(snapshot));
  EXPECT_EQ(read_snapshot(snapshot.string()).step(), 6u);
}

}  // namespace
}  // namespace marsala::world_server
