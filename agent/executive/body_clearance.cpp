#include "marsala/agent/executive/body_clearance.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::executive {
namespace {

/// Navigable again after cells were taken out: occupiable and 8-connected to the robot's cell, as the synthesizer
/// makes it.
void renavigate(deliberative::LocalMap& local) {
  local.navigable = NavigabilityProcessor::navigable_from(local.occupiable, local.robot);
}

}  // namespace

std::vector<BodyClearance> body_clearances(const std::vector<Neighbour>& neighbours, std::uint32_t self_id,
                                           double radius_m, double max_step_m) {
  std::vector<BodyClearance> out;
  out.reserve(neighbours.size());
  for (const Neighbour& n : neighbours) {
    if (!std::isfinite(n.position.x) || !std::isfinite(n.position.y) || !std::isfinite(n.radius_m) ||
        n.agent_id == self_id)
      continue;
    const double moves_first = n.agent_id < self_id ? max_step_m : 0.0;
    out.push_back({n.agent_id, n.position, radius_m + std::max(0.0, n.radius_m) + moves_first});
  }
  return out;
}

bool clear_of(const std::vector<BodyClearance>& others, Position from, Position to) {
  for (const BodyClearance& o : others) {
    // An end that far off along an axis is clear without the square root (distance() is never below the larger
    // coordinate difference, as for within()): keep_clear() asks this of every window cell and every neighbour.
    if (std::max(std::abs(to.x - o.centre.x), std::abs(to.y - o.centre.y)) >= o.min_distance_m) continue;
    const double after = distance(to, o.centre);
    if (after >= o.min_distance_m) continue;
    const double before = distance(from, o.centre);
    if (before < o.min_distance_m && after >= before) continue;  // already too close: moving apart is fine
    return false;
  }
  return true;
}

long long keep_clear(deliberative::LocalMap& local, Position robot, const std::vector<BodyClearance>& others) {
  if (others.empty()) return 0;
  long long removed = 0;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      if (local.occupiable(r, c) == 0 || CellIndex{r, c} == local.robot) continue;
      if (clear_of(others, robot, local.center({r, c}))) continue;
      local.occupiable(r, c) = 0;
      ++removed;
    }
  if (removed > 0) renavigate(local);
  return removed;
}

long long keep_off(deliberative::LocalMap& local, const std::vector<CellIndex>& cells) {
  long long removed = 0;
  for (const CellIndex global : cells) {
    const CellIndex p = local.to_local(global);
    if (!local.contains(p) || local.occupiable(p.row, p.col) == 0 || p == local.robot) continue;
    local.occupiable(p.row, p.col) = 0;
    ++removed;
  }
  if (removed > 0) renavigate(local);
  return removed;
}

}  // namespace marsala::agent::executive
