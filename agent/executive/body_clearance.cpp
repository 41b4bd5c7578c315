#include "marsala/agent/executive/body_clearance.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/heightmap.hpp"
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

namespace {

/// clear_of() for one neighbour.
bool clear_of_one(const BodyClearance& o, Position from, Position to) {
  // An end that far off along an axis is clear without the square root (distance() is never below the larger
  // coordinate difference, as for within()).
  if (std::max(std::abs(to.x - o.centre.x), std::abs(to.y - o.centre.y)) >= o.min_distance_m) return true;
  const double after = distance(to, o.centre);
  if (after >= o.min_distance_m) return true;
  const double before = distance(from, o.centre);
  return before < o.min_distance_m && after >= before;  // already too close: moving apart is fine
}

}  // namespace

bool clear_of(const std::vector<BodyClearance>& others, Position from, Position to) {
  for (const BodyClearance& o : others)
    if (!clear_of_one(o, from, to)) return false;
  return true;
}

long long keep_clear(deliberative::LocalMap& local, Position robot, const std::vector<BodyClearance>& others) {
  if (others.empty()) return 0;
  // A cell is taken out when it is not clear_of() some neighbour, which needs its centre nearer than the neighbour's
  // distance along both axes: each neighbour tests the cells of that box only (the window's other cells are clear of
  // it), the cells the same test as clear_of() gives them.
  CellMask taken = CellMask::Zero(local.rows(), local.cols());
  for (const BodyClearance& o : others) {
    Rect box;
    box.x0 = o.centre.x - o.min_distance_m;
    box.x1 = o.centre.x + o.min_distance_m;
    box.y0 = o.centre.y - o.min_distance_m;
    box.y1 = o.centre.y + o.min_distance_m;
    const CellRect cells = cells_centred_in(local.geometry(), box);
    for (int r = cells.first.row; r < cells.first.row + cells.rows; ++r)
      for (int c = cells.first.col; c < cells.first.col + cells.cols; ++c) {
        if (taken(r, c) != 0 || local.occupiable(r, c) == 0 || CellIndex{r, c} == local.robot) continue;
        if (!clear_of_one(o, robot, local.center({r, c}))) taken(r, c) = 1;
      }
  }
  long long removed = 0;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (taken(r, c) != 0) {
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
