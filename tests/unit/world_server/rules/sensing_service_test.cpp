#include "marsala/world_server/rules/sensing_service.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>

#include "marsala/core/error.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::kLayer;
using testing::request_for;
using testing::small_scenario;

/// A 50 x 70 grid of 0.1 m cells (7 x 5 m) with distinct random heights; tiles of 16: 4 x 5 tiles, the last tile
/// row 2 cells high and the last tile column 6 cells wide.
WorldState sensing_state() {
  GridGeometry g;
  g.rows = 50;
  g.cols = 70;
  g.cell_size_m = 0.1;
  Heightmap h(g, 0.0);
  std::mt19937_64 rng(3);
  for (long long i = 0; i < h.size(); ++i) h.data()[i] = std::uniform_real_distribution<double>(0.0, 0.01)(rng);
  WorldState w = make_world_state(small_scenario(), h, 3);
  for (std::uint32_t id = 1; id <= 3; ++id) admit(w, testing::hello_for(w, id, 50 + id));
  w.agent(1).position.x = 6.65;  // sensing 1 m: the square [5.65, 7.65] x [-0.65, 1.35]
  w.agent(1).position.y = 0.35;
  w.agent(2).position.x = 6.65;  // 1.5 m north of agent 1: exactly its proximity range
  w.agent(2).position.y = 1.85;
  w.agent(3).position.x = 5.0;  // 1.65 m west of agent 1
  w.agent(3).position.y = 0.35;
  return w;
}

std::set<std::pair<int, int>> tile_ids(const protocol::SensorFrame& f) {
  std::set<std::pair<int, int>> out;
  for (const auto& t : f.tiles) out.insert({t.tile_row, t.tile_col});
  return out;
}

void expect_heights_match(const WorldState& w, const protocol::TerrainTile& t) {
  ASSERT_EQ(t.heights.size(), static_cast<std::size_t>(t.rows) * t.cols);
  for (int r = 0; r < t.rows; ++r)
    for (int c = 0; c < t.cols; ++c)
      ASSERT_EQ(t.heights[r * t.cols + c], w.terrain(t.tile_row * 16 + r, t.tile_col * 16 + c));  // bit for bit
}

TEST(SensingService, FirstFrameCarriesEveryTileInRangeWithEdgeTilesSmaller) {
  WorldState w = sensing_state();
  SensingService sensing(w);
  const protocol::SensorFrame f = sensing.frame_for(w, 1);
  // Tile columns 3 [4.8, 6.4] and 4 [6.4, 7.0] m; tile rows 2 [0.2, 1.8] and 3 [0, 0.2] m.
  EXPECT_EQ(tile_ids(f), (std::set<std::pair<int, int>>{{2, 3}, {2, 4}, {3, 3}, {3, 4}}));
  for (const auto& t : f.tiles) {
    EXPECT_EQ(t.rows, t.tile_row == 3 ? 2 : 16);
    EXPECT_EQ(t.cols, t.tile_col == 4 ? 6 : 16);
    expect_heights_match(w, t);
  }
  EXPECT_EQ(f.agent_id, 1u);
  EXPECT_EQ(f.step, 0u);
  EXPECT_EQ(f.x_m, 6.65);
  EXPECT_EQ(f.y_m, 0.35);
  EXPECT_EQ(f.z_m, w.agent(1).z_m);
  EXPECT_EQ(f.material_m3, 0.05);
  EXPECT_EQ(f.last_result, protocol::ActionResult::kNone);
  EXPECT_FALSE(f.run_over);
  EXPECT_TRUE(sensing.frame_for(w, 1, true).run_over);
}

TEST(SensingService, LaterFramesCarryOnlyChangedOrNewTiles) {
  WorldState w = sensing_state();
  SensingService sensing(w);
  sensing.frame_for(w, 1);
  EXPECT_TRUE(sensing.frame_for(w, 1).tiles.empty());

  // Agent 1 deposits 1 m west of itself: cell (46, 56), tile (2, 3).
  protocol::ActionRequest r = request_for(w, 1);
  r.depositions = {{46, 56, kLayer}};
  const double before = w.terrain(46, 56);
  apply_step(w, std::vector<protocol::ActionRequest>{r, request_for(w, 2), request_for(w, 3)});
  ASSERT_EQ(w.terrain(46, 56), before + kLayer);
  const protocol::SensorFrame f = sensing.frame_for(w, 1);
  EXPECT_EQ(f.step, 1u);
  EXPECT_EQ(f.last_result, protocol::ActionResult::kAccepted);
  ASSERT_EQ(tile_ids(f), (std::set<std::pair<int, int>>{{2, 3}}));
  expect_heights_match(w, f.tiles[0]);
  EXPECT_TRUE(sensing.frame_for(w, 1).tiles.empty());

  // Agent 3 never got a frame: everything in its range, the changed tile included.
  const protocol::SensorFrame first_of_3 = sensing.frame_for(w, 3);  // square [4.0, 6.0] x [-0.65, 1.35]
  EXPECT_EQ(tile_ids(first_of_3), (std::set<std::pair<int, int>>{{2, 2}, {2, 3}, {3, 2}, {3, 3}}));

  // Moving north: only the tiles it has not seen.
  w.agent(1).position.y = 1.05;  // square y [0.05, 2.05]: tile rows 1 [1.8, 3.4], 2 and 3
  EXPECT_EQ(tile_ids(sensing.frame_for(w, 1)), (std::set<std::pair<int, int>>{{1, 3}, {1, 4}}));
  sensing.forget(1);
  EXPECT_EQ(sensing.frame_for(w, 1).tiles.size(), 6u);
}

