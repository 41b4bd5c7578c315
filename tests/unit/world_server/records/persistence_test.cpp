#include "marsala/world_server/records/persistence.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "marsala/core/error.hpp"
#include "marsala/runlog/sha256.hpp"
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

/// A run recorded step by step the way the runtime records it: admissions, a drop, a re-admission, random steps with
/// accepted and rejected requests, on a level-site scenario so that the completion check's cache is exercised.
class PersistenceTest : public testing::RecordedRunTest {
 protected:
  PersistenceTest() : RecordedRunTest("marsala_persistence_") {}

  WorldState initial() const { return make_world_state(scenario_, terrain_, 3); }

  /// Runs `steps` steps, writing run.log (and snapshot.pb after step `snapshot_after`, when > 0). Returns the state.
  WorldState record(int steps, int snapshot_after = 0) {
    WorldState state = initial();
    runlog::RunLogWriter log = start_log(state);
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> offset(-0.6, 0.6);
    for (int k = 0; k < steps; ++k) {
      if (k == 10) {
        log.append(dropped_record(state, 3, "request writer lost liveliness"));
        drop_agent(state, 3, "request writer lost liveliness");
      }
      if (k == 14) {
        admit(state, hello_for(state, 3, 555), AdmissionKind::kReadmission);
        log.append(admitted_record(state, 3, AdmissionKind::kReadmission));
      }
      std::vector<Submission> submissions;
      for (std::uint32_t id : state.live_ids()) {
        protocol::ActionRequest r = request_for(state, id);
        const AgentRecord& a = state.agent(id);
        // Half near the robot, half in the site (often out of reach: rejected), so that the site's check sees changes.
        const bool in_site = random() % 2 == 0;
        const double x = in_site ? 2.5 + offset(random) * 0.8 : a.position.x + offset(random);
        const double y = in_site ? 2.1 + offset(random) * 0.15 : a.position.y + offset(random);
        if (a.type.depositor.kind != DepositorKind::kLayer)  // a cube (0.1 m) or cone robot: whole cubes at (x, y)
          r.deposits.push_back({x, y, (random() % 5 == 0 ? 12 : 1) * 0.001});
        else if (const std::optional<CellIndex> c = state.terrain.geometry().cell_at({x, y}))
          r.depositions.push_back({c->row, c->col, (random() % 5 == 0 ? 40 : 1) * kLayer});
        if (random() % 3 == 0) {
          r.move = true;
          r.target_x_m = a.position.x + 0.1;
          r.target_y_m = a.position.y;
        }
        r.refill = random() % 7 == 0;
        if (k % 3 == 0) r.waiting_for = "waits\x01 in step " + std::to_string(k);  // kept as "waits? in step k"
        submissions.push_back({id, r});
        if (random() % 11 == 0) submissions.push_back({id, r});  // a duplicate, rejected
      }
      const StepOutcome outcome = apply_step(state, submissions);
      log.append(step_record(submissions, outcome, state));
      if (snapshot_after > 0 && k + 1 == snapshot_after)
        write_snapshot((dir_ / kSnapshotFile).string(), make_snapshot(state, "small-d1", log.bytes()));
    }
    return state;
  }

  static std::string fingerprint(const WorldState& state) {
    return make_snapshot(state, "small-d1", 0).SerializeAsString();
  }

  Heightmap terrain_ = flat_terrain();
};

TEST_F(PersistenceTest, TheHeaderKeepsTheOverridesSoThatAResumeAppliesThemAgain) {
  const std::string text = small_scenario_text_completing(site_block(4, 1.0));
  const std::vector<std::string> overrides{"max_steps=77", "robot_type.body.sensing_range_m=2.5"};
  const scenario::Scenario changed = scenario::parse_scenario(text, "small.pbtxt", overrides);
  LogStart start;
  start.scenario_text = text;
  const proto::LogHeader h = log_header(changed, start, flat_terrain());
  ASSERT_EQ(h.overrides_size(), 2);
  EXPECT_EQ(h.overrides(0), overrides[0]);
  EXPECT_EQ(h.overrides(1), overrides[1]);
  EXPECT_EQ(h.scenario_text(), text);  // the file as it was: the overrides apply on top of it
  // What prepare_resume does with the header gives the scenario the run had.
  const scenario::Scenario resumed = scenario::parse_scenario(
      h.scenario_text(), h.scenario_file(), std::vector<std::string>(h.overrides().begin(), h.overrides().end()));
  EXPECT_EQ(resumed.max_steps, 77u);
  EXPECT_EQ(resumed.robot_types[0].body.sensing_range_m, 2.5);
  EXPECT_NE(scenario_.robot_types[0].body.sensing_range_m, 2.5);
}

