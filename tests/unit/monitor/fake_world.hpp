#pragma once
// The world server's side of the bus for the monitor's tests: what the monitor reads, and a way to wait
// (on a wake-up, not a sleep) until the monitor's readers have joined.

#include <chrono>
#include <memory>

#include "marsala/bus/bus.hpp"
#include "marsala/protocol/world_proof.hpp"

namespace marsala::monitor::test_support {

/// The world server's side of the bus: a transient-local status writer (depth 1) and an event writer,
/// plus probes that wake the test when the monitor's readers join.
class FakeWorld {
 public:
  explicit FakeWorld(int domain_id) : participant_(bus::make_participant({bus::Vendor::kInProcess, domain_id})) {
    join();
    status_probe_ = participant_->create_reader<protocol::WorldStatus>({"", probe_});
    event_probe_ = participant_->create_reader<protocol::WorldEvent>({"", probe_});
  }

  /// Waits (on the probes' wake-up, at most 5 s) until the monitor's readers joined.
  bool wait_for_monitor(int status_readers, int event_readers) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (status_->matched_readers() < 1 + status_readers || events_->matched_readers() < 1 + event_readers)
      if (!probe_->wait_until(deadline)) return false;
    return true;
  }
  /// Publishes `s` with this world's proof (docs/runtime.md#who-wrote-it), as a world does.
  void publish(protocol::WorldStatus s) {
    s.world_key = protocol::world_key_of(key_);
    s.world_proof = protocol::prove_world(key_, s.run_id, participant_->id().prefix);
    status_->write(s);
  }
  void publish(const protocol::WorldEvent& e) { events_->write(e); }
  /// The world's writers go, as when its process dies or stays paused: readers see no live status writer any more.
  void leave() {
    status_.reset();
    events_.reset();
  }
  /// The world's writers (again, after leave(): a paused world that runs on).
  void join() {
    status_ = participant_->create_writer<protocol::WorldStatus>({"", nullptr, bus::Durability::kTransientLocal, 1});
    events_ = participant_->create_writer<protocol::WorldEvent>({"", nullptr, bus::Durability::kVolatile, 256});
  }

 private:
  std::unique_ptr<bus::Participant> participant_;
  protocol::RunKey key_ = protocol::make_run_key();
  std::shared_ptr<bus::Signal> probe_ = std::make_shared<bus::Signal>();
  std::unique_ptr<bus::Writer<protocol::WorldStatus>> status_;
  std::unique_ptr<bus::Writer<protocol::WorldEvent>> events_;
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> status_probe_;
  std::unique_ptr<bus::Reader<protocol::WorldEvent>> event_probe_;
};

}  // namespace marsala::monitor::test_support
