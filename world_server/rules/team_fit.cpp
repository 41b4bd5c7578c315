#include "marsala/world_server/rules/team_fit.hpp"

#include <cmath>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/format.hpp"

namespace marsala::world_server {

std::string team_fit_problem(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count) {
  for (std::uint32_t id = 1; id <= agent_count && id <= scenario.slots.size(); ++id) {
    const Position start = scenario.slots[id - 1].start;
    const NavigabilityParams& body = scenario.robot_for(id).body.navigability;
    const std::string field = fmt::format("agent[{}] (agent {}).start", id - 1, id);
    const std::optional<CellIndex> cell = terrain.cell_at(start);
    if (!cell) return fmt::format("{}: {} is off the terrain", field, start);
    if (!cell_occupiable(terrain, *cell, body))
      return fmt::format("{}: {}: cell {} is not occupiable for its body ({}): the robot cannot stand there", field,
                         start, *cell, body);
    for (std::uint32_t other = 1; other < id; ++other) {
      const Position q = scenario.slots[other - 1].start;
      const double need_m = 0.5 * (body.delta_m + scenario.robot_for(other).body.navigability.delta_m);
      const double apart_m = std::hypot(start.x - q.x, start.y - q.y);
      if (apart_m < need_m - 1e-9)
        return fmt::format("{}: {}: its body ({} m) overlaps agent {}'s, at {} ({:.2f} m apart, the bodies need {} m)",
                           field, start, body.delta_m, other, q, apart_m, need_m);
    }
  }
  return "";
}

}  // namespace marsala::world_server