TEST_F(PersistenceTest, ReplayingTheLogRebuildsTheStateExactly) {
  const WorldState live = record(40);
  ASSERT_GT(live.deposited_volume_m3, 0.0);
  ASSERT_GT(live.check.evaluations, 1u);
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  EXPECT_EQ(rebuilt.tail_problem, "");
  EXPECT_EQ(rebuilt.snapshot_step, 0u);
  EXPECT_EQ(rebuilt.records, 3u + 40u + 2u);
  EXPECT_EQ(rebuilt.state.step, 40u);
  EXPECT_EQ(runlog::terrain_sha256(rebuilt.state.terrain), runlog::terrain_sha256(live.terrain));
  EXPECT_EQ(fingerprint(rebuilt.state), fingerprint(live));
  EXPECT_EQ(rebuilt.state.agent(3).session, 555u);
}

// A snapshot in the middle, then the records after it: the same state, and each continues identically.
TEST_F(PersistenceTest, CubeAndConeDepositsAreLoggedAndReplayedExactly) {
  // Agent 2 builds with 0.1 m cubes, agent 3 with cones.
  std::string text = small_scenario_text_completing(site_block(4, 1.0));
  const std::string types = R"(
robot_type { name: "cuber" behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cube" cube_size_m: 0.1 } }
robot_type { name: "piler" behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cone" } }
)";
  text.insert(text.find("agent {"), types);
  text.replace(text.find("robot_type: \"tester\" start { x_m: 2.55"), 20, "robot_type: \"cuber\"");
  text.replace(text.find("robot_type: \"tester\" start { x_m: 1.05 y_m: 3.05"), 20, "robot_type: \"piler\"");
  scenario_ = scenario::parse_scenario(text, "mixed.pbtxt");
  // Deposits are judged against the MARS bound of the initial terrain (docs/runtime.md#deposit-bound): a 3 m tower in
  // the south-east corner lifts it above 1.3 m everywhere, so the flat ground around the robots may be built on.
  terrain_(39, 39) = 3.0;
  ASSERT_EQ(initial().agent(2).type.depositor.kind, DepositorKind::kCube);
  ASSERT_EQ(initial().agent(3).type.depositor.kind, DepositorKind::kCone);
  const WorldState live = record(40);
  // The log holds the deposits, and for accepted ones the cells the world raised.
  runlog::RunLogReader scan(log_path());
  int deposits = 0, raised = 0;
  proto::LogRecord record;
  while (scan.next(record))
    if (record.has_step())
      for (const proto::LoggedRequest& q : record.step().requests()) {
        deposits += q.deposits_size();
        raised += q.accepted() ? q.raised_size() : 0;
        if (!q.accepted()) {
          EXPECT_EQ(q.raised_size(), 0);
        }
      }
  EXPECT_GT(deposits, 20);
  EXPECT_GT(raised, 0);
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  EXPECT_EQ(rebuilt.tail_problem, "");
  EXPECT_EQ(runlog::terrain_sha256(rebuilt.state.terrain), runlog::terrain_sha256(live.terrain));
  EXPECT_EQ(fingerprint(rebuilt.state), fingerprint(live));
  EXPECT_GT(live.agent(2).deposited_m3, 0.0);
  EXPECT_GT(live.agent(3).deposited_m3, 0.0);
}

TEST_F(PersistenceTest, ASnapshotAndTheLogAfterItRebuildTheSameState) {
  const WorldState live = record(40, 23);
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  EXPECT_EQ(rebuilt.snapshot_problem, "");
  EXPECT_EQ(rebuilt.snapshot_step, 23u);
  EXPECT_EQ(rebuilt.records, 17u);
  EXPECT_EQ(fingerprint(rebuilt.state), fingerprint(live));
  // The completion check continues as the live one: both evaluate on the same schedule with the same answers.
  WorldState a = live, b = rebuilt.state;
  for (int k = 0; k < 8; ++k) {
    for (WorldState* w : {&a, &b}) {
      protocol::ActionRequest r = request_for(*w, 1);
      r.depositions.push_back({12, 22, kLayer});
      apply_step(*w, std::vector<protocol::ActionRequest>{r});
    }
    EXPECT_EQ(fingerprint(a), fingerprint(b)) << k;
  }
}

// The stall watch and what each agent waits for (docs/runtime.md#stall) are state: a snapshot and the log after it
// rebuild them, so a resumed run stalls at the step the uninterrupted one would.
TEST_F(PersistenceTest, TheStallWatchAndWaitingForSurviveASnapshotAndTheLog) {
  const WorldState live = record(40, 23);
  EXPECT_GT(live.stall.longest_quiet, 0u);
  EXPECT_GT(live.stall.best_progress, 0.0);
  EXPECT_EQ(live.agent(1).waiting_for, "waits? in step 39");
  for (const bool with_snapshot : {true, false}) {
    if (!with_snapshot) fs::remove(dir_ / kSnapshotFile);
    runlog::RunLogReader reader(log_path());
    const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
    EXPECT_EQ(rebuilt.snapshot_step, with_snapshot ? 23u : 0u);
    EXPECT_EQ(rebuilt.state.stall.quiet_since, live.stall.quiet_since);
    EXPECT_EQ(rebuilt.state.stall.longest_quiet, live.stall.longest_quiet);
    EXPECT_EQ(rebuilt.state.stall.best_progress, live.stall.best_progress);
    for (std::uint32_t id = 1; id <= 3; ++id)
      EXPECT_EQ(rebuilt.state.agent(id).waiting_for, live.agent(id).waiting_for) << "agent " << id;
  }
}

// The heading (docs/runtime.md#heading) is state: a snapshot and the log after it rebuild it, so a resumed run's
// cameras look where an uninterrupted run's do.
TEST_F(PersistenceTest, HeadingsSurviveASnapshotAndTheLogAfterIt) {
  const WorldState live = record(40, 23);
  // Agent 1 starts at (1.05, 1.05) facing its target (3.05, 2.05); the recorded moves go east.
  EXPECT_NEAR(initial_heading_rad(live.agent(1)), std::atan2(1.0, 2.0), 1e-12);
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  ASSERT_EQ(rebuilt.snapshot_step, 23u);
  bool turned = false;
  for (std::uint32_t id = 1; id <= 3; ++id) {
    EXPECT_EQ(rebuilt.state.agent(id).heading_rad, live.agent(id).heading_rad) << "agent " << id;
    turned = turned || live.agent(id).heading_rad != initial_heading_rad(live.agent(id));
  }
  EXPECT_TRUE(turned);  // some agent moved, so the heading is not merely the initial one
}

TEST_F(PersistenceTest, AnUnusableSnapshotIsReportedAndTheLogReplayedFromTheStart) {
  const WorldState live = record(30, 12);
  {
    std::fstream f((dir_ / kSnapshotFile).string(), std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(40);
    f.put('\x5a');
  }
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  EXPECT_NE(rebuilt.snapshot_problem, "");
  EXPECT_EQ(rebuilt.snapshot_step, 0u);
  EXPECT_EQ(fingerprint(rebuilt.state), fingerprint(live));
}

TEST_F(PersistenceTest, ATornTailIsCutNeverApplied) {
  record(20);
  const auto full = fs::file_size(log_path());
  fs::resize_file(log_path(), full - 5);
  runlog::RunLogReader reader(log_path());
  const RebuiltState rebuilt = rebuild_state(dir_.string(), initial(), reader);
  EXPECT_NE(rebuilt.tail_problem.find("truncated record"), std::string::npos) << rebuilt.tail_problem;
  EXPECT_EQ(rebuilt.state.step, 19u);  // step 19's record was torn
  EXPECT_LT(rebuilt.good_bytes, full - 5);
}

// A record whose checksum holds but whose verdict the rules do not give is a disagreement, never silently applied.
TEST_F(PersistenceTest, AVerdictTheRulesDoNotGiveIsAnError) {
  WorldState state = initial();
  admit(state, hello_for(state, 1, 101), AdmissionKind::kFirst);
  std::vector<Submission> submissions{{1, request_for(state, 1)}};
  submissions[0].request.depositions.push_back({5, 5, 1000.0});  // far beyond reach and the step limit
  WorldState applied = state;
  const StepOutcome outcome = apply_step(applied, submissions);
  ASSERT_FALSE(outcome.accepted_submissions[0]);
  proto::LogRecord forged = step_record(submissions, outcome, applied);
  forged.mutable_step()->mutable_requests(0)->set_accepted(true);
  try {
    apply_record(state, forged, "run.log (record at byte 99)");
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("accepted by the run and is rejected on replay"), std::string::npos)
        << e.what();
  }
  WorldState skipped = initial();
  admit(skipped, hello_for(skipped, 1, 101), AdmissionKind::kFirst);
  skipped.step = 3;
  EXPECT_THROW(apply_record(skipped, step_record(submissions, outcome, applied), "run.log"), ParseError);
}

}  // namespace
}  // namespace marsala::world_server
