// The agent's runtime edge over the in-process bus, against a scripted world on a thread of the test.

#include "marsala/agent/runtime/agent_runtime.hpp"
#include "marsala/protocol/admit_deadline.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <thread>

#include "marsala/agent/runtime/map_dump.hpp"
#include "marsala/core/error.hpp"
#include "marsala/protocol/world_proof.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::runtime {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

RuntimeConfig config(std::uint32_t id, const std::string& behaviour = "idle") {
  RuntimeConfig c;
  c.agent_id = id;
  c.type.behaviour = behaviour;
  c.type.body = test::husky();
  c.hello_period = 20ms;
  c.admit_timeout = 5s;
  c.world_timeout = 5s;
  return c;
}

/// The run key of the scripted worlds.
const protocol::RunKey& run_key() {
  static const protocol::RunKey key = protocol::make_run_key();
  return key;
}

/// `a` as participant `p` proves itself with `key`: the world's proof (protocol/world_proof.hpp).
protocol::Admission signed_by(const bus::Participant& p, protocol::Admission a,
                              const protocol::RunKey& key = run_key()) {
  a.world_key = protocol::world_key_of(key);
  a.world_proof = protocol::prove_world(key, a.run_id, p.id().prefix);
  return a;
}

protocol::Admission admission_for(const protocol::AgentHello& hello, const Heightmap& h) {
  protocol::Admission a;
  a.agent_id = hello.agent_id;
  a.session = hello.session;
  a.accepted = true;
  a.run_id = "rt";
  a.assignment.world.rows = h.rows();
  a.assignment.world.cols = h.cols();
  a.assignment.world.cell_size_m = h.cell_size_m();
  a.assignment.tile_size = 16;
  a.assignment.target.x = 2.55;
  a.assignment.target.y = 1.05;
  a.assignment.base_radius_m = 0.5;
  return a;
}

/// A scripted world: waits for a hello from `id`, answers `answer(hello)`, then, if admitted, runs `steps` lockstep
/// steps (frame, wait for the request) and a run_over frame. Returns the requests it received.
struct ScriptedWorld {
  bus::Participant& p;
  std::uint32_t id;
  std::uint64_t hellos_seen = 0;
  /// Called before the frame of each step is written, with the agent's partition and the world's frame writer.
  std::function<void(int step, const std::string& partition, bus::Writer<protocol::SensorFrame>& frames)> before_frame;
  /// Steps whose request was there as soon as the frame's write() returned [count].
  int answered_within_write = 0;

  protocol::AgentHello wait_hello(bus::Reader<protocol::AgentHello>& hellos, bus::Signal& signal) {
    const auto deadline = Clock::now() + 5s;
    while (Clock::now() < deadline) {
      signal.wait_for(50ms);
      for (const auto& h : hellos.take()) {
        ++hellos_seen;
        if (h.agent_id == id) return h;
      }
    }
    throw Error("no hello from agent " + std::to_string(id));
  }

