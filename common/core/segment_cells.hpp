#pragma once
// The cells a straight motion passes through (ARCHITECTURE.md grid conventions: a position's cell is the one whose
// half-open square contains it). The world checks every one of them against the robot's body before it accepts a
// motion (docs/runtime.md#rule-2-motion), and the agent checks the same cells before it asks, with this one function,
// so that the two agree bit for bit.

#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Shortest stretch of a segment that counts as passing through a cell [m]: a segment that only touches a cell at a
/// corner, or grazes it for less than this, does not pass through it.
inline constexpr double kSweepMinLengthM = 1e-9;

/// The cells the segment from `a` to `b` passes through, in order from a's cell to b's cell, each once: a's cell,
/// every cell in which the segment runs for at least kSweepMinLengthM, and b's cell. Where the segment runs along a
/// cell boundary, the points of that stretch belong to the cell whose half-open square holds them (as
/// GridGeometry::cell_at decides). Indices may lie off the grid (row < 0, col >= cols, ...) when the segment leaves
/// it; the caller decides what that means. a == b gives a's cell alone. Throws InvalidArgument for a non-finite
/// coordinate.
std::vector<CellIndex> cells_on_segment(const GridGeometry& grid, Position a, Position b);

}  // namespace marsala
