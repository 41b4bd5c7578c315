#include "marsala/agent/reactive/pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "marsala/core/error.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::reactive {
namespace {

// The target lies due north: a robot's distance to it is 100 - y for robots on the x = 0 line.
constexpr Position kTarget{0.0, 100.0};

const auto at = test::neighbour_at;

PipelineParams params() {
  PipelineParams p;
  p.separation_m = 2.0;
  p.back_off_margin_m = 0.5;
  p.return_detect_m = 1.5;
  return p;
}

TEST(Pipeline, AloneOrWithNeighboursBehindTheRobotIsActive) {
  PipelineTracker t(params());
  t.observe({}, kTarget);
  EXPECT_EQ(t.place({0.0, 50.0}, kTarget).role, PipelineRole::kActive);
  t.observe({at(2, 0.0, 48.0), at(3, 0.5, 49.0)}, kTarget);  // both farther from the target
  EXPECT_EQ(t.place({0.0, 50.0}, kTarget).role, PipelineRole::kActive);
  EXPECT_FALSE(t.front({0.0, 50.0}, kTarget).has_value());
}

TEST(Pipeline, RoleFollowsTheDistanceToTheFrontNeighbour) {
  const Position self{0.0, 50.0};
  const struct {
    double y;
    PipelineRole role;
  } cases[] = {
      {53.5, PipelineRole::kFollow},   // 3.5 m ahead: beyond the separation
      {52.01, PipelineRole::kFollow},  // just beyond 2 m
      {52.0, PipelineRole::kHold},     // exactly the separation: hold
      {51.5, PipelineRole::kHold},     // separation - margin: still hold
      {51.4, PipelineRole::kBackOff},  // nearer: step back
      {50.04, PipelineRole::kActive},  // level with the robot (within kAheadMarginM): not ahead
  };
  for (const auto& c : cases) {
    PipelineTracker t(params());
    t.observe({at(7, 0.0, c.y)}, kTarget);
    const PipelinePlace place = t.place(self, kTarget);
    EXPECT_EQ(place.role, c.role) << "neighbour at y = " << c.y << ": " << to_string(place.role);
    EXPECT_EQ(place.front.has_value(), c.role != PipelineRole::kActive);
  }
}

TEST(Pipeline, FrontIsTheNearestNeighbourAheadTiesToTheLowerId) {
  PipelineTracker t(params());
  t.observe({at(5, 1.0, 53.0), at(4, -1.0, 53.0), at(6, 0.0, 60.0), at(2, 0.0, 45.0)}, kTarget);
  const auto f = t.front({0.0, 50.0}, kTarget);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->agent_id, 4u);  // 4 and 5 are equally near; 6 is farther; 2 is behind
}

TEST(Pipeline, ANeighbourMovingAwayFromTheTargetIsReturningAfterTheDetectionDistance) {
  PipelineTracker t(params());
  const Position self{1.0, 50.0};  // the neighbour drives the x = 0 line, this robot beside it
  // The front robot builds at y = 55, then turns back towards the base (y decreasing) on the other lane.
  t.observe({at(3, 0.0, 55.0)}, kTarget);
  EXPECT_EQ(t.place(self, kTarget).role, PipelineRole::kFollow);
  t.observe({at(3, 0.0, 54.0)}, kTarget);  // 1 m back: a builder's short retreat, still the front
  EXPECT_FALSE(t.returning(3));
  EXPECT_EQ(t.place(self, kTarget).role, PipelineRole::kFollow);
  t.observe({at(3, 0.0, 53.5)}, kTarget);  // 1.5 m back: returning
  EXPECT_TRUE(t.returning(3));
  EXPECT_EQ(t.place(self, kTarget).role, PipelineRole::kActive);  // this robot is now the front of the pipeline
  t.observe({at(3, 0.0, 50.5)}, kTarget);                         // passing by on the backward lane: no back-off
  EXPECT_EQ(t.place(self, kTarget).role, PipelineRole::kActive);
  // Refilled, it comes again: approaching by the detection distance from its farthest point rejoins it.
  t.observe({at(3, 0.0, 40.0)}, kTarget);
  t.observe({at(3, 0.0, 41.0)}, kTarget);
  EXPECT_TRUE(t.returning(3));
  t.observe({at(3, 0.0, 41.5)}, kTarget);
  EXPECT_FALSE(t.returning(3));
  EXPECT_EQ(t.place(self, kTarget).role, PipelineRole::kActive);  // behind this robot now
}

TEST(Pipeline, ANeighbourOutOfRangeIsForgotten) {
  PipelineTracker t(params());
  t.observe({at(3, 0.0, 55.0)}, kTarget);
  t.observe({at(3, 0.0, 53.0)}, kTarget);  // 2 m back: returning
  ASSERT_TRUE(t.returning(3));
  t.observe({}, kTarget);  // out of proximity range
  EXPECT_FALSE(t.returning(3));
  t.observe({at(3, 0.0, 53.0)}, kTarget);  // seen again: starts fresh, ahead and not returning
  EXPECT_FALSE(t.returning(3));
  EXPECT_EQ(t.place({0.0, 50.0}, kTarget).role, PipelineRole::kFollow);
}

TEST(Pipeline, BadParametersAreRejected) {
  PipelineParams p = params();
  p.separation_m = 0.0;
  EXPECT_THROW(PipelineTracker{p}, InvalidArgument);
  p = params();
  p.back_off_margin_m = 2.0;  // not below the separation
  EXPECT_THROW(PipelineTracker{p}, InvalidArgument);
  p = params();
  p.return_detect_m = std::nan("");
  EXPECT_THROW(PipelineTracker{p}, InvalidArgument);
  EXPECT_EQ(to_string(PipelineRole::kBackOff), "back_off");
}

}  // namespace
}  // namespace marsala::agent::reactive