  std::vector<protocol::ActionRequest> run(
      const std::function<protocol::Admission(const protocol::AgentHello&)>& answer, int steps,
      bool send_frames = true) {
    auto hello_signal = std::make_shared<bus::Signal>();
    auto hellos = p.create_reader<protocol::AgentHello>({"", hello_signal});
    auto admissions = p.create_writer<protocol::Admission>();
    const protocol::AgentHello hello = wait_hello(*hellos, *hello_signal);
    const protocol::Admission a = signed_by(p, answer(hello));
    // The slot the admission names: `id`, or the one assigned to an "any slot" hello (id 0).
    const std::uint32_t slot = a.agent_id;
    const std::string partition = protocol::partition_for(a.run_id, slot, a.session);
    auto signal = std::make_shared<bus::Signal>();
    auto frames = p.create_writer<protocol::SensorFrame>({partition, nullptr});
    auto requests = p.create_reader<protocol::ActionRequest>({partition, signal});
    admissions->write(a);
    std::vector<protocol::ActionRequest> got;
    if (!a.accepted || !send_frames) return got;
    // Wait until the agent's endpoints exist (they are made on admission).
    for (auto deadline = Clock::now() + 5s; frames->matched_readers() == 0 && Clock::now() < deadline;)
      std::this_thread::sleep_for(1ms);
    const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
    for (int step = 0; step <= steps; ++step) {
      protocol::SensorFrame f;
      f.agent_id = slot;
      f.step = static_cast<std::uint64_t>(step);
      f.x_m = 0.55 + 0.0;
      f.y_m = 1.05;
      f.material_m3 = 1.0;
      f.run_over = step == steps;
      if (step == 0)
        for (int tr = 0; tr < 2; ++tr)
          for (int tc = 0; tc < 3; ++tc) f.tiles.push_back(test::cut_tile(h, 16, tr, tc));
      if (step == 2) {
        f.last_result = protocol::ActionResult::kRejected;
        f.last_reason = "scripted rejection";
      }
      if (before_frame) before_frame(step, partition, *frames);
      frames->write(f);
      if (f.run_over) break;
      const auto deadline = Clock::now() + 5s;
      bool answered = false;
      // The in-process bus delivers on the writing thread, where the agent answers (on_data): before write() returned.
      for (auto& q : requests->take()) {
        answered = answered || q.step == f.step;
        answered_within_write += q.step == f.step ? 1 : 0;
        got.push_back(std::move(q));
      }
      while (!answered && Clock::now() < deadline) {
        signal->wait_for(50ms);
        for (auto& q : requests->take()) {
          answered = answered || q.step == f.step;
          got.push_back(std::move(q));
        }
      }
    }
    return got;
  }
};

TEST(AgentRuntime, HelloAdmissionLockstepAndRunOver) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 101});
  AgentRuntime agent(*participant, config(4, "ramp_builder"));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 101});
  ScriptedWorld world{*world_participant, 4, 0, nullptr};
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  const auto requests = world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 5);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(r.run_id, "rt");
  EXPECT_EQ(r.frames, 6u);
  EXPECT_EQ(r.requests, 5u);
  EXPECT_EQ(r.rejected, 1u);
  EXPECT_EQ(r.last_step, 5u);
  EXPECT_EQ(r.final_state, "done");
  ASSERT_EQ(requests.size(), 5u);
  for (std::size_t i = 0; i < requests.size(); ++i) {
    EXPECT_EQ(requests[i].step, i);
    EXPECT_EQ(requests[i].agent_id, 4u);
    EXPECT_EQ(requests[i].session, agent.config().session);
    EXPECT_TRUE(requests[i].move);  // flat ground, target 2 m east: the ramp builder drives there
  }
  EXPECT_NE(agent.config().session, 0u);
  EXPECT_EQ(agent.config().name, "agent-4");
  // Every frame after the first (which may come before the lockstep is ready, and is then taken by the loop) is
  // decided and answered on the thread that delivered it, without waking the agent's own thread.
  EXPECT_GE(world.answered_within_write, 4);
}

/// A ramp builder (agent 4) dumping its map into `dir`, run against the scripted world of `domain` admitting it to
/// run `run_id` for 3 steps (with frames or not).
RunResult run_dumping_agent(int domain, const std::filesystem::path& dir, const std::string& run_id, bool send_frames) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, domain});
  RuntimeConfig c = config(4, "ramp_builder");
  dump_maps_into(std::make_shared<MapDump>(dir.string()), c);
  AgentRuntime agent(*participant, c);
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, domain});
  ScriptedWorld world{*world_participant, 4, 0, nullptr};
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  world.run(
      [&](const protocol::AgentHello& hello) {
        protocol::Admission a = admission_for(hello, h);
        a.run_id = run_id;
        return a;
      },
      3, send_frames);
  return running.get();
}

