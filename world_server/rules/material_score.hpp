#pragma once
// The material score of a run (docs/runtime.md#material-score, summary.json `material`): the volume the team deposited
// against the exact MARS gap its task needed on the initial terrain, and the volume raised off the task's band.
//   payload_path   need: the payload's route band filled to the MARS bound at the payload's kappa (RouteGap, the
//                  gap the progress counts down: G0); off band: raised outside the construction band
//                  (construction_band.hpp);
//   level_site     need: the site's crop filled to its own MARS bound at the site's kappa (the crop alone, as the
//                  site's occupiability is decided on it), which makes every cell of it occupiable; off band: raised
//                  outside the crop;
//   agents_at_goal need: each slot's route from its start to its target, planned as the payload's is (the agents'
//                  planner over the gap to the MARS bound at its construction kappa, every cell allowed), its band
//                  (the cells within its construction delta / 2 of the route) filled to that bound; bands of several
//                  slots are joined, a cell taking the highest bound asked of it (the ramps' wedges); off band: raised
//                  outside the joined bands.
// ratio = deposited / needed (1 = no material beyond the exact need; 0 when nothing was needed). Pure functions.

#include "marsala/core/heightmap.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// summary.json's `material` block [m^3].
struct MaterialScore {
  double deposited_m3 = 0.0;  ///< the run's deposited volume [m^3]
  double needed_m3 = 0.0;     ///< the exact MARS gap of the task on the initial terrain [m^3]
  double ratio = 0.0;         ///< deposited / needed; 0 when needed is 0
  double off_band_m3 = 0.0;   ///< raised outside the task's band [m^3]
};

/// The cells a task needs raised and the height each needs: 0-cells of `band` need nothing.
struct MaterialNeed {
  CellMask band;      ///< 1 on the task's cells
  Heightmap ceiling;  ///< the height each band cell needs [m]; meaningless off the band
};

/// The need of `state`'s task on `initial` (the run's initial terrain, the grid of state.terrain). payload_path uses
/// state.check.route (planned on `initial` when the state was made). Throws InvalidArgument when the grids differ.
MaterialNeed material_need(const WorldState& state, const Heightmap& initial);

/// Sum over the band of max(0, ceiling - initial) times the cell area [m^3].
double needed_m3(const MaterialNeed& need, const Heightmap& initial);

/// The score of `state` (its terrain the final one) from `initial`. `payload_outside_band_m3`: payload_path's volume
/// outside its construction band (band_report()), used as its off-band volume; ignored for the other kinds.
MaterialScore material_score(const WorldState& state, const Heightmap& initial, double payload_outside_band_m3);

}  // namespace marsala::world_server
