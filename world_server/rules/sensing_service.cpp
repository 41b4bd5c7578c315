#include "marsala/world_server/rules/sensing_service.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/ray_caster.hpp"
#include "marsala/world_server/rules/arbiter.hpp"

namespace marsala::world_server {

SensingService::SensingService(const WorldState& state)
    : layout_(state.tiles()),
      seen_(state.agents.size(), std::vector<std::uint64_t>(static_cast<std::size_t>(layout_.tile_count()), kNever)) {}

void SensingService::forget(std::uint32_t id) {
  if (id >= 1 && id <= seen_.size()) std::fill(seen_[id - 1].begin(), seen_[id - 1].end(), kNever);
}

void SensingService::add_tiles(const WorldState& state, const AgentRecord& me, protocol::SensorFrame& f) {
  std::vector<std::uint64_t>& seen = seen_[me.id - 1];
  const Heightmap& terrain = state.terrain;
  for (int index : layout_.tiles_in_square(me.position, me.type.body.sensing_range_m)) {
    const std::uint64_t version = state.tile_versions[static_cast<std::size_t>(index)];
    if (seen[static_cast<std::size_t>(index)] == version) continue;
    seen[static_cast<std::size_t>(index)] = version;
    const Tile t = layout_.tile(index);
    TerrainTile tile;
    tile.tile_row = t.tile_row;
    tile.tile_col = t.tile_col;
    tile.rows = t.rows;
    tile.cols = t.cols;
    tile.heights.reserve(static_cast<std::size_t>(t.rows) * t.cols);
    for (int r = 0; r < t.rows; ++r)
      for (int c = 0; c < t.cols; ++c) tile.heights.push_back(terrain(t.first_cell.row + r, t.first_cell.col + c));
    f.tiles.push_back(std::move(tile));
  }
}

protocol::SensorFrame SensingService::frame_for(const WorldState& state, std::uint32_t id, bool run_over) {
  const AgentRecord& me = state.agent(id);
  protocol::SensorFrame f;
  f.agent_id = id;
  f.step = state.step;
  f.x_m = me.position.x;
  f.y_m = me.position.y;
  f.z_m = me.z_m;
  f.material_m3 = me.material_m3;
  f.last_result = me.last_result;
  f.last_reason = me.last_reason;
  f.run_over = run_over;

  const SensorSpec& sensor = me.type.sensor;
  if (!sensor.casts_rays()) {
    add_tiles(state, me, f);
  } else if (!run_over && state.step % static_cast<std::uint64_t>(sensor.scan_every_steps) == 0) {
    // docs/runtime.md#sensing: a scan instead of tiles, every scan_every_steps steps, from the robot's pose.
    f.scanned = true;
    f.points = cast_scan(state.terrain, sensor_origin(state.terrain, me.position.x, me.position.y, sensor),
                         me.heading_rad, sensor, scan_seed(state.seed, id, state.step));
  }

  for (const AgentRecord& other : state.agents) {
    if (!other.alive || other.id == id) continue;
    const double dx = other.position.x - me.position.x, dy = other.position.y - me.position.y;
    if (std::sqrt(dx * dx + dy * dy) <= me.type.body.proximity_range_m + tolerance::kLengthM)
      f.neighbours.push_back(
          {other.id, other.position.x, other.position.y, other.z_m, 0.5 * other.type.body.navigability.delta_m});
  }
  return f;
}

}  // namespace marsala::world_server
