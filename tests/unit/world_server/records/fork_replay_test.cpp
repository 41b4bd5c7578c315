#include "marsala/world_server/records/fork_replay.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "marsala/core/error.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using testing::flat_terrain;
using testing::hello_for;
using testing::kLayer;
using testing::request_for;
using testing::site_block;
using testing::small_scenario_text_completing;

/// A parent run recorded as the runtime records it, with requests that depend only on the state and a seeded random
/// stream, so that a "fresh team" (new sessions, same seed) makes the same requests again, as deterministic agents do.
class ForkReplayTest : public testing::RecordedRunTest {
 protected:
  ForkReplayTest() : RecordedRunTest("marsala_fork_") {}

  WorldState initial() const { return make_world_state(scenario_, flat_terrain(), 3); }

  /// Every live agent's requests of this step: deposits near the robot, sometimes a move.
  static std::vector<Submission> requests(const WorldState& state, std::mt19937_64& random) {
    std::uniform_real_distribution<double> offset(-0.6, 0.6);
    std::vector<Submission> out;
    for (std::uint32_t id : state.live_ids()) {
      protocol::ActionRequest r = request_for(state, id);
      const AgentRecord& a = state.agent(id);
      const double x = a.position.x + offset(random), y = a.position.y + offset(random);
      if (a.type.depositor.kind != DepositorKind::kLayer)
        r.deposits.push_back({x, y, 0.001});
      else if (const std::optional<CellIndex> c = state.terrain.geometry().cell_at({x, y}))
        r.depositions.push_back({c->row, c->col, kLayer});
      if (random() % 3 == 0) {
        r.move = true;
        r.target_x_m = a.position.x + 0.1;
        r.target_y_m = a.position.y;
      }
      out.push_back({id, r});
    }
    return out;
  }

  /// A team admitted with sessions base + id.
  WorldState team(std::uint64_t base) const {
    WorldState state = initial();
    for (std::uint32_t id = 1; id <= 3; ++id) admit(state, hello_for(state, id, base + id), AdmissionKind::kFirst);
    return state;
  }

  /// Records `steps` steps into run.log (agent 3 dropped before step `drop_at` when > 0); keeps the terrain digest
  /// after each step in sha_after_[k] (k steps applied).
  void record(int steps, int drop_at = 0) {
    WorldState state = initial();
    runlog::RunLogWriter log = start_log(state);
    std::mt19937_64 random(7);
    sha_after_.push_back(runlog::terrain_sha256(state.terrain));
    for (int k = 0; k < steps; ++k) {
      if (drop_at > 0 && k == drop_at) {
        log.append(dropped_record(state, 3, "request writer lost liveliness"));
        drop_agent(state, 3, "request writer lost liveliness");
      }
      const std::vector<Submission> submissions = requests(state, random);
      const StepOutcome outcome = apply_step(state, submissions);
      log.append(step_record(submissions, outcome, state));
      sha_after_.push_back(runlog::terrain_sha256(state.terrain));
    }
  }

  std::vector<std::string> sha_after_;
};

TEST_F(ForkReplayTest, AFreshTeamReplayingTheParentReachesItsTerrainAtK) {
  record(20);
  const ForkReplay fork = read_fork(dir_.string(), 12, 0, initial());
  EXPECT_EQ(fork.origin().parent_sha256_at_step, sha_after_[12]);
  EXPECT_NE(sha_after_[12], sha_after_[0]);  // the parent built something by then
  EXPECT_EQ(fork.origin().parent_agents, 3u);
  EXPECT_EQ(fork.origin().agents, 3u);
  EXPECT_EQ(fork.origin().parent_run_id, "small-d1");
  WorldState state = team(900);  // new sessions
  std::mt19937_64 random(7);
  for (std::uint64_t k = 0; k < 12; ++k) {
    ASSERT_TRUE(fork.replaying(k));
    const std::vector<Submission> live = requests(state, random);
    ASSERT_EQ(fork.mismatch(k, live), "") << "step " << k;
    apply_step(state, fork.recorded(k, state));
    EXPECT_EQ(state.deposited_volume_m3, fork.deposited_after(k));
  }
  EXPECT_FALSE(fork.replaying(12));
  EXPECT_EQ(runlog::terrain_sha256(state.terrain), sha_after_[12]);
}

