#pragma once
// The exact occupiability kernel behind NavigabilityProcessor (paper eq. 1, ARCHITECTURE.md).
//
// A pair (r, q) violates when |h(r) - h(q)| > eps + kappa |r - q| + 1e-9 m; it makes non-occupiable every
// cell p whose ball B_{delta/2} holds both r and q: the lens (r + B) ∩ (q + B). Every violating pair has a
// unique low end r with h(q) - h(r) > eps + kappa |r - q| + 1e-9, so the kernel only enumerates low ends:
//   1. ring flags: R_k(r), the maximum of h over the Chebyshev ring k around r (window maxima grown by one
//      3-cell dilation per ring), bounds every partner q in ring k, which is at least k cells away; ring k can
//      only hold a violating partner when R_k(r) - h(r) > eps + kappa * cs * k. The partner thresholds are
//      computed with the same expression shape, so rounding never lets a violating partner go unflagged.
//   2. pass one: the innermost ring group of every flagged cell (their lenses cover most of the ball: on rough
//      ground this pass alone clears nearly everything).
//   3. pass two: the other flagged rings, nearest first, for cells whose ball still holds an occupiable cell
//      (8x8 tiles summarise what pass one left), stopping as soon as the whole ball is non-occupiable.
// A violating partner clears its lens: as a bitset over the ball, which touches only still-occupiable cells,
// when the per-partner tables stay small, otherwise as row spans written directly.

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::detail {

/// How the kernel clears the lens of a violating pair.
enum class LensMarking {
  kAutomatic,  ///< bitsets when the per-partner lens tables stay under a few MB, spans otherwise
  kBitsets,    ///< one bitset over the ball per partner offset; only still-occupiable cells are touched
  kSpans,      ///< the lens as row spans, cleared directly
};

/// Occupiable mask of `h` (1 = occupiable) for valid `params` and finite heights; `marking` only changes speed.
CellMask occupiable_mask(const Heightmap& h, const NavigabilityParams& params,
                         LensMarking marking = LensMarking::kAutomatic);

}  // namespace marsala::detail
