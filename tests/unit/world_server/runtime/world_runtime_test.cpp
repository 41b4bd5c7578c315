#include "marsala/world_server/runtime/world_runtime.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <unistd.h>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "marsala/core/error.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "unit/world_server/fake_agent.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::FakeAgent;
using testing::FakeAgentConfig;
using testing::FakeMode;

// Walkers of the small scenario with a goal box for two bodies of 1 m, [1.7, 3.9] x [1.3, 2.6]: agent 1 from
// (1.05, 1.05) and agent 2 from (2.55, 1.05) towards (3.05, 2.05), 0.2 m per step. Agent 1 enters the goal with its
// 4th move (x = 1.05 + 4 * 0.2 * 2 / sqrt 5 = 1.766, y = 1.408), agent 2 with its 2nd, and their bodies stay more than
// 1 m apart all the way: the run completes when step 3 has been applied, after 4 steps.
constexpr std::uint64_t kStepsToGoal = 4;
const char* const kTwoBodyGoal = "goal { x0_m: 1.7 y0_m: 1.3 x1_m: 3.9 y1_m: 2.6 }";

/// The number after the first "key": in a JSON text, or NaN when absent.
double json_number(const std::string& json, const std::string& key) {
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = json.find(tag);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + tag.size(), nullptr);
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class RuntimeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("marsala_runtime_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }

  RuntimeOptions options(std::uint32_t agents, double deadline_s) const {
    RuntimeOptions o;
    o.agents = agents;
    o.admit_timeout_s = 10.0;
    o.step_deadline_s = deadline_s;
    o.out_dir = out_.string();
    o.linger_s = 1.0;
    return o;
  }
  FakeAgentConfig agent(int domain, std::uint32_t id, FakeMode mode = FakeMode::kWalker) const {
    FakeAgentConfig c;
    c.domain = domain;
    c.id = id;
    c.session = 100 + id;
    c.body = scenario_.robot_for(id).body;
    c.mode = mode;
    return c;
  }

  /// Runs `runtime` (on `domain`) with agent 1 walking until the run ends. The runtime outlives the call: its
  /// transient-local status stays readable.
  RunResult run_with_one_walker(WorldRuntime& runtime, int domain) const {
    std::atomic<bool> stop{false};
    RunResult result;
    std::thread world([&] { result = runtime.run(stop); });
    FakeAgent a1(agent(domain, 1));
    world.join();
    a1.join();
    return result;
  }

  /// Sends `hello` until the world answers it; returns the answer.
  static protocol::Admission ask(int domain, const protocol::AgentHello& hello) {
    auto participant = bus::make_participant({bus::Vendor::kInProcess, domain});
    auto signal = std::make_shared<bus::Signal>();
    auto writer = participant->create_writer<protocol::AgentHello>();
    auto reader = participant->create_reader<protocol::Admission>({"", signal});
    for (int attempt = 0; attempt < 500; ++attempt) {
      writer->write(hello);
      signal->wait_for(20ms);
      for (const protocol::Admission& a : reader->take())
        if (a.agent_id == hello.agent_id && a.session == hello.session) return a;
    }
    ADD_FAILURE() << "no answer to the hello of agent " << hello.agent_id;
    return {};
  }

  scenario::Scenario scenario_ =
      scenario::parse_scenario(testing::small_scenario_text_completing(kTwoBodyGoal), "small.pbtxt");
  fs::path out_;
};

