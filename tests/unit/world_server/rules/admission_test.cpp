#include "marsala/world_server/rules/admission.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::flat_terrain;
using testing::hello_for;
using testing::small_scenario;

class AdmissionTest : public ::testing::Test {
 protected:
  AdmissionTest() : state_(make_world_state(small_scenario(), flat_terrain(), 2)) {}
  void expect_refused(const protocol::AgentHello& h, const std::string& words, bool started = false) {
    const AdmissionDecision d = decide_admission(state_, h, started);
    EXPECT_FALSE(d.accepted) << "expected a refusal mentioning '" << words << "'";
    EXPECT_NE(d.reason.find(words), std::string::npos) << d.reason;
  }
  WorldState state_;
};

TEST_F(AdmissionTest, AdmitsAMatchingHelloAndPlacesTheAgentAtItsStart) {
  const protocol::AgentHello h = hello_for(state_, 2, 77);
  ASSERT_TRUE(decide_admission(state_, h, false).accepted);
  EXPECT_TRUE(admit(state_, h));
  const AgentRecord& a = state_.agent(2);
  EXPECT_TRUE(a.admitted);
  EXPECT_TRUE(a.alive);
  EXPECT_EQ(a.session, 77u);
  EXPECT_EQ(a.name, "tester-2");
  EXPECT_EQ(a.position.x, 2.55);
  EXPECT_EQ(a.position.y, 1.05);
  EXPECT_EQ(a.material_m3, 0.05);
  EXPECT_EQ(state_.live_ids(), std::vector<std::uint32_t>{2});
  // A repeated hello of the same session is answered yes again and changes nothing.
  EXPECT_TRUE(decide_admission(state_, h, true).accepted);
  EXPECT_FALSE(admit(state_, h));

  const protocol::Admission m = admission_message(state_, h, {true, ""}, "small-d4");
  EXPECT_EQ(m.agent_id, 2u);
  EXPECT_EQ(m.session, 77u);
  EXPECT_TRUE(m.accepted);
  EXPECT_EQ(m.run_id, "small-d4");
  EXPECT_EQ(m.assignment.world.rows, 40);
  EXPECT_EQ(m.assignment.world.cols, 40);
  EXPECT_EQ(m.assignment.world.cell_size_m, 0.1);
  EXPECT_EQ(m.assignment.tile_size, 16);
  EXPECT_EQ(m.assignment.start.x, 2.55);
  EXPECT_EQ(m.assignment.target.x, 3.05);
  EXPECT_EQ(m.assignment.target.y, 2.05);
  EXPECT_EQ(m.assignment.base.x, 0.55);
  EXPECT_EQ(m.assignment.base_radius_m, 0.5);
}

TEST_F(AdmissionTest, Refusals) {
  protocol::AgentHello h = hello_for(state_, 1, 5);
  h.agent_id = 3;  // slot 3 exists in the scenario, but this run has two agents
  expect_refused(h, "unknown agent id 3");
  h.agent_id = 1000;
  expect_refused(h, "unknown agent id 1000");

  h = hello_for(state_, 1, 5);
  h.body.navigability.kappa = 0.31;
  expect_refused(h, "body differs from robot type 'tester'");
  expect_refused(h, "kappa 0.31");
  h = hello_for(state_, 1, 5);
  h.body.cube_size_m = 0.1;
  expect_refused(h, "cube_size_m");
  h = hello_for(state_, 1, 5);
  h.body.reach_m = std::numeric_limits<double>::quiet_NaN();
  expect_refused(h, "invalid body: reach_m");
  h = hello_for(state_, 1, 5);
  h.body.max_step_m = 1e9;
  expect_refused(h, "invalid body: max_step_m");

  // Admitted with one session: another session of the same id is refused while the first is connected, and takes
  // the slot over when it is not (a restarted process).
  ASSERT_TRUE(admit(state_, hello_for(state_, 1, 5)));
  expect_refused(hello_for(state_, 1, 6), "already admitted with another session that is still connected");
  EXPECT_EQ(decide_admission(state_, hello_for(state_, 1, 6), true, false).kind, AdmissionKind::kTakeover);
  // Not admitted before the start: refused once the run has started.
  expect_refused(hello_for(state_, 2, 9), "already started", true);
  // A dropped agent takes its slot back kMaxReadmissions times, then stays out.
  for (std::uint32_t i = 0; i < kMaxReadmissions; ++i) {
    drop_agent(state_, 1, "lost");
    const protocol::AgentHello back = hello_for(state_, 1, 70 + i);
    const AdmissionDecision again = decide_admission(state_, back, true);
    ASSERT_TRUE(again.accepted) << i;
    ASSERT_EQ(again.kind, AdmissionKind::kReadmission);
    EXPECT_TRUE(admit(state_, back, again.kind));
    EXPECT_EQ(state_.agent(1).readmissions, i + 1);
  }
  drop_agent(state_, 1, "lost");
  expect_refused(hello_for(state_, 1, 99), "lost; it has taken its slot back 3 times, the most a run allows", true);
  const protocol::Admission m = admission_message(state_, hello_for(state_, 1, 5), {false, "no"}, "r");
  EXPECT_FALSE(m.accepted);
  EXPECT_EQ(m.reason, "no");
}

