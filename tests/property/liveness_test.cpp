// Liveness of solid robots (docs/runtime.md#right-of-way): many short randomized runs, in-process (the world's rules
// and the real behaviours, tests/support/lockstep_sim.hpp), 2-6 robots on fields cut by walls into corridors about
// one and a half bodies wide (every third case a wall across the field with doors one body wide, where robots meet
// head on), random starts and targets on open ground. Every run must end with every robot on its
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

/// A field cut in two by a wall across it from border to border (north-south or east-west), with 1-2 doors 1.2-1.6 m
/// wide (two bodies cannot pass in one: robots crossing each way meet head on in a door), and 0-2 random walls.
Heightmap door_field(std::mt19937& rng) {
  Heightmap h = field(rng, std::uniform_int_distribution<int>(0, 2)(rng));
  const bool across_rows = std::uniform_int_distribution<int>(0, 1)(rng) == 0;  // a north-south wall
  const int length = across_rows ? kRows : kCols, at = across_rows ? std::uniform_int_distribution<int>(15, 35)(rng)
                                                                  : std::uniform_int_distribution<int>(10, 20)(rng);
  std::vector<bool> open(static_cast<std::size_t>(length), false);
  const int doors = std::uniform_int_distribution<int>(1, 2)(rng);
  for (int d = 0; d < doors; ++d) {
    const int width = std::uniform_int_distribution<int>(6, 8)(rng);
    const int from = std::uniform_int_distribution<int>(2, length - 2 - width)(rng);
    for (int k = from; k < from + width; ++k) open[static_cast<std::size_t>(k)] = true;
  }
  for (int k = 0; k < length; ++k)
    if (!open[static_cast<std::size_t>(k)]) h(across_rows ? CellIndex{k, at} : CellIndex{at, k}) = 0.25;
  return h;
}

struct Case {
  scenario::Scenario scenario;
  Heightmap terrain;
  std::string text;  // what to print when it fails
};

/// True when every robot can drive from its start to its target keeping its body clear of the bodies of robots
/// standing on every other start and target (a well-formed field: robots that wait at their starts or stand on their
/// targets block nobody), as the agents judge clearance (body_clearance.hpp: the two radii and a step). Only then is a
/// case solvable whatever order the robots arrive in; the right of way needs no more (docs/runtime.md#right-of-way).
bool well_formed(const Heightmap& terrain, const RobotBody& body, const std::vector<scenario::AgentSlot>& slots) {
  const CellMask occupiable = NavigabilityProcessor(body.navigability).occupiable(terrain);
  // The two radii, a step (the disc around a lower id) and a step more: a robot parked "on" its target stands within
  // the target radius of it (a cell here).
  const double keep_m = body.navigability.delta_m + 2.0 * body.max_step_m;
  for (const auto& slot : slots) {
    CellMask free = occupiable;
    for (int r = 0; r < free.rows(); ++r)
      for (int c = 0; c < free.cols(); ++c)
        for (const auto& other : slots)
          for (const Position e : {other.start, other.target})
            if (other.id != slot.id && std::hypot(terrain.cell_center({r, c}).x - e.x, terrain.cell_center({r, c}).y - e.y) <= keep_m + 1e-9) free(r, c) = 0;
    const CellIndex from = *terrain.cell_at(slot.start), to = *terrain.cell_at(slot.target);
    if (free(from.row, from.col) == 0 || NavigabilityProcessor::navigable_from(free, from)(to.row, to.col) == 0)
      return false;
  }
  return true;
}

/// A random case: robots start and end on open cells (clear of walls by a body length) at least 1.5 bodies from
/// every other start and target, on a well-formed field. nullopt when the draw finds no room or the field is not
/// well formed.
std::optional<Case> random_case(std::uint64_t seed) {
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  // Every third seed a field with a wall across and doors, else one of random walls.
  const bool doors = seed % 3 == 0;
  Case k{{}, doors ? door_field(rng) : field(rng, std::uniform_int_distribution<int>(2, 5)(rng)), ""};
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
  if (!well_formed(k.terrain, type.body, s.slots)) return std::nullopt;
  s.completion = scenario::CompletionKind::kAgentsAtGoal;
  s.goal.area = {0.0, 0.0, kCols * kCell, kRows * kCell};
  s.goal.target_radius_m = kCell;
  s.base = {{0.3, 0.3}, 0.2};
  s.tile_size = 16;
  s.seed = seed;
  k.text = fmt::format("seed {}: {} robots{}", seed, robots, doors ? " (a wall across with doors)" : "");
  for (const auto& slot : s.slots) k.text += fmt::format(", {} {} -> {}", slot.id, slot.start, slot.target);
  k.scenario.right_of_way = true;  // the scenario asks for it; team_completes() decides whether the team keeps it
  return k;
}

