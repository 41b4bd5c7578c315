#pragma once
// Lanes (paper Fig. 4: a forward and a backward lane along the construction). Where a path runs in a corridor (a
// band of navigable cells bounded on both sides, such as the built ramp), a robot keeps lane_offset_m to the right
// of the corridor's centre line, seen in the direction it drives: robots going to the front keep to one side of the
// band, robots coming back to the other, and they pass without their bodies meeting. On open ground there is no
// centre line to keep to; the path stays as planned and robots go around each other (body_clearance.hpp).
//
//        left edge  ------------------------------------
//                                 <-- backward lane (right of its direction)
//        centre     - - - - - - - - - - - - - - - - - -
//                   forward lane (right of its direction) -->
//        right edge ------------------------------------
//
// The corridor is measured across the path at each of its cells, perpendicular to the path's direction there, on a
// mask the caller gives (the navigable cells before other robots were taken out, so that a robot in the other lane
// does not move the centre line); so the lane does not depend on where in the corridor the robot stands.

#include <vector>

#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// Cells each side of a path cell over which its direction is taken [cells]: a direction over 2 k + 1 cells follows
/// the band, not the staircase of an 8-connected path.
inline constexpr int kLaneDirectionSpan = 4;
/// Path cells in a row that must lie in a corridor for it to count: a narrow spot between obstacles is not a band.
inline constexpr int kMinCorridorCells = 2 * kLaneDirectionSpan + 1;

/// `path` (local indices, path[0] the robot's cell) with every later cell moved into its lane: across the path at
/// that cell (its direction from path[i - k] to path[i + k], k = kLaneDirectionSpan, clipped to the path), the
/// corridor is the run of cells set in `corridor` through it, sampled every half cell up to corridor_width_m [m]
/// each side; when the run ends on both sides within that, for at least kMinCorridorCells path cells in a row, the
/// lane point is the corridor's centre plus offset_m to the right, kept within the run; elsewhere the path cell
/// itself. The offset from the path changes by at most the distance between consecutive path cells, starting from 0
/// at the robot (lanes are entered and left at 45 degrees at most). A lane point's cell replaces the path cell if it
/// is navigable in `local`. Consecutive repeats are merged; path[0] stays. offset_m <= 0 or a path of one cell:
/// unchanged.
std::vector<CellIndex> lane_path(const deliberative::LocalMap& local, const CellMask& corridor,
                                 const std::vector<CellIndex>& path, double offset_m, double corridor_width_m);

/// `path` (local indices, path[0] where the robot will stand) moved towards the centre line of the corridor it runs
/// in, for what is built along it (docs/runtime.md#the-construction-band): a path cell in a corridor (as lane_path()
/// measures it with offset 0, path[0] included) is moved across the path towards the corridor's centre there, by
/// its distance from it but at most max_shift_m [m], at once (no 45-degree entry); every later cell with no corridor
/// across it (past the corridor's end) is moved by the last shift, across the path's direction there: the centre
/// line carried on; cells before the first corridor cell stay. Consecutive repeats are merged. A path of one cell or
/// max_shift_m <= 0: unchanged. `structure` (optional, the window's size: the cells seen raised,
/// RaisedCells::raised()): path cells that run beside it are left out (nothing is built along them): off it, with
/// structure across the path on either side that begins within corridor_width_m [m] and whose far edge lies more
/// than half of that from the cell, for at least kMinCorridorCells path cells in a row.
std::vector<CellIndex> band_centre_path(const deliberative::LocalMap& local, const CellMask& corridor,
                                        const std::vector<CellIndex>& path, double corridor_width_m,
                                        double max_shift_m, const CellMask* structure = nullptr);

/// 1 on the window's cells whose centre lies within half_width_m [m] of the centre of a cell of one of `paths`
/// (local indices; cells off the window count too): the band a robot fills along its ways; the window's size.
CellMask band_mask(const deliberative::LocalMap& local, const std::vector<std::vector<CellIndex>>& paths,
                   double half_width_m);

/// What is left to fill in a band (docs/runtime.md#the-construction-band): the MARS gap at `kappa` [m/m] of the
/// band's own surface, max(0, P_kappa[h_band] - h) [m], where h_band is the window's heights on the cells of `band`
/// (1: in it; the window's size) and the window's lowest height elsewhere; never above local.gap. Terrain and
/// structure beside the band, natural or built, neither raise the band's target nor are filled from it by more
/// than the band's own slopes ask.
Heightmap band_fill_gap(const deliberative::LocalMap& local, const CellMask& band, double kappa);
/// What is left to fill along a way (docs/runtime.md#the-construction-band, "The way's own surface"):
/// band_fill_gap() with the cells within radius_m [m] of a cell of `path` (local indices) as the only sources, the
/// surface a body of that radius drives on along the path; high ground elsewhere in the band is no source.
Heightmap way_fill_gap(const deliberative::LocalMap& local, const std::vector<CellIndex>& path, double radius_m,
                       double kappa);
/// The sources of way_fill_gap(): band_sources() of the cells within radius_m [m] of a cell of `path`.
Heightmap way_sources(const deliberative::LocalMap& local, const std::vector<CellIndex>& path, double radius_m);
/// h_band of band_fill_gap(): the window's heights on the cells of `band`, its lowest height elsewhere [m].
Heightmap band_sources(const deliberative::LocalMap& local, const CellMask& band);
/// The window's gap capped by another surface's bound: min(local.gap, max(0, P_kappa[sources] - h)) [m] per cell,
/// `sources` [m] the window's size (band_fill_gap: the band's heights; first_seen_gap: the heights first seen).
Heightmap gap_below_bound_of(const deliberative::LocalMap& local, const Heightmap& sources, double kappa);
/// The window's gap capped by `target` [m] (a bound already projected, the window's size): min(local.gap,
/// max(0, target - h)) [m] per cell.
Heightmap gap_below(const deliberative::LocalMap& local, const Heightmap& target);
/// The cells where gap_below() reads its target: those whose local.gap is not <= 0 (1; elsewhere the result is
/// local.gap whatever the target), the window's size. A bound needed only there is projected only there
/// (MarsProcessor::project(h, wanted)).
CellMask gap_cells(const deliberative::LocalMap& local);

}  // namespace marsala::agent::executive