TEST_F(RuntimeTest, AdmitsRefusesRunsToCompletionAndWritesOutputs) {
  constexpr int kDomain = 41;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  auto monitor_signal = std::make_shared<bus::Signal>();
  auto statuses = participant->create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
  auto events = participant->create_reader<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256});
  WorldRuntime runtime(scenario_, testing::flat_terrain(), options(2, 10.0), *participant);
  EXPECT_EQ(runtime.run_id(), "small-d41");
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });

  // Refusals: slot 3 is not part of a two-agent run; agent 1 with another body.
  protocol::AgentHello intruder;
  intruder.agent_id = 3;
  intruder.session = 9;
  intruder.body = scenario_.robot_for(3).body;
  protocol::Admission answer = ask(kDomain, intruder);
  EXPECT_FALSE(answer.accepted);
  EXPECT_NE(answer.reason.find("unknown agent id 3"), std::string::npos) << answer.reason;
  intruder.agent_id = 1;
  intruder.body.navigability.delta_m = 0.5;
  answer = ask(kDomain, intruder);
  EXPECT_FALSE(answer.accepted);
  EXPECT_NE(answer.reason.find("body differs"), std::string::npos) << answer.reason;

  FakeAgentConfig first = agent(kDomain, 1);
  first.deposit_first = true;
  FakeAgent a1(first), a2(agent(kDomain, 2));
  world.join();
  a1.join();
  a2.join();

  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.end_reason, protocol::EndReason::kCompleted);
  EXPECT_EQ(result.steps, kStepsToGoal);
  EXPECT_EQ(result.admitted, 2u);
  const WorldState& s = runtime.state();
  EXPECT_EQ(s.agent(1).accepted, kStepsToGoal);
  EXPECT_EQ(s.agent(1).rejected + s.agent(1).missed + s.agent(2).rejected + s.agent(2).missed, 0u);
  EXPECT_NEAR(s.agent(2).position.x, 2.55 + 4 * 0.2 * 0.5 / std::sqrt(1.25), 1e-12);  // four moves towards (3.05, 2.05)
  EXPECT_NEAR(s.agent(2).position.y, 1.05 + 4 * 0.2 * 1.0 / std::sqrt(1.25), 1e-12);
  const double volume = 2 * testing::kLayer * 0.1 * 0.1;
  EXPECT_EQ(s.deposited_volume_m3, volume);
  EXPECT_EQ(s.terrain(20, 5), 2 * testing::kLayer);

  // Every agent got one frame per step and a final run_over frame.
  for (const FakeAgent* a : {&a1, &a2}) {
    const auto frames = a->frames();
    ASSERT_EQ(frames.size(), kStepsToGoal + 1);
    for (std::uint64_t k = 0; k < frames.size(); ++k) EXPECT_EQ(frames[k].step, k);
    EXPECT_TRUE(frames.back().run_over);
    EXPECT_EQ(frames.back().last_result, protocol::ActionResult::kAccepted);
  }

  // The latest status, as a late monitor sees it.
  auto late = participant->create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
  const auto latest = late->take();
  ASSERT_EQ(latest.size(), 1u);
  EXPECT_FALSE(latest[0].running);
  EXPECT_TRUE(latest[0].completed);
  EXPECT_EQ(latest[0].step, kStepsToGoal);
  EXPECT_EQ(latest[0].progress, 1.0);
  ASSERT_EQ(latest[0].agents.size(), 2u);
  EXPECT_EQ(latest[0].agents[0].state, "walking");
  // While admitting (every 0.5 s, at least once), before step 0, after each step, the final one.
  const std::vector<protocol::WorldStatus> all = statuses->take();
  const auto admitting = static_cast<std::size_t>(
      std::count_if(all.begin(), all.end(), [](const protocol::WorldStatus& st) { return st.admitting; }));
  EXPECT_GE(admitting, 1u);
  EXPECT_EQ(all.size() - admitting, kStepsToGoal + 2);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].admitting, i < admitting) << i;  // admitting first, then never again
    EXPECT_EQ(all[i].world_id, all.front().world_id);
    EXPECT_NE(all[i].world_id, 0u);
  }
  int admitted = 0, refused = 0, deposited = 0, run_over = 0;
  for (const protocol::WorldEvent& e : events->take()) {
    admitted += e.kind == protocol::EventKind::kAdmitted;
    refused += e.kind == protocol::EventKind::kRefused;
    deposited += e.kind == protocol::EventKind::kDeposited;
    run_over += e.kind == protocol::EventKind::kRunOver;
  }
  EXPECT_EQ(admitted, 2);
  EXPECT_EQ(refused, 2);
  EXPECT_EQ(deposited, 1);
  EXPECT_EQ(run_over, 1);

  // Outputs.
  const std::string summary = read_text(out_ / "summary.json");
  for (const std::string& field :
       {std::string("\"completed\": true"), std::string("\"steps\": 4"), std::string("\"agents\": 2"),
        std::string("\"admitted\": 2"), std::string("\"missed_deadlines\": 0"), std::string("\"dds\": \"inprocess\""),
        std::string("\"scenario\": \"small\""), std::string("\"seed\": \"1\""),
        std::string("\"end_reason\": \"completed\""),
        "\"terrain_sha256\": \"" + runlog::terrain_sha256(s.terrain) + "\"", std::string("\"per_agent\""),
        std::string("\"accepted\": 4"), std::string("\"at_goal\": true"), std::string("\"dropped\": false"),
        std::string("\"wall_seconds\"")})
    EXPECT_NE(summary.find(field), std::string::npos) << field << " not in\n" << summary;
  EXPECT_EQ(json_number(summary, "deposited_volume_m3"), s.deposited_volume_m3);  // printed to round-trip
  EXPECT_EQ(json_number(summary, "deposited_m3"), s.agent(1).deposited_m3);
  EXPECT_GT(json_number(summary, "wall_seconds"), 0.0);
  const Heightmap final_terrain = terrain::read_asc((out_ / "terrain_final.asc").string());
  EXPECT_EQ(runlog::terrain_sha256(final_terrain), runlog::terrain_sha256(s.terrain));
  EXPECT_EQ(terrain::read_asc((out_ / "terrain_initial.asc").string()).max_height(), 0.0);
  EXPECT_GT(fs::file_size(out_ / "final.png"), 1000u);
  const std::string log = read_text(out_ / "events.log");
  // JSON Lines: every line one object; the deposition carries its cells (row, col, height).
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);)
    EXPECT_TRUE(line.size() > 2 && line.front() == '{' && line.back() == '}') << "not a JSON object: " << line;
  for (const char* text : {"{\"step\":0,\"agent\":1,\"kind\":\"admitted\"",
                           "{\"step\":0,\"agent\":3,\"kind\":\"refused\",\"detail\":\"unknown agent id 3",
                           "{\"step\":0,\"agent\":1,\"kind\":\"deposited\",\"volume_m3\":",
                           "{\"step\":3,\"agent\":1,\"kind\":\"at_goal\"",
                           "{\"step\":4,\"agent\":0,\"kind\":\"run_over\",\"detail\":\"completed\"}"})
    EXPECT_NE(log.find(text), std::string::npos) << text << " not in\n" << log;
  const std::size_t deposition = log.find("\"kind\":\"deposited\"");
  ASSERT_NE(deposition, std::string::npos);
  EXPECT_NE(log.substr(deposition, log.find('\n', deposition) - deposition).find("\"cells\":[["), std::string::npos)
      << "the deposition names no cells:\n" << log;
}

