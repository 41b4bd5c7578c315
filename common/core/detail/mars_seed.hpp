#pragma once
// First two stages of the MARS processor: a propagated lower bound with the dominated cells
// dropped as sources, and the exact contribution of every nearby source.

#include <cstdint>
#include <vector>

#include "marsala/core/detail/mars_common.hpp"

namespace marsala::detail {

/// Fills lower [m] with a lower bound of P from raster propagation and returns the surviving
/// sources, one bit per cell, one 64-bit mask per kBlock x kBlock leaf (row-major over leaves).
/// A cell is dropped when one surviving source s gives h(s) - kcs |q - s| >= h(q) - tol.
std::vector<std::uint64_t> seed_lower_bound(const Problem& pb, double* lower);

/// lower = max(lower, h(q) - kcs |p - q|) over every q with 0 < |p - q|^2 <= kLocalRadius2 [m]; with
/// `wanted_rows` (one flag per row), only on the rows it marks.
void apply_local_sources(const Problem& pb, double* lower, const std::uint8_t* wanted_rows = nullptr);

}  // namespace marsala::detail
