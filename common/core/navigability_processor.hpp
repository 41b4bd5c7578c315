#pragma once
// NavigabilityProcessor: which cells a robot can occupy (paper eq. 1) and which it can reach from where it
// stands, exactly as defined in ARCHITECTURE.md (grid conventions, tie tolerances included).

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Decides occupiability (paper eq. 1) and navigability from an origin cell, exactly.
///
/// Cell p is occupiable when every pair of cells r, q whose centres lie within delta/2 of p's centre
/// satisfies |h(r) - h(q)| <= eps + kappa * |r - q| (+1e-9 m); it is navigable when it is 8-connected to the
/// origin through occupiable cells. Runs in O(cells * max_ring) for the bounds plus the work on the few cells
/// that can be the low end of a violating pair; never the O(r^4)-per-cell pair check.
class NavigabilityProcessor {
 public:
  /// Validates: kappa > 0 [m/m], delta_m > 0 [m], eps_m >= 0 [m], all finite; else InvalidArgument.
  explicit NavigabilityProcessor(NavigabilityParams params);
  /// The robot's motion parameters (kappa [m/m], delta_m [m], eps_m [m]).
  const NavigabilityParams& params() const { return params_; }
  /// 1 where the cell is occupiable; throws InvalidArgument naming the first non-finite cell.
  CellMask occupiable(const Heightmap& h) const;
  /// 1 where the cell is navigable from `origin` (8-connected through occupiable cells); all 0 when the origin is
  /// not occupiable; throws InvalidArgument when the origin is off the grid.
  CellMask navigable(const Heightmap& h, CellIndex origin) const;
  /// The 8-connected flood fill alone, for callers that already have the occupiable mask (1 = occupiable);
  /// throws InvalidArgument when the origin is off the mask.
  static CellMask navigable_from(const CellMask& occupiable, CellIndex origin);

 private:
  NavigabilityParams params_;
};

}  // namespace marsala