TEST(AgentRuntime, DumpsItsMapWhenTheRunIsOverAndRefusesAFolderOfAnotherRun) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "agent_runtime_dump";
  std::filesystem::remove_all(dir);
  const RunResult first = run_dumping_agent(121, dir, "rt", true);
  ASSERT_EQ(first.outcome, RunOutcome::kRunOver) << first.message;
  // The world sent every tile of its flat 0 m grid at step 0: every cell known, at 0 m.
  const MapRecord record = read_map_record((dir / "agent-4-map.json").string());
  EXPECT_EQ(record.run_id, "rt");
  EXPECT_EQ(record.step, 3u);
  EXPECT_EQ(record.known_cells, 800);
  terrain::AscReadOptions keep;
  keep.keep_nodata = true;
  const Heightmap map = terrain::read_asc((dir / "agent-4-height.asc").string(), keep);
  EXPECT_EQ(map.rows(), 20);
  EXPECT_EQ(map.cols(), 40);
  EXPECT_EQ(map.heights().cwiseAbs().maxCoeff(), 0.0);

  // Another run ("rt2") into the same folder: refused once admitted, nothing sent, the first run's files untouched.
  const auto before = std::filesystem::last_write_time(dir / "agent-4-height.asc");
  const RunResult r = run_dumping_agent(122, dir, "rt2", false);
  EXPECT_EQ(r.outcome, RunOutcome::kOutputRefused);
  EXPECT_NE(r.message.find("agent-4-map.json holds a map of run 'rt'"), std::string::npos) << r.message;
  EXPECT_EQ(r.requests, 0u);
  EXPECT_EQ(read_map_record((dir / "agent-4-map.json").string()).run_id, "rt");
  EXPECT_EQ(std::filesystem::last_write_time(dir / "agent-4-height.asc"), before);
}

TEST(AgentRuntime, IgnoresFramesNotFromItsWorldOrThatMakeNoSense) {
  // An impostor on the domain writes on the agent's partition (partition names are no secret): a "run over" frame,
  // a frame for step 2^62 and a malformed one. The world itself once sends a frame whose tile does not fit the grid.
  // The agent ignores all four and runs to the world's own end, answering every step once.
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 109});
  AgentRuntime agent(*participant, config(4, "ramp_builder"));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 109});
  auto impostor = bus::make_participant({bus::Vendor::kInProcess, 109});
  std::unique_ptr<bus::Writer<protocol::SensorFrame>> forged;
  ScriptedWorld world{*world_participant, 4, 0, nullptr};
  world.before_frame = [&](int step, const std::string& partition, bus::Writer<protocol::SensorFrame>& frames) {
    protocol::SensorFrame f;
    f.agent_id = 4;
    f.x_m = 0.55;
    f.y_m = 1.05;
    if (step == 1) {
      forged = impostor->create_writer<protocol::SensorFrame>({partition, nullptr});
      f.step = 1;
      f.run_over = true;
      forged->write(f);
      f.run_over = false;
      f.step = std::uint64_t{1} << 62;
      forged->write(f);
      f.step = 1;
      f.tiles.push_back({0, 0, 3, 3, {0.0}});  // 1 height for 9 cells
      forged->write(f);
    }
    if (step == 3) {
      f.step = 3;
      f.tiles.push_back({7, 7, 16, 16, std::vector<double>(256, 0.0)});  // off the 20 x 40 grid
      frames.write(f);
    }
  };
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  const auto requests = world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 5);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(r.last_step, 5u);
  EXPECT_EQ(r.requests, 5u);
  EXPECT_EQ(r.ignored_frames, 4u);
  ASSERT_EQ(requests.size(), 5u);
  for (std::size_t i = 0; i < requests.size(); ++i) EXPECT_EQ(requests[i].step, i);
}

TEST(AgentRuntime, IgnoresScansThatMakeNoSense) {
  // A laser robot: frames with a non-finite point, a point far beyond its range, or points without a scan are
  // ignored whole (a log line each, no crash); the run goes on to the world's end.
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 113});
  RuntimeConfig c = config(4, "ramp_builder");
  c.type.sensor = sensor_defaults(SensorKind::kLaser);
  AgentRuntime agent(*participant, c);
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 113});
  ScriptedWorld world{*world_participant, 4, 0, nullptr};
  world.before_frame = [&](int step, const std::string&, bus::Writer<protocol::SensorFrame>& frames) {
    protocol::SensorFrame f;
    f.agent_id = 4;
    f.step = static_cast<std::uint64_t>(step);
    f.x_m = 0.55;
    f.y_m = 1.05;
    f.scanned = true;
    f.points.push_back({0.3F, 0.0F, -0.5F});
    if (step == 1) f.points.push_back({std::numeric_limits<float>::quiet_NaN(), 0.0F, -0.5F});
    if (step == 2) f.points.push_back({100.0F, 0.0F, -0.5F});
    if (step == 3) f.scanned = false;
    if (step >= 1 && step <= 3) frames.write(f);
  };
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  const auto requests = world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 5);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(r.requests, 5u);
  EXPECT_EQ(r.ignored_frames, 3u);
}

