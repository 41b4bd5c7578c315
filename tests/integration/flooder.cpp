// marsala-flooder: floods a domain for fault tests. `hellos`: AgentHello as fast as it can write them, random ids
// (1..1000, and the run's real ones) and random sessions, with valid-looking bodies. `requests`: ActionRequest with
// forged identities and garbage values on every agent partition of the run (a partition wildcard reaches them).
// The world must stay bounded and keep its lockstep (docs/runtime.md#load-limits).
#include <chrono>
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
using Clock = std::chrono::steady_clock;

int run(int argc, char** argv) {
  if (argc < 6) {
    std::cerr << "usage: marsala-flooder hellos|requests SECONDS SCENARIO DDS DOMAIN [RUN_ID]\n";
    return 2;
  }
  const std::string mode = argv[1];
  const double seconds = std::stod(argv[2]);
  const scenario::Scenario sc = scenario::load_scenario(argv[3]);
  const bus::Vendor vendor = bus::vendor_from_string(argv[4]);
  const int domain = std::stoi(argv[5]);
  const std::string run_id = argc > 6 ? argv[6] : sc.name + "-d" + std::to_string(domain);
  if (mode != "hellos" && mode != "requests") throw InvalidArgument("mode must be hellos or requests");

  auto participant = bus::make_participant({vendor, domain});
  std::mt19937_64 random(std::random_device{}());
  std::uniform_int_distribution<std::uint32_t> any_id(1, 1000), slot(1, static_cast<std::uint32_t>(sc.slots.size()));
  std::uint64_t written = 0;
  const Clock::time_point start = Clock::now(), end = start + std::chrono::duration_cast<Clock::duration>(
                                                                  std::chrono::duration<double>(seconds));
  if (mode == "hellos") {
    auto writer = participant->create_writer<protocol::AgentHello>();
    protocol::AgentHello hello;
    hello.name = "flood";
    hello.behaviour = sc.robot_for(1).behaviour;
    hello.body = sc.robot_for(1).body;
    while (Clock::now() < end) {
      for (int i = 0; i < 64; ++i, ++written) {
        hello.agent_id = written % 4 == 0 ? slot(random) : any_id(random);
        hello.session = random() | 1u;
        writer->write(hello);
      }
    }
  } else {
    auto writer = participant->create_writer<protocol::ActionRequest>({run_id + "/agent-*", nullptr});
    protocol::ActionRequest r;
    r.state = "flood";
    while (Clock::now() < end) {
      for (int i = 0; i < 64; ++i, ++written) {
        r.agent_id = slot(random);
        r.session = random();
        r.step = random() % 100000;
        r.move = random() % 2 == 0;
        r.target_x_m = random() % 3 == 0 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
        r.depositions.assign(random() % 4, Deposition{0, 0, 0.5});
        writer->write(r);
      }
    }
  }
  const double took = std::chrono::duration<double>(Clock::now() - start).count();
  std::cout << "flooder: " << written << " " << mode << " in " << took << " s ("
            << static_cast<long long>(written / took) << "/s)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "marsala-flooder: " << e.what() << "\n";
    return 1;
  }
}
