#include "marsala/core/route_sites.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigable_path_planner.hpp"

namespace marsala {
namespace {

constexpr double kTinyGapM = 1e-9;  // as the world's kRaisedM: below this a cell is natural ground

void check(bool ok, const char* what, double value) {
  if (!ok) throw InvalidArgument(fmt::format("route sites: {} = {} is out of range", what, value));
}

}  // namespace

Heightmap route_gap(const Heightmap& terrain, double kappa, double radius_m) {
  check(std::isfinite(kappa) && kappa > 0.0, "kappa", kappa);
  check(std::isfinite(radius_m) && radius_m >= 0.0, "radius_m", radius_m);
  if (radius_m > 0.0) {
    // Brute force over the square: (2 R + 1)^2 cells per cell, ~1 s for 640 x 640 cells and R = 20 cells.
    const double cs = terrain.cell_size_m();
    const int reach = static_cast<int>(std::floor(radius_m / cs + 1e-9));
    std::vector<double> drop;  // kappa * distance for each offset of the square, row-major
    for (int dr = -reach; dr <= reach; ++dr)
      for (int dc = -reach; dc <= reach; ++dc) drop.push_back(kappa * cs * std::sqrt(double(dr * dr + dc * dc)));
    Heightmap gap(terrain.geometry(), 0.0);
    const int rows = terrain.rows(), cols = terrain.cols(), side = 2 * reach + 1;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const double h = terrain(r, c);
        double best = h;
        for (int rr = std::max(0, r - reach); rr <= std::min(rows - 1, r + reach); ++rr) {
          const double* line = terrain.data() + static_cast<std::ptrdiff_t>(rr) * cols;
          const double* d = drop.data() + static_cast<std::ptrdiff_t>(rr - r + reach) * side + reach;
          for (int cc = std::max(0, c - reach); cc <= std::min(cols - 1, c + reach); ++cc)
            best = std::max(best, line[cc] - d[cc - c]);
        }
        gap(r, c) = best - h;
      }
    return gap;
  }
  return MarsProcessor(kappa).gap(terrain);
}

RouteSites plan_route_sites(const Heightmap& gap, CellIndex from, CellIndex to, const RouteSiteParams& params) {
  check(std::isfinite(params.width_m) && params.width_m > 0.0, "width_m", params.width_m);
  check(std::isfinite(params.min_depth_m) && params.min_depth_m >= 0.0, "min_depth_m", params.min_depth_m);
  check(std::isfinite(params.min_natural_m) && params.min_natural_m >= 0.0, "min_natural_m", params.min_natural_m);
  for (const CellIndex c : {from, to})
    if (!gap.contains(c))
      throw InvalidArgument(fmt::format("route sites: cell {} is off the {} x {} grid", c, gap.rows(), gap.cols()));
  const double cs = gap.cell_size_m();
  // Every cell is allowed: filling the gap makes it passable (as the world's plan_route_gap).
  const NavigablePathPlanner planner(default_planner_params(params.width_m, cs));
  PlannerResult plan = planner.plan(gap, CellMask::Ones(gap.rows(), gap.cols()), from, to);
  RouteSites out;
  if (!plan.found) return out;  // cannot happen with every cell allowed, but stay a value
  out.route = std::move(plan.path);
  const std::size_t n = out.route.size();
  out.along_m.resize(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const CellIndex p = out.route[i - 1], c = out.route[i];
    out.along_m[i] = out.along_m[i - 1] + ((p.row != c.row && p.col != c.col) ? cs * std::sqrt(2.0) : cs);
  }
  out.length_m = out.along_m.back();
  out.from_gap_m = gap(out.route.front());
  out.to_gap_m = gap(out.route.back());

  // Band volume owned by each route cell: the band cells its ball holds that no earlier cell's did.
  std::vector<double> owned_m3(n, 0.0);
  CellMask taken = CellMask::Zero(gap.rows(), gap.cols());
  const std::vector<CellIndex> ball = disc_offsets(params.width_m / (2.0 * cs));
  for (std::size_t i = 0; i < n; ++i)
    for (const CellIndex& o : ball) {
      const CellIndex b{out.route[i].row + o.row, out.route[i].col + o.col};
      if (!gap.contains(b) || taken(b.row, b.col) != 0) continue;
      taken(b.row, b.col) = 1;
      ++out.band_cells;
      owned_m3[i] += gap(b) * cs * cs;
    }

  // Runs of route cells that need construction, merged across natural ground shorter than min_natural_m.
  const double depth = std::max(params.min_depth_m, kTinyGapM);
  struct Run {
    std::size_t first, last;
  };
  std::vector<Run> runs;
  for (std::size_t i = 0; i < n; ++i) {
    const double g = gap(out.route[i]);
    if (!(g > kTinyGapM && g >= depth)) continue;
    if (runs.empty() || out.along_m[i] - out.along_m[runs.back().last] >= params.min_natural_m) runs.push_back({i, i});
    runs.back().last = i;
  }
  // Each site owns the route from the middle of the natural ground before it to the middle of the one after.
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::size_t begin = k == 0 ? 0 : (runs[k - 1].last + runs[k].first) / 2 + 1;
    const std::size_t end = k + 1 == runs.size() ? n : (runs[k].last + runs[k + 1].first) / 2 + 1;
    RouteSite site;
    site.from_m = out.along_m[runs[k].first];
    site.to_m = out.along_m[runs[k].last];
    for (std::size_t i = begin; i < end; ++i) {
      site.volume_m3 += owned_m3[i];
      if (i >= runs[k].first && i <= runs[k].last) site.max_gap_m = std::max(site.max_gap_m, gap(out.route[i]));
    }
    out.sites.push_back(site);
  }
  for (const double v : owned_m3) out.band_volume_m3 += v;
  return out;
}

}  // namespace marsala
