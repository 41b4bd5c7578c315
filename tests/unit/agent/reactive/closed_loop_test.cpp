// Closed loop without the world server: ramp builders drive a mini world (tests/unit/agent/mini_world.hpp) on the
// paper's platform scenario (Fig. 2) at a small size: 12 x 8 m at 0.1 m, a 1.5 m platform on the east side.
// Every request is checked against the rules of docs/runtime.md#validation before it is applied; the robots must end on
// the platform top with a navigable way from their start, within a step budget. Path builders (paper Fig. 4) must lay
// a way a payload can drive from the base to the platform.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "marsala/agent/reactive/path_builder.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/core/deposition.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "unit/agent/mini_world.hpp"

namespace marsala::agent {
namespace {

using reactive::PathBuilder;
using reactive::RampBuilder;

constexpr double kPlatformX = 8.0;  // west edge of the platform [m]
constexpr double kPlatformH = 1.5;  // [m]

Heightmap platform_terrain(double height_m = kPlatformH) {
  Heightmap h({80, 120, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c)
      if (h.cell_center({r, c}).x >= kPlatformX) h(r, c) = height_m;
  return h;
}

RobotBody husky(double kappa, double capacity_m3) {
  RobotBody b;
  b.navigability.kappa = kappa;
  b.navigability.delta_m = 1.0;
  b.navigability.eps_m = 0.05;
  b.max_step_m = 0.2;
  b.max_deposit_m3 = 0.02;
  b.material_capacity_m3 = capacity_m3;
  b.reach_m = 1.5;
  b.sensing_range_m = 4.0;
  b.proximity_range_m = 3.0;
  b.cube_size_m = 0.05;
  return b;
}

struct LoopResult {
  bool all_on_top = false;
  int steps = 0;
  std::vector<int> steps_to_top;  // per robot, -1 if never
  Heightmap initial, final_terrain;
  std::vector<std::vector<CellIndex>> trajectories;
  std::vector<Position> final_positions;
  double deposited_m3 = 0.0;
  double decide_ms_mean = 0.0, decide_ms_max = 0.0;
  int refills = 0;
  std::vector<std::string> states;  // last state per robot
};

bool on_top(const Heightmap& h, Position p) { return p.x >= kPlatformX && h(*h.cell_at(p)) >= kPlatformH - 0.1; }

/// Runs `starts.size()` ramp builders until all stand on the platform top or `max_steps` pass. Every request must
/// be accepted by the mini world (ASSERTed inside).
LoopResult run_loop(const RobotBody& body, const std::vector<Position>& starts, const std::vector<Position>& targets,
                    int max_steps) {
  LoopResult out;
  test::MiniWorld world(platform_terrain(), 16, {1.0, 4.0}, 1.0);
  out.initial = world.terrain();
  std::vector<std::unique_ptr<RampBuilder>> agents;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    AgentContext ctx;
    ctx.agent_id = static_cast<std::uint32_t>(i + 1);
    ctx.session = 1000 + i;
    ctx.type.body = body;
    ctx.neighbour_keep_out_m = neighbour_keep_out_m(body.navigability.delta_m, body.max_step_m);
    agents.push_back(std::make_unique<RampBuilder>(ctx));
    agents.back()->on_admission(world.admit(ctx.agent_id, ctx.session, body, starts[i], targets[i]));
  }
  out.steps_to_top.assign(starts.size(), -1);
  double total_ms = 0.0;
  int decisions = 0;
  for (int step = 0; step < max_steps; ++step) {
    std::vector<protocol::ActionRequest> requests;
    for (auto& agent : agents) {
      const std::uint32_t id = static_cast<std::uint32_t>(&agent - &agents[0] + 1);
      const protocol::SensorFrame frame = world.frame_for(id);
      const auto t0 = std::chrono::steady_clock::now();
      protocol::ActionRequest q = agent->decide(frame);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      total_ms += ms;
      out.decide_ms_max = std::max(out.decide_ms_max, ms);
      ++decisions;
      EXPECT_EQ(q.step, frame.step);
      EXPECT_EQ(q.agent_id, id);
      out.refills += q.refill ? 1 : 0;
      requests.push_back(std::move(q));
    }
    const auto reasons = world.apply_step(requests);
    for (std::size_t i = 0; i < reasons.size(); ++i)
      if (!reasons[i].empty()) {
        ADD_FAILURE() << "step " << step << ": agent " << requests[i].agent_id << " (" << requests[i].state
                      << ") rejected: " << reasons[i];
        out.steps = step + 1;
        return out;
      }
    static const int every = std::getenv("MARSALA_LOOP_TRACE") ? std::atoi(std::getenv("MARSALA_LOOP_TRACE")) : 0;
    if (every > 0 && step % every == 0)
      for (std::size_t i = 0; i < agents.size(); ++i) {
        const auto& rb = world.robot(static_cast<std::uint32_t>(i + 1));
        const auto& tr = agents[i]->last_trace();
        std::printf(
            "step %d robot %zu at (%.2f, %.2f) z %.3f material %.3f state %s plan %d/%zu goal (%d,%d) "
            "move %d deps %zu (cand %d, dropped %d) origin (%d,%d) nav %lld\n",
            step, i + 1, rb.pos.x, rb.pos.y, world.terrain()(*world.terrain().cell_at(rb.pos)), rb.material_m3,
            requests[i].state.c_str(), tr.plan.found, tr.plan.path.size(), tr.local_goal.row + tr.window_offset.row,
            tr.local_goal.col + tr.window_offset.col, requests[i].move, requests[i].depositions.size(),
            tr.deposition.candidates, tr.deposition.dropped_for_way_back,
            tr.local_origin ? tr.local_origin->row + tr.window_offset.row : -1,
            tr.local_origin ? tr.local_origin->col + tr.window_offset.col : -1, tr.navigable_cells);
      }
    bool all = true;
    for (std::size_t i = 0; i < agents.size(); ++i) {
      const bool top = on_top(world.terrain(), world.robot(static_cast<std::uint32_t>(i + 1)).pos);
      if (top && out.steps_to_top[i] < 0) out.steps_to_top[i] = step + 1;
      all = all && top;
    }
    out.steps = step + 1;
    if (all) {
      out.all_on_top = true;
      break;
    }
  }
  out.final_terrain = world.terrain();
  for (const auto& [id, r] : world.robots()) {
    out.deposited_m3 += r.deposited_m3;
    out.final_positions.push_back(r.pos);
  }
  for (auto& agent : agents) {
    out.trajectories.push_back(agent->map().trajectory());
    out.states.push_back(agent->state_name());
  }
  out.decide_ms_mean = decisions ? total_ms / decisions : 0.0;
  return out;
}

/// Checks the outcome: all on top within the budget, each with a navigable way from its start cell, and reports
/// the measurements.
void check_and_report(const char* name, const RobotBody& body, const std::vector<Position>& starts,
                      const LoopResult& r) {
  // Never above the MARS of the initial terrain: the robots only fill the gap (local MARS bounds are consistent
  // with the global one).
  const Heightmap bound = MarsProcessor(body.navigability.kappa).project(r.initial);
  const double over = (r.final_terrain.heights() - bound.heights()).maxCoeff();
  EXPECT_LE(over, 1e-9) << name << ": the terrain rose above P_kappa of the initial terrain";
  EXPECT_TRUE(r.all_on_top) << name << ": not every robot reached the platform top in " << r.steps << " steps";
  if (!r.all_on_top) return;
  const NavigabilityProcessor nav({body.navigability.kappa, body.navigability.delta_m, body.navigability.eps_m});
  const CellMask occ = nav.occupiable(r.final_terrain);
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const CellIndex start = *r.final_terrain.cell_at(starts[i]);
    const CellIndex end = *r.final_terrain.cell_at(r.final_positions[i]);
    EXPECT_EQ(NavigabilityProcessor::navigable_from(occ, start)(end.row, end.col), 1)
        << name << ": robot " << i + 1 << " has no navigable way back to its start";
    EXPECT_GE(r.final_terrain(end), kPlatformH - 1e-12);
  }
  // Deposited volume against the MARS target volume of the paths actually driven (global gap, initial terrain).
  const Heightmap gap = MarsProcessor(body.navigability.kappa).gap(r.initial);
  std::vector<CellIndex> driven;
  for (const auto& t : r.trajectories) driven.insert(driven.end(), t.begin(), t.end());
  const double target =
      deposition_target_volume(gap, path_footprint(gap.geometry(), driven, body.navigability.delta_m));
  std::string tops;
  for (int s : r.steps_to_top) tops += std::to_string(s) + " ";
  std::printf(
      "[closed loop] %s: steps to the top per robot: %s| run %d steps | deposited %.3f m^3 | MARS target "
      "of the driven paths %.3f m^3 (ratio %.2f) | refills %d | decide %.2f ms mean, %.2f ms max\n",
      name, tops.c_str(), r.steps, r.deposited_m3, target, r.deposited_m3 / target, r.refills, r.decide_ms_mean,
      r.decide_ms_max);
  // Filling the gap under the driven footprint is necessary for a navigable path; more than 3x is waste.
  EXPECT_GT(r.deposited_m3, 0.5 * target);
  EXPECT_LT(r.deposited_m3, 3.0 * target);
}

TEST(ClosedLoop, OneRobotClimbsThePlatformKappa05) {
  const auto body = husky(0.5, 10.0);
  const std::vector<Position> starts{{1.5, 4.0}}, targets{{10.0, 4.0}};
  const LoopResult r = run_loop(body, starts, targets, 300);
  check_and_report("kappa 0.5, 1 robot", body, starts, r);
}

TEST(ClosedLoop, OneRobotClimbsThePlatformKappa03) {
  // The 5 m ramp is longer than the robot sees (4 m) when it first meets the platform: it must back off.
  const auto body = husky(0.3, 10.0);
  const std::vector<Position> starts{{1.5, 4.0}}, targets{{10.0, 4.0}};
  const LoopResult r = run_loop(body, starts, targets, 500);
  check_and_report("kappa 0.3, 1 robot", body, starts, r);
}

TEST(ClosedLoop, ThreeRobotsShareARampKappa03) {
  // 1.3 m apart: their footprints (1.1 m wide) nearly touch and their reaches overlap (territories split them).
  const auto body = husky(0.3, 10.0);
  const std::vector<Position> starts{{1.5, 2.5}, {1.5, 3.8}, {1.5, 5.1}};
  const std::vector<Position> targets{{10.0, 2.5}, {10.0, 3.8}, {10.0, 5.1}};
  const LoopResult r = run_loop(body, starts, targets, 600);
  check_and_report("kappa 0.3, 3 robots 1.3 m apart", body, starts, r);
}

TEST(ClosedLoop, TwoRobotsSideBySideKappa05) {
  // 1 m apart (one body length): their reach overlaps, territories split the cells between them.
  const auto body = husky(0.5, 10.0);
  const std::vector<Position> starts{{1.5, 3.5}, {1.5, 4.5}}, targets{{10.0, 3.5}, {10.0, 4.5}};
  const LoopResult r = run_loop(body, starts, targets, 400);
  check_and_report("kappa 0.5, 2 robots 1 m apart", body, starts, r);
}

TEST(ClosedLoop, RefillsAtTheBaseWhenMaterialRunsOut) {
  const auto body = husky(0.5, 0.8);  // a third of what the ramp needs
  const std::vector<Position> starts{{1.5, 4.0}}, targets{{10.0, 4.0}};
  const LoopResult r = run_loop(body, starts, targets, 600);
  check_and_report("kappa 0.5, 1 robot, 0.8 m^3 capacity", body, starts, r);
  EXPECT_GE(r.refills, 2);
}

TEST(ClosedLoop, IsDeterministic) {
  const auto body = husky(0.5, 10.0);
  const std::vector<Position> starts{{1.5, 3.0}, {1.5, 4.6}}, targets{{10.0, 3.0}, {10.0, 4.6}};
  const LoopResult a = run_loop(body, starts, targets, 400);
  const LoopResult b = run_loop(body, starts, targets, 400);
  ASSERT_TRUE(a.all_on_top);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.trajectories, b.trajectories);
  EXPECT_TRUE(a.final_terrain.heights() == b.final_terrain.heights());  // bit for bit
  EXPECT_EQ(a.states, b.states);
}

