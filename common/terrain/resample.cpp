#include "marsala/terrain/resample.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::terrain {
namespace {

// Tolerance of floor(width / cs' + 1e-9): 0.6 / 0.2 is 2.9999999999999996 and must give 3 cells.
constexpr double kCountTolerance = 1e-9;
constexpr double kMaxResampledCells = 2147483648.0;  // 2^31

// Kept cell range [first, last] along one axis: centres first + (i + 0.5) * cs (as
// GridGeometry::cell_center computes them) inside [lo, hi). Returns false when none.
bool centres_in(double origin_m, double cell_size_m, int count, double lo_m, double hi_m, int& first, int& last) {
  auto centre = [&](int i) { return origin_m + (i + 0.5) * cell_size_m; };
  // Start from the arithmetic estimate, then settle it with the exact comparisons of the definition.
  const double estimate_lo = std::ceil((lo_m - origin_m) / cell_size_m - 0.5);
  const double estimate_hi = std::ceil((hi_m - origin_m) / cell_size_m - 0.5) - 1.0;
  first = static_cast<int>(std::clamp(estimate_lo, 0.0, static_cast<double>(count)));
  last = static_cast<int>(std::clamp(estimate_hi, -1.0, static_cast<double>(count - 1)));
  while (first > 0 && centre(first - 1) >= lo_m) --first;
  while (first < count && centre(first) < lo_m) ++first;
  while (last + 1 < count && centre(last + 1) < hi_m) ++last;
  while (last >= 0 && centre(last) >= hi_m) --last;
  return first <= last;
}

// Source sample positions and weights along one axis of the resampled grid.
struct Taps {
  std::vector<int> lower;
  std::vector<int> upper;
  std::vector<double> fraction;
};

// New cell i has its centre at (i + 0.5) * new_cs from the grid's low edge, that is at
// (i + 0.5) * ratio - 0.5 source cells from the first source centre; clamped to the outermost centres.
Taps make_taps(int new_count, double ratio, int source_count) {
  Taps taps;
  taps.lower.resize(new_count);
  taps.upper.resize(new_count);
  taps.fraction.resize(new_count);
  for (int i = 0; i < new_count; ++i) {
    const double u = std::clamp((i + 0.5) * ratio - 0.5, 0.0, static_cast<double>(source_count - 1));
    const int lower = std::min(static_cast<int>(std::floor(u)), source_count - 1);
    taps.lower[i] = lower;
    taps.upper[i] = std::min(lower + 1, source_count - 1);
    taps.fraction[i] = u - lower;
  }
  return taps;
}

}  // namespace

Heightmap crop(const Heightmap& map, double x0_m, double y0_m, double width_m, double height_m) {
  if (!std::isfinite(x0_m) || !std::isfinite(y0_m) || !std::isfinite(width_m) || !std::isfinite(height_m))
    throw InvalidArgument("crop: the rectangle must be finite");
  if (!(width_m > 0.0) || !(height_m > 0.0))
    throw InvalidArgument(fmt::format("crop: width and height must be positive, got {} x {} m", width_m, height_m));
  const GridGeometry& g = map.geometry();
  int col_first = 0, col_last = 0, south_first = 0, south_last = 0;
  // Rows are counted from the south here: cell_center's y is yll + (rows - r - 0.5) * cs.
  if (g.rows <= 0 || g.cols <= 0 ||
      !centres_in(g.xll_m, g.cell_size_m, g.cols, x0_m, x0_m + width_m, col_first, col_last) ||
      !centres_in(g.yll_m, g.cell_size_m, g.rows, y0_m, y0_m + height_m, south_first, south_last))
    throw InvalidArgument(
        fmt::format("crop: no cell centre lies in [{}, {}) x [{}, {}) m", x0_m, x0_m + width_m, y0_m, y0_m + height_m));
  const int top_row = g.rows - 1 - south_last;
  return map.window({top_row, col_first}, south_last - south_first + 1, col_last - col_first + 1);
}

Heightmap resample_bilinear(const Heightmap& map, double cell_size_m) {
  if (!(cell_size_m > 0.0) || !std::isfinite(cell_size_m))
    throw InvalidArgument(
        fmt::format("resample_bilinear: cell size must be positive and finite, got {} m", cell_size_m));
  const GridGeometry& g = map.geometry();
  if (g.rows <= 0 || g.cols <= 0) throw InvalidArgument("resample_bilinear: the heightmap is empty");
  const double cols_real = std::floor(g.cols * g.cell_size_m / cell_size_m + kCountTolerance);
  const double rows_real = std::floor(g.rows * g.cell_size_m / cell_size_m + kCountTolerance);
  if (cols_real < 1.0 || rows_real < 1.0)
    throw InvalidArgument(fmt::format("resample_bilinear: a cell of {} m does not fit in the {} x {} m extent",
                                      cell_size_m, g.cols * g.cell_size_m, g.rows * g.cell_size_m));
  if (cols_real * rows_real > kMaxResampledCells)
    throw InvalidArgument(
        fmt::format("resample_bilinear: a cell of {} m would give {} x {} cells", cell_size_m, cols_real, rows_real));
  GridGeometry out_geometry = g;
  out_geometry.cols = static_cast<int>(cols_real);
  out_geometry.rows = static_cast<int>(rows_real);
  out_geometry.cell_size_m = cell_size_m;
  Heightmap out(out_geometry);

  // ratio == 1 when the size is unchanged, so the identity resampling is exact.
  const double ratio = cell_size_m / g.cell_size_m;
  const Taps x_taps = make_taps(out_geometry.cols, ratio, g.cols);
  // Along y the taps count from the south edge; source row r is south index rows - 1 - r.
  const Taps y_taps = make_taps(out_geometry.rows, ratio, g.rows);
  for (int r = 0; r < out_geometry.rows; ++r) {
    const int south = out_geometry.rows - 1 - r;
    const int source_low = g.rows - 1 - y_taps.lower[south];   // southern source row
    const int source_high = g.rows - 1 - y_taps.upper[south];  // northern source row
    const double s = y_taps.fraction[south];
    for (int c = 0; c < out_geometry.cols; ++c) {
      const int c0 = x_taps.lower[c];
      const int c1 = x_taps.upper[c];
      const double t = x_taps.fraction[c];
      // Differences, not weights: a constant neighbourhood gives its value exactly.
      const double h_low = map(source_low, c0) + t * (map(source_low, c1) - map(source_low, c0));
      const double h_high = map(source_high, c0) + t * (map(source_high, c1) - map(source_high, c0));
      out(r, c) = h_low + s * (h_high - h_low);
    }
  }
  return out;
}

}  // namespace marsala::terrain
