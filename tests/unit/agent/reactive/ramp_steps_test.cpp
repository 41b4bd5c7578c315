// The ramp builder's steps (agent/reactive/ramp_steps.hpp), called directly, as both behaviours call them: what
// each step requests and which building phase it reports, on a flat 6 x 10 m world with a platform.

#include "marsala/agent/reactive/ramp_steps.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/core/sensor_spec.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::reactive {
namespace {

// The noise margin of a scanned map's depositions: kScanGapMargin spreads of the height error a hit gives on the
// steepest surface the robot builds. Against a direct simulation: the sensor at its mount height above the hit's
// level, each range drawn with the sensor's noise, the hit's height against the height of a slope kappa through the
// true hit where the noisy hit lands, on either side (rising away from the sensor or towards it); the larger spread
// of that error, times kScanGapMargin.
TEST(ScanGapMargin, IsThreeSpreadsOfTheHeightErrorOfAHitOnTheSteepestSurface) {
  std::mt19937_64 rng(7);
  for (const SensorKind kind : {SensorKind::kRgbd, SensorKind::kLaser})
    for (const double distance_m : {1.0, 2.5})
      for (const double kappa : {0.0, 0.3, 0.5}) {
        const SensorSpec sensor = sensor_defaults(kind);
        const double h = sensor.mount_height_m, r = std::hypot(distance_m, h);
        const double ux = distance_m / r, uz = -h / r;
        std::normal_distribution<double> noise(0.0, sensor.noise_sd_at(r));
        double worst = 0.0;
        for (const double rises : {1.0, -1.0}) {  // the slope rising away from the sensor, then towards it
          double sum2 = 0.0;
          const int n = 100000;
          for (int i = 0; i < n; ++i) {
            const double range = r + noise(rng);
            const double x = ux * range, z = h + uz * range;  // the hit; the true one at (distance_m, 0)
            const double error = z - rises * kappa * (x - distance_m);
            sum2 += error * error;
          }
          worst = std::max(worst, std::sqrt(sum2 / n));
        }
        const double simulated = kScanGapMargin * worst;
        EXPECT_NEAR(scan_gap_margin_m(sensor, distance_m, kappa), simulated, 0.02 * simulated)
            << to_string(kind) << " " << distance_m << " m, kappa " << kappa;
      }
  SensorSpec exact = sensor_defaults(SensorKind::kRgbd);
  exact.noise_sd_m = exact.noise_sd_per_m2 = 0.0;
  EXPECT_EQ(scan_gap_margin_m(exact, 2.5, 0.3), 0.0);
  // Derived by hand: the camera at 2.5 m, r = hypot(2.5, 0.5) = 2.5495 m, sd = 0.002 + 0.002 r^2 = 0.0150 m,
  // 3 sd (0.5 / r + 0.3 x 2.5 / r) = 0.02206 m; the laser (sd 0.01 m) 0.01471 m.
  EXPECT_NEAR(scan_gap_margin_m(sensor_defaults(SensorKind::kRgbd), 2.5, 0.3), 0.02206, 1e-5);
  EXPECT_NEAR(scan_gap_margin_m(sensor_defaults(SensorKind::kLaser), 2.5, 0.3), 0.01471, 1e-5);
  EXPECT_THROW(scan_gap_margin_m(exact, -1.0, 0.3), InvalidArgument);
  EXPECT_THROW(scan_gap_margin_m(exact, 1.0, std::nan("")), InvalidArgument);
}

constexpr Position kTarget{8.0, 3.05};
constexpr Position kBase{0.55, 3.05};

/// Steps of agent 3 with `body`, admitted with the target on the platform and the base at the west end.
std::unique_ptr<RampSteps> admitted_steps(const RobotBody& body = test::husky()) {
  const AgentContext c = test::agent_context(3, body);
  auto steps = std::make_unique<RampSteps>(c);
  steps->admit(test::admission_on(c, test::platform_world().geometry(), kTarget, kBase));
  return steps;
}

protocol::SensorFrame frame(const RampSteps& steps, std::uint64_t step, Position pose, double material_m3 = 1.0) {
  return test::full_frame(steps.context(), step, pose, material_m3, test::platform_world());
}

protocol::ActionRequest empty(const RampSteps& steps, const protocol::SensorFrame& f) {
  return empty_request(steps.context(), f, "");
}

/// One return_step() of `steps` at `pose` with no material left: whether it refilled, its request and its trace.
struct Returned {
  bool refilled = false;
  protocol::ActionRequest request;
  BuildTrace trace;
};
Returned return_once(RampSteps& steps, std::uint64_t step, Position pose) {
  Returned out;
  const protocol::SensorFrame f = frame(steps, step, pose, 0.0);
  const BuildView view = steps.look(f, out.trace);
  out.request = empty(steps, f);
  out.refilled = steps.return_step(view.local, f, out.trace, out.request);
  return out;
}

TEST(BuildPhase, Names) {
  EXPECT_EQ(to_string(BuildPhase::kAdvance), "advance");
  EXPECT_EQ(to_string(BuildPhase::kBuild), "build");
  EXPECT_EQ(to_string(BuildPhase::kRetreat), "retreat");
}

TEST(RampSteps, RefusesAnInvalidBodyConstructionOrGoalSynthesizerAndHasNoMapBeforeAdmission) {
  RobotBody bad = test::husky();
  bad.navigability.kappa = -1.0;
  EXPECT_THROW(RampSteps(test::agent_context(3, bad)), InvalidArgument);
  AgentContext c = test::agent_context(3, test::husky());
  c.type.construction = NavigabilityParams{c.type.body.navigability.kappa, 0.0, c.type.body.navigability.eps_m};
  EXPECT_THROW(RampSteps{c}, InvalidArgument);
  c = test::agent_context(3, test::husky());
  c.type.goal_synthesizer = "anywhere";
  EXPECT_THROW(RampSteps{c}, InvalidArgument);
  c = test::agent_context(3, test::husky());
  RampSteps steps(c);
  EXPECT_FALSE(steps.admitted());
  EXPECT_THROW(steps.map(), InvalidArgument);
  protocol::Admission other = test::admission_on(c, test::platform_world().geometry(), kTarget, kBase);
  other.session = 1;
  EXPECT_THROW(steps.admit(other), InvalidArgument);
  EXPECT_FALSE(steps.admitted());
  steps.admit(test::admission_on(c, test::platform_world().geometry(), kTarget, kBase));
  EXPECT_TRUE(steps.admitted());
  EXPECT_EQ(steps.context().assignment.target.x, kTarget.x);
  EXPECT_EQ(steps.map().known_cells(), 0);
}

TEST(RampSteps, LookBuildsTheLocalMapTowardsTheTarget) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  const BuildView view = steps.look(frame(steps, 0, {5.05, 3.05}), trace);
  EXPECT_EQ(view.robot.x, 5.05);
  EXPECT_EQ(view.target.x, kTarget.x);
  EXPECT_EQ(view.target.y, kTarget.y);
  EXPECT_EQ(steps.map().known_cells(), 6000);
  EXPECT_EQ(trace.window_offset, view.local.offset);
  EXPECT_EQ(trace.local_goal, view.local.goal);
  EXPECT_GT(trace.navigable_cells, 0);
  EXPECT_FALSE(trace.planned);
}

