// marsala-impostor: a participant that speaks in the world's name, for integration tests (issue 30's attack table;
// docs/runtime.md#who-wrote-it). For the whole run it
//   - answers every agent hello it hears (first hellos, and the hellos of agents whose frames stopped while the world
//     was paused) with a refusal "this run is closed" and an acceptance, signed with a run key of its own;
//   - writes, on the partition of every agent the world admits, a "run over" frame, a frame for step 2^62 and a
//     malformed frame, and a "run over" frame again whenever that agent says hello again;
//   - publishes, every 0.5 s once every agent was admitted, a WorldStatus "completed at step 999999" of the run,
//     carrying in turn the world's own proof (copied from its status), a proof with its own key and none; and a
//     WorldEvent run_over.
// Agents given the run key must believe none of it, and monitors none of the statuses and events.
//
// Usage: marsala-impostor VENDOR DOMAIN AGENTS TIMEOUT_S
//   Prints "impostor ready" once it hears the world's admissions (start the agents after that). Exits 0 when the
//   world's last status (running false) comes after it forged for AGENTS admitted agents; 1 when TIMEOUT_S passed
//   first. Prints what it forged.
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
#include "marsala/protocol/world_proof.hpp"

namespace {

using namespace marsala;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class Impostor {
 public:
  Impostor(bus::Vendor vendor, int domain)
      // In the world's role: at an index the agents probe, so that its forgeries do reach them.
      : participant_(bus::make_participant({vendor, domain, {}, bus::Role::kWorld})),
        key_(protocol::make_run_key()),
        signal_(std::make_shared<bus::Signal>()),
        admissions_(participant_->create_reader<protocol::Admission>({"", signal_, bus::Durability::kVolatile, 64})),
        hellos_(participant_->create_reader<protocol::AgentHello>({"", signal_, bus::Durability::kVolatile, 64})),
        world_statuses_(
            participant_->create_reader<protocol::WorldStatus>({"", signal_, bus::Durability::kTransientLocal, 16})),
        forged_admissions_(
            participant_->create_writer<protocol::Admission>({"", nullptr, bus::Durability::kVolatile, 64})),
        statuses_(participant_->create_writer<protocol::WorldStatus>({"", nullptr, bus::Durability::kVolatile, 1})),
        events_(participant_->create_writer<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256})) {
    std::cout << "impostor is participant " << participant_->id().to_string() << std::endl;
  }

  /// True once the world's admission writer is matched: what it answers from then on reaches this reader.
  bool hears_the_world() const { return admissions_->alive_writers() >= 1; }
  void wait(std::chrono::milliseconds at_most) { signal_->wait_for(at_most); }

  /// One round: hellos answered, admissions and the world's statuses read, frames forged. True when the world's
  /// last status came.
  bool round() {
    for (const bus::Received<protocol::Admission>& r : admissions_->take_received())
      if (r.from != participant_->id() && r.sample.accepted) admitted(r.sample);
    for (const bus::Received<protocol::AgentHello>& r : hellos_->take_received()) answer(r.sample);
    bool over = false;
    for (const bus::Received<protocol::WorldStatus>& r : world_statuses_->take_received()) {
      if (r.from == participant_->id() || r.sample.world_proof.empty()) continue;
      world_status_ = r.sample;
      over = over || !r.sample.running;
    }
    return over;
  }

  /// Every 0.5 s once every agent was admitted: a forged status and event.
  void forge_status(std::size_t agents) {
    if (frames_.size() < agents || world_status_.run_id.empty() || Clock::now() < next_status_) return;
    next_status_ = Clock::now() + 500ms;
    protocol::WorldStatus s = world_status_;
    s.step = 999999;
    s.running = false;
    s.completed = true;
    switch (statuses_forged_++ % 3) {
      case 0: break;  // the world's own key and proof, copied
      case 1:
        s.world_key = protocol::world_key_of(key_);
        s.world_proof = protocol::prove_world(key_, s.run_id, participant_->id().prefix);
        break;
      default:
        s.world_key.clear();
        s.world_proof.clear();
        break;
    }
    statuses_->write(s);
    protocol::WorldEvent e;
    e.step = 999999;
    e.kind = protocol::EventKind::kRunOver;
    e.detail = "forged";
    events_->write(e);
  }

  std::size_t forged_for() const { return frames_.size(); }
  void report() const {
    std::cout << "forged " << answers_ << " admissions (refusals and acceptances), frames for " << frames_.size()
              << " agents (" << run_over_frames_ << " run-over frames), " << statuses_forged_
              << " statuses 'completed at step 999999' of run '" << world_status_.run_id << "'" << std::endl;
  }

 private:
  /// A refusal and an acceptance of `hello`'s session, signed with this impostor's own key; and, to an agent already
  /// admitted (a hello because its frames stopped), a run-over frame.
  void answer(const protocol::AgentHello& hello) {
    protocol::Admission a;
    a.agent_id = hello.agent_id;
    a.session = hello.session;
    a.run_id = world_status_.run_id.empty() ? std::string("forged") : world_status_.run_id;
    a.world_key = protocol::world_key_of(key_);
    a.world_proof = protocol::prove_world(key_, a.run_id, participant_->id().prefix);
    a.reason = "this run is closed";
    forged_admissions_->write(a);
    a.accepted = true;
    a.reason.clear();
    forged_admissions_->write(a);
    answers_ += 2;
    if (const auto it = frames_.find(hello.agent_id); it != frames_.end()) write_run_over(hello.agent_id, *it->second);
  }

  void write_run_over(std::uint32_t agent, bus::Writer<protocol::SensorFrame>& frames) {
    protocol::SensorFrame f;
    f.agent_id = agent;
    f.step = 1;
    f.run_over = true;
    frames.write(f);
    ++run_over_frames_;
  }

  /// The world admitted `a`: on its partition, a run-over frame, a frame for step 2^62 and a malformed frame.
  void admitted(const protocol::Admission& a) {
    if (frames_.count(a.agent_id) != 0) return;
    auto frames = participant_->create_writer<protocol::SensorFrame>(
        {protocol::partition_for(a.run_id, a.agent_id, a.session), nullptr, bus::Durability::kVolatile, 64});
    for (auto deadline = Clock::now() + 5s; frames->matched_readers() == 0 && Clock::now() < deadline;)
      std::this_thread::sleep_for(5ms);
    write_run_over(a.agent_id, *frames);
    protocol::SensorFrame f;
    f.agent_id = a.agent_id;
    f.x_m = a.assignment.start.x;
    f.y_m = a.assignment.start.y;
    f.step = std::uint64_t{1} << 62;
    frames->write(f);
    f.step = 2;
    f.tiles.push_back({0, 0, 3, 3, {0.0}});  // one height for nine cells
    frames->write(f);
    std::cout << "forged 3 frames for agent " << a.agent_id << " on " << (frames->matched_readers() > 0 ? "a" : "no")
              << " matched reader" << std::endl;
    frames_.emplace(a.agent_id, std::move(frames));
  }

  std::unique_ptr<bus::Participant> participant_;
  protocol::RunKey key_;  // its own: no agent given the run's key believes it
  std::shared_ptr<bus::Signal> signal_;
  std::unique_ptr<bus::Reader<protocol::Admission>> admissions_;
  std::unique_ptr<bus::Reader<protocol::AgentHello>> hellos_;
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> world_statuses_;
  std::unique_ptr<bus::Writer<protocol::Admission>> forged_admissions_;
  std::unique_ptr<bus::Writer<protocol::WorldStatus>> statuses_;
  std::unique_ptr<bus::Writer<protocol::WorldEvent>> events_;
  std::map<std::uint32_t, std::unique_ptr<bus::Writer<protocol::SensorFrame>>> frames_;  // by agent id
  protocol::WorldStatus world_status_;  // the world's latest (its proof, copied into forged statuses)
  Clock::time_point next_status_{};
  std::uint64_t answers_ = 0, run_over_frames_ = 0, statuses_forged_ = 0;
};

int run(int argc, char** argv) {
  if (argc != 5) throw InvalidArgument("usage: marsala-impostor VENDOR DOMAIN AGENTS TIMEOUT_S");
  const std::size_t agents = std::stoul(argv[3]);
  const auto deadline = Clock::now() + std::chrono::seconds(std::stoi(argv[4]));
  Impostor impostor(bus::vendor_from_string(argv[1]), std::stoi(argv[2]));
  while (!impostor.hears_the_world()) {
    if (Clock::now() >= deadline) {
      std::cout << "timed out before the world's admissions matched" << std::endl;
      return 1;
    }
    impostor.wait(50ms);
  }
  std::cout << "impostor ready" << std::endl;
  for (;;) {
    if (Clock::now() >= deadline) {
      impostor.report();
      std::cout << "timed out before the world's last status" << std::endl;
      return 1;
    }
    impostor.wait(50ms);
    const bool over = impostor.round();
    impostor.forge_status(agents);
    if (over) break;
  }
  impostor.report();
  return impostor.forged_for() >= agents ? 0 : 1;
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
