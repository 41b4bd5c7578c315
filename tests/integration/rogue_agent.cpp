// marsala-rogue-agent: a misbehaving agent process for integration tests. It gets admitted like a real agent,
// then sends one bad request per step (spoofed id and session on another agent's partition, wrong step, NaN,
// over-threshold deposition, out-of-reach deposition, a duplicate, absurd motion), then leaves. The world must
// reject each with a reason, never crash, and let the other agents complete.
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
    default: what = "duplicate request for the same step"; break;
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

  auto participant = bus::make_participant({vendor, domain});
  auto signal = std::make_shared<bus::Signal>();
  auto hello_writer = participant->create_writer<protocol::AgentHello>();
  auto admissions = participant->create_reader<protocol::Admission>({"", signal});

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
      // Agent 1's partition is named by its session, which the rogue does not know: a partition wildcard reaches it.
      participant->create_writer<protocol::ActionRequest>({admission.run_id + "/agent-1-*", nullptr});

  int attacks_sent = 0;
  constexpr int kAttacks = 8;
  constexpr int kHonestSteps = 4;
  int honest_after = 0;
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while (std::chrono::steady_clock::now() < deadline) {
    signal->wait_for(100ms);
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
      const protocol::ActionRequest bad =
          attack(attacks_sent, valid, frame, admission.assignment.world.cell_size_m, spoof, what);
      std::cout << "rogue: step " << frame.step << " sending " << what << std::endl;
      (spoof ? victim : requests)->write(bad);
      if (attacks_sent == kAttacks - 1) requests->write(bad);       // the duplicate goes out twice
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
