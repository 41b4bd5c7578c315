#pragma once
// Construction sites along the payload's path (paper §V-A, Fig. 3: the path crossed natural terrain and three
// separate construction sites, at 7.3, 15.9 and 19.2 m along it). Measured on the final terrain against the initial
// one: the route cells the builders raised, grouped into stretches separated by unraised (natural) ground at least
// as long as the payload's body, each with the material of the raised regions it crosses. Pure function.

#include <cstdint>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {

/// One stretch of the route over built ground.
struct ConstructionSite {
  double from_m = 0.0;     ///< where it starts along the route, from the route's first cell's centre [m]
  double to_m = 0.0;       ///< where it ends [m]
  double volume_m3 = 0.0;  ///< material in the 8-connected regions of raised cells it crosses [m^3]
  std::int64_t cells = 0;  ///< raised cells in those regions
};

/// A cell counts as raised when it stands more than this above its initial height [m].
inline constexpr double kRaisedM = 1e-9;

/// The construction sites of `route` (cells of `final_terrain`, in order) against `initial`: runs of raised route
/// cells, runs closer than min_gap_m [m] along the route merged; each region of raised cells is counted with the
/// first site that crosses it. Positions along the route are the sums of its steps (cs or cs sqrt 2). Throws
/// InvalidArgument when the two terrains differ in size or a route cell is off the grid.
std::vector<ConstructionSite> construction_sites(const Heightmap& initial, const Heightmap& final_terrain,
                                                 const PayloadRoute& route, double min_gap_m);

}  // namespace marsala::world_server
