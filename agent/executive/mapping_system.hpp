#pragma once
// Mapping system (paper §III, executive layer): the agent's own map of the world, built only from the terrain
// tiles of its sensor frames, and its trajectory. The agent never sees the global terrain: a cell it has not
// sensed stays unknown.

#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// Empty when `tile` fits the world grid cut in tile_size-cell tiles (its place, its size, as many heights as cells,
/// each finite and below kMaxMagnitude); otherwise the problem, naming the tile.
std::string tile_problem(const TerrainTile& tile, const GridGeometry& world, int tile_size);

/// The agent's map: heights [m] of the world grid with a known-mask, and the cells it stood on.
class MappingSystem {
 public:
  /// An empty map of the world grid cut in tile_size x tile_size tiles; throws InvalidArgument on a bad geometry
  /// or tile_size < 1.
  MappingSystem(const GridGeometry& world, int tile_size);

  /// Writes one sensing's tiles (heights copied bit for bit) and records the pose it was taken from [m]; throws
  /// InvalidArgument when a tile does not fit the grid or the pose is off the grid (a broken contract by the sender).
  void integrate(const std::vector<TerrainTile>& tiles, Position pose);
  /// Writes one tile; throws InvalidArgument naming the tile when its place, size or heights are inconsistent.
  /// Each cell goes to its world index moved by the registration offset; cells moved off the grid are dropped.
  void integrate_tile(const TerrainTile& tile);
  /// Where the robot believes the terrain it senses lies: tiles integrated from now on write world cell (r, c) at
  /// (r + offset.row, c + offset.col). A robot with localisation error registers what it senses at its believed pose
  /// (docs/runtime.md#localisation-error); (0, 0), the default, is the world's registration.
  void set_registration(CellIndex offset) { registration_ = offset; }
  /// Appends the cell under `pose` [m] to the trajectory (consecutive repeats are kept once); throws
  /// InvalidArgument when the pose is off the grid or not finite.
  void record_pose(Position pose);

  /// The map: known cells hold the world's heights [m], unknown cells 0.
  const Heightmap& heights() const { return heights_; }
  /// 1 where the cell has been sensed at least once.
  const CellMask& known() const { return known_; }
  bool is_known(CellIndex cell) const { return heights_.contains(cell) && known_(cell.row, cell.col) != 0; }
  /// Number of known cells.
  long long known_cells() const { return known_count_; }
  /// Cells stood on, oldest first, consecutive repeats removed (global indices).
  const std::vector<CellIndex>& trajectory() const { return trajectory_; }
  /// The world grid.
  const GridGeometry& geometry() const { return heights_.geometry(); }
  int tile_size() const { return tile_size_; }

 private:
  Heightmap heights_;
  CellMask known_;
  long long known_count_ = 0;
  int tile_size_;
  CellIndex registration_{0, 0};
  std::vector<CellIndex> trajectory_;
};

}  // namespace marsala::agent::executive
