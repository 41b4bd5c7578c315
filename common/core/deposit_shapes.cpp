#include "marsala/core/deposit_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/registry.hpp"

namespace marsala {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Footprint edges this close to a cell edge [cells] are on it: a cube of side cs centred on a cell centre must not
// leave 1e-17 m slivers on its neighbours.
constexpr double kEdgeSnapCells = 1e-9;

const NamedRegistry<DepositorKind>& registry() {
  static const NamedRegistry<DepositorKind> names = [] {
    NamedRegistry<DepositorKind> r("depositor");
    r.add("layer", DepositorKind::kLayer);
    r.add("cube", DepositorKind::kCube);
    r.add("cone", DepositorKind::kCone);
    return r;
  }();
  return names;
}

double snap(double u) {
  const double whole = std::round(u);
  return std::abs(u - whole) < kEdgeSnapCells ? whole : u;
}

/// Overlap of [u0, u1] with the unit cells [i, i + 1) of 0 <= i < n, as (first index, fractions), scaled so that the
/// fractions add up to u1 - u0 exactly when the interval lies on the cells; off_grid when it leaves [0, n].
struct Overlaps {
  long long first = 0;
  std::vector<double> fractions;
  bool off_grid = false;
};

Overlaps overlaps(double u0, double u1, int n) {
  Overlaps o;
  u0 = snap(u0);
  u1 = snap(u1);
  o.off_grid = u0 < 0.0 || u1 > static_cast<double>(n);
  const double lo = std::max(u0, 0.0), hi = std::min(u1, static_cast<double>(n));
  if (!(hi > lo)) return o;
  const long long first = static_cast<long long>(std::floor(lo));
  const long long last = std::min<long long>(n - 1, static_cast<long long>(std::ceil(hi)) - 1);
  o.first = first;
  double sum = 0.0;
  for (long long i = first; i <= last; ++i) {
    const double f = std::min(hi, static_cast<double>(i + 1)) - std::max(lo, static_cast<double>(i));
    o.fractions.push_back(f > kEdgeSnapCells ? f : 0.0);
    sum += o.fractions.back();
  }
  // Rescale so that the on-grid fractions add up to the on-grid length: the volume is conserved to rounding.
  if (sum > 0.0)
    for (double& f : o.fractions) f *= (hi - lo) / sum;
  return o;
}

bool finite(Position p) { return std::isfinite(p.x) && std::isfinite(p.y); }

}  // namespace

std::string to_string(DepositorKind kind) {
  switch (kind) {
    case DepositorKind::kLayer: return "layer";
    case DepositorKind::kCube: return "cube";
    case DepositorKind::kCone: return "cone";
  }
  return "layer";
}

DepositorKind depositor_kind(const std::string& name) { return registry().find(name); }

std::vector<std::string> depositor_names() { return registry().names(); }

DepositShape cube_column_shape(const GridGeometry& grid, Position centre, double side_m, int cubes) {
  if (!finite(centre) || !(side_m > 0.0) || !std::isfinite(side_m) || cubes < 0)
    throw InvalidArgument(fmt::format(
        "cube column at {}: side {} m must be finite and > 0, the centre finite and the cube count ({}) >= 0", centre,
        side_m, cubes));
  DepositShape shape;
  const double cs = grid.cell_size_m;
  const double half = 0.5 * side_m / cs;  // [cells]
  const double u = (centre.x - grid.xll_m) / cs, v = (centre.y - grid.yll_m) / cs;
  // Columns along u (east); rows along v (north): row r covers v in [rows - r - 1, rows - r).
  const Overlaps cols = overlaps(u - half, u + half, grid.cols);
  const Overlaps rows_up = overlaps(v - half, v + half, grid.rows);
  shape.on_grid = !cols.off_grid && !rows_up.off_grid;
  if (cubes == 0) return shape;
  const double column_m = cubes * side_m;
  for (std::size_t j = rows_up.fractions.size(); j-- > 0;) {  // northmost first: ascending rows
    const int row = grid.rows - 1 - static_cast<int>(rows_up.first + static_cast<long long>(j));
    for (std::size_t i = 0; i < cols.fractions.size(); ++i) {
      const double rise = column_m * (rows_up.fractions[j] * cols.fractions[i]);
      if (!(rise > 0.0)) continue;
      shape.rises.push_back({{row, static_cast<int>(cols.first + static_cast<long long>(i))}, rise});
      shape.volume_m3 += rise * cs * cs;
    }
  }
  return shape;
}

