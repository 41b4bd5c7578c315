#include "marsala/agent/reactive/waiting_for.hpp"

#include <gtest/gtest.h>

namespace marsala::agent::reactive {
namespace {

Neighbour neighbour(std::uint32_t id, double x, double y, double radius_m = 0.5) {
  Neighbour n;
  n.agent_id = id;
  n.position = {x, y};
  n.radius_m = radius_m;
  return n;
}

TEST(WaitingFor, RobotsCloseByAreThoseWithinTheGapNearestFirst) {
  // Robot at (0, 0), radius 0.5 m, gap 1 m: a neighbour of radius 0.5 counts up to 2 m between centres.
  const std::vector<Neighbour> around{neighbour(5, 1.9, 0.0), neighbour(3, 0.0, -1.2), neighbour(9, 2.1, 0.0)};
  EXPECT_EQ(robots_close_by(around, {0.0, 0.0}, 0.5, 1.0), "3 at 1.2 m, 5 at 1.9 m");
  EXPECT_EQ(robots_close_by(around, {0.0, 0.0}, 0.5, 0.1), "");
  EXPECT_EQ(robots_close_by({}, {0.0, 0.0}, 0.5, 1.0), "");
}

TEST(WaitingFor, FrontNeighbourSaysWhoAndHowFar) {
  EXPECT_EQ(front_neighbour_text(neighbour(7, 1.2, 0.8), {0.0, 0.0}, "hold"), "front neighbour 7 at 1.4 m (hold)");
}

TEST(WaitingFor, AReturnThatAsksForNothingSaysWhatItLacked) {
  BuildTrace trace;
  protocol::ActionRequest idle;
  EXPECT_EQ(return_waiting_text(trace, idle, "", 0, 20.0), "no way towards the base in the known map");
  trace.planned = true;
  EXPECT_EQ(return_waiting_text(trace, idle, "3 at 1.2 m", 0, 20.0),
            "no route towards the base through known cells: robots 3 at 1.2 m close by");
  trace.plan.found = true;
  EXPECT_EQ(return_waiting_text(trace, idle, "", 0, 20.0), "no step towards the base");
  protocol::ActionRequest moving;
  moving.move = true;
  EXPECT_EQ(return_waiting_text(trace, moving, "3 at 1.2 m", kReturnPatienceFrames - 1, 20.0), "");
  EXPECT_EQ(return_waiting_text(trace, moving, "3 at 1.2 m", kReturnPatienceFrames, 19.84),
            "no nearer the base (19.8 m) for 40 steps: robots 3 at 1.2 m close by");
  EXPECT_EQ(build_waiting_text(""), "no deposition path through known cells");
}

TEST(WaitingFor, ReturnProgressCountsFramesWithoutGettingNearer) {
  ReturnProgress p;
  EXPECT_EQ(p.observe(20.0), 0);
  EXPECT_EQ(p.observe(20.2), 1);   // farther
  EXPECT_EQ(p.observe(19.97), 2);  // nearer by less than kMinGainM
  EXPECT_EQ(p.observe(20.0), 3);
  EXPECT_EQ(p.observe(19.9), 0);  // nearer: a new best
  EXPECT_EQ(p.observe(19.9), 1);
  p.reset();
  EXPECT_EQ(p.observe(30.0), 0);
}

}  // namespace
}  // namespace marsala::agent::reactive
