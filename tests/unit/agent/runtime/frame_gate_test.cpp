// The frame gate without a bus: which frames an agent takes, repeats, calls stale or ignores
// (docs/runtime.md#lockstep).

#include "marsala/agent/runtime/frame_gate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace marsala::agent::runtime {
namespace {

bus::WriterId writer(std::uint8_t first) {
  bus::WriterId id;
  id.prefix[0] = first;
  return id;
}

Assignment ten_by_twenty() {
  Assignment a;
  a.world = {10, 20, 0.0, 0.0, 0.5};  // 10 m x 5 m
  a.tile_size = 16;
  return a;
}

protocol::SensorFrame frame(std::uint64_t step, std::uint32_t agent_id = 7) {
  protocol::SensorFrame f;
  f.agent_id = agent_id;
  f.step = step;
  f.x_m = 2.25;
  f.y_m = 1.25;
  return f;
}

FrameGate gate() { return FrameGate(7, ten_by_twenty(), SensorSpec{}, writer(1)); }

TEST(FrameGate, TakesOnlyTheAdmittingWorldsFramesForThisAgent) {
  const FrameGate g = gate();
  EXPECT_EQ(g.judge(frame(1), writer(1)).call, FrameCall::kDecide);
  const FrameJudgement stranger = g.judge(frame(1), writer(2));
  EXPECT_EQ(stranger.call, FrameCall::kIgnored);
  EXPECT_NE(stranger.problem.find("written by participant " + writer(2).to_string()), std::string::npos);
  EXPECT_NE(stranger.problem.find("(" + writer(1).to_string() + ")"), std::string::npos);
  const FrameJudgement other = g.judge(frame(1, 8), writer(1));
  EXPECT_EQ(other.call, FrameCall::kIgnored);
  EXPECT_EQ(other.problem, "addressed to agent 8");
}

TEST(FrameGate, AWorldResumedFromItsLogSpeaksFromItsNewParticipant) {
  FrameGate g = gate();
  g.set_world(writer(3));
  EXPECT_EQ(g.world(), writer(3));
  EXPECT_EQ(g.judge(frame(1), writer(3)).call, FrameCall::kDecide);
  EXPECT_EQ(g.judge(frame(1), writer(1)).call, FrameCall::kIgnored);
}

TEST(FrameGate, RepeatsEveryAnsweredStepItKeeps) {
  FrameGate g = gate();
  const auto request_of = [](std::uint64_t step) {
    protocol::ActionRequest request;
    request.agent_id = 7;
    request.step = step;
    request.move = true;
    request.target_x_m = 0.25 * static_cast<double>(step);
    return request;
  };
  for (std::uint64_t step = 3; step <= 5; ++step) g.answered(step, request_of(step));
  EXPECT_EQ(g.judge(frame(5), writer(1)).call, FrameCall::kRepeat);
  ASSERT_TRUE(g.request_for(5));
  EXPECT_EQ(g.request_for(5)->target_x_m, 1.25);
  // A late copy of an earlier frame from the same world: stale.
  EXPECT_EQ(g.judge(frame(4), writer(1)).call, FrameCall::kStale);
  // The world restarted and went back (a resume cut its log's tail): the requests of those steps again, never new
  // decisions.
  g.set_world(writer(2));
  EXPECT_EQ(g.judge(frame(4), writer(2)).call, FrameCall::kRepeat);
  ASSERT_TRUE(g.request_for(3));
  EXPECT_EQ(g.request_for(3)->target_x_m, 0.75);
  // A step before any kept is decided anew; so is the next step.
  EXPECT_EQ(g.judge(frame(2), writer(2)).call, FrameCall::kDecide);
  EXPECT_FALSE(g.request_for(2));
  EXPECT_EQ(g.judge(frame(6), writer(2)).call, FrameCall::kDecide);
  // The run-over frame ends the run whatever its step.
  protocol::SensorFrame over = frame(3);
  over.run_over = true;
  EXPECT_EQ(g.judge(over, writer(2)).call, FrameCall::kRunOver);
  // Deciding step 4 again forgets the requests of 4 and 5: they were never applied in this world's history.
  g.answered(4, request_of(40));
  EXPECT_EQ(g.request_for(4)->step, 40u);
  EXPECT_FALSE(g.request_for(5));
  EXPECT_EQ(g.judge(frame(5), writer(2)).call, FrameCall::kDecide);
  EXPECT_EQ(g.judge(frame(3), writer(2)).call, FrameCall::kStale);  // answered since by this world: a late copy
  EXPECT_EQ(g.request_for(3)->target_x_m, 0.75);
}

// docs/runtime.md#standing-answers: a standing request answered the steps whose frames the world held back, up to the
// next request; a world that went back to one of them gets it again for that step, never a new decision.
TEST(FrameGate, AStandingRequestIsRepeatedForTheStepsItStoodFor) {
  FrameGate g = gate();
  protocol::ActionRequest stands;
  stands.agent_id = 7;
  stands.step = 3;
  stands.state = "idle";
  stands.standing = true;
  g.answered(3, stands);
  protocol::ActionRequest moves;
  moves.agent_id = 7;
  moves.step = 9;
  moves.move = true;
  g.answered(9, moves);
  g.set_world(writer(2));
  for (std::uint64_t step = 4; step <= 8; ++step) {
    EXPECT_EQ(g.judge(frame(step), writer(2)).call, FrameCall::kRepeat) << step;
    const std::optional<protocol::ActionRequest> r = g.request_for(step);
    ASSERT_TRUE(r) << step;
    EXPECT_EQ(r->step, step);
    EXPECT_EQ(r->state, "idle");
    EXPECT_FALSE(r->move);
  }
  EXPECT_EQ(g.request_for(9)->step, 9u);
  EXPECT_TRUE(g.request_for(9)->move);
  EXPECT_EQ(g.judge(frame(10), writer(2)).call, FrameCall::kDecide);
  EXPECT_FALSE(g.request_for(10)) << "a new step is decided";
  // However far the world held its frames back after a standing request, the next frame is decided.
  EXPECT_EQ(g.judge(frame(9 + kMaxStepsAhead + 1), writer(2)).call, FrameCall::kIgnored) << "the last did not stand";
  stands.step = 10;
  g.answered(10, stands);
  EXPECT_EQ(g.judge(frame(10 + 5 * kMaxStepsAhead), writer(2)).call, FrameCall::kDecide);
  // A request that did not stand answered its own step only.
  FrameGate h = gate();
  stands.standing = false;
  h.answered(3, stands);
  h.answered(9, moves);
  h.set_world(writer(2));
  EXPECT_FALSE(h.request_for(5));
  EXPECT_EQ(h.judge(frame(5), writer(2)).call, FrameCall::kDecide);
}

TEST(FrameGate, KeepsTheLastRequestsOnly) {
  FrameGate g = gate();
  for (std::uint64_t step = 1; step <= kRequestHistory + 10; ++step) g.answered(step, {});
  EXPECT_FALSE(g.request_for(10));
  EXPECT_TRUE(g.request_for(11));  // the oldest of the kRequestHistory kept
  g.set_world(writer(2));
  EXPECT_EQ(g.judge(frame(10), writer(2)).call, FrameCall::kDecide);
  EXPECT_EQ(g.judge(frame(11), writer(2)).call, FrameCall::kRepeat);
}

TEST(FrameGate, AFrameAMillionStepsAheadIsNotTheWorlds) {
  FrameGate g = gate();
  // Before the first answer, any step is the first.
  EXPECT_EQ(g.judge(frame(5 + 2 * kMaxStepsAhead), writer(1)).call, FrameCall::kDecide);
  g.answered(5, {});
  EXPECT_EQ(g.judge(frame(5 + kMaxStepsAhead), writer(1)).call, FrameCall::kDecide);
  const FrameJudgement far = g.judge(frame(6 + kMaxStepsAhead), writer(1));
  EXPECT_EQ(far.call, FrameCall::kIgnored);
  EXPECT_EQ(far.problem, "step 1000006 is more than 1000000 steps ahead of the last one answered (5)");
}

TEST(FrameGate, IgnoresFramesThatDoNotDescribeTheWorld) {
  const FrameGate g = gate();
  protocol::SensorFrame off = frame(1);
  off.x_m = 10.5;  // east of the 10 m grid
  EXPECT_EQ(g.judge(off, writer(1)).problem, "pose (10.5, 1.25) m is not on the grid");
  protocol::SensorFrame material = frame(1);
  material.material_m3 = -1.0;
  EXPECT_EQ(g.judge(material, writer(1)).call, FrameCall::kIgnored);
  protocol::SensorFrame scan = frame(1);
  scan.scanned = true;
  EXPECT_EQ(g.judge(scan, writer(1)).problem, "a scan for a robot whose sensor is 'ground_truth'");
  protocol::SensorFrame points = frame(1);
  points.points.push_back({0.0f, 0.0f, 0.0f});
  EXPECT_EQ(g.judge(points, writer(1)).problem, "1 scan points in a frame without a scan");
  protocol::SensorFrame neighbour = frame(1);
  neighbour.neighbours.push_back({3, {std::nan(""), 1.0}, 0.0, 0.5});
  EXPECT_EQ(g.judge(neighbour, writer(1)).call, FrameCall::kIgnored);
  protocol::SensorFrame wide = frame(1);
  wide.neighbours.push_back({3, {1.0, 1.0}, 0.0, 2e3});
  EXPECT_EQ(g.judge(wide, writer(1)).problem, "neighbour 3 has a body radius of 2000 m, not in [0, 1000] m");
  protocol::SensorFrame tile = frame(1);
  tile.tiles.push_back({0, 0, 10, 16, std::vector<double>(160, 0.0)});
  EXPECT_EQ(g.judge(tile, writer(1)).call, FrameCall::kDecide);
  tile.tiles.back().heights.pop_back();
  EXPECT_EQ(g.judge(tile, writer(1)).call, FrameCall::kIgnored);
}

}  // namespace
}  // namespace marsala::agent::runtime
