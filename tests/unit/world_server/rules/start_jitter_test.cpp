// Start jitter: seeded, deterministic, uniform in the disc, only onto occupiable cells, the slot's start as the
// fallback; make_world_state and the admission use the jittered start.

#include "marsala/world_server/rules/start_jitter.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/admission.hpp"
#include "support/navigability_brute_force.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

scenario::AgentSlot slot(std::uint32_t id, double x, double y) {
  scenario::AgentSlot s;
  s.id = id;
  s.start.x = x;
  s.start.y = y;
  return s;
}

RobotBody body() {
  RobotBody b;
  b.navigability.kappa = 0.3;
  b.navigability.delta_m = 0.5;
  b.navigability.eps_m = 0.05;
  return b;
}

TEST(StartJitter, SameSeedSameStartsOtherSeedsOrIdsOtherStarts) {
  const Heightmap flat(GridGeometry{60, 60, 0.0, 0.0, 0.1});
  const Position a = jittered_start(flat, slot(1, 3.0, 3.0), body(), 1.0, 42);
  const Position b = jittered_start(flat, slot(1, 3.0, 3.0), body(), 1.0, 42);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  const Position other_seed = jittered_start(flat, slot(1, 3.0, 3.0), body(), 1.0, 43);
  const Position other_id = jittered_start(flat, slot(2, 3.0, 3.0), body(), 1.0, 42);
  EXPECT_FALSE(a.x == other_seed.x && a.y == other_seed.y);
  EXPECT_FALSE(a.x == other_id.x && a.y == other_id.y);
  // No jitter: exactly the slot's start, whatever the seed.
  const Position none = jittered_start(flat, slot(1, 3.01, 2.99), body(), 0.0, 42);
  EXPECT_EQ(none.x, 3.01);
  EXPECT_EQ(none.y, 2.99);
}

TEST(StartJitter, OffsetsAreUniformInTheDisc) {
  // On flat ground every draw is kept: the first point of each stream. Uniform in the disc of radius R: mean offset
  // near 0, half the points within R / sqrt 2, a quarter in each quadrant.
  const Heightmap flat(GridGeometry{100, 100, 0.0, 0.0, 0.1});
  constexpr int kAgents = 4000;
  constexpr double kRadius = 2.0;
  double sx = 0.0, sy = 0.0;
  int inner = 0, north_east = 0;
  for (std::uint32_t id = 1; id <= kAgents; ++id) {
    const Position p = jittered_start(flat, slot(id, 5.0, 5.0), body(), kRadius, 7);
    const double dx = p.x - 5.0, dy = p.y - 5.0, d = std::sqrt(dx * dx + dy * dy);
    ASSERT_LE(d, kRadius + 1e-12) << id;
    sx += dx;
    sy += dy;
    inner += d <= kRadius / std::sqrt(2.0);
    north_east += dx > 0.0 && dy > 0.0;
  }
  // Standard errors: mean 2 / (2 sqrt 4000) = 0.016 m; fractions 0.008 and 0.007. Bounds are about 4 of them.
  EXPECT_NEAR(sx / kAgents, 0.0, 0.065);
  EXPECT_NEAR(sy / kAgents, 0.0, 0.065);
  EXPECT_NEAR(static_cast<double>(inner) / kAgents, 0.5, 0.032);
  EXPECT_NEAR(static_cast<double>(north_east) / kAgents, 0.25, 0.028);
}

TEST(StartJitter, OnlyOccupiableCellsOnTheGridAreChosen) {
  // A 1 m tall block covers x > 3 m: cells within delta/2 = 0.25 m of its edge and the block's top near the edge
  // are not occupiable; the top far from the edge is. Starts at the edge, jittered by 1 m.
  Heightmap h(GridGeometry{60, 60, 0.0, 0.0, 0.1});
  for (int r = 0; r < 60; ++r)
    for (int c = 30; c < 60; ++c) h(r, c) = 1.0;
  const CellMask occupiable = marsala::testing::occupiable_brute_force(h, {0.3, 0.5, 0.05});
  int moved = 0;
  for (std::uint32_t id = 1; id <= 300; ++id) {
    const Position p = jittered_start(h, slot(id, 3.0, 3.0), body(), 1.0, 99);
    const auto cell = h.cell_at(p);
    ASSERT_TRUE(cell) << id;
    EXPECT_EQ(occupiable(cell->row, cell->col), 1) << id;
    EXPECT_LE(std::hypot(p.x - 3.0, p.y - 3.0), 1.0 + 1e-12);
    moved += p.x != 3.0 || p.y != 3.0;
  }
  EXPECT_EQ(moved, 300);
  // Near the grid's corner, draws off the grid are skipped.
  for (std::uint32_t id = 1; id <= 100; ++id)
    EXPECT_TRUE(h.cell_at(jittered_start(h, slot(id, 0.02, 0.02), body(), 1.0, 5)));
}

TEST(StartJitter, WithNoOccupiableCellInReachTheSlotsStartStays) {
  // A checkerboard of 0 and 1 m: no cell is occupiable, so every draw fails.
  Heightmap h(GridGeometry{40, 40, 0.0, 0.0, 0.1});
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) h(r, c) = (r + c) % 2;
  const Position p = jittered_start(h, slot(3, 2.0, 2.0), body(), 0.8, 1);
  EXPECT_EQ(p.x, 2.0);
  EXPECT_EQ(p.y, 2.0);
  EXPECT_THROW(jittered_start(h, slot(3, 2.0, 2.0), body(), -0.1, 1), InvalidArgument);
  EXPECT_THROW(jittered_start(h, slot(3, 2.0, 2.0), body(), std::nan(""), 1), InvalidArgument);
}

TEST(StartJitter, TheWorldStateAndTheAdmissionUseTheJitteredStart) {
  const scenario::Scenario plain = testing::small_scenario();
  scenario::Scenario jittered = testing::small_scenario("start_jitter_m: 0.4\nseed: 17\n");
  const WorldState s = make_world_state(jittered, testing::flat_terrain(), 3);
  for (std::uint32_t id = 1; id <= 3; ++id) {
    const scenario::AgentSlot& sl = plain.slots[id - 1];
    const AgentRecord& a = s.agent(id);
    const Position expected = jittered_start(s.terrain, sl, a.type.body, 0.4, 17);
    EXPECT_EQ(a.start.x, expected.x);
    EXPECT_EQ(a.start.y, expected.y);
    EXPECT_EQ(a.position.x, expected.x);
    EXPECT_TRUE(a.start.x != sl.start.x || a.start.y != sl.start.y) << id;
    EXPECT_LE(std::hypot(a.start.x - sl.start.x, a.start.y - sl.start.y), 0.4 + 1e-12);
  }
  // Another seed, other starts; the admission reports the state's start.
  jittered.seed = 18;
  WorldState t = make_world_state(jittered, testing::flat_terrain(), 3);
  EXPECT_NE(t.agent(1).start.x, s.agent(1).start.x);
  const protocol::AgentHello hello = testing::hello_for(t, 2, 77);
  admit(t, hello);
  const protocol::Admission m = admission_message(t, hello, decide_admission(t, hello, false), "run");
  EXPECT_EQ(m.assignment.start.x, t.agent(2).start.x);
  EXPECT_EQ(m.assignment.start.y, t.agent(2).start.y);
  EXPECT_EQ(t.agent(2).position.x, t.agent(2).start.x);
}

}  // namespace
}  // namespace marsala::world_server