TEST_F(RuntimeTest, AnAgentThatMissesThreeDeadlinesIsDroppedTheOthersContinue) {
  constexpr int kDomain = 42;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  WorldRuntime runtime(scenario_, testing::flat_terrain(), options(2, 0.15), *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });
  FakeAgent a1(agent(kDomain, 1)), a2(agent(kDomain, 2, FakeMode::kSilent));
  world.join();
  a1.join();
  a2.join();

  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.steps, kStepsToGoal);
  const AgentRecord& silent = runtime.state().agent(2);
  EXPECT_EQ(silent.missed, 3u);
  EXPECT_TRUE(silent.dropped);
  EXPECT_FALSE(silent.alive);
  EXPECT_NE(silent.drop_reason.find("3 consecutive missed deadlines"), std::string::npos);
  EXPECT_EQ(runtime.state().agent(1).missed, 0u);
  // The dropped agent was told the run is over for it, right after its third miss.
  const auto frames = a2.frames();
  ASSERT_EQ(frames.size(), 4u);
  // At most the copy for a reader that matched after step 0's first: no repair fits in a 0.15 s step.
  EXPECT_LE(a2.copies(), 1);
  EXPECT_EQ(frames[1].last_result, protocol::ActionResult::kMissed);
  EXPECT_TRUE(frames.back().run_over);
  EXPECT_EQ(frames.back().step, 3u);
  const std::string summary = read_text(out_ / "summary.json");
  EXPECT_NE(summary.find("\"missed_deadlines\": 3"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"dropped\": true"), std::string::npos) << summary;
}

