#pragma once
// The physical shapes of deposits (docs/runtime.md#depositors): where material placed at a position ends up on a
// heightmap. One algorithm for the world (which applies a deposit) and the agent (which predicts it), so both agree
// bit for bit. Pure functions.
//
//   cube column (side s, k cubes, centre c)      cone (volume V dumped at c, angle of repose theta)
//   +-----+-----+-----+                            h'(p) = max(h(p), z - tan(theta) |p - c|),
//   |  +--|-----|--+  |  each cell the s x s         z (the apex) such that sum (h' - h) cs^2 = V:
//   |  |##|#####|##|  |  footprint overlaps rises              /^^\.
//   +--|--+-----+--|--+  by k s (overlap area / cs^2)     ___/    \___   the pile flows down existing slopes
//   |  +--|-----|--+  |                               ___/            \___   until it meets the ground

#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/robot_type.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// One cell a deposit raises.
struct CellRise {
  CellIndex cell;
  double rise_m = 0.0;  ///< > 0 [m]
};

/// Where a deposit's material goes.
struct DepositShape {
  std::vector<CellRise> rises;  ///< the on-grid cells it raises, each once, row-major order
  bool on_grid = true;          ///< false: part of the shape leaves the grid (rises then hold the on-grid part only)
  double volume_m3 = 0.0;       ///< sum of rise * cs^2 over `rises` [m^3]
};

/// A deposit may leave a cell at most this fraction of its robot's construction eps above the world's deposit bound,
/// the MARS bound of the initial terrain (docs/runtime.md#deposit-bound) [1].
inline constexpr double kDepositOvershootFraction = 0.1;

/// Tolerance of cone_pile_shape's volume: |volume_m3 - V| <= kConeVolumeRelTolerance * V (rounding only: the apex
/// is solved exactly, not iterated).
inline constexpr double kConeVolumeRelTolerance = 1e-9;
/// A cell rises under a cone only when the apex clears its h(p) + tan(repose) |p - dump| by more than this [m]
/// (ties are common on built terrain; see cone_pile_shape).
inline constexpr double kConeTieM = 1e-9;

/// A column of `cubes` cubes of side `side_m` [m] standing with its centre at `centre` [m] (any position): every
/// cell the side x side footprint overlaps rises by cubes * side * (overlap area / cs^2), so the volume is
/// cubes * side^3 exactly (up to rounding) and a footprint straddling cells splits between them by area. Footprint
/// edges within 1e-9 cells of a cell edge are taken as on it (no slivers from rounding). Throws InvalidArgument on a
/// non-finite centre, a side that is not finite and > 0, or cubes < 0.
DepositShape cube_column_shape(const GridGeometry& grid, Position centre, double side_m, int cubes);

/// The number of whole cubes of side `side_m` in `volume_m3` (round half away from zero), when `volume_m3` is
/// within 1e-6 cubes of it; else -1. Non-finite or negative input: -1.
long long whole_cubes(double volume_m3, double side_m);

/// `volume_m3` of granular material dumped at `dump` [m] settles as a cone at the angle of repose `repose_deg`
/// [deg]: h'(p) = max(h(p), z - tan(repose) |p - dump|) (|.| from cell centres), with the apex height z solved
/// exactly (cells sorted by h(p) + tan(repose) |p - dump|, filled like water from below) so that the added volume
/// is `volume_m3` within kConeVolumeRelTolerance; a cell the apex would clear by at most kConeTieM does not rise (the
/// surface there may stand up to 1e-9 m above the cone). on_grid is false when the dump point is off the grid or the pile
/// reaches a cell of the grid's outermost ring (it would spill over the edge). Throws InvalidArgument on a
/// non-finite dump point, a volume that is not finite and >= 0, or an angle not in (0, 90).
DepositShape cone_pile_shape(const Heightmap& terrain, Position dump, double volume_m3, double repose_deg);

}  // namespace marsala