TEST(SensingService, NeighboursWithinProximityRangeOnly) {
  WorldState w = sensing_state();
  SensingService sensing(w);
  protocol::SensorFrame f = sensing.frame_for(w, 1);
  ASSERT_EQ(f.neighbours.size(), 1u);  // agent 2 at exactly 1.5 m; agent 3 at 1.65 m is out
  EXPECT_EQ(f.neighbours[0].agent_id, 2u);
  EXPECT_EQ(f.neighbours[0].position.x, 6.65);
  EXPECT_EQ(f.neighbours[0].position.y, 1.85);
  EXPECT_EQ(f.neighbours[0].z_m, w.agent(2).z_m);
  f = sensing.frame_for(w, 3);
  EXPECT_TRUE(f.neighbours.empty());
  w.agent(3).position.x = 5.2;  // now 1.45 m from agent 1
  f = sensing.frame_for(w, 1);
  ASSERT_EQ(f.neighbours.size(), 2u);
  EXPECT_EQ(f.neighbours[0].agent_id, 2u);
  EXPECT_EQ(f.neighbours[1].agent_id, 3u);
  drop_agent(w, 2, "test");
  f = sensing.frame_for(w, 1);
  ASSERT_EQ(f.neighbours.size(), 1u);
  EXPECT_EQ(f.neighbours[0].agent_id, 3u);
  EXPECT_THROW(sensing.frame_for(w, 4), InvalidArgument);
}

/// The small scenario on flat ground 0.2 m high, agent 1 with a sensor of its own, agents 2 and 3 ground truth.
WorldState scanning_state(const SensorSpec& sensor) {
  scenario::Scenario s = small_scenario(R"(robot_type { name: "scanner" })");
  s.robot_types.back().sensor = sensor;
  s.slots[0].robot_type = "scanner";
  WorldState w = make_world_state(s, testing::flat_terrain(0.2), 3);
  for (std::uint32_t id = 1; id <= 3; ++id) admit(w, testing::hello_for(w, id, 70 + id));
  return w;
}

// A laser robot gets its scan instead of tiles, every scan_every_steps steps, the same points for the same seed,
// agent and step; the others keep their tiles.
TEST(SensingService, ALaserRobotGetsPointsInsteadOfTiles) {
  SensorSpec laser = sensor_defaults(SensorKind::kLaser);
  laser.scan_every_steps = 2;
  WorldState w = scanning_state(laser);
  SensingService sensing(w);
  const protocol::SensorFrame f = sensing.frame_for(w, 1);
  EXPECT_TRUE(f.scanned);
  EXPECT_TRUE(f.tiles.empty());
  ASSERT_FALSE(f.points.empty());
  // Every point on the flat ground 0.2 m, seen from 0.5 m above it at the robot's start.
  for (const ScanPoint& p : f.points) EXPECT_NEAR(f.z_m + laser.mount_height_m + p.z_m, 0.2, 0.08);
  EXPECT_EQ(f.points, cast_scan(w.terrain, sensor_origin(w.terrain, f.x_m, f.y_m, laser), w.agent(1).heading_rad,
                                laser, scan_seed(w.seed, 1, 0)));
  const protocol::SensorFrame other = sensing.frame_for(w, 2);
  EXPECT_FALSE(other.scanned);
  EXPECT_TRUE(other.points.empty());
  EXPECT_FALSE(other.tiles.empty());

  apply_step(w, std::vector<protocol::ActionRequest>{});  // step 1: no scan
  const protocol::SensorFrame odd = sensing.frame_for(w, 1);
  EXPECT_FALSE(odd.scanned);
  EXPECT_TRUE(odd.points.empty());
  EXPECT_TRUE(odd.tiles.empty());
  apply_step(w, std::vector<protocol::ActionRequest>{});  // step 2: a scan, with other noise
  const protocol::SensorFrame even = sensing.frame_for(w, 1);
  EXPECT_TRUE(even.scanned);
  EXPECT_NE(even.points, f.points);
  EXPECT_FALSE(sensing.frame_for(w, 1, true).scanned);  // run over: nothing to sense for
}