TEST(RampSteps, BuildStepAdvancesAlongThePathOnFlatGround) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  const protocol::SensorFrame f = frame(steps, 0, {1.05, 3.05});
  const BuildView view = steps.look(f, trace);
  protocol::ActionRequest q = empty(steps, f);
  EXPECT_EQ(steps.build_step(view.local, f, trace, q), BuildPhase::kAdvance);
  EXPECT_TRUE(trace.planned);
  EXPECT_TRUE(trace.plan.found);
  ASSERT_TRUE(q.move);
  ASSERT_TRUE(trace.motion.has_value());
  EXPECT_NEAR(q.target_x_m, 1.25, 1e-12);
  EXPECT_EQ(trace.motion->target.x, q.target_x_m);
  EXPECT_TRUE(q.depositions.empty());
}

/// The world cell of the motion the steps request at their first frame, at (1.05, 3.05) on the platform world (an
/// advance); the view of that frame in `view`.
CellIndex first_motion_cell(RampSteps& steps, BuildView& view) {
  BuildTrace trace;
  const protocol::SensorFrame f0 = frame(steps, 0, {1.05, 3.05});
  view = steps.look(f0, trace);
  protocol::ActionRequest q = empty(steps, f0);
  EXPECT_EQ(steps.build_step(view.local, f0, trace, q), BuildPhase::kAdvance);
  EXPECT_TRUE(q.move);
  return *steps.map().geometry().cell_at({q.target_x_m, q.target_y_m});
}

// docs/runtime.md#refused-requests: a motion the world refused as not occupiable is information. The robot (still
// where it was, its map unchanged) never asks for that cell again, however many steps pass; once its map reads the
// cell's ball differently (another robot built there), it may.
TEST(RampSteps, ACellTheWorldRefusedIsNotRequestedAgainUntilTheMapAroundItChanges) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  BuildView view;
  const CellIndex refused = first_motion_cell(steps, view);
  protocol::ActionRequest q;
  const auto local = [&](const BuildView& v) {
    return CellIndex{refused.row - v.local.offset.row, refused.col - v.local.offset.col};
  };
  EXPECT_NE(view.local.occupiable(local(view).row, local(view).col), 0);

  // The world refused it, naming the cell.
  protocol::SensorFrame f = frame(steps, 1, {1.05, 3.05});
  f.last_result = protocol::ActionResult::kRejected;
  f.last_reason = fmt::format("target cell ({}, {}) is not occupiable for this body", refused.row, refused.col);
  for (std::uint64_t step = 1; step < 1 + 5 * kRefusedMotionSteps; ++step) {
    if (step > 1) f = frame(steps, step, {1.05, 3.05});
    trace = BuildTrace{};
    view = steps.look(f, trace);
    ASSERT_TRUE(steps.refused().contains(refused)) << "step " << step;
    EXPECT_EQ(view.local.occupiable(local(view).row, local(view).col), 0);
    q = empty(steps, f);
    (void)steps.build_step(view.local, f, trace, q);
    if (q.move) {
      EXPECT_NE(*steps.map().geometry().cell_at({q.target_x_m, q.target_y_m}), refused) << "step " << step;
    }
  }
  // Another robot raised a cell of its ball: the map changed there, the cell is judged again.
  Heightmap built = test::platform_world();
  built(refused.row, refused.col + 1) += 0.05;
  trace = BuildTrace{};
  view = steps.look(test::full_frame(steps.context(), 1000, {1.05, 3.05}, 1.0, built), trace);
  EXPECT_FALSE(steps.refused().contains(refused));
}

// A motion refused for a neighbour's body (rule 2.5) depends on where the others stand: held out for a while only.
TEST(RampSteps, AMotionRefusedForANeighboursBodyIsLeftOutForAWhile) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  BuildView view;
  const CellIndex refused = first_motion_cell(steps, view);
  protocol::ActionRequest q;
  protocol::SensorFrame f1 = frame(steps, 1, {1.05, 3.05});
  f1.last_result = protocol::ActionResult::kRejected;
  f1.last_reason = "motion ends 0.9 m from agent 2, whose body it would overlap (bodies need 1 m)";
  trace = BuildTrace{};
  view = steps.look(f1, trace);
  EXPECT_TRUE(steps.refused().contains(refused));
  trace = BuildTrace{};
  view = steps.look(frame(steps, 1 + kRefusedMotionSteps - 1, {1.05, 3.05}), trace);
  EXPECT_TRUE(steps.refused().contains(refused));
  trace = BuildTrace{};
  view = steps.look(frame(steps, 1 + kRefusedMotionSteps, {1.05, 3.05}), trace);
  EXPECT_FALSE(steps.refused().contains(refused));
}

