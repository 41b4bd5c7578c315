#include "marsala/core/navigable_path_planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <tuple>

#include "marsala/core/deposition.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala {
namespace {

/// An open-list entry; ordered by f, then l (nearer the goal first), then cell index: fully deterministic.
struct Entry {
  double f;
  double l;
  int index;
  double k;  // g + alpha * c when pushed
  friend bool operator>(const Entry& a, const Entry& b) {
    return std::tie(a.f, a.l, a.index) > std::tie(b.f, b.l, b.index);
  }
};

}  // namespace

PlannerParams default_planner_params(double delta_m, double cell_size_m) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m) || !(cell_size_m > 0.0) || !std::isfinite(cell_size_m))
    throw InvalidArgument(
        fmt::format("planner: body length {} m and cell size {} m must be finite and > 0", delta_m, cell_size_m));
  PlannerParams p;
  p.delta_m = delta_m;
  p.beta = 1.0;
  p.alpha = cell_size_m / static_cast<double>(disc_offsets(delta_m / (2.0 * cell_size_m)).size());
  return p;
}

NavigablePathPlanner::NavigablePathPlanner(PlannerParams params) : params_(params) {
  if (!(params.alpha >= 0.0) || !std::isfinite(params.alpha) || !(params.beta >= 0.0) || !std::isfinite(params.beta) ||
      !(params.delta_m > 0.0) || !std::isfinite(params.delta_m))
    throw InvalidArgument(
        fmt::format("planner: alpha ({}) and beta ({}) must be finite and >= 0, delta ({} m) finite and > 0",
                    params.alpha, params.beta, params.delta_m));
}

PlannerResult NavigablePathPlanner::plan(const Heightmap& gap, const CellMask& allowed, CellIndex start,
                                         CellIndex goal) const {
  const int rows = gap.rows(), cols = gap.cols();
  if (allowed.rows() != rows || allowed.cols() != cols)
    throw InvalidArgument(fmt::format("planner: the allowed mask is {} x {} but the gap grid {} x {}", allowed.rows(),
                                      allowed.cols(), rows, cols));
  if (!gap.contains(start) || !gap.contains(goal))
    throw InvalidArgument(fmt::format("planner: start {} or goal {} is off the {} x {} map", start, goal, rows, cols));
  PlannerResult result;
  if (allowed(start.row, start.col) == 0 || allowed(goal.row, goal.col) == 0) return result;

  const double cs = gap.cell_size_m();
  const long long n = static_cast<long long>(rows) * cols;
  const auto ball = disc_offsets(params_.delta_m / (2.0 * cs));
  // A cell whose whole ball lies on the grid reads its ball by linear offsets, without a bounds test, and without a
  // test of each value when every gap value is valid; the sum is taken in the ball's order either way (the same bits).
  int reach = 0;
  std::vector<std::ptrdiff_t> ball_at;
  ball_at.reserve(ball.size());
  for (const CellIndex o : ball) {
    reach = std::max({reach, std::abs(o.row), std::abs(o.col)});
    ball_at.push_back(static_cast<std::ptrdiff_t>(o.row) * cols + o.col);
  }
  bool all_valid = true;
  for (long long i = 0; i < n && all_valid; ++i) all_valid = gap.data()[i] >= 0.0 && std::isfinite(gap.data()[i]);
  // Ball sums of the gap (eq. 5), computed when a cell is first reached.
  std::vector<double> ball_gap(static_cast<std::size_t>(n), -1.0);
  const auto ball_sum = [&](int r, int c) {
    double& s = ball_gap[static_cast<std::size_t>(r) * cols + c];
    if (s < 0.0 && all_valid && r >= reach && r < rows - reach && c >= reach && c < cols - reach) {
      const double* at = gap.data() + static_cast<std::ptrdiff_t>(r) * cols + c;
      double sum = 0.0;
      for (const std::ptrdiff_t k : ball_at) sum += at[k];
      s = sum;
    }
    if (s < 0.0) {
      s = 0.0;
      int inside = 0;
      for (const CellIndex o : ball) {
        const CellIndex q{r + o.row, c + o.col};
        if (!gap.contains(q)) continue;
        const double v = gap(q);
        if (!(v >= 0.0) || !std::isfinite(v)) throw InvalidArgument(fmt::format("planner: MARS gap at {} is {}", q, v));
        s += v;
        ++inside;
      }
      // A ball cut by the map edge is priced at its mean gap: otherwise the edge would be a cheap corridor.
      if (inside < static_cast<int>(ball.size())) s = s * static_cast<double>(ball.size()) / inside;
    }
    return s;
  };
  const auto heuristic = [&](int r, int c) {
    const double dr = r - goal.row, dc = c - goal.col;
    return cs * std::sqrt(dr * dr + dc * dc);
  };

  std::vector<double> best_k(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<double> g_of(static_cast<std::size_t>(n), 0.0), c_of(static_cast<std::size_t>(n), 0.0);
  std::vector<int> parent(static_cast<std::size_t>(n), -1);
  std::vector<std::uint8_t> closed(static_cast<std::size_t>(n), 0);
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  const int start_index = start.row * cols + start.col, goal_index = goal.row * cols + goal.col;
  best_k[start_index] = 0.0;
  open.push({params_.beta * heuristic(start.row, start.col), heuristic(start.row, start.col), start_index, 0.0});
  const double diagonal = cs * std::sqrt(2.0);

  while (!open.empty()) {
    const Entry e = open.top();
    open.pop();
    if (closed[e.index] || e.k > best_k[e.index]) continue;
    closed[e.index] = 1;
    ++result.expanded;
    if (e.index == goal_index) break;
    const int r = e.index / cols, c = e.index % cols;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        const int nr = r + dr, nc = c + dc;
        if (nr < 0 || nr >= rows || nc < 0 || nc >= cols || allowed(nr, nc) == 0) continue;
        const int ni = nr * cols + nc;
        if (closed[ni]) continue;
        const double g = g_of[e.index] + (dr != 0 && dc != 0 ? diagonal : cs);
        const double cc = c_of[e.index] + ball_sum(nr, nc);
        const double k = g + params_.alpha * cc;
        if (!(k < best_k[ni])) continue;
        best_k[ni] = k;
        g_of[ni] = g;
        c_of[ni] = cc;
        parent[ni] = e.index;
        const double l = heuristic(nr, nc);
        open.push({k + params_.beta * l, l, ni, k});
      }
  }
  if (!closed[goal_index]) return result;

  for (int i = goal_index; i != -1; i = parent[i]) result.path.push_back({i / cols, i % cols});
  std::reverse(result.path.begin(), result.path.end());
  result.found = true;
  result.length_m = g_of[goal_index];
  result.gap_cost_m = c_of[goal_index];
  result.target_volume_m3 = deposition_target_volume(gap, path_footprint(gap.geometry(), result.path, params_.delta_m));
  return result;
}

}  // namespace marsala
