#include "marsala/world_server/rules/team_fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/format.hpp"

namespace marsala::world_server {
namespace {

/// True when bodies of delta_a and delta_b [m] centred at a and b overlap (bodies_overlap(): touching is allowed).
bool overlap(Position a, double delta_a, Position b, double delta_b) {
  return distance(a, b) < 0.5 * (delta_a + delta_b) - 1e-9;
}

/// The cells whose centres lie within radius_m of `centre`, farthest first (a disc fills best from its rim), ties in
/// row-major order.
std::vector<CellIndex> cells_near(const Heightmap& terrain, Position centre, double radius_m) {
  const GridGeometry& g = terrain.geometry();
  std::vector<std::tuple<double, int, int>> found;
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      const double d = distance(g.cell_center({r, c}), centre);
      if (d <= radius_m + 1e-9) found.emplace_back(-d, r, c);
    }
  std::sort(found.begin(), found.end());
  std::vector<CellIndex> cells;
  cells.reserve(found.size());
  for (const auto& [d, r, c] : found) cells.push_back({r, c});
  return cells;
}

}  // namespace

std::string start_placement_problem(const scenario::Scenario& scenario, const Heightmap& terrain,
                                    std::uint32_t agent_count) {
  for (std::uint32_t id = 1; id <= agent_count && id <= scenario.slots.size(); ++id) {
    const Position start = scenario.slots[id - 1].start;
    const NavigabilityParams& body = scenario.robot_for(id).body.navigability;
    const std::string field = fmt::format("agent[{}] (agent {}).start", id - 1, id);
    const std::optional<CellIndex> cell = terrain.cell_at(start);
    if (!cell) return fmt::format("{}: {} is off the terrain", field, start);
    if (!cell_occupiable(terrain, *cell, body))
      return fmt::format("{}: {}: cell {} is not occupiable for its body ({})", field, start, *cell, body);
    for (std::uint32_t other = 1; other < id; ++other) {
      const Position q = scenario.slots[other - 1].start;
      const double other_delta_m = scenario.robot_for(other).body.navigability.delta_m;
      if (overlap(start, body.delta_m, q, other_delta_m))
        return fmt::format("{}: {}: its body ({} m) overlaps agent {}'s, at {} ({:.2f} m apart, the bodies need {} m)",
                           field, start, body.delta_m, other, q, distance(start, q),
                           0.5 * (body.delta_m + other_delta_m));
    }
  }
  return "";
}

std::uint32_t greedy_placed(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count,
                            double radius_m) {
  const GridGeometry& g = terrain.geometry();
  const std::vector<CellIndex> cells = cells_near(terrain, scenario.base.centre, radius_m);
  std::map<std::tuple<double, double, double>, std::vector<signed char>> occupiable;  // per body: -1 unknown, 0, 1
  std::vector<std::pair<Position, double>> placed;
  for (std::uint32_t id = 1; id <= agent_count && id <= scenario.slots.size(); ++id) {
    const NavigabilityParams& body = scenario.robot_for(id).body.navigability;
    std::vector<signed char>& known = occupiable[{body.kappa, body.delta_m, body.eps_m}];
    known.resize(cells.size(), -1);
    bool found = false;
    for (std::size_t i = 0; i < cells.size() && !found; ++i) {
      const Position p = g.cell_center(cells[i]);
      const bool clear = std::none_of(placed.begin(), placed.end(),
                                      [&](const auto& q) { return overlap(p, body.delta_m, q.first, q.second); });
      if (!clear) continue;
      if (known[i] < 0) known[i] = cell_occupiable(terrain, cells[i], body) ? 1 : 0;
      if (known[i] == 0) continue;
      placed.emplace_back(p, body.delta_m);
      found = true;
    }
    if (!found) return id - 1;
  }
  return agent_count;
}

std::string team_fit_problem(const scenario::Scenario& scenario, const Heightmap& terrain, std::uint32_t agent_count) {
  const std::string starts = start_placement_problem(scenario, terrain, agent_count);
  if (starts.empty()) return "";
  double radius_m = scenario.base.radius_m;
  for (std::uint32_t id = 1; id <= agent_count && id <= scenario.slots.size(); ++id)
    radius_m = std::max(radius_m, distance(scenario.slots[id - 1].start, scenario.base.centre));
  const std::uint32_t placed = greedy_placed(scenario, terrain, agent_count, radius_m);
  if (placed == agent_count) return "";
  return fmt::format(
      "agent ({} robots): only {} of their bodies find room, disjoint, on cells occupiable for them within {:.2f} m "
      "of the base's centre (the base and its farthest start), and the slots' starts are no placement either: {}",
      agent_count, placed, radius_m, starts);
}

}  // namespace marsala::world_server