TEST(RampSteps, BuildStepBlockedAtTheFootBuildsInPlace) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  const Position robot{6.45, 3.05};  // the next cell east touches the platform within half a body
  const protocol::SensorFrame f = frame(steps, 0, robot);
  const BuildView view = steps.look(f, trace);
  protocol::ActionRequest q = empty(steps, f);
  EXPECT_EQ(steps.build_step(view.local, f, trace, q), BuildPhase::kBuild);
  EXPECT_FALSE(q.move);
  ASSERT_FALSE(q.depositions.empty());
  EXPECT_EQ(q.depositions.size(), trace.deposition.depositions.size());
  const Heightmap h = test::platform_world();
  double volume_m3 = 0.0;
  for (const protocol::Deposition& d : q.depositions) {
    const Position centre = h.cell_center({d.row, d.col});
    EXPECT_LE(std::hypot(centre.x - robot.x, centre.y - robot.y), test::husky().reach_m + 1e-9);
    volume_m3 += d.height_m * 0.01;
  }
  EXPECT_LE(volume_m3, test::husky().max_deposit_m3 + 1e-12);
}

TEST(RampSteps, BlockedWithNothingInReachTheRobotRetreatsThenAdvancesAgainAfterIdleRetreatMoves) {
  // reach = delta / 2: material only in a ring the robot never reaches, so retreating never deposits; after
  // ceil((reach + delta) / max_step) + 1 = 9 idle retreat moves it tries the path again. (Its steps back follow the
  // local origin, which here flips between the ends of its short trajectory: it paces between x = 6.05 and 6.25 m.)
  RobotBody body = test::husky();
  body.reach_m = 0.5;
  const auto owned = admitted_steps(body);
  RampSteps& steps = *owned;
  Position robot{5.95, 3.05};
  {
    BuildTrace trace;
    const protocol::SensorFrame f = frame(steps, 0, robot);
    const BuildView view = steps.look(f, trace);
    protocol::ActionRequest q = empty(steps, f);
    ASSERT_EQ(steps.build_step(view.local, f, trace, q), BuildPhase::kAdvance);
    robot = {6.45, 3.05};  // to the foot of the platform
  }
  BuildTrace trace;
  protocol::SensorFrame f = frame(steps, 1, robot);
  BuildView view = steps.look(f, trace);
  protocol::ActionRequest q = empty(steps, f);
  ASSERT_EQ(steps.build_step(view.local, f, trace, q), BuildPhase::kRetreat);
  ASSERT_TRUE(q.move);
  EXPECT_LT(q.target_x_m, robot.x);
  EXPECT_TRUE(q.depositions.empty());
  int retreat_moves = 1;
  for (std::uint64_t step = 2; step < 20; ++step) {
    const Position at{q.target_x_m, q.target_y_m};
    trace = BuildTrace{};
    f = frame(steps, step, at);
    view = steps.look(f, trace);
    q = empty(steps, f);
    const BuildPhase phase = steps.retreat_step(view.local, f, trace, q);
    ASSERT_TRUE(q.move) << "step " << step;
    EXPECT_TRUE(q.depositions.empty());
    if (phase == BuildPhase::kAdvance) {
      EXPECT_GT(q.target_x_m, at.x);  // up the path again
      break;
    }
    EXPECT_LT(q.target_x_m, robot.x);  // never up to the foot where it was blocked
    ++retreat_moves;
  }
  EXPECT_EQ(retreat_moves, 9);
}

TEST(RampSteps, BuildStepWithoutAPathThroughKnownCellsRequestsNothing) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  const Position robot{1.05, 2.05};
  const protocol::SensorFrame f = test::keep_tile_at(frame(steps, 0, robot), test::platform_world().geometry(), robot);
  const BuildView view = steps.look(f, trace);
  protocol::ActionRequest q = empty(steps, f);
  EXPECT_FALSE(steps.build_step(view.local, f, trace, q).has_value());
  EXPECT_TRUE(trace.planned);
  EXPECT_FALSE(trace.plan.found);
  EXPECT_FALSE(q.move);
  EXPECT_TRUE(q.depositions.empty());
}

TEST(RampSteps, ReturnStepHeadsForTheBaseAndRefillsWithinItsRadius) {
  const auto owned = admitted_steps();
  Returned r = return_once(*owned, 0, {2.05, 3.05});
  EXPECT_FALSE(r.refilled);
  ASSERT_TRUE(r.request.move);
  EXPECT_NEAR(r.request.target_x_m, 1.85, 1e-12);  // a whole step west
  EXPECT_FALSE(r.request.refill);
  EXPECT_TRUE(r.trace.planned);
  // A step from the base radius (0.5 m): the motion ends inside it, so the same request refills.
  r = return_once(*owned, 1, {1.15, 3.05});
  EXPECT_TRUE(r.refilled);
  EXPECT_TRUE(r.request.move);
  EXPECT_TRUE(r.request.refill);
  EXPECT_TRUE(r.trace.refill);
  // Inside it already: refill in place.
  r = return_once(*owned, 2, {0.85, 3.05});
  EXPECT_TRUE(r.refilled);
  EXPECT_FALSE(r.request.move);
  EXPECT_TRUE(r.request.refill);
}

TEST(RampSteps, ARobotNoNearerTheBaseForTwoWindowCrossingsTakesItsWayHomeForTheRestOfTheTrip) {
  const auto owned = admitted_steps();
  const RobotBody& body = owned->context().type.body;
  // The robot's motions are never carried out (it stays at x = 6.05 m): as it would be when its window's nearest
  // cell to the base lies one way from one cell and the other way from the next.
  const int patience = static_cast<int>(std::ceil(4.0 * body.sensing_range_m / body.max_step_m));
  for (int k = 0; k <= patience + 2; ++k) {
    const Returned r = return_once(*owned, static_cast<std::uint64_t>(k), {6.05, 3.05});
    EXPECT_FALSE(r.refilled);
    EXPECT_TRUE(r.request.move) << k;
    // The first call sets the trip's nearest distance; `patience` calls later without getting nearer, the way home.
    EXPECT_EQ(r.trace.home_route, k >= patience) << k;
  }
  // At the base the trip ends: the next trip starts with the nearest cell of its window again.
  EXPECT_TRUE(return_once(*owned, 100, {0.85, 3.05}).refilled);
  const Returned next = return_once(*owned, 101, {6.05, 3.05});
  EXPECT_FALSE(next.refilled);
  EXPECT_FALSE(next.trace.home_route);
}

