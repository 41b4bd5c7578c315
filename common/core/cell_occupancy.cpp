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

/// The cells of `cell`'s ball on the grid (offsets `offsets`) with their heights.
struct BallCell {
  CellIndex cell;
  double height;
};
std::vector<BallCell> ball_cells(const Heightmap& h, CellIndex cell, const std::vector<CellIndex>& offsets) {
  std::vector<BallCell> ball;
  ball.reserve(offsets.size());
  for (const CellIndex& o : offsets) {
    const CellIndex c{cell.row + o.row, cell.col + o.col};
    if (h.contains(c)) ball.push_back({c, h(c)});
  }
  return ball;
}

/// How much the heights of two ball cells may differ [m]: the expression NavigabilityProcessor's kernel uses, so that
/// ties are decided identically.
double pair_threshold(const NavigabilityParams& p, double cs, const BallCell& a, const BallCell& b) {
  const long long dr = a.cell.row - b.cell.row, dc = a.cell.col - b.cell.col;
  return p.eps_m + p.kappa * (cs * std::sqrt(static_cast<double>(dr * dr + dc * dc))) + tolerance::kHeightM;
}

bool occupiable_by_pairs(const Heightmap& h, CellIndex cell, const NavigabilityParams& p,
                         const std::vector<CellIndex>& offsets) {
  const std::vector<BallCell> ball = ball_cells(h, cell, offsets);
  const double cs = h.cell_size_m();
  for (std::size_t a = 0; a < ball.size(); ++a)
    for (std::size_t b = a + 1; b < ball.size(); ++b)
      if (std::abs(ball[a].height - ball[b].height) > pair_threshold(p, cs, ball[a], ball[b])) return false;
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

std::vector<OccupancyBreach> occupancy_breaches(const Heightmap& terrain, CellIndex cell,
                                                const NavigabilityParams& params) {
  if (!terrain.contains(cell))
    throw InvalidArgument(
        fmt::format("occupancy_breaches: cell {} is off the {} x {} grid", cell, terrain.rows(), terrain.cols()));
  // The pairs occupiable_by_pairs() judges, by the same threshold, so that a breach is found exactly where it says no.
  const std::vector<BallCell> ball =
      ball_cells(terrain, cell, disc_offsets(params.delta_m / (2.0 * terrain.cell_size_m())));
  const double cs = terrain.cell_size_m();
  // Per lower cell, its worst pair and where that pair comes in the pair order (a < b, a first), for the ties.
  struct Worst {
    double excess = 0.0;
    std::size_t rank = 0;
    CellIndex high;
  };
  std::vector<Worst> worst(ball.size());
  for (std::size_t a = 0; a < ball.size(); ++a)
    for (std::size_t b = a + 1; b < ball.size(); ++b) {
      const double excess = std::abs(ball[a].height - ball[b].height) - pair_threshold(params, cs, ball[a], ball[b]);
      if (!(excess > 0.0)) continue;
      const bool a_low = ball[a].height < ball[b].height;
      Worst& w = worst[a_low ? a : b];
      if (!(excess > w.excess)) continue;
      w = Worst{excess, a * ball.size() + b, a_low ? ball[b].cell : ball[a].cell};
    }
  std::vector<std::size_t> lows;
  for (std::size_t i = 0; i < ball.size(); ++i)
    if (worst[i].excess > 0.0) lows.push_back(i);
  std::sort(lows.begin(), lows.end(), [&](std::size_t x, std::size_t y) {
    return worst[x].excess != worst[y].excess ? worst[x].excess > worst[y].excess : worst[x].rank < worst[y].rank;
  });
  std::vector<OccupancyBreach> out;
  out.reserve(lows.size());
  for (const std::size_t i : lows) out.push_back({ball[i].cell, worst[i].high});
  return out;
}

std::optional<OccupancyBreach> occupancy_breach(const Heightmap& terrain, CellIndex cell,
                                                const NavigabilityParams& params) {
  const std::vector<OccupancyBreach> all = occupancy_breaches(terrain, cell, params);
  if (all.empty()) return std::nullopt;
  return all.front();
}

bool cell_occupiable_in_ball(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& params,
                             const std::vector<CellIndex>& ball) {
  if (!terrain.contains(cell))
    throw InvalidArgument(
        fmt::format("cell_occupiable: cell {} is off the {} x {} grid", cell, terrain.rows(), terrain.cols()));
  return occupiable_by_pairs(terrain, cell, params, ball);
}

CellMask blind_cells(const CellMask& known, double radius_cells) {
  const int rows = static_cast<int>(known.rows()), cols = static_cast<int>(known.cols());
  CellMask blind = CellMask::Zero(rows, cols);
  if (known.size() == 0 || known.minCoeff() != 0) return blind;
  // The ball as one span of columns per row offset: disc_offsets holds, for row offset dr, the columns
  // [-half[dr], half[dr]] (a disc). A cell is blind when one of its ball's spans holds an unknown cell: counted by
  // prefix sums of the unknown cells along each row, (2 reach + 1) look-ups per cell instead of one write per unknown
  // cell and offset (the scanned maps' windows are half unknown).
  const std::vector<CellIndex> ball = disc_offsets(radius_cells);
  int reach = 0;
  for (const CellIndex& o : ball) reach = std::max(reach, std::abs(o.row));
  std::vector<int> half(static_cast<std::size_t>(2 * reach + 1), -1);
  for (const CellIndex& o : ball) {
    int& h = half[static_cast<std::size_t>(o.row + reach)];
    h = std::max(h, std::abs(o.col));
  }
  const std::size_t stride = static_cast<std::size_t>(cols) + 1;
  std::vector<int> unknown_before(static_cast<std::size_t>(rows) * stride, 0);  // row r, columns [0, c)
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      unknown_before[r * stride + c + 1] = unknown_before[r * stride + c] + (known(r, c) == 0 ? 1 : 0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      for (int dr = -reach; dr <= reach; ++dr) {
        const int y = r + dr, w = half[static_cast<std::size_t>(dr + reach)];
        if (y < 0 || y >= rows || w < 0) continue;
        const int c0 = std::max(0, c - w), c1 = std::min(cols - 1, c + w);
        if (unknown_before[y * stride + c1 + 1] > unknown_before[y * stride + c0]) {
          blind(r, c) = 1;
          break;
        }
      }
  return blind;
}

}  // namespace marsala