long long whole_cubes(double volume_m3, double side_m) {
  if (!std::isfinite(volume_m3) || !(volume_m3 >= 0.0) || !(side_m > 0.0) || !std::isfinite(side_m)) return -1;
  const double n = volume_m3 / (side_m * side_m * side_m);
  if (!std::isfinite(n) || n > 1e15) return -1;
  const double w = std::round(n);
  return std::abs(n - w) <= 1e-6 ? static_cast<long long>(w) : -1;
}

DepositShape cone_pile_shape(const Heightmap& terrain, Position dump, double volume_m3, double repose_deg) {
  if (!finite(dump) || !std::isfinite(volume_m3) || !(volume_m3 >= 0.0) || !(repose_deg > 0.0) ||
      !(repose_deg < 90.0))
    throw InvalidArgument(fmt::format(
        "cone pile at {}: volume {} m^3 must be finite and >= 0, the angle of repose {} deg in (0, 90), the dump "
        "point finite",
        dump, volume_m3, repose_deg));
  DepositShape shape;
  const GridGeometry& grid = terrain.geometry();
  const std::optional<CellIndex> at = grid.cell_at(dump);
  if (!at) {
    shape.on_grid = false;
    return shape;
  }
  if (volume_m3 == 0.0) return shape;
  const double cs = grid.cell_size_m;
  const double slope = std::tan(repose_deg * kPi / 180.0);
  const double fill_m = volume_m3 / (cs * cs);  // the volume as a height over one cell [m]
  const auto base = [&](CellIndex p) {  // the apex height at which p starts to rise
    const Position c = grid.cell_center(p);
    return terrain(p) + slope * std::hypot(c.x - dump.x, c.y - dump.y);
  };
  // The apex is at most base(dump cell) + fill_m (that cell alone would hold the volume), and a cell farther than R
  // from the dump point starts to rise only above min(h) + slope R: cells beyond R never rise.
  const double apex_bound = base(*at) + fill_m;
  const double radius_m = (apex_bound - terrain.min_height()) / slope;
  const double radius_cells = std::min(radius_m / cs + 1.0, static_cast<double>(grid.rows + grid.cols));
  const int span = static_cast<int>(std::ceil(radius_cells));
  const int r0 = std::max(0, at->row - span), r1 = std::min(grid.rows - 1, at->row + span);
  const int c0 = std::max(0, at->col - span), c1 = std::min(grid.cols - 1, at->col + span);
  struct Candidate {
    double base_m;
    CellIndex cell;
  };
  std::vector<Candidate> cells;
  for (int r = r0; r <= r1; ++r)
    for (int c = c0; c <= c1; ++c) {
      const double b = base({r, c});
      if (b < apex_bound) cells.push_back({b, {r, c}});
    }
  // Lowest base first, ties in row-major order (the scan order; stable): deterministic.
  std::stable_sort(cells.begin(), cells.end(), [](const Candidate& a, const Candidate& b) { return a.base_m < b.base_m; });
  // Water filling: with the n lowest cells rising, the apex is z = (fill + sum of their bases) / n; the first n whose
  // z does not reach the next base is the solution.
  double sum = 0.0, apex = apex_bound;
  std::size_t n = 0;
  while (n < cells.size()) {
    sum += cells[n].base_m;
    ++n;
    apex = (fill_m + sum) / static_cast<double>(n);
    // A cell whose base the apex passes by less than kConeTieM stays as it is: built terrain sits exactly on slopes,
    // so apex and base often tie, and rounding must not decide whether a cell (under a robot, off the grid) rises.
    if (n == cells.size() || apex <= cells[n].base_m + kConeTieM) break;
  }
  std::vector<CellRise> rises;
  for (std::size_t i = 0; i < n; ++i) {  // the first n cells' bases lie below the apex (the first by any amount)
    const double rise = apex - cells[i].base_m;
    if (rise > 0.0) rises.push_back({cells[i].cell, rise});
  }
  std::sort(rises.begin(), rises.end(), [](const CellRise& a, const CellRise& b) {
    return a.cell.row != b.cell.row ? a.cell.row < b.cell.row : a.cell.col < b.cell.col;
  });
  for (const CellRise& r : rises) {
    shape.volume_m3 += r.rise_m * cs * cs;
    if (r.cell.row == 0 || r.cell.col == 0 || r.cell.row == grid.rows - 1 || r.cell.col == grid.cols - 1)
      shape.on_grid = false;
  }
  shape.rises = std::move(rises);
  return shape;
}

}  // namespace marsala