// docs/runtime.md#re-admission: a live agent that asks during the run whether it is still counted in is answered on its
// own partition with its frame again (its watch takes a frame as the answer), not with an admission, which goes to
// every agent of the team.
TEST_F(RuntimeTest, ALiveAgentAskingDuringTheRunIsAnsweredWithItsFrameNotAnAdmission) {
  constexpr int kDomain = 49;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  WorldRuntime runtime(scenario_, testing::flat_terrain(), options(2, 1.0), *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });
  FakeAgentConfig asker = agent(kDomain, 1);
  asker.ask_at_step = 1;  // after answering step 1's frame (its admission was answered long before)
  // Agent 2 never answers: each of its first three steps waits the 1 s deadline, time for agent 1's question.
  FakeAgent a1(asker), a2(agent(kDomain, 2, FakeMode::kSilent));
  world.join();
  a1.join();
  a2.join();

  EXPECT_TRUE(result.completed);
  EXPECT_GE(a1.copies(), 1) << "the question is answered by a copy of the frame it already answered";
  EXPECT_EQ(a1.answers_after_ask(), 0) << "no admission on the team's topic";
  EXPECT_EQ(runtime.state().agent(1).missed, 0u);
}

// docs/runtime.md#standing-answers: a robot whose empty answer stands gets a frame only when the frame tells it something
// new (here: a walker passing within its proximity range), the world taking its answer for every other step; the run
// is the same as with a frame every step (standing_answers: false): every step accepted for both robots, none missed,
// the same end, and every frame held back told nothing its predecessor had not.
TEST_F(RuntimeTest, AStandingAnswerIsTakenWhileFramesWouldTellNothingNew) {
  struct Run {
    RunResult result;
    std::vector<protocol::SensorFrame> frames;  // the stander's
    std::uint32_t accepted[2] = {0, 0};
    std::uint32_t rejected[2] = {0, 0};
    std::uint32_t missed[2] = {0, 0};
    Position walker;
  };
  const auto run = [&](int domain, bool standing) {
    scenario_ = scenario::parse_scenario(
        testing::small_scenario_text_completing(
            kTwoBodyGoal, std::string("max_steps: 30") + (standing ? "" : " standing_answers: false")),
        "small.pbtxt");
    auto participant = bus::make_participant({bus::Vendor::kInProcess, domain});
    RuntimeOptions o = options(2, 10.0);
    o.max_steps = 30;
    o.out_dir = (out_ / std::to_string(domain)).string();
    WorldRuntime runtime(scenario_, testing::flat_terrain(), o, *participant);
    std::atomic<bool> stop{false};
    Run r;
    std::thread world([&] { r.result = runtime.run(stop); });
    // Agent 2 stands at (2.55, 1.05), 1.5 m from agent 1's start: the walker is its neighbour from step 0 and moves
    // within its range until the stander's body stops it (its motions refused); then nothing changes around agent 2.
    FakeAgent a1(agent(domain, 1)), a2(agent(domain, 2, FakeMode::kStander));
    world.join();
    a1.join();
    a2.join();
    r.frames = a2.frames();
    for (std::uint32_t id : {1u, 2u}) {
      r.accepted[id - 1] = runtime.state().agent(id).accepted;
      r.rejected[id - 1] = runtime.state().agent(id).rejected;
      r.missed[id - 1] = runtime.state().agent(id).missed;
    }
    r.walker = runtime.state().agent(1).position;
    return r;
  };
  const Run every = run(52, false);
  const Run stood = run(53, true);

  for (const Run* r : {&every, &stood}) {
    EXPECT_EQ(r->result.end_reason, protocol::EndReason::kMaxSteps);
    EXPECT_EQ(r->result.steps, 30u);
    EXPECT_EQ(r->accepted[0] + r->rejected[0], 30u);  // the walker's way passes the stander's body
    EXPECT_EQ(r->accepted[1], 30u);
    EXPECT_EQ(r->missed[0] + r->missed[1], 0u);
  }
  EXPECT_EQ(stood.accepted[0], every.accepted[0]);
  EXPECT_EQ(stood.walker.x, every.walker.x);
  EXPECT_EQ(stood.walker.y, every.walker.y);
  ASSERT_EQ(every.frames.size(), 31u) << "30 steps and the run-over frame";
  ASSERT_GE(stood.frames.size(), 3u);
  EXPECT_TRUE(stood.frames.back().run_over);
  EXPECT_LT(stood.frames.size(), 20u) << "no frame for the steps after the walker stopped";
  // Every frame the stander got is the one of that step with a frame every step; every frame held back repeats the
  // last one it got in pose, material, result and neighbours.
  std::size_t next = 0;
  for (const protocol::SensorFrame& f : every.frames) {
    if (next < stood.frames.size() && stood.frames[next].step == f.step && stood.frames[next].run_over == f.run_over) {
      const protocol::SensorFrame& got = stood.frames[next++];
      ASSERT_EQ(got.neighbours.size(), f.neighbours.size()) << f.step;
      for (std::size_t i = 0; i < f.neighbours.size(); ++i) {
        EXPECT_EQ(got.neighbours[i].position.x, f.neighbours[i].position.x) << f.step;
        EXPECT_EQ(got.neighbours[i].position.y, f.neighbours[i].position.y) << f.step;
      }
      EXPECT_EQ(got.last_result, f.last_result) << f.step;
      continue;
    }
    ASSERT_GT(next, 0u) << "the frame of step 0 goes out";
    const protocol::SensorFrame& last = stood.frames[next - 1];
    EXPECT_FALSE(f.run_over);
    EXPECT_EQ(f.x_m, last.x_m) << f.step;
    EXPECT_EQ(f.y_m, last.y_m) << f.step;
    EXPECT_EQ(f.last_result, last.last_result) << f.step;
    ASSERT_EQ(f.neighbours.size(), last.neighbours.size()) << f.step;
    for (std::size_t i = 0; i < f.neighbours.size(); ++i) {
      EXPECT_EQ(f.neighbours[i].position.x, last.neighbours[i].position.x) << f.step;
      EXPECT_EQ(f.neighbours[i].position.y, last.neighbours[i].position.y) << f.step;
    }
  }
  EXPECT_EQ(next, stood.frames.size()) << "every frame the stander got was one of the run's";
}

