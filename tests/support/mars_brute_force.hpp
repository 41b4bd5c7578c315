#pragma once
// Brute-force reference for the MARS projection (paper eq. 2), straight from the definition in
// ARCHITECTURE.md: P(p) = max over all cells q of h(q) - kappa * |p - q|. O(N^2); small grids only.

#include <cmath>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::testing {

/// P_kappa[h] [m] by visiting every pair of cells; distances between cell centres via std::hypot [m].
inline Heightmap mars_brute_force(const Heightmap& h, double kappa) {
  Heightmap projected = h;
  for (int pr = 0; pr < h.rows(); ++pr) {
    for (int pc = 0; pc < h.cols(); ++pc) {
      const Position p = h.cell_center({pr, pc});
      double best = h(pr, pc);
      for (int qr = 0; qr < h.rows(); ++qr) {
        for (int qc = 0; qc < h.cols(); ++qc) {
          const Position q = h.cell_center({qr, qc});
          const double value = h(qr, qc) - kappa * std::hypot(p.x - q.x, p.y - q.y);
          if (value > best) best = value;
        }
      }
      projected(pr, pc) = best;
    }
  }
  return projected;
}

}  // namespace marsala::testing
