#pragma once
// Whether one cell is occupiable (ARCHITECTURE.md, grid conventions): the single-cell question the world asks of every
// motion and start, and the agent of its own body, answered exactly as NavigabilityProcessor answers it for a grid.

#include <optional>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// How cell_occupiable decides; every method gives the same answer (ARCHITECTURE.md definition).
enum class OccupancyMethod {
  kAutomatic,  ///< pairs for balls up to a few thousand cells, the processor window beyond
  kPairs,      ///< every pair of the ball, with the processor's threshold expression
  kWindow,     ///< NavigabilityProcessor on the window that holds the ball
};

/// True when on-grid `cell` is occupiable for `params` on `terrain`: every pair of cells within delta/2 of its centre
/// (cells off the grid ignored) has |h(r) - h(q)| <= eps + kappa |r - q| + 1e-9 m. Throws InvalidArgument when the
/// cell is off the grid.
bool cell_occupiable(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& params,
                     OccupancyMethod method = OccupancyMethod::kAutomatic);

/// Two cells of a ball whose heights break the occupancy rule: `low` lies below `high` by more than eps + kappa |low -
/// high| allows.
struct OccupancyBreach {
  CellIndex low;
  CellIndex high;
};

/// Why on-grid `cell` is not occupiable for `params`: the pair of its ball that breaks the rule by the most (the first
/// in disc_offsets order among equals); nullopt when the cell is occupiable. What a robot that tried to stand there
/// would feel: where its body found a drop. Throws InvalidArgument when the cell is off the grid.
std::optional<OccupancyBreach> occupancy_breach(const Heightmap& terrain, CellIndex cell,
                                                const NavigabilityParams& params);

/// Every cell of on-grid `cell`'s ball that lies too far below another, each with the cell it breaks the rule against
/// by the most: the worst pair first (occupancy_breach()), then by how much each breaks it, most first (ties in
/// disc_offsets order); empty when the cell is occupiable. What a body that tried to stand there would feel all over:
/// every drop under it, not only the deepest. Throws InvalidArgument when the cell is off the grid.
std::vector<OccupancyBreach> occupancy_breaches(const Heightmap& terrain, CellIndex cell,
                                                const NavigabilityParams& params);

/// cell_occupiable() by every pair of `ball`, the offsets disc_offsets(delta / (2 cs)) the caller computed once for
/// many cells of one grid (quadratic in the ball's size). Throws InvalidArgument when the cell is off the grid.
bool cell_occupiable_in_ball(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& params,
                             const std::vector<CellIndex>& ball);

/// 1 where the body ball of a cell (radius_cells = delta / (2 cs), disc_offsets) holds a cell that `known` marks 0:
/// whether such a cell is occupiable cannot be judged (an agent's map, a robot's believed map). Cells off the mask do
/// not count. Sized as `known`.
CellMask blind_cells(const CellMask& known, double radius_cells);

}  // namespace marsala