// docs/runtime.md#standing-answers: an agent whose answer stands and asks whether it is still counted in is answered
// by its frame of the next step (then its answer stands again), neither by a copy of an old frame nor by an admission.
TEST_F(RuntimeTest, AStandingAgentAskingIsAnsweredByItsNextFrame) {
  constexpr int kDomain = 54;
  constexpr std::uint64_t kSteps = 20000;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  RuntimeOptions o = options(1, 10.0);
  o.max_steps = kSteps;
  scenario_ = scenario::parse_scenario(
      testing::small_scenario_text_completing(kTwoBodyGoal, "max_steps: 20000 stall_steps: 0"), "small.pbtxt");
  WorldRuntime runtime(scenario_, testing::flat_terrain(), o, *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });
  FakeAgentConfig asker = agent(kDomain, 1, FakeMode::kStander);
  asker.ask_at_step = 1;  // after answering the frame of step 1, whose answer stands
  FakeAgent a1(asker);
  world.join();
  a1.join();

  EXPECT_EQ(result.end_reason, protocol::EndReason::kMaxSteps);
  EXPECT_EQ(runtime.state().agent(1).accepted, kSteps);
  EXPECT_EQ(runtime.state().agent(1).missed, 0u);
  const std::vector<protocol::SensorFrame> frames = a1.frames();
  ASSERT_EQ(frames.size(), 4u) << "steps 0 and 1 (its first result is news), the answer to its question, run over";
  EXPECT_EQ(frames[0].step, 0u);
  EXPECT_EQ(frames[1].step, 1u);
  EXPECT_GT(frames[2].step, 1u);
  EXPECT_LT(frames[2].step, kSteps) << "answered during the run, by the frame of a step";
  EXPECT_FALSE(frames[2].run_over);
  EXPECT_TRUE(frames[3].run_over);
  EXPECT_EQ(a1.copies(), 0) << "no copy of an old frame";
  EXPECT_EQ(a1.answers_after_ask(), 0) << "no admission on the team's topic";
}

