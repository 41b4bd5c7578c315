#include "marsala/terrain/map_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/statistics.hpp"

namespace marsala::terrain {
namespace {

/// Largest difference of the lower-left corners two grids of one run may have [m]: both are written from one geometry.
constexpr double kCornerToleranceM = 1e-6;

void check_same_grid(const Heightmap& believed, const Heightmap& truth) {
  const GridGeometry& b = believed.geometry();
  const GridGeometry& t = truth.geometry();
  if (b.rows != t.rows || b.cols != t.cols || b.cell_size_m != t.cell_size_m)
    throw InvalidArgument(fmt::format("the grids differ: believed {} x {} cells of {} m, true {} x {} cells of {} m",
                                      b.rows, b.cols, b.cell_size_m, t.rows, t.cols, t.cell_size_m));
  if (std::abs(b.xll_m - t.xll_m) > kCornerToleranceM || std::abs(b.yll_m - t.yll_m) > kCornerToleranceM)
    throw InvalidArgument(fmt::format("the grids differ: believed lower-left corner ({}, {}) m, true ({}, {}) m",
                                      b.xll_m, b.yll_m, t.xll_m, t.yll_m));
}

}  // namespace

CellMask believed_passable(const Heightmap& believed, const NavigabilityParams& body) {
  const NavigabilityProcessor processor(body);
  // Unknown cells read as 0 m for the processor; every cell whose ball holds one is cleared below, so the value
  // decides nothing that is kept.
  Heightmap filled = believed;
  CellMask unknown = CellMask::Zero(believed.rows(), believed.cols());
  for (int r = 0; r < believed.rows(); ++r)
    for (int c = 0; c < believed.cols(); ++c) {
      const double h = believed(r, c);
      if (std::isinf(h))
        throw InvalidArgument(fmt::format("believed map: infinite height at cell {}", CellIndex{r, c}));
      if (std::isnan(h)) {
        unknown(r, c) = 1;
        filled(r, c) = 0.0;
      }
    }
  const CellMask passable = processor.occupiable(filled);
  const CellMask known = (unknown.array() == 0).cast<std::uint8_t>();
  const CellMask blind = blind_cells(known, body.delta_m / (2.0 * believed.cell_size_m()));
  return (passable.array() != 0 && blind.array() == 0).cast<std::uint8_t>();
}

MapComparison compare_maps(const Heightmap& believed, const Heightmap& truth, const NavigabilityParams& body) {
  check_same_grid(believed, truth);
  for (int r = 0; r < truth.rows(); ++r)
    for (int c = 0; c < truth.cols(); ++c)
      if (!std::isfinite(truth(r, c)))
        throw InvalidArgument(
            fmt::format("true map: height {} at cell {} is not finite", truth(r, c), CellIndex{r, c}));
  MapComparison result;
  result.cells = believed.size();
  std::vector<double> errors;
  for (int r = 0; r < believed.rows(); ++r)
    for (int c = 0; c < believed.cols(); ++c)
      if (std::isfinite(believed(r, c))) errors.push_back(std::abs(believed(r, c) - truth(r, c)));
  result.known_cells = static_cast<long long>(errors.size());
  result.median_error_m = median(errors);
  result.p95_error_m = percentile(errors, 0.95);
  result.max_error_m = errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end());
  const CellMask passable = believed_passable(believed, body);
  const CellMask really = NavigabilityProcessor(body).occupiable(truth);
  result.believed_passable = passable.cast<long long>().sum();
  result.true_passable = really.cast<long long>().sum();
  result.believed_passable_not = (passable.array() != 0 && really.array() == 0).cast<long long>().sum();
  return result;
}

}  // namespace marsala::terrain