/// Path builders (the construction pipeline) leave the base until a payload (kappa 0.25, 2 m wide) has a navigable
/// way from the base to the target on the mini world's terrain, checked every 10 steps as the world server does.
TEST(ClosedLoop, PathBuildersLayAPathForAPayload) {
  constexpr double kHeightM = 0.75;
  const Position base{1.0, 4.0}, target{10.0, 4.0};
  test::MiniWorld world(platform_terrain(kHeightM), 16, base, 1.0);
  const Heightmap initial = world.terrain();
  const RobotBody body = husky(0.3, 0.5);
  RobotType type;
  type.behaviour = "path_builder";
  type.body = body;
  type.construction = NavigabilityParams{0.25, 3.0, body.navigability.eps_m};
  type.pipeline.separation_m = 2.0;
  const NavigabilityProcessor payload({0.25, 2.0, 0.05});
  const std::vector<Position> starts{{1.5, 4.0}, {1.0, 3.2}, {0.6, 4.6}};
  std::vector<std::unique_ptr<PathBuilder>> builders;
  for (std::uint32_t id = 1; id <= starts.size(); ++id) {
    AgentContext c;
    c.agent_id = id;
    c.session = 2000 + id;
    c.type = type;
    c.neighbour_keep_out_m = neighbour_keep_out_m(body.navigability.delta_m, body.max_step_m);
    builders.push_back(std::make_unique<PathBuilder>(c));
    builders.back()->on_admission(world.admit(id, c.session, body, starts[id - 1], target));
  }
  const CellIndex from = *initial.cell_at(base), to = *initial.cell_at(target);
  int steps = 0, refills = 0;
  bool done = false;
  for (; steps < 2000 && !done; ++steps) {
    std::vector<protocol::ActionRequest> requests;
    for (std::uint32_t id = 1; id <= builders.size(); ++id) {
      requests.push_back(builders[id - 1]->decide(world.frame_for(id)));
      refills += requests.back().refill ? 1 : 0;
    }
    const auto reasons = world.apply_step(requests);
    for (std::size_t i = 0; i < reasons.size(); ++i)
      ASSERT_EQ(reasons[i], "") << "step " << steps << ": robot " << i + 1 << " in " << requests[i].state;
    if (steps % 10 == 9)
      done = NavigabilityProcessor::navigable_from(payload.occupiable(world.terrain()), from)(to.row, to.col) == 1;
  }
  double deposited_m3 = 0.0;
  for (const auto& [id, r] : world.robots()) deposited_m3 += r.deposited_m3;
  std::printf(
      "[closed loop] path builders, 3 robots, %.2f m platform: payload path after %d steps | deposited "
      "%.3f m^3 | refills %d\n",
      kHeightM, steps, deposited_m3, refills);
  EXPECT_TRUE(done) << "no navigable way for the payload after " << steps << " steps";
  EXPECT_GE(refills, 1);
  // The builders only fill the MARS gap at the construction kappa.
  const Heightmap bound = MarsProcessor(0.25).project(initial);
  EXPECT_LE((world.terrain().heights() - bound.heights()).maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace marsala::agent