TEST_F(RuntimeTest, AnAgentWhoseWriterGoesAwayIsDroppedAtOnce) {
  constexpr int kDomain = 43;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  // A long deadline: the drop must come from liveliness, not from missed deadlines.
  WorldRuntime runtime(scenario_, testing::flat_terrain(), options(2, 20.0), *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  const auto t0 = std::chrono::steady_clock::now();
  std::thread world([&] { result = runtime.run(stop); });
  FakeAgentConfig quitter = agent(kDomain, 2, FakeMode::kQuitter);
  quitter.quit_at_step = 3;
  FakeAgent a1(agent(kDomain, 1)), a2(quitter);
  world.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  a1.join();
  a2.join();

  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.steps, kStepsToGoal);
  EXPECT_LT(seconds, 10.0);
  const AgentRecord& gone = runtime.state().agent(2);
  EXPECT_TRUE(gone.dropped);
  EXPECT_EQ(gone.drop_reason, "request writer lost liveliness");
  EXPECT_EQ(gone.missed, 0u);
  EXPECT_EQ(gone.accepted, 3u);
}

TEST_F(RuntimeTest, StopEndsTheRunCleanlyWithRunOverFramesAndOutputs) {
  constexpr int kDomain = 44;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  WorldRuntime runtime(scenario_, testing::flat_terrain(), options(2, 20.0), *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });
  FakeAgent a1(agent(kDomain, 1, FakeMode::kSilent)), a2(agent(kDomain, 2, FakeMode::kSilent));
  // Wait for both frames of step 0 (the world now waits for requests that never come), then stop.
  for (int i = 0; i < 1000 && (a1.frames().empty() || a2.frames().empty()); ++i) std::this_thread::sleep_for(5ms);
  const auto t0 = std::chrono::steady_clock::now();
  stop = true;
  world.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  a1.join();
  a2.join();
  EXPECT_EQ(result.end_reason, protocol::EndReason::kSignal);
  EXPECT_FALSE(result.completed);
  EXPECT_EQ(result.steps, 0u);
  for (const FakeAgent* a : {&a1, &a2}) {
    const auto frames = a->frames();
    ASSERT_EQ(frames.size(), 2u);
    EXPECT_TRUE(frames.back().run_over);
  }
  EXPECT_TRUE(fs::exists(out_ / "summary.json"));
  EXPECT_TRUE(fs::exists(out_ / "terrain_final.asc"));
}

TEST_F(RuntimeTest, MaxStepsEndsAnUnfinishedRun) {
  constexpr int kDomain = 45;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  RuntimeOptions o = options(1, 10.0);
  o.max_steps = 5;
  // The small goal [2.9, 3.2] x [1.9, 2.2]: agent 1 needs 11 steps.
  WorldRuntime runtime(testing::small_scenario(), testing::flat_terrain(), o, *participant);
  const RunResult result = run_with_one_walker(runtime, kDomain);
  EXPECT_EQ(result.end_reason, protocol::EndReason::kMaxSteps);
  EXPECT_FALSE(result.completed);
  EXPECT_EQ(result.steps, 5u);
  EXPECT_NE(read_text(out_ / "summary.json").find("\"completed\": false"), std::string::npos);
}

TEST_F(RuntimeTest, APayloadScenarioNavigableFromTheStartCompletesAtOnceWithTheSeedGiven) {
  constexpr int kDomain = 50;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  const scenario::Scenario payload =
      scenario::parse_scenario(testing::small_scenario_text_completing(testing::payload_block()), "payload.pbtxt");
  RuntimeOptions o = options(1, 10.0);
  o.seed = 1234;
  WorldRuntime runtime(payload, testing::flat_terrain(), o, *participant);
  const RunResult result = run_with_one_walker(runtime, kDomain);
  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.end_reason, protocol::EndReason::kCompleted);
  EXPECT_EQ(result.steps, 0u);
  auto late = participant->create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
  const auto latest = late->take();
  ASSERT_EQ(latest.size(), 1u);
  EXPECT_EQ(latest[0].progress, 1.0);
  const std::string summary = read_text(out_ / "summary.json");
  for (const char* field : {"\"completion\": \"payload_path\"", "\"path_found\": true", "\"seed\": \"1234\"",
                            "\"completed\": true", "\"idle_steps\": 0"})
    EXPECT_NE(summary.find(field), std::string::npos) << field << " not in\n" << summary;
  EXPECT_NEAR(json_number(summary, "path_length_m"), 2.5 * std::sqrt(2.0), 1e-12);
}

