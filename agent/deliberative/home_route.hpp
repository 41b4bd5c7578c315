#pragma once
// The way home: a route from where the robot stands to the base station over the robot's whole own map, not only its
// sensing window. The window alone holds no way out of a pocket whose exit lies beyond it (a basin below a
// structure's side wall, 20 m from the base and 50 m by road): heading for the window's cell nearest the base leads
// into the pocket's far wall, where every robot on its way back then waits for ever. The robot came from the base, so
// its map holds the way it came at least.

#include <optional>
#include <vector>

#include "marsala/agent/deliberative/known_map.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::deliberative {

/// A shortest 8-connected route (steps of 1 and sqrt 2 cells) from `from` (world index) to the nearest cell whose
/// centre lies within `radius_m` of `base` [m], through cells occupiable for `body` on the known map, a cell counting
/// only when every cell of its body ball is known. Searched over the rectangle spanning `from`, the base and the
/// trajectory, widened by margin_m [m] and clipped to the grid (the map knows nothing farther from where the robot
/// went than its sensing range). World indices, `from` first; nullopt when there is none (or `from` is not
/// occupiable). Throws InvalidArgument when `from` is off the grid or a parameter is not finite and > 0.
std::optional<std::vector<CellIndex>> home_route(const KnownMap& map, const NavigabilityParams& body, CellIndex from,
                                                 Position base, double radius_m, double margin_m);

}  // namespace marsala::agent::deliberative
