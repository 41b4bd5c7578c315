#pragma once
// The sensing service: each agent's SensorFrame from the authoritative state. Terrain goes out in tiles that meet
// the agent's square sensing window and changed since that agent last received them (per agent and tile, the
// version it has seen) for a ground-truth sensor; a laser or rgbd sensor gets a ray-cast scan every
// scan_every_steps steps instead (common/core/ray_caster.hpp). Neighbours are the other live agents within its
// proximity range.

#include <cstdint>
#include <limits>
#include <vector>

#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// Builds sensor frames and remembers which tile versions each agent has received.
class SensingService {
 public:
  /// Sized for `state`'s agents and tiles; every agent starts having seen nothing.
  explicit SensingService(const WorldState& state);

  /// The frame of agent `id` for state.step: pose, material, last result and reason, the tiles in range it has not
  /// seen in their current version (ascending tile index) or its scan (a laser or rgbd sensor), neighbours within proximity_range_m (2D, +1e-9 m,
  /// ascending id), and `run_over`. Marks the sent tiles as seen. Throws InvalidArgument for an unknown id.
  protocol::SensorFrame frame_for(const WorldState& state, std::uint32_t id, bool run_over = false);

  /// Forgets what agent `id` has seen, so its next frame carries every tile in range again.
  void forget(std::uint32_t id);

 private:
  /// Adds to `f` the tiles in `me`'s square window it has not received in their current version; marks them seen.
  void add_tiles(const WorldState& state, const AgentRecord& me, protocol::SensorFrame& f);

  static constexpr std::uint64_t kNever = std::numeric_limits<std::uint64_t>::max();
  TileLayout layout_;
  std::vector<std::vector<std::uint64_t>> seen_;  ///< [agent id - 1][tile index]: version received, or kNever
};

}  // namespace marsala::world_server
