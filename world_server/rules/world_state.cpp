#include "marsala/world_server/rules/world_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/mars_processor.hpp"

namespace marsala::world_server {

AgentRecord& WorldState::agent(std::uint32_t id) {
  return const_cast<AgentRecord&>(static_cast<const WorldState&>(*this).agent(id));
}

const AgentRecord& WorldState::agent(std::uint32_t id) const {
  if (!has_agent(id))
    throw InvalidArgument(fmt::format("no agent {} in this run (agents 1..{})", id, agents.size()));
  return agents[id - 1];
}

std::vector<std::uint32_t> WorldState::live_ids() const {
  std::vector<std::uint32_t> ids;
  for (const AgentRecord& a : agents)
    if (a.alive) ids.push_back(a.id);
  return ids;
}

void check_agent_count(const scenario::Scenario& scenario, std::uint32_t agent_count) {
  if (agent_count == 0 || agent_count > scenario.slots.size())
    throw InvalidArgument(fmt::format("agent count {} must be in 1..{} (the scenario's agent slots)", agent_count,
                                      scenario.slots.size()));
}

WorldState world_state_at(const scenario::Scenario& scenario, Heightmap terrain, const std::vector<Position>& starts) {
  const auto agent_count = static_cast<std::uint32_t>(starts.size());
  check_agent_count(scenario, agent_count);
  WorldState s;
  s.terrain = std::move(terrain);
  s.goal = scenario.goal;
  s.base = scenario.base;
  s.tile_size = scenario.tile_size;
  s.seed = scenario.seed;
  s.stall_steps = scenario.stall_steps;
  s.tile_versions.assign(static_cast<std::size_t>(s.tiles().tile_count()), 0);
  s.depositor = AgentIdGrid::Zero(s.terrain.rows(), s.terrain.cols());
  s.completion = scenario.completion;
  s.payload_path = scenario.payload_path;
  s.site = scenario.site;
  for (std::uint32_t id = 1; id <= agent_count; ++id) {
    const scenario::AgentSlot& slot = scenario.slots[id - 1];
    const RobotType& type = scenario.robot_for(id);
    // docs/runtime.md#depositors: a cube narrower than a cell has no footprint of its own on the heightmap.
    if (type.depositor.kind == DepositorKind::kCube &&
        depositor_cube_size_m(type) < s.terrain.cell_size_m() - 1e-12)
      throw InvalidArgument(fmt::format(
          "robot type '{}': depositor.cube_size_m {} m is smaller than the cell size {} m; a cube narrower than a "
          "cell has no footprint of its own (use the layer depositor, or a cube at least a cell wide)",
          type.name, depositor_cube_size_m(type), s.terrain.cell_size_m()));
    AgentRecord a;
    a.id = id;
    a.type = type;
    const Position& start = starts[id - 1];
    a.start = start;
    a.target = slot.target;
    a.position = start;
    a.z_m = height_under(s.terrain, a.position.x, a.position.y);
    a.heading_rad = initial_heading_rad(a);
    s.agents.push_back(std::move(a));
  }
  // docs/runtime.md#deposit-bound: one MARS of the initial terrain, at the slope of the flattest structure any robot
  // of the team builds (the highest bound), so every robot may build what any other builds for. A team that has a
  // cube or cone robot, or a robot that builds from its own scans, is judged by it; a team of layer robots with exact
  // maps (which never exceed it) does not pay for it.
  const auto judged = [](const AgentRecord& a) {
    return a.type.depositor.kind != DepositorKind::kLayer || a.type.sensor.casts_rays();
  };
  if (std::any_of(s.agents.begin(), s.agents.end(), judged)) {
    s.deposit_bound_kappa = construction_params(s.agents.front().type).kappa;
    for (const AgentRecord& a : s.agents)
      s.deposit_bound_kappa = std::min(s.deposit_bound_kappa, construction_params(a.type).kappa);
    s.deposit_bound = MarsProcessor(s.deposit_bound_kappa).project(s.terrain);
  }
  return s;
}

double initial_heading_rad(const AgentRecord& a) {
  const double dx = a.target.x - a.start.x, dy = a.target.y - a.start.y;
  return dx == 0.0 && dy == 0.0 ? 0.0 : std::atan2(dy, dx);
}

double height_under(const Heightmap& terrain, double x_m, double y_m) {
  const auto cell = terrain.cell_at({x_m, y_m});
  return cell ? terrain(*cell) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace marsala::world_server
