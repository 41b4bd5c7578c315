#pragma once
// The terrain a scenario describes, and the check that its agents, base and goal lie on it.

#include <string>

#include "marsala/core/heightmap.hpp"
#include "marsala/scenario/scenario.hpp"

namespace marsala::scenario {

/// Smallest cell size a world may have [m]; the largest, and the largest height magnitude, are kMaxMagnitude (1e6 m).
inline constexpr double kMinCellSizeM = 1e-4;

/// The scenario's terrain [m]: generated (lower-left corner at (0, 0)), or read from its .asc/.tif file (path
/// resolved against the scenario file's folder), then cropped, resampled and shifted to a zero base as the scenario
/// says. Then the magnitudes (cell size in [kMinCellSizeM, kMaxMagnitude] m, |height| <= kMaxMagnitude m) and
/// check_placement(). Throws IoError for a missing file, ParseError for a bad file, InvalidArgument for bad generator
/// parameters, magnitudes or placements; every message names the scenario.
Heightmap build_terrain(const Scenario& scenario);

/// The scenario's terrain file resolved against the scenario file's folder (unchanged when absolute).
std::string resolve_terrain_path(const Scenario& scenario);

/// Throws InvalidArgument naming the field when a slot's start or target or the base centre lies off the grid, or
/// the goal rectangle is not inside the grid's extent.
void check_placement(const Scenario& scenario, const GridGeometry& grid);

}  // namespace marsala::scenario
