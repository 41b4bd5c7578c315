#pragma once
// What the agent knows of the world, as the deliberative layer reads it. The executive's mapping system fills it
// (executive::MappingSystem::known_map()); the local map synthesizer reads it and never sees the mapping system, so
// the layers point one way: executive -> deliberative.

#include <unordered_map>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::deliberative {

/// The cells a robot stood on, as its map read their body balls then: row-major world index -> the heights of the
/// cells of its ball in `ball` order, NaN where the cell was unknown or off the grid
/// (executive::MappingSystem::record_stood).
struct StoodCells {
  std::vector<CellIndex> ball;  ///< the body ball's offsets, disc_offsets(delta / (2 cs)) [cells]
  double margin_m = 0.0;        ///< a ball reads as then when each cell is within this of its height then [m]
  std::unordered_map<long long, std::vector<double>> balls;
};

/// A read-only view of the agent's own map of the world grid; it refers to the map that made it and lives no longer.
struct KnownMap {
  const Heightmap& heights;                  ///< the world grid: known cells hold the sensed heights [m], unknown 0
  const CellMask& known;                     ///< 1 where the cell has been sensed at least once
  const CellMask& assumed;                   ///< 1 where no sensor read the surface (assumed ground, a bound)
  const CellMask& bound;                     ///< 1 where `assumed` is a lower bound from faces (not assumed ground)
  const std::vector<CellIndex>& trajectory;  ///< cells stood on, oldest first (world indices)
  bool scanned = false;                      ///< built from range scans (holes, shadows), not ground-truth tiles
  const StoodCells* stood = nullptr;         ///< cells stood on with their balls then (a scanned map), or none
  /// A scanned map's overflight (executive::MappingSystem::overflight()): per cell the lowest height [m] a ray of the
  /// latest scan crossed its column at without striking it, +inf where none did; or none (not recorded).
  const Heightmap* overflight = nullptr;

  /// The world grid.
  const GridGeometry& geometry() const { return heights.geometry(); }
};

}  // namespace marsala::agent::deliberative
