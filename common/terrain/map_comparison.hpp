#pragma once
// How well a robot's own map matches the true terrain (docs/runtime.md#seeing-the-map, `marsala-terrain compare`): the
// map holds the heights the robot believes [m], NaN where it knows nothing (its dump, agent-<id>-height.asc, reads so
// with AscReadOptions::keep_nodata); the truth is a complete grid of the same cells (the run's terrain_final.asc).
//
// "Passable" is occupiable for a robot body (ARCHITECTURE.md, grid conventions; cell_occupancy.hpp): on the believed
// map a cell is passable when it is known, no unknown cell lies within delta/2 of its centre (the robot cannot judge a
// body ball it has not seen: the local map synthesizer calls such a cell blind) and every pair of its ball passes.

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::terrain {

/// What compare_maps() finds; errors are |believed - true| over the known cells [m].
struct MapComparison {
  long long cells = 0;                  ///< cells of the grid [count]
  long long known_cells = 0;            ///< cells the believed map knows (finite) [count]
  double median_error_m = 0.0;          ///< median absolute error, nearest rank (core/statistics.hpp); 0 if none [m]
  double p95_error_m = 0.0;             ///< 95th percentile of the same [m]
  double max_error_m = 0.0;             ///< largest absolute error [m]
  long long believed_passable = 0;      ///< cells passable for the body on the believed map [count]
  long long believed_passable_not = 0;  ///< of those, not occupiable on the true map [count]
  long long true_passable = 0;          ///< cells occupiable for the body on the true map [count]

  /// known_cells / cells, 0 for an empty grid.
  double known_fraction() const { return cells > 0 ? static_cast<double>(known_cells) / cells : 0.0; }
};

/// 1 where a cell of `believed` (NaN = unknown) is passable for `body`: known, no unknown cell within delta/2 of its
/// centre (cells off the grid ignored), and occupiable (every pair of its ball within eps + kappa d + 1e-9 m). Throws
/// InvalidArgument for an infinite height or body parameters NavigabilityProcessor refuses.
CellMask believed_passable(const Heightmap& believed, const NavigabilityParams& body);

/// Compares `believed` (NaN = unknown) with `truth` for a robot of `body`. Throws InvalidArgument when the grids differ
/// (rows, cols, cell size, or lower-left corner by more than 1e-6 m), a true height is not finite, a believed one is
/// infinite, or the body is invalid.
MapComparison compare_maps(const Heightmap& believed, const Heightmap& truth, const NavigabilityParams& body);

}  // namespace marsala::terrain