/// Runs slot `id` of `k` alone (as agent 1) for at most `steps`; true when it ends on its target.
bool completes_alone(const Case& k, std::uint64_t steps, std::uint32_t id) {
  scenario::Scenario s = k.scenario;
  s.slots = {s.slots[id - 1]};
  s.slots[0].id = 1;
  LockstepSim sim(s, k.terrain, static_cast<std::uint32_t>(s.slots.size()), true);
  while (sim.state().step < steps && !world_server::is_completed(sim.state())) sim.step();
  return world_server::is_completed(sim.state());
}

/// An environment variable as a number, or `fallback` when it is not set.
long long env_number(const char* name, long long fallback) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::atoll(v) : fallback;
}

/// Prints the field of `k`, northmost row first: '#' a wall, 'a'.. a robot's start, 'A'.. its target, '.' ground.
void print_field(const Case& k) {
  std::vector<std::string> rows(kRows, std::string(kCols, '.'));
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c)
      if (k.terrain({r, c}) > 0.0) rows[r][c] = '#';
  for (const auto& slot : k.scenario.slots) {
    const CellIndex s = *k.terrain.cell_at(slot.start), t = *k.terrain.cell_at(slot.target);
    rows[s.row][s.col] = static_cast<char>('a' + slot.id - 1);
    rows[t.row][t.col] = static_cast<char>('A' + slot.id - 1);
  }
  for (const std::string& row : rows) fmt::print("{}\n", row);
}

/// Runs the whole team of `k` for at most `steps`, keeping the right of way when `right_of_way`; with `every` > 0
/// prints every robot each `every` steps (to look inside one case: MARSALA_LIVENESS_SEED, MARSALA_LIVENESS_EVERY).
/// True when every robot ends on its target.
bool team_completes(const Case& k, std::uint64_t steps, bool right_of_way, long long every) {
  LockstepSim sim(k.scenario, k.terrain, static_cast<std::uint32_t>(k.scenario.slots.size()), right_of_way);
  if (every > 0) print_field(k);
  while (sim.state().step < steps && !world_server::is_completed(sim.state())) {
    sim.step();
    if (every <= 0 || sim.state().step % static_cast<std::uint64_t>(every) != 0) continue;
    std::string line;
    for (const auto& a : sim.state().agents) line += fmt::format(" {}@{} {}", a.id, a.position, a.state);
    fmt::print("{}:{}\n", sim.state().step, line);
  }
  return world_server::is_completed(sim.state());
}

// The property: on a well-formed field, a team whose every robot reaches its target alone reaches all targets
// together. A case that fails is looked at robot by robot: when one of them cannot do it alone either (the builder
// then builds its way, not drives it), the case says nothing about the right of way and does not count; every
// counted case must complete. MARSALA_LIVENESS_RUNS sets the number of counted runs (default 200),
// MARSALA_LIVENESS_PROTOCOL=0 runs the teams without the right of way (the test then fails).
TEST(Liveness, RobotsInCorridorsAlwaysReachTheirTargets) {
  const long long wanted = env_number("MARSALA_LIVENESS_RUNS", 200), only = env_number("MARSALA_LIVENESS_SEED", 0);
  const long long every = only > 0 ? env_number("MARSALA_LIVENESS_EVERY", 20) : 0;
  const bool right_of_way = env_number("MARSALA_LIVENESS_PROTOCOL", 1) != 0;  // 0: without it, to see the test fail
  constexpr std::uint64_t kSteps = 600;  // the longest route is about 15 m, 75 steps, alone
  long long runs = 0, failed = 0, not_alone = 0;
  for (std::uint64_t seed = only > 0 ? static_cast<std::uint64_t>(only) : 1; runs < wanted; ++seed) {
    const auto k = random_case(seed);
    if (!k) {
      if (only > 0) break;
      continue;
    }
    if (team_completes(*k, kSteps, right_of_way, every)) {
      ++runs;
    } else {
      std::vector<std::uint32_t> alone_fail;
      for (const auto& slot : k->scenario.slots)
        if (!completes_alone(*k, kSteps, slot.id)) alone_fail.push_back(slot.id);
      if (!alone_fail.empty()) {
        ++not_alone;
      } else {
        ++runs, ++failed;
        ADD_FAILURE() << k->text << ": not all on their targets after " << kSteps << " steps";
      }
    }
    if (only > 0) break;
  }
  EXPECT_EQ(failed, 0) << "of " << runs << " runs (" << not_alone
                       << " more cases left out: a robot of them fails alone)";
  fmt::print("liveness: {} runs, {} failed, {} cases left out (a robot fails alone)\n", runs, failed, not_alone);
}

}  // namespace
}  // namespace marsala::test
