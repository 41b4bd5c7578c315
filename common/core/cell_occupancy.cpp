#include "marsala/core/cell_occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala {
namespace {

// Balls above this many cells are checked by the processor on a window: the pair check is quadratic.
constexpr std::size_t kMaxPairBallCells = 2000;

bool occupiable_by_pairs(const Heightmap& h, CellIndex cell, const NavigabilityParams& p,
                         const std::vector<CellIndex>& offsets) {
  struct BallCell {
    int dr, dc;
    double height;
  };
  std::vector<BallCell> ball;
  ball.reserve(offsets.size());
  for (const CellIndex& o : offsets) {
    const CellIndex c{cell.row + o.row, cell.col + o.col};
    if (h.contains(c)) ball.push_back({o.row, o.col, h(c)});
  }
  const double cs = h.cell_size_m();
  for (std::size_t a = 0; a < ball.size(); ++a)
    for (std::size_t b = a + 1; b < ball.size(); ++b) {
      const long long dr = ball[a].dr - ball[b].dr, dc = ball[a].dc - ball[b].dc;
      // The expression NavigabilityProcessor's kernel uses, so that ties are decided identically.
      const double threshold =
          p.eps_m + p.kappa * (cs * std::sqrt(static_cast<double>(dr * dr + dc * dc))) + tolerance::kHeightM;
      if (std::abs(ball[a].height - ball[b].height) > threshold) return false;
    }
  return true;
}

bool occupiable_by_window(const Heightmap& h, CellIndex cell, const NavigabilityParams& p,
                          const std::vector<CellIndex>& offsets) {
  int reach = 0;
  for (const CellIndex& o : offsets) reach = std::max({reach, std::abs(o.row), std::abs(o.col)});
  const int r0 = std::max(0, cell.row - reach), c0 = std::max(0, cell.col - reach);
  const int r1 = std::min(h.rows() - 1, cell.row + reach), c1 = std::min(h.cols() - 1, cell.col + reach);
  // The ball of `cell` lies inside the window, so the window's edges clip nothing the definition keeps.
  const Heightmap window = h.window({r0, c0}, r1 - r0 + 1, c1 - c0 + 1);
  return NavigabilityProcessor(p).occupiable(window)(cell.row - r0, cell.col - c0) != 0;
}

}  // namespace

bool cell_occupiable(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& params,
                     OccupancyMethod method) {
  if (!terrain.contains(cell))
    throw InvalidArgument(
        fmt::format("cell_occupiable: cell {} is off the {} x {} grid", cell, terrain.rows(), terrain.cols()));
  const std::vector<CellIndex> offsets = disc_offsets(params.delta_m / (2.0 * terrain.cell_size_m()));
  if (method == OccupancyMethod::kAutomatic)
    method = offsets.size() <= kMaxPairBallCells ? OccupancyMethod::kPairs : OccupancyMethod::kWindow;
  return method == OccupancyMethod::kPairs ? occupiable_by_pairs(terrain, cell, params, offsets)
                                           : occupiable_by_window(terrain, cell, params, offsets);
}

CellMask blind_cells(const CellMask& known, double radius_cells) {
  CellMask blind = CellMask::Zero(known.rows(), known.cols());
  if (known.minCoeff() != 0) return blind;
  const std::vector<CellIndex> ball = disc_offsets(radius_cells);
  for (int r = 0; r < known.rows(); ++r)
    for (int c = 0; c < known.cols(); ++c) {
      if (known(r, c) != 0) continue;
      // The ball is symmetric: the cells whose ball holds (r, c) are those within it of (r, c).
      for (const CellIndex& o : ball) {
        const int pr = r - o.row, pc = c - o.col;
        if (pr >= 0 && pc >= 0 && pr < known.rows() && pc < known.cols()) blind(pr, pc) = 1;
      }
    }
  return blind;
}

}  // namespace marsala
