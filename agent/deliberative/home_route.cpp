#include "marsala/agent/deliberative/home_route.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::deliberative {
namespace {

/// The rectangle [top, bottom] x [left, right] of world indices the search runs on.
struct Box {
  int top = 0, left = 0, bottom = 0, right = 0;
  void include(CellIndex c) {
    top = std::min(top, c.row), bottom = std::max(bottom, c.row);
    left = std::min(left, c.col), right = std::max(right, c.col);
  }
};

Box search_box(const KnownMap& map, CellIndex from, CellIndex base_cell, int margin) {
  Box b{from.row, from.col, from.row, from.col};
  b.include(base_cell);
  for (const CellIndex c : map.trajectory) b.include(c);
  const GridGeometry& g = map.geometry();
  return {std::max(0, b.top - margin), std::max(0, b.left - margin), std::min(g.rows - 1, b.bottom + margin),
          std::min(g.cols - 1, b.right + margin)};
}

/// Occupiable cells of the box's heights whose whole body ball is known (box indices).
CellMask judged_occupiable(const KnownMap& map, const NavigabilityParams& body, const Box& box) {
  const int rows = box.bottom - box.top + 1, cols = box.right - box.left + 1;
  const Heightmap heights = map.heights.window({box.top, box.left}, rows, cols);
  CellMask occupiable = NavigabilityProcessor(body).occupiable(heights);
  const auto ball = disc_offsets(body.delta_m / (2.0 * map.geometry().cell_size_m));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (map.known(box.top + r, box.left + c) != 0) continue;
      for (const CellIndex o : ball) {
        const int pr = r - o.row, pc = c - o.col;
        if (pr >= 0 && pc >= 0 && pr < rows && pc < cols) occupiable(pr, pc) = 0;
      }
    }
  return occupiable;
}

}  // namespace

std::optional<std::vector<CellIndex>> home_route(const KnownMap& map, const NavigabilityParams& body, CellIndex from,
                                                 Position base, double radius_m, double margin_m) {
  const GridGeometry& g = map.geometry();
  if (!g.contains(from)) throw InvalidArgument(fmt::format("home route: the start cell {} is off the grid", from));
  for (const double v : {base.x, base.y, radius_m, margin_m})
    if (!std::isfinite(v)) throw InvalidArgument("home route: the base, its radius and the margin must be finite");
  if (!(radius_m > 0.0) || !(margin_m >= 0.0))
    throw InvalidArgument(fmt::format("home route: radius {} m must be > 0 and margin {} m >= 0", radius_m, margin_m));
  const double cs = g.cell_size_m;
  const CellIndex base_cell = g.cell_at(base).value_or(from);  // a base off the grid: the box around the trajectory
  const Box box = search_box(map, from, base_cell, static_cast<int>(std::ceil(margin_m / cs)) + 1);
  const CellMask occupiable = judged_occupiable(map, body, box);
  const int rows = occupiable.rows(), cols = occupiable.cols();
  const auto index = [&](int r, int c) { return static_cast<std::size_t>(r) * cols + c; };
  const int r0 = from.row - box.top, c0 = from.col - box.left;
  if (occupiable(r0, c0) == 0) return std::nullopt;

  // Dijkstra from the robot's cell until the first cell within the base radius (ties: the lower index first).
  std::vector<double> cost(static_cast<std::size_t>(rows) * cols, std::numeric_limits<double>::infinity());
  std::vector<std::size_t> parent(cost.size(), 0);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  cost[index(r0, c0)] = 0.0;
  open.push({0.0, index(r0, c0)});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > cost[i]) continue;
    const int r = static_cast<int>(i / cols), c = static_cast<int>(i % cols);
    const Position centre = g.cell_center({box.top + r, box.left + c});
    if (std::hypot(centre.x - base.x, centre.y - base.y) <= radius_m) {
      std::vector<CellIndex> route;
      for (std::size_t k = i;; k = parent[k]) {
        route.push_back({box.top + static_cast<int>(k / cols), box.left + static_cast<int>(k % cols)});
        if (k == index(r0, c0)) break;
      }
      std::reverse(route.begin(), route.end());
      return route;
    }
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const int nr = r + dr, nc = c + dc;
        if ((dr == 0 && dc == 0) || nr < 0 || nc < 0 || nr >= rows || nc >= cols || occupiable(nr, nc) == 0) continue;
        const double next = d + (dr != 0 && dc != 0 ? std::sqrt(2.0) : 1.0);
        if (next < cost[index(nr, nc)]) cost[index(nr, nc)] = next, parent[index(nr, nc)] = i, open.push({next, index(nr, nc)});
      }
  }
  return std::nullopt;
}

}  // namespace marsala::agent::deliberative
