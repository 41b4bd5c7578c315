// Liveness of solid robots (docs/runtime.md#right-of-way): many short randomized runs, in-process (the world's rules
// and the real behaviours, tests/support/lockstep_sim.hpp), 2-6 robots on fields cut by walls into corridors about
// one and a half bodies wide, random starts and targets on open ground. Every run must end with every robot on its
// target: a knot of robots that wait for each other never dissolves by luck, only by the protocol.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "lockstep_sim.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::test {
namespace {

constexpr double kCell = 0.2;    // [m]
constexpr double kDelta = 0.6;   // body length [m]
constexpr int kRows = 30, kCols = 50;  // 6 x 10 m

RobotType mover() {
  RobotType t;
  t.name = "mover";
  t.behaviour = "ramp_builder";
  t.body.navigability = {0.3, kDelta, 0.05};
  t.body.max_step_m = 0.2;
  t.body.max_deposit_m3 = 0.01;
  t.body.material_capacity_m3 = 50.0;  // no trips back: the runs are about meeting, not supply
  t.body.reach_m = 0.8;
  t.body.sensing_range_m = 2.0;
  t.body.proximity_range_m = 2.0;
  t.body.cube_size_m = 0.1;
  return t;
}

/// A field with `walls` random wall segments 0.25 m high (a step no body drives over; a ramp over one is cheap) (north-south or east-west, 2-4 m long) leaving corridors; the
/// border stays open ground.
Heightmap field(std::mt19937& rng, int walls) {
  Heightmap h({kRows, kCols, 0.0, 0.0, kCell}, 0.0);
  std::uniform_int_distribution<int> row(4, kRows - 5), col(4, kCols - 5), len(10, 20), dir(0, 1);
  for (int w = 0; w < walls; ++w) {
    const int r = row(rng), c = col(rng), n = len(rng);
    for (int k = 0; k < n; ++k) {
      const CellIndex cell = dir(rng) == 0 ? CellIndex{r, c + k} : CellIndex{r + k, c};
      if (cell.row > 1 && cell.col > 1 && cell.row < kRows - 2 && cell.col < kCols - 2) h(cell) = 0.25;
    }
  }
  return h;
}

struct Case {
  scenario::Scenario scenario;
  Heightmap terrain;
  std::string text;  // what to print when it fails
};

/// A random case: robots start and end on open cells (clear of walls by a body length) at least 1.5 bodies from
/// every other start and target, all in one navigable region. nullopt when the draw finds no room.
std::optional<Case> random_case(std::uint64_t seed) {
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  Case k{{}, field(rng, std::uniform_int_distribution<int>(2, 5)(rng)), ""};
  const RobotType type = mover();
  NavigabilityParams wide = type.body.navigability;
  wide.delta_m = 2.0 * kDelta;  // open ground: a ball twice the body's is level
  const CellMask open = NavigabilityProcessor(wide).occupiable(k.terrain);
  std::uniform_int_distribution<int> row(0, kRows - 1), col(0, kCols - 1);
  const int robots = std::uniform_int_distribution<int>(2, 6)(rng);
  std::vector<Position> taken;
  const auto draw = [&]() -> std::optional<Position> {
    for (int attempt = 0; attempt < 200; ++attempt) {
      const CellIndex c{row(rng), col(rng)};
      if (open(c.row, c.col) == 0) continue;
      const Position p = k.terrain.cell_center(c);
      bool clear = true;
      for (const Position q : taken) clear = clear && std::hypot(p.x - q.x, p.y - q.y) >= 1.5 * kDelta;
      if (!clear) continue;
      taken.push_back(p);
      return p;
    }
    return std::nullopt;
  };
  scenario::Scenario& s = k.scenario;
  s.name = "liveness";
  s.robot_types = {type};
  for (int i = 0; i < robots; ++i) {
    const auto start = draw(), target = draw();
    if (!start || !target) return std::nullopt;
    s.slots.push_back({static_cast<std::uint32_t>(i + 1), type.name, *start, *target});
  }
  const CellMask navigable =
      NavigabilityProcessor(type.body.navigability).navigable(k.terrain, *k.terrain.geometry().cell_at(s.slots[0].start));
  for (const auto& slot : s.slots)
    for (const Position p : {slot.start, slot.target}) {
      const CellIndex c = *k.terrain.geometry().cell_at(p);
      if (navigable(c.row, c.col) == 0) return std::nullopt;
    }
  s.completion = scenario::CompletionKind::kAgentsAtGoal;
  s.goal.area = {0.0, 0.0, kCols * kCell, kRows * kCell};
  s.goal.target_radius_m = kCell;
  s.base = {{0.3, 0.3}, 0.2};
  s.tile_size = 16;
  s.seed = seed;
  k.text = fmt::format("seed {}: {} robots", seed, robots);
  for (const auto& slot : s.slots) k.text += fmt::format(", {} {} -> {}", slot.id, slot.start, slot.target);
  return k;
}

/// Runs `k` with its first `robots` slots (or only slot `only` when > 0) for at most `steps`; true when complete.
bool completes(const Case& k, std::uint64_t steps, std::uint32_t only = 0) {
  scenario::Scenario s = k.scenario;
  if (only > 0) {
    s.slots = {s.slots[only - 1]};
    s.slots[0].id = 1;
  }
  LockstepSim sim(s, k.terrain, static_cast<std::uint32_t>(s.slots.size()));
  while (sim.state().step < steps && !world_server::is_completed(sim.state())) sim.step();
  return world_server::is_completed(sim.state());
}

TEST(Liveness, RobotsInCorridorsAlwaysReachTheirTargets) {
  const int kRuns = std::getenv("MARSALA_LIVENESS_RUNS") ? std::atoi(std::getenv("MARSALA_LIVENESS_RUNS")) : 200;
  constexpr std::uint64_t kSteps = 600;  // the longest route is about 30 m, 150 steps, alone
  int runs = 0, failed = 0;
  for (std::uint64_t seed = 1; runs < kRuns; ++seed) {
    auto k = random_case(seed);
    if (!k) continue;
    if (std::getenv("MARSALA_LIVENESS_SEED") && std::to_string(seed) != std::getenv("MARSALA_LIVENESS_SEED")) continue;
    ++runs;
    LockstepSim sim(k->scenario, k->terrain, static_cast<std::uint32_t>(k->scenario.slots.size()));
    while (sim.state().step < kSteps && !world_server::is_completed(sim.state())) {
      sim.step();
      if (std::getenv("MARSALA_LIVENESS_SEED") && sim.state().step % std::atoi(std::getenv("MARSALA_LIVENESS_EVERY") ? std::getenv("MARSALA_LIVENESS_EVERY") : "20") == 0) {
        std::string line;
        for (const auto& a : sim.state().agents)
          line += fmt::format(" {}@({:.2f},{:.2f}){} {}", a.id, a.position.x, a.position.y, a.state, a.last_reason);
        fmt::print("{}:{}\n", sim.state().step, line);
      }
    }
    if (world_server::is_completed(sim.state())) continue;
    ++failed;
    std::string where;
    for (const auto& a : sim.state().agents)
      where += fmt::format(" {}@{}({}{})", a.id, a.position, a.state, completes(*k, kSteps, a.id) ? "" : ", fails alone");
    ADD_FAILURE() << k->text << ": not all on their targets after " << kSteps << " steps:" << where;
  }
  EXPECT_EQ(failed, 0) << "of " << runs << " runs";
}

}  // namespace
}  // namespace marsala::test