TEST_F(RuntimeTest, ALevelSiteRunPublishesItsLevelFractionAsProgress) {
  constexpr int kDomain = 51;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  const scenario::Scenario site =
      scenario::parse_scenario(testing::small_scenario_text_completing(testing::site_block()), "site.pbtxt");
  Heightmap terrain = testing::flat_terrain();
  terrain(15, 25) = -0.1;  // spoils 9 of the site's 100 cells
  RuntimeOptions o = options(1, 10.0);
  o.max_steps = 4;
  WorldRuntime runtime(site, terrain, o, *participant);
  const RunResult result = run_with_one_walker(runtime, kDomain);
  EXPECT_EQ(result.end_reason, protocol::EndReason::kMaxSteps);
  auto late = participant->create_reader<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
  const auto latest = late->take();
  ASSERT_EQ(latest.size(), 1u);
  EXPECT_DOUBLE_EQ(latest[0].progress, 0.91);
  const std::string summary = read_text(out_ / "summary.json");
  EXPECT_DOUBLE_EQ(json_number(summary, "site_level_fraction"), 0.91);
  EXPECT_EQ(json_number(summary, "idle_steps"), 4.0);  // the walker never deposits
  EXPECT_NE(summary.find("\"completion\": \"level_site\""), std::string::npos) << summary;
}

TEST_F(RuntimeTest, TheAdmitTimeoutCountsFromTheLatestAdmission) {
  // Admit timeout 2 s: agent 1 comes at 1.2 s, agent 2 at 2.6 s, past the 2 s from the start but within 2 s of agent
  // 1's admission: a team admitted one by one is waited for (before, the run started at 2 s with agent 1 alone).
  constexpr int kDomain = 48;
  auto participant = bus::make_participant({bus::Vendor::kInProcess, kDomain});
  RuntimeOptions o = options(2, 10.0);
  o.admit_timeout_s = 2.0;
  WorldRuntime runtime(scenario_, testing::flat_terrain(), o, *participant);
  std::atomic<bool> stop{false};
  RunResult result;
  std::thread world([&] { result = runtime.run(stop); });
  std::this_thread::sleep_for(1200ms);
  FakeAgent a1(agent(kDomain, 1));
  std::this_thread::sleep_for(1400ms);
  FakeAgent a2(agent(kDomain, 2));
  world.join();
  a1.join();
  a2.join();
  EXPECT_TRUE(result.completed);
  for (std::uint32_t id : {1u, 2u}) {
    EXPECT_TRUE(runtime.state().agent(id).admitted) << "agent " << id;
    EXPECT_EQ(runtime.state().agent(id).missed, 0u) << "agent " << id;  // both there from step 0
  }
}

TEST_F(RuntimeTest, NoAgentWithinTheAdmitTimeoutIsAnError) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 46});
  RuntimeOptions o = options(2, 1.0);
  o.admit_timeout_s = 0.2;
  WorldRuntime runtime(scenario_, testing::flat_terrain(), o, *participant);
  std::atomic<bool> stop{false};
  try {
    runtime.run(stop);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no agent admitted"), std::string::npos) << e.what();
  }
}

TEST_F(RuntimeTest, BadOptionsThrow) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 47});
  EXPECT_THROW(WorldRuntime(scenario_, testing::flat_terrain(), options(4, 1.0), *participant), InvalidArgument);
  RuntimeOptions o = options(2, 1.0);
  o.run_id = "a/b";
  EXPECT_THROW(WorldRuntime(scenario_, testing::flat_terrain(), o, *participant), InvalidArgument);
  o.run_id = "*";
  EXPECT_THROW(WorldRuntime(scenario_, testing::flat_terrain(), o, *participant), InvalidArgument);
  EXPECT_EQ(default_run_id("ramp", 7), "ramp-d7");
}

}  // namespace
}  // namespace marsala::world_server
