// marsala-impostor: a participant that speaks in the world's name, for integration tests. It listens to the
// admissions on the default partition (as any listener can), and for every agent admitted writes on that agent's
// partition a "run over" frame, a frame for step 2^62 and a malformed frame; and it publishes a WorldStatus and a
// WorldEvent claiming that the run completed at step 999999. Agents must ignore the frames and the monitor the
// status: they come from a participant that is not the run's world (docs/runtime.md#who-wrote-it).
//
// Usage: marsala-impostor VENDOR DOMAIN AGENTS TIMEOUT_S
//   Prints "impostor ready" once it hears the world's admissions (start the agents after that). Exits 0 once it has
//   forged for AGENTS admitted agents, 1 when TIMEOUT_S passed first.
#include <chrono>
#include <cstdint>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"

namespace {

using namespace marsala;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

void forge_frames(bus::Participant& participant, const protocol::Admission& a,
                  std::vector<std::unique_ptr<bus::Writer<protocol::SensorFrame>>>& keep) {
  auto frames = participant.create_writer<protocol::SensorFrame>(
      {protocol::partition_for(a.run_id, a.agent_id, a.session), nullptr, bus::Durability::kVolatile, 64});
  for (auto deadline = Clock::now() + 5s; frames->matched_readers() == 0 && Clock::now() < deadline;)
    std::this_thread::sleep_for(5ms);
  protocol::SensorFrame f;
  f.agent_id = a.agent_id;
  f.x_m = a.assignment.start.x;
  f.y_m = a.assignment.start.y;
  f.step = 1;
  f.run_over = true;
  frames->write(f);
  f.run_over = false;
  f.step = std::uint64_t{1} << 62;
  frames->write(f);
  f.step = 2;
  f.tiles.push_back({0, 0, 3, 3, {0.0}});  // one height for nine cells
  frames->write(f);
  std::cout << "forged 3 frames for agent " << a.agent_id << " on " << (frames->matched_readers() > 0 ? "a" : "no")
            << " matched reader" << std::endl;
  keep.push_back(std::move(frames));
}

int run(int argc, char** argv) {
  if (argc != 5) throw InvalidArgument("usage: marsala-impostor VENDOR DOMAIN AGENTS TIMEOUT_S");
  const bus::Vendor vendor = bus::vendor_from_string(argv[1]);
  const int domain = std::stoi(argv[2]);
  const std::size_t agents = std::stoul(argv[3]);
  const auto deadline = Clock::now() + std::chrono::seconds(std::stoi(argv[4]));
  // In the world's role: at an index the agents probe, so that its forgeries do reach them.
  auto participant = bus::make_participant({vendor, domain, {}, bus::Role::kWorld});
  std::cout << "impostor is participant " << participant->id().to_string() << std::endl;
  auto signal = std::make_shared<bus::Signal>();
  auto admissions = participant->create_reader<protocol::Admission>({"", signal, bus::Durability::kVolatile, 64});
  auto statuses = participant->create_writer<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
  auto events = participant->create_writer<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256});
  // Ready once the world's admission writer is matched: what it answers from then on reaches this reader.
  while (admissions->alive_writers() < 1) {
    if (Clock::now() >= deadline) {
      std::cout << "timed out before the world's admissions matched" << std::endl;
      return 1;
    }
    signal->wait_for(50ms);
  }
  std::cout << "impostor ready" << std::endl;
  std::vector<std::unique_ptr<bus::Writer<protocol::SensorFrame>>> keep;
  std::set<std::uint32_t> done;
  std::string run_id;
  while (done.size() < agents) {
    if (Clock::now() >= deadline) {
      std::cout << "timed out after forging for " << done.size() << " agents" << std::endl;
      return 1;
    }
    signal->wait_for(50ms);
    for (const protocol::Admission& a : admissions->take()) {
      if (!a.accepted || !done.insert(a.agent_id).second) continue;
      run_id = a.run_id;
      forge_frames(*participant, a, keep);
    }
  }
  protocol::WorldStatus s;
  s.run_id = run_id;
  s.step = 999999;
  s.running = false;
  s.completed = true;
  statuses->write(s);
  protocol::WorldEvent e;
  e.step = 999999;
  e.kind = protocol::EventKind::kRunOver;
  e.detail = "forged";
  events->write(e);
  std::cout << "forged a status and an event: run '" << run_id << "' completed at step 999999" << std::endl;
  std::this_thread::sleep_for(2s);  // keep the transient-local status available to late readers a little
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "marsala-impostor: " << e.what() << "\n";
    return 2;
  }
}
