#pragma once
// Completion, checked on the authoritative terrain, in one of three kinds (scenario::CompletionKind):
//   agents_at_goal  every live agent (at least one) stands inside the goal rectangle at >= the goal's min_height_m
//                   and, when the goal has a target_radius_m, within that distance of its own target;
//   payload_path    the payload (kappa, delta, eps of PayloadPath) has a navigable path from the cell of `from` to
//                   the cell of `to`: 8-connected through occupiable cells of the whole grid (paper §V-A), and the
//                   cell of `to` stands at most one cube layer above its initial height (the largest layer of the
//                   run's robot types): the path reaches the target on its own ground, not on a structure raised
//                   over it;
//   level_site      the terrain cropped to the site (cells whose centres lie inside) has an 8-connected component
//                   of cells occupiable for the site's kappa, delta, eps (balls cut at the crop's edge) covering at
//                   least min_fraction of the crop's cells (paper §V-B).
// The pure functions below decide each from a terrain; WorldState keeps an incremental check (CompletionCheck) that
// apply_step evaluates on its schedule and is_completed reads.

#include <optional>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// True when `agent`'s centre lies in the goal rectangle (closed, +1e-9 m), the height under it is at least
/// goal.min_height_m - 1e-9 m and, when goal.target_radius_m > 0, it is within target_radius_m + 1e-9 m of its own
/// target.
bool at_goal(const WorldState& state, const AgentRecord& agent);

/// agents_at_goal: at least one agent is live and every live agent is at the goal. payload_path, level_site: the
/// latest evaluation of the terrain check (state.check.met).
bool is_completed(const WorldState& state);

/// agents_at_goal: fraction of the live agents at the goal (0 when none is live); payload_path: 1 when the latest
/// check completed (the path found and the target's cell kept), else the part of the route's initial MARS gap filled
/// at that check (1 - gap left / initial gap, 0 when the route had no gap), at most 0.999 while not completed;
/// level_site: the latest level fraction. In [0, 1] (docs/runtime.md#progress).
double progress(const WorldState& state);

/// Sets up the terrain check of a payload_path or level_site state (its cache on the current terrain) and evaluates
/// it once; nothing for agents_at_goal. Throws InvalidArgument when the payload's `from` or `to` is off the grid or
/// the site holds no cell of the grid.
void start_completion_check(WorldState& state);

/// Evaluates the terrain check now: brings the cached occupiable mask up to date with the terrain changes recorded
/// in it, then decides met (payload: path_found and the target kept; site: the level fraction); counts the
/// evaluation. Nothing for agents_at_goal.
void evaluate_completion(WorldState& state);

/// payload_path: how far the cell of `to` stands above its initial height on the current terrain [m].
double target_rise_m(const WorldState& state);

/// payload_path: why the run is not complete, or what was met, in one sentence for summaries and logs ("no payload
/// path from base to target", "payload path found, but the target's cell stands 1.98 m above its initial height
/// (at most 0.016 m allowed)", "payload path found, target's cell within 0.016 m of its initial height"); found is
/// whether the payload has its path on the current terrain. Empty for the other kinds.
std::string payload_completion_detail(const WorldState& state, bool found);

/// One cube layer of the largest cube among `state`'s agents' robot types on its grid [m] (cube_layer_m).
double largest_cube_layer_m(const WorldState& state);

/// The site's cells: those whose centres lie in [x0, x1] x [y0, y1] (closed, 1e-9 m tolerance); empty when none.
CellRect site_cells(const GridGeometry& grid, const scenario::Site& site);

/// Size of the largest 8-connected component of the mask's 1-cells [cells]; 0 when there is none.
long long largest_component(const CellMask& mask);

/// True when `to` is 8-connected to `from` through 1-cells of `passable` (both must be 1). Throws InvalidArgument
/// when either is off the mask.
bool connected(const CellMask& passable, CellIndex from, CellIndex to);

/// True when the payload has a navigable path on `terrain` (whole grid): the cell of `to` is navigable from the cell
/// of `from` for the payload's kappa, delta_m, eps_m. Throws InvalidArgument when `from` or `to` is off the grid.
bool payload_path_navigable(const Heightmap& terrain, const scenario::PayloadPath& path);

/// The site's level fraction on `terrain`: largest 8-connected component of the crop's occupiable cells (balls cut
/// at the crop's edge) / cells of the crop, in [0, 1]. Throws InvalidArgument when the site holds no cell of the grid.
double site_level_fraction(const Heightmap& terrain, const scenario::Site& site);

/// The payload's route on `terrain` and its band (docs/runtime.md#progress): the agents' planner (paper eq. 4-5,
/// default_planner_params for the payload's delta_m) from the cell of `from` to the cell of `to` through every cell,
/// priced by the MARS gap at the payload's kappa; the band is every cell within delta_m / 2 of a route cell (the
/// disc_offsets ball), each with its MARS bound. Throws InvalidArgument when `from` or `to` is off the grid.
RouteGap plan_route_gap(const Heightmap& terrain, const scenario::PayloadPath& path);

/// The MARS gap left over the route's band on `terrain` (the grid it was planned on): the sum over its cells of
/// max(0, bound - height) times the cell area [m^3].
double route_gap_m3(const Heightmap& terrain, const RouteGap& route);

/// A one-line account of the progress for people, e.g. "12.31 of 21.30 m3 of MARS gap left on the route",
/// "site 83.2 % level (100.0 % needed)", "2 of 3 live agents at the goal".
std::string progress_detail(const WorldState& state);

/// A path of cells and its length.
struct PayloadRoute {
  std::vector<CellIndex> cells;  ///< from the first cell to the last, consecutive cells 8-adjacent
  double length_m = 0.0;         ///< sum of the steps: cs for a side step, cs * sqrt(2) for a diagonal one [m]
};

/// A shortest 8-connected path through 1-cells of `passable` from `from` to `to`, found by the core's
/// NavigablePathPlanner with alpha = 0 (Euclidean step costs: cs or cs * sqrt 2; among equally short paths a
/// deterministic one), or nullopt when there is none (either end blocked or disconnected). Throws InvalidArgument when
/// an end is off the mask or cell_size_m is not > 0.
std::optional<PayloadRoute> shortest_path(const CellMask& passable, CellIndex from, CellIndex to, double cell_size_m);

/// The payload's constructed path on `terrain`: a shortest path through cells occupiable for the payload (whole
/// grid) from the cell of `from` to the cell of `to`, or nullopt when there is none. Throws InvalidArgument when
/// `from` or `to` is off the grid.
std::optional<PayloadRoute> payload_path(const Heightmap& terrain, const scenario::PayloadPath& path);

}  // namespace marsala::world_server
