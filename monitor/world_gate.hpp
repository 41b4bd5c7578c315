#pragma once
// Which statuses and events the monitor believes. Anyone on the domain can publish a WorldStatus (without DDS
// Security): one forged "completed at step 999999" made `tail` print it and exit 0 while the run went on. A world
// proves itself in every status: the run key's public half and its signature of (run, its participant)
// (protocol/world_proof.hpp), which no other participant can reuse. The gate believes only proven statuses; it
// pins, per run id, the first world that proves itself and its key, and lets through what that participant writes.
// Another participant proving the same key is the run's world resumed from its log (docs/runtime.md#resume), a new
// participant: believed when it continues the run (its step not behind the last one). Anything else is another
// world/publisher, never believed. Events are believed from pinned worlds only. Given the run's key (the environment
// variable MARSALA_RUN_KEY names its file, the world's OUT/run.key), the gate believes only worlds proving that key,
// also before the first status: a stranger cannot be pinned by publishing first.

#include <map>
#include <ostream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::monitor {

class WorldGate {
 public:
  /// Ignored samples are reported on `err`, once per (what, participant). `world_key`: the run's public key (hex,
  /// protocol::world_key_of()); empty: the first world that proves itself is pinned for its run.
  explicit WorldGate(std::ostream& err, std::string world_key = world_key_from_environment())
      : err_(err), world_key_(std::move(world_key)) {}

  /// The public key of the run key in the file MARSALA_RUN_KEY names; empty when it is not set. Throws
  /// InvalidArgument naming the variable and file when that file is no run key.
  static std::string world_key_from_environment();

  /// The statuses of `batch` to believe, in their order.
  std::vector<protocol::WorldStatus> statuses(std::vector<bus::Received<protocol::WorldStatus>> batch);
  /// The events of `batch` written by a pinned world, in their order; while no world is pinned they are held (the
  /// latest kMaxHeldEvents) and judged once a status pins one.
  std::vector<protocol::WorldEvent> events(std::vector<bus::Received<protocol::WorldEvent>> batch);
  /// Samples ignored so far [count].
  std::uint64_t ignored() const { return ignored_; }

 private:
  struct World {
    bus::WriterId writer;
    std::string key;  // the run key's public half it proved
    std::uint64_t last_step = 0;
  };
  /// True when `s` carries a proof of its run's world for participant `from` (checked once per participant and key).
  bool proven(const protocol::WorldStatus& s, const bus::WriterId& from);
  void report(const std::string& what, const bus::WriterId& from, const std::string& why);

  std::ostream& err_;
  std::string world_key_;                // the run's public key, when known beforehand
  std::map<std::string, World> worlds_;  // by run id
  std::set<std::string> proofs_;         // (participant, run, key, proof) already checked and found to hold
  static constexpr std::size_t kMaxProofs = 4096;
  static constexpr std::size_t kMaxHeldEvents = 4096;
  std::vector<bus::Received<protocol::WorldEvent>> held_;
  std::set<std::string> reported_;
  std::uint64_t ignored_ = 0;
};

}  // namespace marsala::monitor