TEST_F(ForkReplayTest, ARequestThatDiffersNamesItsAgentAndStep) {
  record(8);
  const ForkReplay fork = read_fork(dir_.string(), 8, 2, initial());
  EXPECT_EQ(fork.origin().agents, 2u);
  WorldState state = team(900);
  std::mt19937_64 random(7);
  for (std::uint64_t k = 0; k < 5; ++k) {
    const std::vector<Submission> live = requests(state, random);
    apply_step(state, fork.recorded(k, state));
    (void)live;
  }
  std::vector<Submission> live = requests(state, random);
  ASSERT_EQ(fork.mismatch(5, live), "");
  std::vector<Submission> moved = live;
  moved[1].request.target_x_m += 0.1;
  moved[1].request.move = true;
  EXPECT_NE(fork.mismatch(5, moved).find("agent 2 at step 5"), std::string::npos) << fork.mismatch(5, moved);
  std::vector<Submission> silent(live.begin(), live.begin() + 2);
  EXPECT_NE(fork.mismatch(5, silent).find("agent 3 sent no request at step 5"), std::string::npos);
  std::vector<Submission> twice = live;
  twice.push_back(live[0]);
  EXPECT_NE(fork.mismatch(5, twice).find("agent 1 at step 5"), std::string::npos);
  std::vector<Submission> traced = live;  // the trace-only fields are no part of a request's meaning
  traced[0].request.decision_us = 1234;
  EXPECT_EQ(fork.mismatch(5, traced), "");
}

TEST_F(ForkReplayTest, WhatCannotBeForkedIsRefusedWithOneLine) {
  const auto refused = [&](std::uint64_t at, std::uint32_t agents, const std::string& part) {
    try {
      read_fork(dir_.string(), at, agents, initial());
      ADD_FAILURE() << "fork at " << at << " accepted; expected: " << part;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  };
  refused(1, 0, "no run.log there");
  record(10, 6);
  refused(11, 0, "the parent ran 10 steps; K must lie in 0..10");
  refused(7, 0, "agent 3 was dropped before step 7");
  EXPECT_EQ(read_fork(dir_.string(), 6, 0, initial()).origin().parent_sha256_at_step, sha_after_[6]);
  EXPECT_EQ(read_fork(dir_.string(), 0, 0, initial()).origin().parent_sha256_at_step, sha_after_[0]);
  fs::resize_file(log_path(), fs::file_size(log_path()) - 3);  // a torn last record
  refused(2, 0, "torn run.log");
}

TEST_F(ForkReplayTest, ALateJoinCannotBeRepeatedByATeamStartedAfresh) {
  // A parent in which agent 3 took a first admission at step 3 (as a fork's late slot does): a fork before it is
  // fine, one after it is refused.
  WorldState state = initial();
  runlog::RunLogWriter log = start_log(state, 2);
  std::mt19937_64 random(7);
  for (int k = 0; k < 6; ++k) {
    if (k == 3) {
      admit(state, hello_for(state, 3, 103), AdmissionKind::kFirst);
      log.append(admitted_record(state, 3, AdmissionKind::kFirst));
    }
    const std::vector<Submission> submissions = requests(state, random);
    log.append(step_record(submissions, apply_step(state, submissions), state));
  }
  log.sync();
  EXPECT_EQ(read_fork(dir_.string(), 3, 0, initial()).origin().at_step, 3u);
  try {
    read_fork(dir_.string(), 5, 0, initial());
    ADD_FAILURE() << "a fork after the late join was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("agent 3 joined at step 3 before step 5"), std::string::npos) << e.what();
  }
}

TEST_F(ForkReplayTest, AForkWhoseTeamGrewIsNotForkedAgain) {
  WorldState state = initial();
  ForkOrigin grown;
  grown.parent_dir = "out/parent";
  grown.at_step = 4;
  grown.parent_agents = 2;
  grown.agents = 3;
  LogStart start;
  start.run_id = "small-d2";
  start.agents = 3;
  start.fork = &grown;
  runlog::RunLogWriter::create(log_path(), log_header(scenario_, start, state.terrain)).sync();
  try {
    read_fork(dir_.string(), 0, 0, initial());
    ADD_FAILURE() << "a fork of a grown fork was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("a fork whose team grew at step 4 (slots 3..3 joined late)"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("fork its parent out/parent instead"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace marsala::world_server