TEST(AgentRuntime, AGroundTruthRobotIgnoresScans) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 114});
  AgentRuntime agent(*participant, config(4, "ramp_builder"));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 114});
  ScriptedWorld world{*world_participant, 4, 0, nullptr};
  world.before_frame = [&](int step, const std::string&, bus::Writer<protocol::SensorFrame>& frames) {
    if (step != 2) return;
    protocol::SensorFrame f;
    f.agent_id = 4;
    f.step = 2;
    f.x_m = 0.55;
    f.y_m = 1.05;
    f.scanned = true;
    frames.write(f);
  };
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 4);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(r.ignored_frames, 1u);
}

TEST(AgentRuntime, RefusalEndsTheRunWithTheWorldsReason) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 102});
  AgentRuntime agent(*participant, config(2));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 102});
  ScriptedWorld world{*world_participant, 2, 0, nullptr};
  world.run(
      [](const protocol::AgentHello& hello) {
        protocol::Admission a;
        a.agent_id = hello.agent_id;
        a.session = hello.session;
        a.accepted = false;
        a.reason = "body differs from slot 2";
        return a;
      },
      0);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRefused);
  EXPECT_NE(r.message.find("body differs from slot 2"), std::string::npos) << r.message;
  EXPECT_EQ(r.final_state, "wait_admission");
}

TEST(AgentRuntime, RepeatsHellosAndIgnoresOtherSessions) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 103});
  RuntimeConfig c = config(6);
  c.session = 1234;
  c.admit_timeout = 400ms;
  AgentRuntime agent(*participant, c);
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 103});
  auto signal = std::make_shared<bus::Signal>();
  auto hellos = world_participant->create_reader<protocol::AgentHello>({"", signal});
  auto admissions = world_participant->create_writer<protocol::Admission>();
  std::atomic<bool> stop{false};
  const auto t0 = Clock::now();
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  std::vector<protocol::AgentHello> got;
  while (Clock::now() - t0 < 300ms) {
    signal->wait_for(20ms);
    for (auto& h : hellos->take()) {
      got.push_back(h);
      protocol::Admission a;  // accepted, but for another session of agent 6
      a.agent_id = 6;
      a.session = 999;
      a.accepted = true;
      a.run_id = "other";
      admissions->write(a);
    }
  }
  const RunResult r = running.get();
  const double waited_s = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(r.outcome, RunOutcome::kAdmitTimeout);
  EXPECT_GE(waited_s, 0.39);
  EXPECT_GE(got.size(), 5u);  // every 20 ms for 300 ms (loosely: the machine is shared)
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got[0].agent_id, 6u);
  EXPECT_EQ(got[0].session, 1234u);
  EXPECT_EQ(got[0].behaviour, "idle");
  EXPECT_EQ(got[0].body.reach_m, 1.5);
}

