#pragma once
// MARS processor (paper eq. 2, 3): the smallest kappa-Lipschitz grid function above a heightmap,
//   P(p) = max over all cells q of h(q) - kappa * |p - q|,   gap(p) = P(p) - h(p) >= 0,
// with |p - q| the Euclidean distance between cell centres [m] (ARCHITECTURE.md, grid conventions).
//
// Accuracy: every output value is a true cone value h(q) - kappa |p - q| (so it never exceeds the
// exact P beyond rounding) and it falls short of the exact P by at most 2 tol, where
// tol = max(1e-10 m, 1e-15 (max |h| + kappa * grid diagonal)), capped at kappa * cell size / 4:
// one tol for dropping near-tied sources, one for pruning. For terrain below 1e5 m: <= 2e-10 m.
//
// Method (single-threaded; peak extra memory about 12.7 bytes per cell including the output):
//  1. Seed: two raster sweeps (as in 8SSEDT) propagate each cell's best *foreign* source, the best
//     other cell found so far, even when it stays below the cell's own height. A cell q whose
//     foreign source s gives h(s) - kappa |q - s| >= h(q) - tol is dominated (by the triangle
//     inequality its cone lies under s's cone + tol everywhere) and is dropped as a source; each
//     dropped cell is re-checked directly against the root of its pointer chain, so tolerances never
//     add up. On MARS outputs fed back every ramp cell ties bit for bit with its source and drops.
//  2. Local pass: every source within 5 cells of each cell is applied exactly (dense, vectorised).
//  3. Exact search over a quadtree of the surviving sources (8 x 8 cell leaves, one bit per cell),
//     one 8 x 8 block of targets at a time; a node is dropped for a target when an upper bound of
//     its sources' values there is <= the current value + tol. Bounds: max h - kappa * distance, and
//     up to two surfaces above all the node's sources: planes with |slope| < kappa, cones
//     M - kappa |q - c| and bowls M + kappa |q - c| with fitted apexes c. These are exact on planes,
//     cones and bowls of slope exactly kappa (any angle, any apex) and on ridges where two meet,
//     so such inputs prune near the root although every cell is a near-tied source.
//
// The bounds of a node are tested on all 64 targets of a block at once, two at a time without branches (only the
// rows and column pairs on the grid in a block cut by its edge); a leaf's sources are applied, in bit order, only to
// targets where a branch-free check finds one above the limit. The heights of the last leaves read (up to 1024, about
// 0.55 MB) are kept for the next blocks. Each target's search reads only its own limit, so project(h, wanted) skips
// the blocks and rows without wanted cells and gives the wanted ones the same bits.
//
// Speed (0.1 m cells, kappa 0.3, one core's CPU time, bench/mars_bench.cpp, README "Performance"): about 0.19 s
// (generated mix) and 0.27 s (fractal) at 1024 x 1024, 0.9 and 1.3 s at 2048 x 2048, 0.08-0.2 s for the
// slope-kappa inputs above at 1024 x 1024. Known slow case: surfaces steeper than kappa by less than ~0.1%, e.g. a
// plane of slope 1.001 kappa (0.61 s at 1024 x 1024) or a cone of slope 1.0001 kappa with its apex between cell
// centres (~4 s before the block-wide tests, not measured since): near-ties that no node bound separates. Results
// stay exact.
#include <string>

#include "marsala/core/heightmap.hpp"

namespace marsala {

/// Empty when MARS can be computed in doubles for slope `kappa` [m/m] on a grid of rows x cols cells of
/// `cell_size_m` [m] whose heights reach `max_abs_height_m` [m] in magnitude; otherwise why not. The rise over one
/// cell (kappa x cell size) must exceed 16 spacings of doubles at the magnitude the heights and the longest drop
/// reach: below that a rise is lost in rounding and the cone search cannot climb (it would never end).
std::string mars_problem(double kappa, double cell_size_m, double max_abs_height_m, int rows, int cols);

/// Computes P_kappa[h] (paper eq. 2) and the MARS gap (eq. 3) exactly on a whole grid.
class MarsProcessor {
 public:
  /// kappa: maximum climbable slope [m/m]; throws InvalidArgument unless finite and > 0.
  explicit MarsProcessor(double kappa);
  /// Maximum climbable slope, rise over run [m/m].
  double kappa() const { return kappa_; }
  /// P_kappa[h] with the geometry of h [m]; throws InvalidArgument naming the first non-finite cell, or saying why
  /// kappa, the cell size and the heights cannot be computed together (mars_problem()).
  Heightmap project(const Heightmap& h) const;
  /// P_kappa[h] on the cells where `wanted` is non-zero, the same bits there as project(h), and h [m] on the others:
  /// for a caller that reads the bound on part of the grid (the search for the others is skipped; the seed and the
  /// source tree still cover the whole grid). Throws like project(), and InvalidArgument when `wanted` is not the
  /// size of h.
  Heightmap project(const Heightmap& h, const CellMask& wanted) const;
  /// P_kappa[h] - h [m], >= 0 everywhere; throws like project().
  Heightmap gap(const Heightmap& h) const;

 private:
  Heightmap solve(const Heightmap& h, const CellMask* wanted) const;

  double kappa_;
};

}  // namespace marsala
