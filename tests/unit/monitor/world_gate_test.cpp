#include "marsala/monitor/world_gate.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "marsala/protocol/world_proof.hpp"

namespace marsala::monitor {
namespace {

bus::WriterId participant(std::uint8_t n) {
  bus::WriterId id;
  id.prefix[0] = 1;
  id.prefix[11] = n;
  return id;
}

/// A status of `run` at `step` written by `from`, proven with `key` for `signer` (a forger copies a proof made for
/// another participant by giving signer != from).
bus::Received<protocol::WorldStatus> status(const std::string& run, std::uint64_t step, bus::WriterId from,
                                            const protocol::RunKey& key, bus::WriterId signer, bool completed = false) {
  protocol::WorldStatus s;
  s.run_id = run;
  s.step = step;
  s.completed = completed;
  s.world_key = protocol::world_key_of(key);
  s.world_proof = protocol::prove_world(key, run, signer.prefix);
  return {s, from};
}

std::vector<std::uint64_t> steps(const std::vector<protocol::WorldStatus>& statuses) {
  std::vector<std::uint64_t> out;
  for (const auto& s : statuses) out.push_back(s.step);
  return out;
}

TEST(WorldGate, AForgedStatusOfARunIsNeverBelieved) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), forger = participant(2);
  const protocol::RunKey key = protocol::make_run_key(), own = protocol::make_run_key();
  EXPECT_EQ(steps(gate.statuses({status("r", 10, world, key, world), status("r", 11, world, key, world)})),
            (std::vector<std::uint64_t>{10, 11}));
  // "completed at step 999999" from another participant: with the world's proof copied (made for the world's
  // participant), with a key of its own, or with none: never believed, even after the world fell silent.
  auto unsigned_status = status("r", 999999, forger, key, forger, true);
  unsigned_status.sample.world_proof.clear();
  EXPECT_EQ(steps(gate.statuses({status("r", 999999, forger, key, world, true), status("r", 12, world, key, world),
                                 status("r", 999999, forger, own, forger, true), unsigned_status})),
            (std::vector<std::uint64_t>{12}));
  EXPECT_EQ(gate.ignored(), 3u);
  EXPECT_NE(err.str().find("ignoring statuses from participant " + forger.to_string() +
                           ": another world/publisher of run 'r'"),
            std::string::npos)
      << err.str();
  // Reported once per participant, counted every time.
  EXPECT_EQ(err.str().find("ignoring", err.str().find("ignoring") + 1), std::string::npos) << err.str();
  // Another run is another world: its first proven publisher is pinned for it.
  EXPECT_EQ(steps(gate.statuses({status("other", 5, forger, own, forger)})), (std::vector<std::uint64_t>{5}));
}

TEST(WorldGate, AResumedWorldProvingTheRunKeyContinuesTheRun) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), resumed = participant(3);
  const protocol::RunKey key = protocol::make_run_key();
  gate.statuses({status("r", 40, world, key, world)});
  // A status that goes back is refused; one that continues the run is believed, at once.
  EXPECT_TRUE(gate.statuses({status("r", 39, resumed, key, resumed)}).empty());
  EXPECT_EQ(steps(gate.statuses({status("r", 40, resumed, key, resumed)})), (std::vector<std::uint64_t>{40}));
  EXPECT_NE(err.str().find("continues from participant " + resumed.to_string()), std::string::npos) << err.str();
  // The old world's late statuses, behind the resumed one: not believed.
  EXPECT_TRUE(gate.statuses({status("r", 38, world, key, world)}).empty());
}

TEST(WorldGate, GivenTheRunKeyAStrangerPublishingFirstIsNeverPinned) {
  std::ostringstream err;
  const protocol::RunKey key = protocol::make_run_key(), own = protocol::make_run_key();
  WorldGate gate(err, protocol::world_key_of(key));
  const bus::WriterId world = participant(1), forger = participant(2);
  EXPECT_TRUE(gate.statuses({status("r", 999999, forger, own, forger, true)}).empty());
  EXPECT_EQ(steps(gate.statuses({status("r", 1, world, key, world)})), (std::vector<std::uint64_t>{1}));
  EXPECT_NE(err.str().find("not the run's key"), std::string::npos) << err.str();
  EXPECT_EQ(gate.ignored(), 1u);
}

TEST(WorldGate, EventsArePassedFromAPinnedWorldOnlyAndHeldUntilOneIs) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), forger = participant(2);
  protocol::WorldEvent e;
  e.step = 3;
  EXPECT_TRUE(gate.events({{e, world}, {e, forger}}).empty());  // held: no world known yet
  gate.statuses({status("r", 3, world, protocol::make_run_key(), world)});
  e.step = 4;
  const auto passed = gate.events({{e, world}});
  ASSERT_EQ(passed.size(), 2u);  // the held one of the world, then this one; the forger's dropped
  EXPECT_EQ(passed[0].step, 3u);
  EXPECT_EQ(passed[1].step, 4u);
  EXPECT_EQ(gate.ignored(), 1u);
}

}  // namespace
}  // namespace marsala::monitor
