#pragma once
// Construction sites along a route, before anything is built (paper §V-A, Fig. 3: the path crossed natural terrain
// and three separate construction sites, at 7.3, 15.9 and 19.2 m along it). The route is the one the builders
// plan: the navigable path planner (eq. 4-5, default_planner_params for the band width) through every cell, priced
// by the MARS gap at the construction kappa. A route cell needs construction when its own MARS gap is at least
// min_depth_m; sites are runs of such cells, runs closer than min_natural_m along the route merged (as the world's
// construction_sites measures what was built). Each site's volume is the MARS gap of the band (cells within
// width_m / 2 of a route cell) nearest its part of the route: every band cell goes to the first route cell whose
// ball holds it, and the route is split between two sites in the middle of the natural ground between them, so the
// sites' volumes add up to the band's. Pure function.

#include <cstdint>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// How the route is built and what counts as a site.
struct RouteSiteParams {
  double width_m = 2.0;        ///< band width: the planner's footprint and the band whose gap is counted [m]
  double min_depth_m = 0.0;    ///< a route cell needs construction when its gap is > 1e-9 m and >= this [m]
  double min_natural_m = 2.0;  ///< natural ground shorter than this between two runs does not separate them [m]
};

/// One construction site along the route.
struct RouteSite {
  double from_m = 0.0;     ///< first route cell needing construction, along the route from its first cell [m]
  double to_m = 0.0;       ///< last such cell [m]
  double volume_m3 = 0.0;  ///< MARS gap of the band cells nearest this part of the route [m^3]
  double max_gap_m = 0.0;  ///< largest gap of a route cell in the site [m]
};

/// The planned route and its sites.
struct RouteSites {
  std::vector<CellIndex> route;  ///< from ... to, 8-connected
  std::vector<double> along_m;   ///< position of each route cell along the route (steps cs or cs sqrt 2) [m]
  double length_m = 0.0;         ///< route length [m]
  double band_volume_m3 = 0.0;   ///< MARS gap over the band [m^3]
  std::int64_t band_cells = 0;   ///< cells of the band
  std::vector<RouteSite> sites;  ///< in order along the route
  double from_gap_m = 0.0;       ///< MARS gap of the first route cell [m]
  double to_gap_m = 0.0;         ///< MARS gap of the last route cell [m]
};

/// MARS gap of `terrain` at slope kappa [m], >= 0. With radius_m > 0, the gap a builder sees: each cell's bound is
/// taken over the cells of the square of half-side radius_m around it only (max h(q) - kappa |p - q|), as an agent's
/// local map is a square window of its sensing range around it (paper §III-A); 0 (the default) takes every cell.
/// Throws InvalidArgument unless kappa > 0 and radius_m >= 0, both finite.
Heightmap route_gap(const Heightmap& terrain, double kappa, double radius_m = 0.0);

/// Plans the builders' route from `from` to `to` on `gap` (route_gap of the terrain at params.kappa) and measures its
/// sites. Throws InvalidArgument when from or to is off the grid or a parameter is not finite or out of range
/// (width > 0; min_depth, min_natural >= 0).
RouteSites plan_route_sites(const Heightmap& gap, CellIndex from, CellIndex to, const RouteSiteParams& params);

}  // namespace marsala