// The admit timeout counts from the latest agent the world admitted for the first time, up to
// protocol::kAdmitProgressCap timeouts: a world admitting a crowd one by one is not gone.
TEST(AgentRuntime, WaitsWhileTheWorldAdmitsOtherAgentsUpToTheCap) {
  for (const bool endless : {false, true}) {
    const int domain = endless ? 111 : 110;
    auto participant = bus::make_participant({bus::Vendor::kInProcess, domain});
    RuntimeConfig c = config(6);
    c.admit_timeout = 400ms;
    AgentRuntime agent(*participant, c);
    auto world_participant = bus::make_participant({bus::Vendor::kInProcess, domain});
    auto admissions = world_participant->create_writer<protocol::Admission>();
    std::atomic<bool> stop{false};
    const auto t0 = Clock::now();
    auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
    // Another agent admitted every 250 ms: for 1 s (agents 10..13), or for as long as the agent waits.
    std::uint32_t other = 10;
    while (running.wait_for(250ms) != std::future_status::ready && (endless || Clock::now() - t0 < 1000ms)) {
      protocol::Admission a;
      a.agent_id = other++;
      a.session = 77;
      a.accepted = true;
      a.run_id = "crowd";
      admissions->write(a);
    }
    const RunResult r = running.get();
    const double waited_s = std::chrono::duration<double>(Clock::now() - t0).count();
    EXPECT_EQ(r.outcome, RunOutcome::kAdmitTimeout);
    if (endless) {  // the cap: protocol::kAdmitProgressCap x 0.4 s
      EXPECT_GE(waited_s, protocol::kAdmitProgressCap * 0.4 - 0.01);
      EXPECT_LT(waited_s, protocol::kAdmitProgressCap * 0.4 + 1.0);
    } else {  // 0.4 s after the last admission (at 0.75-1 s): well past 0.4 s, before the cap
      EXPECT_GE(waited_s, 1.1);
      EXPECT_LT(waited_s, protocol::kAdmitProgressCap * 0.4 - 0.01);
    }
    EXPECT_NE(r.message.find("while the world admitted"), std::string::npos) << r.message;
  }
}

// --id auto: the hello asks for any slot (agent_id 0) under the name "<type>-any"; the agent takes the admission
// of its own session whatever slot it names, and from then on is that slot: partition, frames, requests, name.
TEST(AgentRuntime, AnySlotTakesTheAssignedIdFromItsAdmission) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 107});
  RuntimeConfig c = config(0, "ramp_builder");
  c.type.name = "husky";
  AgentRuntime agent(*participant, c);
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 107});
  ScriptedWorld world{*world_participant, 0, 0, nullptr};
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  protocol::AgentHello asked;
  const auto requests = world.run(
      [&](const protocol::AgentHello& hello) {
        asked = hello;
        protocol::Admission a = admission_for(hello, h);
        a.agent_id = 5;  // the world's choice
        return a;
      },
      3);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(asked.agent_id, 0u);
  EXPECT_EQ(asked.name, "husky-any");
  EXPECT_EQ(asked.behaviour, "ramp_builder");
  EXPECT_EQ(agent.config().agent_id, 5u);
  EXPECT_EQ(agent.config().name, "husky-5");
  ASSERT_EQ(requests.size(), 3u);
  for (const protocol::ActionRequest& q : requests) {
    EXPECT_EQ(q.agent_id, 5u);
    EXPECT_EQ(q.session, agent.config().session);
  }
}

// An "any slot" agent ignores answers to other sessions (whatever slot they name) and ends on a refusal of its own.
TEST(AgentRuntime, AnySlotRefusalEndsTheRunWithTheWorldsReason) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 108});
  AgentRuntime agent(*participant, config(0));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 108});
  auto signal = std::make_shared<bus::Signal>();
  auto hellos = world_participant->create_reader<protocol::AgentHello>({"", signal});
  auto admissions = world_participant->create_writer<protocol::Admission>();
  bool answered = false;
  for (const auto deadline = Clock::now() + 5s; !answered && Clock::now() < deadline;) {
    signal->wait_for(20ms);
    for (const auto& hello : hellos->take()) {
      protocol::Admission other;  // accepted, for another session: not this agent's
      other.agent_id = 2;
      other.session = hello.session + 1;
      other.accepted = true;
      admissions->write(other);
      protocol::Admission no;
      no.agent_id = 0;
      no.session = hello.session;
      no.reason = "any slot: all 3 slots of this robot type are taken";
      admissions->write(signed_by(*world_participant, no));
      answered = true;
    }
  }
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRefused);
  EXPECT_NE(r.message.find("all 3 slots of this robot type are taken"), std::string::npos) << r.message;
  EXPECT_EQ(agent.config().agent_id, 0u);
}