// Re-admission keeps what the world knows of the robot (pose, material, counts) and clears its misses.
TEST_F(AdmissionTest, ReadmissionKeepsTheWorldsRecordOfTheRobot) {
  ASSERT_TRUE(admit(state_, hello_for(state_, 1, 5)));
  AgentRecord& a = state_.agent(1);
  a.position.x += 1.0;
  a.material_m3 = 0.25;
  a.accepted = 12;
  a.consecutive_missed = 2;
  a.recent_misses = 0x5;
  const double x = a.position.x;
  drop_agent(state_, 1, "request writer lost liveliness");
  const protocol::AgentHello back = hello_for(state_, 1, 6);
  const AdmissionDecision d = decide_admission(state_, back, true);
  ASSERT_EQ(d.kind, AdmissionKind::kReadmission);
  EXPECT_TRUE(admit(state_, back, d.kind));
  EXPECT_TRUE(a.alive);
  EXPECT_FALSE(a.dropped);
  EXPECT_EQ(a.drop_reason, "");
  EXPECT_EQ(a.session, 6u);
  EXPECT_EQ(a.position.x, x);
  EXPECT_EQ(a.material_m3, 0.25);
  EXPECT_EQ(a.accepted, 12u);
  EXPECT_EQ(a.consecutive_missed, 0u);
  EXPECT_EQ(a.recent_misses, 0u);
  // The re-admitted session repeats its hello: nothing changes.
  EXPECT_EQ(decide_admission(state_, back, true).kind, AdmissionKind::kRepeat);
  EXPECT_FALSE(admit(state_, back, AdmissionKind::kRepeat));
}

// --id auto: the lowest never-admitted slot of the hello's type; the same slot again for a repeated hello of the
// session; refusals when the run started, the body fits no slot, or every such slot is taken.
TEST_F(AdmissionTest, AnySlotTakesTheLowestFreeSlotOfItsType) {
  protocol::AgentHello any = hello_for(state_, 1, 500);
  any.agent_id = kAnySlot;
  const AdmissionDecision first = decide_admission(state_, any, false);
  ASSERT_TRUE(first.accepted) << first.reason;
  EXPECT_EQ(first.kind, AdmissionKind::kFirst);
  EXPECT_EQ(first.agent_id, 1u);
  protocol::AgentHello slot = any;
  slot.agent_id = first.agent_id;
  ASSERT_TRUE(admit(state_, slot, first.kind));
  EXPECT_EQ(admission_message(state_, any, first, "r").agent_id, 1u);  // the answer names the slot
  // The world records it under the slot's id and the name a fixed-id agent of that slot gives.
  any.name = "tester-any";
  const protocol::AgentHello as_slot = slot_hello(state_, any, first);
  EXPECT_EQ(as_slot.agent_id, 1u);
  EXPECT_EQ(as_slot.name, "tester-1");
  EXPECT_EQ(as_slot.session, 500u);
  EXPECT_EQ(slot_hello(state_, hello_for(state_, 2, 9), {true, {}, AdmissionKind::kFirst, 2}).name, "tester-2");

  const AdmissionDecision again = decide_admission(state_, any, false);
  EXPECT_EQ(again.kind, AdmissionKind::kRepeat);
  EXPECT_EQ(again.agent_id, 1u);

  protocol::AgentHello other = any;
  other.session = 501;
  const AdmissionDecision second = decide_admission(state_, other, false);
  ASSERT_TRUE(second.accepted);
  EXPECT_EQ(second.agent_id, 2u);
  slot = other;
  slot.agent_id = 2;
  admit(state_, slot, second.kind);

  other.session = 502;
  expect_refused(other, "any slot: all 2 slots of this robot type are taken");
  EXPECT_NE(decide_admission(state_, other, true).reason.find("already started"), std::string::npos);
  other.body.navigability.kappa = 0.31;
  expect_refused(other, "no slot of this run has a robot type with this body");
  other = any;
  other.session = 503;
  other.behaviour = "idle";  // the body of the slots' type, another behaviour: no slot of that type
  expect_refused(other, "no slot of this run has a robot type with this body and behaviour 'idle'");
}

// Two "any slot" hellos decided in one round take different slots, and the repeated hello of each keeps its own.
TEST_F(AdmissionTest, TwoAnySlotHellosTakeDifferentSlotsAndKeepThem) {
  std::vector<std::uint32_t> taken;
  for (std::uint64_t session : {600u, 601u}) {
    protocol::AgentHello any = hello_for(state_, 1, session);
    any.agent_id = kAnySlot;
    const AdmissionDecision d = decide_admission(state_, any, false);
    ASSERT_TRUE(d.accepted) << d.reason;
    ASSERT_TRUE(admit(state_, slot_hello(state_, any, d), d.kind));
    taken.push_back(d.agent_id);
  }
  EXPECT_EQ(taken, (std::vector<std::uint32_t>{1, 2}));
  for (std::size_t i = 0; i < 2; ++i) {
    protocol::AgentHello again = hello_for(state_, 1, 600 + i);
    again.agent_id = kAnySlot;
    const AdmissionDecision d = decide_admission(state_, again, true);  // also after the start: idempotent
    EXPECT_TRUE(d.accepted);
    EXPECT_EQ(d.kind, AdmissionKind::kRepeat);
    EXPECT_EQ(d.agent_id, taken[i]);
    EXPECT_EQ(admission_message(state_, again, d, "r").agent_id, taken[i]);
  }
  EXPECT_EQ(state_.agent(2).name, "tester-2");
}

}  // namespace
}  // namespace marsala::world_server
