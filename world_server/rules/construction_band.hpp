#pragma once
// The construction band of a payload_path run (docs/runtime.md#summaryjson, deposited_outside_band_m3): every cell
// within half the band's width of a cell of the payload's route: its path on the final terrain when it has one (the
// route the builders made, completion.hpp payload_path), else its route planned on the initial terrain
// (RouteGap::route; the builders need not take it: on path_gale they build 6-8 m beside it). What the builders
// raised outside the band is material the payload's way did not need. Pure functions.

#include <optional>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// The band's width for a team: the widest construction width (construction.width_m) of its robot types, at least
/// the payload's delta_m [m].
double construction_band_width_m(const WorldState& state);

/// The route the band follows: `final_path`'s cells when there is one, else state.check.route.route.
const std::vector<CellIndex>& band_route_cells(const WorldState& state, const std::optional<PayloadRoute>& final_path);

/// 1 on every cell of a `rows` x `cols` grid of cell_size_m [m] whose centre lies within width_m / 2 [m] of a cell
/// of `route` (the disc_offsets ball, its tie tolerance).
CellMask construction_band(const std::vector<CellIndex>& route, int rows, int cols, double cell_size_m, double width_m);

/// The volume raised outside `band`: the sum over its 0-cells of max(0, final - initial) times the cell area [m^3].
/// Throws InvalidArgument when the terrains and the band differ in size.
double deposited_outside_band_m3(const Heightmap& initial, const Heightmap& final_terrain, const CellMask& band);

/// A payload_path run's band and what was raised outside it (summary.json's construction_band_width_m and
/// deposited_outside_band_m3).
struct BandReport {
  double width_m = 0.0;     ///< construction_band_width_m() [m]
  double outside_m3 = 0.0;  ///< deposited_outside_band_m3() over state.terrain [m^3]
};
/// The report of `state` (its terrain the final one) from `initial`, the band along band_route_cells(state,
/// final_path). Throws InvalidArgument when the terrains differ in size.
BandReport band_report(const WorldState& state, const Heightmap& initial,
                       const std::optional<PayloadRoute>& final_path);

}  // namespace marsala::world_server