// A stranger answers first, in the world's name: a refusal, then an acceptance, signed with a key of its own, with the
// world's proof copied from another participant, and unsigned. An agent given the run key believes none of them and
// is admitted by the world that proves the key.
TEST(AgentRuntime, BelievesOnlyTheWorldThatProvesTheRunKey) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 110});
  RuntimeConfig c = config(3);
  c.world_key = protocol::world_key_of(run_key());
  AgentRuntime agent(*participant, c);
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto stranger = bus::make_participant({bus::Vendor::kInProcess, 110});
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 110});
  auto signal = std::make_shared<bus::Signal>();
  auto hellos = stranger->create_reader<protocol::AgentHello>({"", signal});
  auto forged = stranger->create_writer<protocol::Admission>();
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  bool done = false;
  for (const auto deadline = Clock::now() + 5s; !done && Clock::now() < deadline;) {
    signal->wait_for(20ms);
    for (const auto& hello : hellos->take()) {
      protocol::Admission no = admission_for(hello, h);
      no.accepted = false;
      no.reason = "this run is closed";
      forged->write(signed_by(*stranger, no, protocol::make_run_key()));
      protocol::Admission yes = admission_for(hello, h);
      yes.run_id = "forged";
      forged->write(signed_by(*stranger, yes, protocol::make_run_key()));
      forged->write(signed_by(*world_participant, yes));  // the run key's proof, but made for another participant
      forged->write(yes);                                 // no proof at all
      done = true;
    }
  }
  ASSERT_TRUE(done);
  ScriptedWorld world{*world_participant, 3, 0, nullptr};
  const auto requests = world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 2);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kRunOver) << r.message;
  EXPECT_EQ(r.run_id, "rt");
  EXPECT_EQ(r.ignored_admissions, 4u);
  EXPECT_EQ(requests.size(), 2u);
}

TEST(AgentRuntime, WorldSilenceAfterAdmissionTimesOut) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 104});
  RuntimeConfig c = config(1);
  c.world_timeout = 300ms;
  AgentRuntime agent(*participant, c);
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  auto world_participant = bus::make_participant({bus::Vendor::kInProcess, 104});
  ScriptedWorld world{*world_participant, 1, 0, nullptr};
  const Heightmap h({20, 40, 0.0, 0.0, 0.1}, 0.0);
  world.run([&](const protocol::AgentHello& hello) { return admission_for(hello, h); }, 0, false);
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kWorldTimeout);
  EXPECT_EQ(r.frames, 0u);
}

TEST(AgentRuntime, StopsWhenAsked) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 105});
  AgentRuntime agent(*participant, config(1));
  std::atomic<bool> stop{false};
  auto running = std::async(std::launch::async, [&] { return agent.run(stop); });
  std::this_thread::sleep_for(50ms);
  stop = true;
  const auto t0 = Clock::now();
  const RunResult r = running.get();
  EXPECT_EQ(r.outcome, RunOutcome::kStopped);
  EXPECT_LT(Clock::now() - t0, 1s);
}

TEST(AgentRuntime, RejectsBadConfigurationBeforeAnyTraffic) {
  auto participant = bus::make_participant({bus::Vendor::kInProcess, 106});
  EXPECT_NO_THROW(AgentRuntime(*participant, config(0)));  // 0: any slot (--id auto), assigned at admission
  EXPECT_THROW(AgentRuntime(*participant, config(0, "dancer")), InvalidArgument);
  EXPECT_THROW(AgentRuntime(*participant, config(1, "dancer")), InvalidArgument);
  RuntimeConfig c = config(1);
  c.world_timeout = -1ms;
  EXPECT_THROW(AgentRuntime(*participant, c), InvalidArgument);
  c.world_timeout = 0ms;  // 0: wait for a silent world for ever
  EXPECT_NO_THROW(AgentRuntime(*participant, c));
  EXPECT_EQ(to_string(RunOutcome::kAdmitTimeout), "admit_timeout");
  EXPECT_NE(random_session(), 0u);
  EXPECT_NE(random_session(), random_session());
}

}  // namespace
}  // namespace marsala::agent::runtime
