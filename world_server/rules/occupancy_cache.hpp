#pragma once
// The occupiable mask of one rectangle of the terrain (the whole grid for a payload, the site for levelling), kept up
// to date incrementally between completion checks. Pure data and computation: no IO, no threads.
//
// Why a windowed update gives the whole computation's answer: a cell's occupiability reads only the heights of the
// cells in its ball B (radius delta / 2, reach R = max |dr|, |dc| of disc_offsets), cut at the area's edge. So
// after cells change, only cells within R (Chebyshev) of a changed cell can change, and recomputing a rectangle T of
// cells on the window W = (T dilated by R) clipped to the area sees, for every cell of T, exactly the ball it has in
// the area (W's edges cut nothing the area keeps). Changes are recorded as the bounding box of the changed cells of
// each block of kBlockCells x kBlockCells cells; an update dilates each box by R, merges overlapping ones, and
// recomputes each resulting T on its W:
//
//   changed cells x, box of a block [x x], T = box + R, W = T + R (all clipped to the area)
//   +--------------------------------+
//   |      W . . . . . . . .         |
//   |      . T - - - - - .  .        |
//   |      . |   [x  x]  |  .        |
//   |      . |   [  x ]  |  .        |
//   |      . + - - - - - +  .        |
//   |      . . . . . . . . .         |
//   +--------------------------------+

#include <cstdint>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::world_server {

/// Occupiability (paper eq. 1, ARCHITECTURE.md) of the cells of one area of a terrain, balls cut at the area's edge,
/// recomputed only where heights changed.
class OccupancyCache {
 public:
  /// Side of the blocks in which changes are recorded [cells].
  static constexpr int kBlockCells = 16;

  OccupancyCache() = default;
  /// Computes the mask of `area` of `terrain` for `params` (NavigabilityProcessor on the area). Throws
  /// InvalidArgument when the area is empty or leaves the grid, or the parameters are invalid.
  OccupancyCache(const Heightmap& terrain, CellRect area, NavigabilityParams params);

  /// Records that terrain cell `cell` (grid coordinates) changed; cells outside the area change nothing in it.
  void mark_changed(CellIndex cell);
  /// True when a cell of the area changed since the last update (or construction).
  bool has_changes() const { return has_changes_; }
  /// Cells (grid coordinates) whose marking reproduces the changes recorded since the last update: the corners of
  /// each block's box. A cache rebuilt on the current terrain and given these behaves as this one does from here on
  /// (a snapshot of the world keeps them).
  std::vector<CellIndex> pending_changes() const;
  /// Brings the mask up to date with `terrain` (the grid it was built on), recomputing only the cells the recorded
  /// changes can affect; returns how many cells were recomputed (0 without changes).
  long long update(const Heightmap& terrain);

  /// 1 where the area's cell is occupiable; element (r, c) is grid cell (area.first.row + r, area.first.col + c).
  const CellMask& occupiable() const { return mask_; }
  const CellRect& area() const { return area_; }
  const NavigabilityParams& params() const { return params_; }
  /// Chebyshev reach of the ball [cells].
  int reach() const { return reach_; }

 private:
  void recompute(const Heightmap& terrain, const CellRect& target);

  CellRect area_;
  NavigabilityParams params_;
  int reach_ = 0;
  int block_rows_ = 0;
  int block_cols_ = 0;
  /// Per block of the area, row-major: the bounding box of its changed cells (area coordinates, inclusive), or
  /// row0 > row1 when none changed.
  struct Box {
    int row0, col0, row1, col1;
  };
  static const Box kNoChange;
  std::vector<Box> changed_;
  bool has_changes_ = false;
  CellMask mask_;
};

}  // namespace marsala::world_server
