#pragma once
// Which statuses and events the monitor believes. Anyone on the domain can publish a WorldStatus (without DDS
// Security): one forged "completed at step 999999" made `tail` print it and exit 0 while the run went on. The gate
// pins, per run id, the participant that first published that run's status (its world) and lets through only what
// that participant writes. A status of the run from another participant is believed only when it continues the run
// (its step not behind the last one) after the pinned world has been silent for kWorldSilence: a world restarted
// from its log (docs/runtime.md#resume) is a new participant. Events are believed from pinned worlds only.

#include <chrono>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::monitor {

class WorldGate {
 public:
  using Clock = std::chrono::steady_clock;
  /// How long a pinned world must be silent before another participant may continue its run.
  static constexpr std::chrono::seconds kWorldSilence{3};

  /// Ignored samples are reported on `err`, once per (run, participant).
  explicit WorldGate(std::ostream& err) : err_(err) {}

  /// The statuses of `batch` to believe, in their order.
  std::vector<protocol::WorldStatus> statuses(std::vector<bus::Received<protocol::WorldStatus>> batch,
                                              Clock::time_point now = Clock::now());
  /// The events of `batch` written by a pinned world, in their order; while no world is pinned they are held (the
  /// latest kMaxHeldEvents) and judged once a status pins one.
  std::vector<protocol::WorldEvent> events(std::vector<bus::Received<protocol::WorldEvent>> batch);
  /// Samples ignored so far [count].
  std::uint64_t ignored() const { return ignored_; }

 private:
  struct World {
    bus::WriterId writer;
    std::uint64_t last_step = 0;
    Clock::time_point last_heard;
  };
  void report(const std::string& what, const bus::WriterId& from, const std::string& why);

  std::ostream& err_;
  std::map<std::string, World> worlds_;  // by run id
  static constexpr std::size_t kMaxHeldEvents = 4096;
  std::vector<bus::Received<protocol::WorldEvent>> held_;
  std::set<std::string> reported_;
  std::uint64_t ignored_ = 0;
};

}  // namespace marsala::monitor
