// marsala-rogue-agent: a misbehaving agent process for integration tests. It gets admitted like a real agent,
// then sends one bad request per step (spoofed id on another agent's partition, wrong step, NaN, over-threshold
// deposition, out-of-reach deposition, a duplicate, absurd motion, and agent 1's own session, read from its hello,
// driving agent 1 west), then leaves. The world must reject each with a reason or ignore it (requests on agent 1's
// session from this participant: docs/runtime.md#who-wrote-it), never crash, and let the other agents complete.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <random>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"
#include "marsala/scenario/scenario.hpp"

namespace {

using namespace marsala;
using namespace std::chrono_literals;

/// The bad request for the n-th step of the attack, built on a valid empty one; `spoof` is set when the request
/// must go out on the victim's partition instead of the rogue's own.
protocol::ActionRequest attack(int n, const protocol::ActionRequest& valid, const protocol::SensorFrame& frame,
                               double cell_m, bool& spoof, std::string& what) {
  protocol::ActionRequest r = valid;
  spoof = false;
  switch (n) {
    case 0:
      what = "spoofed id 1 on agent 1's partition";
      r.agent_id = 1;
      spoof = true;
      break;
    case 1:
      what = "wrong step";
      r.step += 5;
      break;
    case 2:
      what = "NaN motion target";
      r.move = true;
      r.target_x_m = std::numeric_limits<double>::quiet_NaN();
      r.target_y_m = frame.y_m;
      break;
    case 3:
      what = "deposition over the per-step threshold and the material";
      r.depositions.push_back({0, 0, 1.0});
      for (int c = 1; c < 50; ++c) r.depositions.push_back({1, c, 1.0});
      break;
    case 4:
      what = "deposition out of reach";
      r.depositions.push_back({0, 0, 0.0125});
      break;
    case 5:
      what = "absurd motion (1e30 m)";
      r.move = true;
      r.target_x_m = 1e30;
      r.target_y_m = 1e30;
      break;
    case 6:
      what = "negative deposition";
      r.depositions.push_back({0, 0, -cell_m});
      break;
    case 7: what = "duplicate request for the same step"; break;
    default:
      what = "agent 1's session: a motion west on its partition";
      spoof = true;
      break;
  }
  return r;
}

int run(int argc, char** argv) {
  if (argc < 5) {
    std::cerr << "usage: marsala-rogue-agent SCENARIO ID DDS DOMAIN\n";
    return 2;
  }
  const scenario::Scenario sc = scenario::load_scenario(argv[1]);
  const auto id = static_cast<std::uint32_t>(std::stoul(argv[2]));
  const bus::Vendor vendor = bus::vendor_from_string(argv[3]);
  const int domain = std::stoi(argv[4]);
  const RobotType& robot = sc.robot_for(id);

  // In the world's role: at an index agents probe, so that agent 1's hellos reach it (clients do not find each other).
  auto participant = bus::make_participant({vendor, domain, {}, bus::Role::kWorld});
  auto signal = std::make_shared<bus::Signal>();
  auto hello_writer = participant->create_writer<protocol::AgentHello>();
  auto admissions = participant->create_reader<protocol::Admission>({"", signal});
  auto others = participant->create_reader<protocol::AgentHello>({"", nullptr});  // agent 1's session, in clear

  protocol::AgentHello hello;
  hello.agent_id = id;
  hello.session = std::random_device{}() | 1u;
  hello.name = "rogue";
  hello.behaviour = robot.behaviour;
  hello.body = robot.body;

  protocol::Admission admission;
  const auto give_up = std::chrono::steady_clock::now() + 60s;
  while (!admission.accepted) {
    if (std::chrono::steady_clock::now() > give_up) throw Error("rogue: no admission within 60 s");
    hello_writer->write(hello);
    signal->wait_for(200ms);
    for (const auto& a : admissions->take())
      if (a.agent_id == id && a.session == hello.session) admission = a;
  }
  const std::string mine = protocol::partition_for(admission.run_id, id, hello.session);
  auto frames = participant->create_reader<protocol::SensorFrame>({mine, signal});
  auto requests = participant->create_writer<protocol::ActionRequest>({mine, nullptr});
  auto victim =
      // Agent 1's partition is named by its session: a partition wildcard reaches it.
      participant->create_writer<protocol::ActionRequest>({admission.run_id + "/agent-1-*", nullptr});
  std::uint64_t victim_session = 0;  // from agent 1's hellos, which it says before the lockstep starts

  int attacks_sent = 0;
  constexpr int kAttacks = 9;
  constexpr int kHonestSteps = 4;
  int honest_after = 0;
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (std::chrono::steady_clock::now() < deadline) {
    signal->wait_for(100ms);
    for (const protocol::AgentHello& h : others->take())
      if (h.agent_id == 1 && h.session != victim_session) {
        victim_session = h.session;
        std::cout << "rogue: agent 1 says hello with session " << std::hex << victim_session << std::dec << std::endl;
      }
    for (const auto& frame : frames->take()) {
      if (frame.run_over) return 0;
      if (attacks_sent > 0)
        std::cout << "rogue: step " << frame.step << " previous request " << protocol::to_string(frame.last_result)
                  << (frame.last_reason.empty() ? "" : ": " + frame.last_reason) << std::endl;
      protocol::ActionRequest valid;
      valid.agent_id = id;
      valid.session = hello.session;
      valid.step = frame.step;
      valid.state = "rogue";
      if (attacks_sent == kAttacks) {
        // Stay a few honest steps before leaving: a copy still in flight when the participant goes away would be
        // read only after the world dropped the rogue, and a dropped agent's requests are discarded unread.
        if (++honest_after == kHonestSteps) {
          std::cout << "rogue: done, leaving" << std::endl;
          return 0;
        }
        requests->write(valid);
        continue;
      }
      bool spoof = false;
      std::string what;
      protocol::ActionRequest bad =
          attack(attacks_sent, valid, frame, admission.assignment.world.cell_size_m, spoof, what);
      if (attacks_sent == kAttacks - 1) {  // in agent 1's name, as agent 1 would: its id, session and step
        if (victim_session == 0) throw Error("rogue: agent 1's hello was never heard");
        bad.agent_id = 1;
        bad.session = victim_session;
        bad.move = true;
        bad.target_x_m = frame.x_m - admission.assignment.world.cell_size_m;  // any valid-looking motion
        bad.target_y_m = frame.y_m;
      }
      std::cout << "rogue: step " << frame.step << " sending " << what << std::endl;
      (spoof ? victim : requests)->write(bad);
      if (attacks_sent == 7) requests->write(bad);                  // the duplicate goes out twice
      if (spoof || bad.step != frame.step) requests->write(valid);  // keep our own barrier slot filled
      ++attacks_sent;
    }
  }
  std::cerr << "rogue: the run did not move on within 120 s\n";
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "marsala-rogue-agent: " << e.what() << "\n";
    return 1;
  }
}
