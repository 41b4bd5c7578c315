#pragma once
// Helpers for agent unit tests: an agent map that knows a whole terrain, tiles cut from a terrain, bodies, and the
// context, admission and frames a behaviour is driven with.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::test {

/// The behaviours' test world: a flat 6 x 10 m terrain at 0.1 m cells with a 1.5 m platform from x = 7 m eastwards.
inline Heightmap platform_world() {
  Heightmap h({60, 100, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 70; c < h.cols(); ++c) h(r, c) = 1.5;
  return h;
}

/// The tile (tr, tc) of `h` cut in tile_size tiles, as the world sends it.
inline TerrainTile cut_tile(const Heightmap& h, int tile_size, int tr, int tc) {
  TerrainTile t;
  t.tile_row = tr;
  t.tile_col = tc;
  t.rows = std::min(tile_size, h.rows() - tr * tile_size);
  t.cols = std::min(tile_size, h.cols() - tc * tile_size);
  for (int r = 0; r < t.rows; ++r)
    for (int c = 0; c < t.cols; ++c) t.heights.push_back(h(tr * tile_size + r, tc * tile_size + c));
  return t;
}

/// An agent map that has been sent every tile of `h`.
inline executive::MappingSystem full_map(const Heightmap& h, int tile_size = 16) {
  executive::MappingSystem map(h.geometry(), tile_size);
  for (int tr = 0; tr * tile_size < h.rows(); ++tr)
    for (int tc = 0; tc * tile_size < h.cols(); ++tc) map.integrate_tile(cut_tile(h, tile_size, tr, tc));
  return map;
}

/// A neighbour as a frame reports it: agent `id` standing at (x, y) [m] (height 0).
/// A neighbour with a 1 m body (radius 0.5 m) at (x, y) [m].
inline Neighbour neighbour_at(std::uint32_t id, double x, double y) { return {id, x, y, 0.0, 0.5}; }

/// A Husky-like body: delta 1 m, eps 5 cm, 20 cm steps, 0.02 m^3 per step, 1.5 m reach, 5 cm cubes.
inline RobotBody husky(double kappa = 0.5) {
  RobotBody b;
  b.navigability.kappa = kappa;
  b.navigability.delta_m = 1.0;
  b.navigability.eps_m = 0.05;
  b.max_step_m = 0.2;
  b.max_deposit_m3 = 0.02;
  b.material_capacity_m3 = 10.0;
  b.reach_m = 1.5;
  b.sensing_range_m = 4.0;
  b.proximity_range_m = 3.0;
  b.cube_size_m = 0.05;
  return b;
}

/// A local map with hand-made heights and gap (all known, placed at the world's origin), masks from the
/// navigability processor.
inline deliberative::LocalMap make_local_map(const Heightmap& heights, const Heightmap& gap, NavigabilityParams nav,
                                             CellIndex robot, std::optional<CellIndex> origin) {
  deliberative::LocalMap m;
  m.world = heights.geometry();
  m.offset = {0, 0};
  m.heights = heights;
  m.known = CellMask::Ones(heights.rows(), heights.cols());
  m.blind = CellMask::Zero(heights.rows(), heights.cols());
  m.gap = gap;
  m.occupiable = NavigabilityProcessor(nav).occupiable(heights);
  m.navigable = NavigabilityProcessor::navigable_from(m.occupiable, robot);
  m.robot = robot;
  m.origin = origin;
  m.goal = robot;
  return m;
}

/// The context of agent `id` (session 77) with `body` and the keep-out of a team of such bodies.
inline AgentContext agent_context(std::uint32_t id, const RobotBody& body) {
  AgentContext c;
  c.agent_id = id;
  c.session = 77;
  c.type.body = body;
  c.neighbour_keep_out_m = neighbour_keep_out_m(body.navigability.delta_m, body.max_step_m);
  return c;
}

/// The world's admission of `c` on `grid` in 16-cell tiles, heading for `target` [m], with its base station at
/// `base` [m] (radius 0.5 m).
inline protocol::Admission admission_on(const AgentContext& c, const GridGeometry& grid, Position target,
                                        Position base) {
  protocol::Admission a;
  a.agent_id = c.agent_id;
  a.session = c.session;
  a.accepted = true;
  a.run_id = "test";
  a.assignment.world.rows = grid.rows;
  a.assignment.world.cols = grid.cols;
  a.assignment.world.xll_m = grid.xll_m;
  a.assignment.world.yll_m = grid.yll_m;
  a.assignment.world.cell_size_m = grid.cell_size_m;
  a.assignment.tile_size = 16;
  a.assignment.target.x = target.x;
  a.assignment.target.y = target.y;
  a.assignment.base.x = base.x;
  a.assignment.base.y = base.y;
  a.assignment.base_radius_m = 0.5;
  return a;
}

/// The frame of step `step` for `c` at `pose` [m] with `material_m3` on board, carrying every 16-cell tile of `h`.
inline protocol::SensorFrame full_frame(const AgentContext& c, std::uint64_t step, Position pose, double material_m3,
                                        const Heightmap& h) {
  protocol::SensorFrame f;
  f.agent_id = c.agent_id;
  f.step = step;
  f.x_m = pose.x;
  f.y_m = pose.y;
  f.material_m3 = material_m3;
  for (int tr = 0; tr * 16 < h.rows(); ++tr)
    for (int tc = 0; tc * 16 < h.cols(); ++tc) f.tiles.push_back(cut_tile(h, 16, tr, tc));
  return f;
}

/// `f` with only the tile holding the point `p` [m] of `grid` (16-cell tiles): what a robot that sees no farther
/// than that tile would have.
inline protocol::SensorFrame keep_tile_at(protocol::SensorFrame f, const GridGeometry& grid, Position p) {
  const CellIndex cell = *grid.cell_at(p);
  std::vector<protocol::TerrainTile> kept;
  for (auto& t : f.tiles)
    if (t.tile_row == cell.row / 16 && t.tile_col == cell.col / 16) kept.push_back(std::move(t));
  f.tiles = std::move(kept);
  return f;
}

/// A scanning robot's frame of `step` for agent `id` at `robot` [m] (z_m [m] under it), with 1 m^3 on board and no
/// points yet.
inline protocol::SensorFrame scan_frame(std::uint32_t id, std::uint64_t step, Position robot, double z_m = 0.0) {
  protocol::SensorFrame f;
  f.agent_id = id;
  f.step = step;
  f.x_m = robot.x;
  f.y_m = robot.y;
  f.z_m = z_m;
  f.material_m3 = 1.0;
  f.scanned = true;
  return f;
}

}  // namespace marsala::agent::test
