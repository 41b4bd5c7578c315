#pragma once
// The structure a robot has seen built (docs/runtime.md#the-construction-band): every cell of the world grid keeps
// the height the robot's map first held for it, and a cell whose map height now stands above that by more than a
// tolerance has been raised since, by this robot or another. On a shallow fill (a few cube layers between
// occupiable natural ground) the built strip is no corridor of navigable cells, but it is a strip of raised cells;
// its centre line is what every front robot fills around (lane.hpp band_centre_path). Read from the robot's own map
// only, so scanning robots can keep the rule with what their sensors showed.

#include <cstddef>
#include <vector>

#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// First-seen heights of a world grid and the cells raised above them.
class RaisedCells {
 public:
  /// No cell seen yet, for a world grid of rows x cols cells; throws InvalidArgument when either is not positive.
  RaisedCells(int rows, int cols);

  /// Records the window's known cells not seen before at their current heights [m] (the local map's heights and
  /// known mask; cells off the world grid are ignored).
  void observe(const deliberative::LocalMap& local);
  /// 1 on the window's known cells whose height stands above the first height recorded for them by more than
  /// tolerance_m [m]; the window's size.
  CellMask raised(const deliberative::LocalMap& local, double tolerance_m) const;
  /// The first height recorded for world cell `cell` [m]; NaN when none was (or the cell is off the grid).
  double first_height_m(CellIndex cell) const;

 private:
  bool on_grid(CellIndex cell) const { return cell.row >= 0 && cell.col >= 0 && cell.row < rows_ && cell.col < cols_; }
  std::size_t index(CellIndex cell) const { return static_cast<std::size_t>(cell.row) * cols_ + cell.col; }
  int rows_ = 0;
  int cols_ = 0;
  std::vector<double> first_m_;  // per world cell (row-major); NaN: never known
};

/// The window's heights as first seen (`raised`), a cell never recorded at its current height [m]; the window's size.
Heightmap first_seen_heights(const deliberative::LocalMap& local, const RaisedCells& raised);
/// The window's gap against the MARS bound at `kappa` [m/m] of its heights as first seen (`raised`; a cell never
/// recorded at its current height): min(local.gap, max(0, P_kappa[h_first] - h)) [m] per cell, the window's size.
/// Structure built since raises nothing in it: the cells beside a built strip keep the price of the natural terrain.
Heightmap first_seen_gap(const deliberative::LocalMap& local, const RaisedCells& raised, double kappa);

}  // namespace marsala::agent::executive