TEST(RampSteps, StepBackGoesAwayFromTheGoalBeforeTheRobotHasMoved) {
  const auto owned = admitted_steps();
  RampSteps& steps = *owned;
  BuildTrace trace;
  const Position robot{4.05, 3.05};
  const BuildView view = steps.look(frame(steps, 0, robot), trace);
  const auto motion = steps.step_back(view.local, robot);
  ASSERT_TRUE(motion.has_value());
  const Position goal = view.local.center(view.local.goal);
  EXPECT_GT(std::hypot(motion->target.x - goal.x, motion->target.y - goal.y),
            std::hypot(robot.x - goal.x, robot.y - goal.y));
  EXPECT_LE(motion->distance_m, test::husky().max_step_m + 1e-12);
}

}  // namespace
}  // namespace marsala::agent::reactive

namespace marsala::agent::reactive {
namespace {

TEST(RampSteps, AfterARejectedRequestWithDepositsTheNextCarriesAtMostHalfAsManyUntilOneIsAccepted) {
  AgentContext c = test::agent_context(3, test::husky());
  c.type.depositor.kind = DepositorKind::kCone;
  RampSteps steps(c);
  steps.admit(test::admission_on(c, test::platform_world().geometry(), kTarget, kBase));
  const Position robot{6.45, 3.05};  // blocked at the foot of the platform: builds in place
  const auto deposits_with = [&](protocol::ActionResult last) {
    protocol::SensorFrame f = frame(steps, 0, robot);
    f.last_result = last;
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    protocol::ActionRequest q = empty(steps, f);
    steps.build_step(view.local, f, trace, q);
    EXPECT_TRUE(q.depositions.empty());
    EXPECT_EQ(q.deposits.size(), trace.deposition.deposits.size());
    return q.deposits.size();
  };
  const std::size_t full = deposits_with(protocol::ActionResult::kNone);
  ASSERT_GE(full, 2u);
  const std::size_t half = deposits_with(protocol::ActionResult::kRejected);
  EXPECT_EQ(half, full / 2);
  std::size_t n = half;
  for (int i = 0; i < 4 && n > 0; ++i) {
    const std::size_t next = deposits_with(protocol::ActionResult::kRejected);
    EXPECT_EQ(next, n / 2);
    n = next;
  }
  EXPECT_EQ(n, 0u);  // no deposits now: the robot does something else, and the world judges something new
  deposits_with(protocol::ActionResult::kAccepted);  // the request without deposits was accepted
  EXPECT_EQ(deposits_with(protocol::ActionResult::kAccepted), full);
}

// A pile the world refused because it reached a robot's body (rule 3d.8) is not dumped in the same cell again while
// the refusal holds: the request after it differs, although the map is the same.
TEST(RampSteps, APileThatReachedARobotsBodyIsNotDumpedThereAgain) {
  AgentContext c = test::agent_context(3, test::husky());
  c.type.depositor.kind = DepositorKind::kCone;
  RampSteps steps(c);
  const GridGeometry grid = test::platform_world().geometry();
  steps.admit(test::admission_on(c, grid, kTarget, kBase));
  const Position robot{6.45, 3.05};  // blocked at the foot of the platform: builds in place
  const auto request_after = [&](std::uint64_t step, protocol::ActionResult last, const std::string& reason) {
    protocol::SensorFrame f = frame(steps, step, robot);
    f.last_result = last;
    f.last_reason = reason;
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    protocol::ActionRequest q = empty(steps, f);
    steps.build_step(view.local, f, trace, q);
    return q;
  };
  const protocol::ActionRequest first = request_after(0, protocol::ActionResult::kNone, "");
  ASSERT_FALSE(first.deposits.empty());
  const Position dumped = first.deposits.front().centre;
  const CellIndex cell = *grid.cell_at(dumped);
  // The same request is what an accepted one would be followed by on this unchanged map.
  const protocol::ActionRequest again = request_after(1, protocol::ActionResult::kAccepted, "");
  ASSERT_FALSE(again.deposits.empty());
  EXPECT_EQ(again.deposits.front().centre, dumped);
  const std::string reason = fmt::format("deposit at ({}, {}) m raises cell ({}, {}), under agent 3", dumped.x,
                                         dumped.y, cell.row, cell.col - 3);
  int with_deposits = 0;
  for (std::uint64_t step = 2; step < 2 + 30; ++step) {
    const bool refused = step == 2;
    const protocol::ActionRequest next =
        request_after(step, refused ? protocol::ActionResult::kRejected : protocol::ActionResult::kAccepted,
                      refused ? reason : std::string());
    for (const Deposit& d : next.deposits) EXPECT_NE(*grid.cell_at(d.centre), cell) << "step " << step;
    if (!next.deposits.empty()) ++with_deposits;
  }
  EXPECT_GT(with_deposits, 20);  // it builds on beside the pile it may not dump
}

/// Flat ground 6 x 10 m (0.1 m cells) with eight 0.12 m spikes six cells from each of `centres`, along the axes and
/// the diagonals (4, 4): each of a centre's eight neighbour cells holds one in its body ball (radius 5 cells), the
/// centre's own ball none; a spike breaks the rule by 2 cm against the cells beside it, within a laser map's noise.
Heightmap walled_in_world(std::initializer_list<CellIndex> centres) {
  Heightmap h({60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (const CellIndex b : centres)
    for (const CellIndex o : {CellIndex{0, 6}, CellIndex{0, -6}, CellIndex{6, 0}, CellIndex{-6, 0}, CellIndex{4, 4},
                              CellIndex{4, -4}, CellIndex{-4, 4}, CellIndex{-4, -4}})
      h(b.row + o.row, b.col + o.col) = 0.12;
  return h;
}

// A scanning robot whose map leaves it no move asks the world: first the path's next cell, then the way it came. Flat
// ground with eight 0.12 m spikes six cells (0.6 m) from the cell B it stands on, along the axes and diagonals (4, 4):
// each of B's eight neighbour cells holds one of them in its body ball (radius 5 cells), B's own ball none; a spike
// breaks the rule by 2 cm against the cells beside it, within the laser map's noise margin. It came
// from A, 0.2 m west of B; with nothing to fill (no material) and no navigable cell but its own, it asks for the next
// cell east (towards its target); once the world has refused that, for a motion back to A; once the world has refused
// that too, it asks nothing until its map changes. A robot that reads exact heights asks nothing.
TEST(RampSteps, AScanningRobotWalledInOnItsMapAsksTheWorldTheWayItCame) {
  const CellIndex b{30, 40};
  const Heightmap h = walled_in_world({b});
  const Position at_b = h.geometry().cell_center(b);
  const Position at_a{at_b.x - 0.2, at_b.y};
  const CellIndex a = *h.geometry().cell_at(at_a);
  const CellIndex east{b.row, b.col + 1};
  const auto requests_of = [&](bool scanning, const std::vector<std::string>& refusals) {
    AgentContext c = test::agent_context(3, test::husky());
    if (scanning) c.type.sensor = sensor_defaults(SensorKind::kLaser);
    RampSteps steps(c);
    steps.admit(test::admission_on(c, h.geometry(), {9.05, at_b.y}, {0.55, at_b.y}));
    std::vector<protocol::ActionRequest> out;
    for (std::uint64_t step = 0; step <= refusals.size() + 1; ++step) {
      protocol::SensorFrame f = test::full_frame(c, step, step == 0 ? at_a : at_b, 0.0, h);
      if (step >= 2) {
        f.last_result = protocol::ActionResult::kRejected;
        f.last_reason = refusals[step - 2];
      }
      BuildTrace trace;
      const BuildView view = steps.look(f, trace);
      if (step == 0) continue;  // the frame at A: its trajectory
      protocol::ActionRequest q = empty_request(c, f, "");
      (void)steps.build_step(view.local, f, trace, q);
      EXPECT_EQ(trace.navigable_cells, 1) << "step " << step;
      out.push_back(q);
    }
    return out;
  };
  const auto refused = [](CellIndex target, CellIndex low, CellIndex high) {
    return fmt::format(
        "target cell ({}, {}) is not occupiable for this body: cell ({}, {}) at 0 m lies too far below cell ({}, {}) "
        "at 0.12 m",
        target.row, target.col, low.row, low.col, high.row, high.col);
  };
  const auto cell_of = [&](const protocol::ActionRequest& q) { return h.geometry().cell_at({q.target_x_m, q.target_y_m}); };
  const auto asked = requests_of(true, {refused(east, {b.row, b.col + 5}, {b.row, b.col + 6}),
                                        refused(a, {a.row, a.col - 5}, {a.row, a.col - 4})});
  ASSERT_EQ(asked.size(), 3u);
  ASSERT_TRUE(asked[0].move);
  EXPECT_EQ(cell_of(asked[0]), east);
  ASSERT_TRUE(asked[1].move);
  EXPECT_NEAR(asked[1].target_x_m, at_a.x, 1e-9);
  EXPECT_NEAR(asked[1].target_y_m, at_a.y, 1e-9);
  EXPECT_FALSE(asked[2].move);
  const auto exact = requests_of(false, {});
  ASSERT_EQ(exact.size(), 1u);
  EXPECT_FALSE(exact[0].move);
}

/// Flat ground 6 x 10 m (0.1 m cells) with a step of `step_m` from column 50 east.
Heightmap ridge_world(double step_m) {
  Heightmap h({60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int col = 50; col < h.cols(); ++col) h(r, col) = step_m;
  return h;
}

/// The requests of agent 3 (a laser robot when `scanning`) that stands at `from`, then at `at` on `h` with
/// `material_m3` on board, one build_step() per frame; the frame at each step of `results` carries that result and
/// reason.
std::vector<protocol::ActionRequest> build_requests(const Heightmap& h, bool scanning, Position from, Position at,
                                                    double material_m3,
                                                    const std::vector<std::pair<protocol::ActionResult, std::string>>&
                                                        results) {
  AgentContext c = test::agent_context(3, test::husky());
  if (scanning) c.type.sensor = sensor_defaults(SensorKind::kLaser);
  RampSteps steps(c);
  steps.admit(test::admission_on(c, h.geometry(), {9.05, at.y}, {0.55, at.y}));
  std::vector<protocol::ActionRequest> out;
  for (std::size_t step = 0; step <= results.size(); ++step) {
    protocol::SensorFrame f = test::full_frame(c, step, step == 0 ? from : at, material_m3, h);
    if (step > 0) {
      f.last_result = results[step - 1].first;
      f.last_reason = results[step - 1].second;
    }
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    if (step == 0) continue;  // the frame at `from`: its trajectory
    protocol::ActionRequest q = empty_request(c, f, "");
    (void)steps.build_step(view.local, f, trace, q);
    out.push_back(q);
  }
  return out;
}

// The robot of the next two tests, on B (30, 44) of ridge_world(0.12) (flat ground with a 0.12 m step from column 50),
// come from the west with no material: for each of its requests (scanning or reading exact heights, the world answering
// `results` in turn), whether it moves to the next cell east, (30, 45), and whether it moves east at all.
struct AskedNext {
  std::vector<bool> next;
  std::vector<bool> east;
};
AskedNext asks_next(bool scanning, const std::vector<std::pair<protocol::ActionResult, std::string>>& results) {
  const Heightmap h = ridge_world(0.12);
  const Position at_b = h.geometry().cell_center({30, 44});
  AskedNext out;
  for (const protocol::ActionRequest& q : build_requests(h, scanning, {at_b.x - 0.2, at_b.y}, at_b, 0.0, results)) {
    out.next.push_back(q.move && h.geometry().cell_at({q.target_x_m, q.target_y_m}) == CellIndex{30, 45});
    out.east.push_back(q.move && q.target_x_m > at_b.x);
  }
  return out;
}

// A scanning robot blocked on its path with nothing to fill asks the world the path's next cell. B's ball (radius 5
// cells) ends at column 49; the next cell east holds the step in its ball, which breaks the rule by 2 cm (within the
// laser map's noise margin), so the robot's map holds it out, and with no material there is nothing to fill. It asks
// for a motion there; once the world has refused it (naming the drop), it asks for it no more while its map reads the
// same. A robot that reads exact heights never asks a cell its map holds out.
TEST(RampSteps, AScanningRobotBlockedWithNothingToFillAsksTheWorldThePathsNextCell) {
  const std::string refused =
      "target cell (30, 45) is not occupiable for this body: cell (30, 49) at 0 m lies too far below cell (30, 50) at "
      "0.12 m";
  using R = protocol::ActionResult;
  const AskedNext scanning = asks_next(true, {{R::kAccepted, ""}, {R::kRejected, refused}, {R::kAccepted, ""}});
  EXPECT_EQ(scanning.next, (std::vector<bool>{true, false, false}));
  const AskedNext exact = asks_next(false, {{R::kAccepted, ""}});
  EXPECT_EQ(exact.next, (std::vector<bool>{false}));
  EXPECT_EQ(exact.east, (std::vector<bool>{false}));
}

// A walled-in scanning robot asks the world its way back around the cells the world has answered. The spikes of the
// walled-in test around B (30, 44) on flat ground; the robot came from A (30, 30), 1.4 m west, the way back. It asks
// the path's next cell east first (refused: the spike east of B); then the next cell of the straight way back,
// (30, 43); refused too (the world naming the spike west of B, (30, 38), over (30, 39): both in the ball of (30, 43)),
// it asks a cell beside that one, whose ball does not hold both, instead of asking nothing.
TEST(RampSteps, AWalledInRobotAsksItsWayBackAroundTheCellsTheWorldRefused) {
  const CellIndex b{30, 44};
  const Heightmap h = walled_in_world({b});
  const Position at_b = h.geometry().cell_center(b);
  const Position at_a = h.geometry().cell_center({30, 30});
  using R = protocol::ActionResult;
  const std::string east =
      "target cell (30, 45) is not occupiable for this body: cell (30, 49) at 0 m lies too far below cell (30, 50) at "
      "0.12 m";
  const std::string west =
      "target cell (30, 43) is not occupiable for this body: cell (30, 39) at 0 m lies too far below cell (30, 38) at "
      "0.12 m";
  const auto requests = build_requests(h, true, at_a, at_b, 0.0,
                                       {{R::kAccepted, ""}, {R::kRejected, east}, {R::kRejected, west}});
  ASSERT_EQ(requests.size(), 3u);
  const auto cell_of = [&](const protocol::ActionRequest& q) { return h.geometry().cell_at({q.target_x_m, q.target_y_m}); };
  ASSERT_TRUE(requests[0].move);
  EXPECT_EQ(cell_of(requests[0]), (CellIndex{30, 45}));
  ASSERT_TRUE(requests[1].move);
  EXPECT_EQ(cell_of(requests[1]), (CellIndex{30, 43}));
  ASSERT_TRUE(requests[2].move);
  const CellIndex asked = *cell_of(requests[2]);
  EXPECT_EQ(asked.col, 43);
  EXPECT_EQ(std::abs(asked.row - 30), 1);
}

// A walled-in robot keeps the cell it asks its way back to while it stays walled in. Flat ground; spikes wall in P
// (30, 44) and Q (20, 58) alone (as in the walled-in test above); the robot came from A (15, 30), north-west. On P,
// refused the path's next cell east, it asks its way back towards A, the latest cell of its trajectory a body length
// away and no nearer the goal (east). Put down on Q, still walled in, a robot choosing afresh would head for P, south-
// west (now the latest such cell); it keeps A and asks the cell west or north-west. (The world never moves a robot so: the frames only put it where its memory is tested.)
TEST(RampSteps, AWalledInRobotKeepsTheCellItAsksItsWayBackTo) {
  const Heightmap h = walled_in_world({{30, 44}, {20, 58}});
  const GridGeometry& g = h.geometry();
  AgentContext c = test::agent_context(3, test::husky());
  c.type.sensor = sensor_defaults(SensorKind::kLaser);
  RampSteps steps(c);
  steps.admit(test::admission_on(c, g, {9.05, g.cell_center({30, 44}).y}, {0.55, g.cell_center({30, 44}).y}));
  using R = protocol::ActionResult;
  struct Frame {
    CellIndex at;
    R result;
    std::string reason;
  };
  const std::vector<Frame> frames{
      {{15, 30}, R::kNone, ""},
      {{30, 44}, R::kAccepted, ""},
      {{30, 44}, R::kRejected,
       "target cell (30, 45) is not occupiable for this body: cell (30, 49) at 0 m lies too far below cell (30, 50) at "
       "0.12 m"},
      {{20, 58}, R::kAccepted, ""},
  };
  std::vector<protocol::ActionRequest> requests;
  for (std::size_t step = 0; step < frames.size(); ++step) {
    protocol::SensorFrame f = test::full_frame(c, step, g.cell_center(frames[step].at), 0.0, h);
    f.last_result = frames[step].result;
    f.last_reason = frames[step].reason;
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    protocol::ActionRequest q = empty_request(c, f, "");
    if (step < 3)
      (void)steps.build_step(view.local, f, trace, q);
    else
      (void)steps.retreat_step(view.local, f, trace, q);  // as the builder does after a retreat
    requests.push_back(q);
  }
  const auto cell_of = [&](const protocol::ActionRequest& q) { return *g.cell_at({q.target_x_m, q.target_y_m}); };
  ASSERT_TRUE(requests[1].move);
  EXPECT_EQ(cell_of(requests[1]), (CellIndex{30, 45}));  // the path's next cell east
  ASSERT_TRUE(requests[2].move);
  EXPECT_EQ(cell_of(requests[2]), (CellIndex{29, 43}));  // refused: the way back, towards A
  ASSERT_TRUE(requests[3].move);
  EXPECT_EQ(cell_of(requests[3]).col, 57);  // on Q: still towards A, not south-west towards P
  EXPECT_LE(cell_of(requests[3]).row, 20);
}

// A told drop holds a cell out only where the cell's ball holds both its cells. The same robot is refused a motion
// through (30, 47), the world naming (30, 49) at 0 m too far below (30, 52) at 0.3 m: the pair lies in the ball of
// (30, 47) but not in that of (30, 45) (the high cell is 7 cells away), so the robot still asks for (30, 45); told the
// pair (30, 49) / (30, 50), both in that ball, it does not.
TEST(RampSteps, AToldDropHoldsOutOnlyTheCellsWhoseBallHoldsBothItsCells) {
  using R = protocol::ActionResult;
  const std::string through = "motion passes through cell (30, 47), not occupiable for this body: cell (30, 49) at 0 m "
                              "lies too far below cell ";
  EXPECT_EQ(asks_next(true, {{R::kAccepted, ""}, {R::kRejected, through + "(30, 52) at 0.3 m"}}).next,
            (std::vector<bool>{true, true}));
  EXPECT_EQ(asks_next(true, {{R::kAccepted, ""}, {R::kRejected, through + "(30, 50) at 0.3 m"}}).next,
            (std::vector<bool>{true, false}));
}

// The drop the world named is filled until the pair passes the occupancy rule (rule 2.3), whatever the robot's map
// leaves unconfirmed. A 0.3 m step from column 50; a laser robot on B (30, 44) whose map comes from tiles alone (no
// scan confirms a gap, so it fills nothing) moves and is told that the next cell east is not occupiable: (27, 49) at
// 0 m lies too far below (30, 50) at 0.3 m (both in that cell's ball, 0.316 m apart; (27, 49) is outside B's own). It
// then raises (27, 49) to within eps + kappa d of the step's top and no higher than the step's slope allows.
TEST(RampSteps, TheDropTheWorldNamedIsFilledUntilThePairPasses) {
  const double top_m = 0.3;
  const Heightmap h = ridge_world(top_m);
  const Position at = h.geometry().cell_center({30, 44});
  const Position from{at.x - 0.2, at.y};
  const CellIndex low{27, 49};
  const auto rise_of = [&](const protocol::ActionRequest& q) {
    double rise = 0.0;
    for (const Deposition& d : q.depositions)
      if (CellIndex{d.row, d.col} == low) rise += d.height_m;
    return rise;
  };
  using R = protocol::ActionResult;
  const std::string refused =
      "target cell (30, 45) is not occupiable for this body: cell (27, 49) at 0 m lies too far below cell (30, 50) at "
      "0.3 m";
  const auto requests = build_requests(h, true, from, at, 1.0, {{R::kAccepted, ""}, {R::kRejected, refused}});
  ASSERT_EQ(requests.size(), 2u);
  EXPECT_TRUE(requests[0].depositions.empty());  // nothing confirmed to fill
  EXPECT_TRUE(requests[0].move);
  const NavigabilityParams nav = test::husky().navigability;
  const double slope_m = nav.kappa * 0.1 * std::hypot(3.0, 1.0);
  const double rise = rise_of(requests[1]);
  EXPECT_GE(rise, top_m - slope_m - nav.eps_m);
  EXPECT_LE(rise, top_m - slope_m + 1e-12);
}

/// The platform world with a 0.3 m step instead of the 1.5 m platform: its top lies below the laser (0.5 m up), which
/// sees no higher than 10 degrees up.
Heightmap step_world() {
  Heightmap h = test::platform_world();
  for (int r = 0; r < h.rows(); ++r)
    for (int col = 70; col < h.cols(); ++col) h(r, col) = 0.3;
  return h;
}

/// Steps of agent 3, a laser robot, admitted on `h` with the target on the platform.
std::unique_ptr<RampSteps> laser_steps(const Heightmap& h) {
  AgentContext c = test::agent_context(3, test::husky());
  c.type.sensor = sensor_defaults(SensorKind::kLaser);
  auto steps = std::make_unique<RampSteps>(c);
  steps->admit(test::admission_on(c, h.geometry(), kTarget, kBase));
  return steps;
}

/// A scanning robot's frame of `step` at `robot` [m], with 1 m^3 on board and no points yet.
protocol::SensorFrame scan_frame(std::uint64_t step, Position robot) { return test::scan_frame(3, step, robot); }

// A laser robot before a 0.3 m step: the MARS gap in front of it is real, but it fills it only once its last 3 scans
// in a row all showed it on cells they hit (kConfirmScans): one scan's misread step is no gap. Each frame here
// carries a scan of the same terrain from the same pose; the first two frames request no deposition, the third does,
// and a robot with exact sensing at the same pose at its first.
TEST(RampSteps, AScanningRobotFillsAGapOnlyOnceItsLastScansAgree) {
  const Heightmap h = step_world();
  const auto owned = laser_steps(h);
  RampSteps& steps = *owned;
  const SensorSpec& laser = steps.context().type.sensor;
  const Position robot{6.05, 3.05};
  const Point3 origin = sensor_origin(h, robot.x, robot.y, laser);
  bool deposited_before_third = false;
  for (std::uint64_t step = 0; step < 3; ++step) {
    protocol::SensorFrame f = scan_frame(step, robot);
    f.points = cast_scan(h, origin, 0.0, laser, step + 1);
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    protocol::ActionRequest q = empty(steps, f);
    (void)steps.build_step(view.local, f, trace, q);
    const bool deposits = !q.depositions.empty();
    EXPECT_GT(view.local.gap.heights().maxCoeff(), 0.2) << "step " << step;  // the step's gap, seen at every scan
    if (step < 2) {
      deposited_before_third = deposited_before_third || deposits;
    } else {
      EXPECT_TRUE(deposits) << "the third scan confirms the gap";
    }
  }
  EXPECT_FALSE(deposited_before_third);

  // The same robot with exact sensing fills it at its first frame.
  AgentContext exact = test::agent_context(3, test::husky());
  RampSteps now(exact);
  now.admit(test::admission_on(exact, h.geometry(), kTarget, kBase));
  const protocol::SensorFrame f = test::full_frame(exact, 0, robot, 1.0, h);
  BuildTrace trace;
  const BuildView view = now.look(f, trace);
  protocol::ActionRequest q = empty(now, f);
  (void)now.build_step(view.local, f, trace, q);
  EXPECT_FALSE(q.depositions.empty());
}

// A scanning robot's accepted pile is in its map as the pile settles on the map's terrain (the world settles it on
// the truth): no scan need see it, and the next pile beside it is planned on top of it.
TEST(RampSteps, AScanningRobotsAcceptedPileIsInItsMap) {
  const Heightmap h = step_world();
  AgentContext c = test::agent_context(3, test::husky());
  c.type.sensor = sensor_defaults(SensorKind::kLaser);
  c.type.depositor.kind = DepositorKind::kCone;
  RampSteps steps(c);
  steps.admit(test::admission_on(c, h.geometry(), kTarget, kBase));
  const Position robot{6.05, 3.05};
  const Point3 origin = sensor_origin(h, robot.x, robot.y, c.type.sensor);
  protocol::ActionRequest q;
  for (std::uint64_t step = 0; step < 8 && q.deposits.empty(); ++step) {
    protocol::SensorFrame f = scan_frame(step, robot);
    f.points = cast_scan(h, origin, 0.0, c.type.sensor, step + 1);
    BuildTrace trace;
    const BuildView view = steps.look(f, trace);
    q = empty(steps, f);
    (void)steps.build_step(view.local, f, trace, q);
  }
  ASSERT_FALSE(q.deposits.empty());
  // The piles as the world would settle them on the map the robot planned on, one on another.
  const Heightmap before = steps.map().heights();
  Heightmap expected = before;
  for (const Deposit& d : q.deposits)
    for (const CellRise& r : cone_pile_shape(expected, d.centre, d.volume_m3, c.type.depositor.repose_deg).rises)
      expected(r.cell) += r.rise_m;
  protocol::SensorFrame f = scan_frame(3, robot);  // a frame without points: nothing seen anew
  f.scanned = false;
  f.last_result = protocol::ActionResult::kAccepted;
  BuildTrace trace;
  (void)steps.look(f, trace);
  const Heightmap& now = steps.map().heights();
  const CellIndex dump = *h.geometry().cell_at(q.deposits.front().centre);
  EXPECT_GT(now(dump) - before(dump), 0.01);
  EXPECT_NEAR(now(dump), expected(dump), 1e-9);
  for (int r = 0; r < h.rows(); ++r)
    for (int col = 0; col < h.cols(); ++col)
      if (now(r, col) != before(r, col)) {
        EXPECT_NEAR(now(r, col), expected(r, col), 1e-9) << r << "," << col;
      }
}

// docs/runtime.md#mapping: a gap stays current after the scans stop hitting it (the robot turned away, built cells hide
// it) as long as no other robot came within reach of it: only this robot can have built there. A laser robot before a
// 0.3 m step confirms the gap with 3 scans, then gets frames whose scans hit nothing: it still fills the gap. The same
// robot does not when a neighbour stood on the gap in two of those frames (gone again when it decides): the neighbour
// may have built there.
TEST(RampSteps, AGapStaysCurrentUntilAnotherRobotComesNearIt) {
  for (const bool neighbour : {false, true}) {
    const Heightmap h = step_world();
    const auto owned = laser_steps(h);
    RampSteps& steps = *owned;
    const SensorSpec& laser = steps.context().type.sensor;
    const Position robot{6.05, 3.05};
    const Point3 origin = sensor_origin(h, robot.x, robot.y, laser);
    bool deposits = false;
    for (std::uint64_t step = 0; step < 7; ++step) {
      protocol::SensorFrame f = scan_frame(step, robot);
      if (step < 3) f.points = cast_scan(h, origin, 0.0, laser, step + 1);  // then scans that hit nothing
      if ((step == 3 || step == 4) && neighbour) f.neighbours.push_back({2, {7.05, 3.05}, 0.3, 0.5});  // then gone
      BuildTrace trace;
      const BuildView view = steps.look(f, trace);
      protocol::ActionRequest q = empty(steps, f);
      (void)steps.build_step(view.local, f, trace, q);
      if (step == 6) deposits = !q.depositions.empty();
    }
    EXPECT_EQ(deposits, !neighbour) << (neighbour ? "with" : "without") << " a neighbour";
  }
}

}  // namespace
}  // namespace marsala::agent::reactive

namespace marsala::agent::reactive {
namespace {

// A built embankment 3 m wide and 0.3 m high along x (its centre line at y = 3 m) on flat ground: the MARS cones of
// its top leave a gap in a strip beside each side (0.3 - kappa d > 0 within 0.6 m of it). A robot on top in the right
// lane (0.75 m south of the centre, heading east) with a 3 m construction band and a deposition threshold large
// enough to fill all it reaches in one step.
constexpr double kEmbankmentCentreY = 3.0;

Heightmap embankment_world() {
  Heightmap h({60, 120, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c)
      if (std::abs(h.cell_center({r, c}).y - kEmbankmentCentreY) < 1.5) h(r, c) = 0.3;
  return h;
}

/// The depositions of one build step of the robot in the lane, with or without the band's centre line.
std::vector<protocol::Deposition> lane_robot_depositions(bool band_centre) {
  RobotBody body = test::husky();
  body.max_deposit_m3 = 1.0;
  AgentContext c = test::agent_context(3, body);
  c.type.construction = NavigabilityParams{0.5, 3.0, 0.05};
  RampSteps steps(c);
  const Heightmap world = embankment_world();
  steps.admit(test::admission_on(c, world.geometry(), {11.5, kEmbankmentCentreY}, {0.55, kEmbankmentCentreY}));
  steps.set_lane(0.75, 3.0);
  steps.set_band_centre(band_centre);
  BuildTrace trace;
  const protocol::SensorFrame f = test::full_frame(c, 0, {4.05, kEmbankmentCentreY - 0.75}, 1.0, world);
  const BuildView view = steps.look(f, trace);
  protocol::ActionRequest q = empty_request(c, f, "");
  steps.build_step(view.local, f, trace, q);
  return q.depositions;
}

TEST(RampSteps, WithTheBandCentreARobotInASideLaneLeavesAStructureAsWideAsTheBand) {
  const Heightmap world = embankment_world();
  // Beside the band: farther from the centre line than half the band and the half cell by which the centre line's
  // cell (the rows next to y = 3 m are at 2.95 and 3.05 m) may lie off it.
  const auto beside = [&](const protocol::Deposition& d) {
    return std::abs(world.cell_center({d.row, d.col}).y - kEmbankmentCentreY) > 1.5 + 0.05 + 1e-9;
  };
  // Without it the footprint is centred on the robot's own path, 0.75 m off the centre, and fills the gap beside
  // the embankment: the structure widens.
  const auto own = lane_robot_depositions(false);
  EXPECT_GT(std::count_if(own.begin(), own.end(), beside), 0);
  // With it what the robot fills follows the embankment's centre line, up to the slope of the way's own surface
  // (the flat top the body drives on): the embankment fills the band already, nothing is left to fill, beside the
  // band or in it (the band's own surface would still have asked for the band's edge cells off the top).
  const auto centred = lane_robot_depositions(true);
  EXPECT_EQ(std::count_if(centred.begin(), centred.end(), beside), 0);
  EXPECT_TRUE(centred.empty());
}

}  // namespace
}  // namespace marsala::agent::reactive