// The camera looks along the heading: towards the target at first, then along the last motion of non-zero length.
TEST(SensingService, TheCameraLooksAlongTheRobotsHeading) {
  WorldState w = scanning_state(sensor_defaults(SensorKind::kRgbd));
  const AgentRecord& me = w.agent(1);
  EXPECT_NEAR(me.heading_rad, std::atan2(2.05 - 1.05, 3.05 - 1.05), 1e-12);  // start (1.05, 1.05), target (3.05, 2.05)
  SensingService sensing(w);
  // Every point within half the field of view (43.5 deg) of the heading, and some near each edge of it.
  const auto expect_facing = [](const protocol::SensorFrame& f, double heading) {
    ASSERT_FALSE(f.points.empty());
    double lowest = 1.0, highest = -1.0;
    for (const ScanPoint& p : f.points) {
      const double off = std::remainder(std::atan2(p.y_m, p.x_m) - heading, 2.0 * 3.14159265358979323846);
      lowest = std::min(lowest, off);
      highest = std::max(highest, off);
    }
    EXPECT_GE(lowest, -0.7593 - 1e-4);
    EXPECT_LE(highest, 0.7593 + 1e-4);
    EXPECT_LT(lowest, -0.6);
    EXPECT_GT(highest, 0.6);
  };
  expect_facing(sensing.frame_for(w, 1), me.heading_rad);
  // A move north: the heading turns north; a motion of zero length leaves it.
  apply_step(w, std::vector<protocol::ActionRequest>{testing::move_to(w, 1, 1.05, 1.25)});
  EXPECT_NEAR(w.agent(1).heading_rad, 0.5 * 3.14159265358979323846, 1e-12);
  apply_step(w, std::vector<protocol::ActionRequest>{testing::move_to(w, 1, 1.05, 1.25)});
  EXPECT_NEAR(w.agent(1).heading_rad, 0.5 * 3.14159265358979323846, 1e-12);
  expect_facing(sensing.frame_for(w, 1), 0.5 * 3.14159265358979323846);
}

TEST(TileLayout, SizesAndSquaresAgreeWithABruteForceReference) {
  GridGeometry g;
  g.rows = 37;
  g.cols = 53;
  g.xll_m = -2.0;
  g.yll_m = 10.0;
  g.cell_size_m = 0.25;
  const TileLayout layout(g, 8);
  ASSERT_EQ(layout.tile_rows(), 5);
  ASSERT_EQ(layout.tile_cols(), 7);
  int cells = 0;
  for (int i = 0; i < layout.tile_count(); ++i) cells += layout.tile(i).rows * layout.tile(i).cols;
  EXPECT_EQ(cells, 37 * 53);  // the tiles cut the grid exactly
  EXPECT_EQ(layout.tile(layout.index(4, 6)).rows, 5);
  EXPECT_EQ(layout.tile(layout.index(4, 6)).cols, 5);
  EXPECT_EQ(layout.index_of({36, 52}), layout.index(4, 6));

  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    const Position p{std::uniform_real_distribution<double>(-6.0, 16.0)(rng),
                     std::uniform_real_distribution<double>(5.0, 24.0)(rng)};
    const double r = std::uniform_real_distribution<double>(0.0, 4.0)(rng);
    std::vector<int> want;
    for (int i = 0; i < layout.tile_count(); ++i) {
      const Tile t = layout.tile(i);
      // The tile's rectangle from its corner cells' centres.
      const Position nw = g.cell_center(t.first_cell);
      const Position se = g.cell_center({t.first_cell.row + t.rows - 1, t.first_cell.col + t.cols - 1});
      const double x0 = nw.x - 0.125, x1 = se.x + 0.125, y0 = se.y - 0.125, y1 = nw.y + 0.125;
      if (x0 <= p.x + r && x1 >= p.x - r && y0 <= p.y + r && y1 >= p.y - r) want.push_back(i);
    }
    ASSERT_EQ(layout.tiles_in_square(p, r), want) << "trial " << trial;
  }
  EXPECT_TRUE(layout.tiles_in_square({100.0, 100.0}, 1.0).empty());
  EXPECT_EQ(layout.tiles_in_square({0.0, 15.0}, 1e9).size(), 35u);
  EXPECT_THROW(TileLayout(g, 0), InvalidArgument);
}

}  // namespace
}  // namespace marsala::world_server
