#include "marsala/core/navigability_processor.hpp"

#include <cmath>
#include <cstddef>
#include <deque>
#include <sstream>
#include <string>

#include "marsala/core/detail/navigability_kernel.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

void require(bool ok, const char* name, double value, const char* rule) {
  if (!ok) throw InvalidArgument(fmt::format("NavigabilityProcessor: {} must be {}, got {}", name, rule, value));
}

void check_finite(const Heightmap& h) {
  const double* heights = h.data();
  const long long n = h.size();
  for (long long i = 0; i < n; ++i)
    if (!std::isfinite(heights[i])) {
      const CellIndex cell{static_cast<int>(i / h.cols()), static_cast<int>(i % h.cols())};
      throw InvalidArgument(
          fmt::format("NavigabilityProcessor: height at cell {} is not finite ({})", cell, heights[i]));
    }
}

void check_origin(int rows, int cols, CellIndex origin) {
  if (origin.row < 0 || origin.row >= rows || origin.col < 0 || origin.col >= cols)
    throw InvalidArgument(fmt::format("NavigabilityProcessor: origin {} is off the {} x {} grid", origin, rows, cols));
}

}  // namespace

NavigabilityProcessor::NavigabilityProcessor(NavigabilityParams params) : params_(params) {
  require(std::isfinite(params_.kappa) && params_.kappa > 0.0, "kappa", params_.kappa, "finite and > 0 [m/m]");
  require(std::isfinite(params_.delta_m) && params_.delta_m > 0.0, "delta_m", params_.delta_m, "finite and > 0 [m]");
  require(std::isfinite(params_.eps_m) && params_.eps_m >= 0.0, "eps_m", params_.eps_m, "finite and >= 0 [m]");
}

CellMask NavigabilityProcessor::occupiable(const Heightmap& h) const {
  check_finite(h);
  return detail::occupiable_mask(h, params_);
}

CellMask NavigabilityProcessor::navigable(const Heightmap& h, CellIndex origin) const {
  check_origin(h.rows(), h.cols(), origin);
  return navigable_from(occupiable(h), origin);
}

CellMask NavigabilityProcessor::navigable_from(const CellMask& occupiable, CellIndex origin) {
  const int rows = static_cast<int>(occupiable.rows()), cols = static_cast<int>(occupiable.cols());
  check_origin(rows, cols, origin);
  CellMask navigable = CellMask::Zero(rows, cols);
  if (occupiable(origin.row, origin.col) == 0) return navigable;
  // Breadth-first: the queue holds the frontier only, which stays small on open ground.
  std::deque<CellIndex> frontier;
  navigable(origin.row, origin.col) = 1;
  frontier.push_back(origin);
  while (!frontier.empty()) {
    const CellIndex cell = frontier.front();
    frontier.pop_front();
    for (int dr = -1; dr <= 1; ++dr) {
      const int r = cell.row + dr;
      if (r < 0 || r >= rows) continue;
      for (int dc = -1; dc <= 1; ++dc) {
        const int c = cell.col + dc;
        if (c < 0 || c >= cols || navigable(r, c) != 0 || occupiable(r, c) == 0) continue;
        navigable(r, c) = 1;
        frontier.push_back({r, c});
      }
    }
  }
  return navigable;
}

}  // namespace marsala
