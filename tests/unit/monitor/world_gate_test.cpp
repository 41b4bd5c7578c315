#include "marsala/monitor/world_gate.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace marsala::monitor {
namespace {

using namespace std::chrono_literals;

bus::WriterId participant(std::uint8_t n) {
  bus::WriterId id;
  id.prefix[0] = 1;
  id.prefix[11] = n;
  return id;
}

bus::Received<protocol::WorldStatus> status(const std::string& run, std::uint64_t step, bus::WriterId from,
                                            bool completed = false) {
  protocol::WorldStatus s;
  s.run_id = run;
  s.step = step;
  s.completed = completed;
  return {s, from};
}

std::vector<std::uint64_t> steps(const std::vector<protocol::WorldStatus>& statuses) {
  std::vector<std::uint64_t> out;
  for (const auto& s : statuses) out.push_back(s.step);
  return out;
}

TEST(WorldGate, AForgedStatusOfALiveRunIsIgnored) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), forger = participant(2);
  const auto t0 = WorldGate::Clock::now();
  EXPECT_EQ(steps(gate.statuses({status("r", 10, world), status("r", 11, world)}, t0)),
            (std::vector<std::uint64_t>{10, 11}));
  // "completed at step 999999" from another participant while the world speaks: not believed.
  EXPECT_EQ(steps(gate.statuses({status("r", 999999, forger, true), status("r", 12, world)}, t0 + 1s)),
            (std::vector<std::uint64_t>{12}));
  EXPECT_EQ(gate.ignored(), 1u);
  EXPECT_NE(err.str().find("ignoring statuses from participant " + forger.to_string()), std::string::npos)
      << err.str();
  // Reported once per participant, counted every time.
  gate.statuses({status("r", 999999, forger, true)}, t0 + 2s);
  EXPECT_EQ(gate.ignored(), 2u);
  EXPECT_EQ(err.str().find("ignoring", err.str().find("ignoring") + 1), std::string::npos);
  // Another run is another world: its first publisher is pinned for it.
  EXPECT_EQ(steps(gate.statuses({status("other", 5, forger)}, t0 + 2s)), (std::vector<std::uint64_t>{5}));
}

TEST(WorldGate, ARestartedWorldContinuesTheRunAfterSilence) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), resumed = participant(3);
  const auto t0 = WorldGate::Clock::now();
  gate.statuses({status("r", 40, world)}, t0);
  // Too soon: the pinned world was heard 1 s ago.
  EXPECT_TRUE(gate.statuses({status("r", 41, resumed)}, t0 + 1s).empty());
  // After kWorldSilence, a status that goes back is still refused; one that continues the run is believed.
  EXPECT_TRUE(gate.statuses({status("r", 39, resumed)}, t0 + WorldGate::kWorldSilence).empty());
  EXPECT_EQ(steps(gate.statuses({status("r", 40, resumed)}, t0 + WorldGate::kWorldSilence)),
            (std::vector<std::uint64_t>{40}));
  EXPECT_NE(err.str().find("continues from participant " + resumed.to_string()), std::string::npos) << err.str();
  // The old world is now the stranger.
  EXPECT_TRUE(gate.statuses({status("r", 41, world)}, t0 + WorldGate::kWorldSilence + 1s).empty());
}

TEST(WorldGate, EventsArePassedFromAPinnedWorldOnlyAndHeldUntilOneIs) {
  std::ostringstream err;
  WorldGate gate(err);
  const bus::WriterId world = participant(1), forger = participant(2);
  protocol::WorldEvent e;
  e.step = 3;
  EXPECT_TRUE(gate.events({{e, world}, {e, forger}}).empty());  // held: no world known yet
  gate.statuses({status("r", 3, world)});
  e.step = 4;
  const auto passed = gate.events({{e, world}});
  ASSERT_EQ(passed.size(), 2u);  // the held one of the world, then this one; the forger's dropped
  EXPECT_EQ(passed[0].step, 3u);
  EXPECT_EQ(passed[1].step, 4u);
  EXPECT_EQ(gate.ignored(), 1u);
}

}  // namespace
}  // namespace marsala::monitor
