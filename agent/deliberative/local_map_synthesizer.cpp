#include "marsala/agent/deliberative/local_map_synthesizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala::agent::deliberative {
namespace {

int clamp_int(double v, int lo, int hi) {
  if (!(v >= lo)) return lo;  // also catches NaN
  if (v > hi) return hi;
  return static_cast<int>(v);
}

bool rim(const KnownMap& map, CellIndex n) {
  if (!map.heights.contains(n) || map.known(n.row, n.col) == 0) return false;
  return map.assumed(n.row, n.col) == 0 || map.bound(n.row, n.col) != 0;  // a guess is no rim
}

}  // namespace

double notch_fill(const KnownMap& map, CellIndex cell) {
  if (!map.heights.contains(cell) || map.bound(cell.row, cell.col) == 0) return 0.0;
  const double floor_m = map.heights(cell);
  double level_m = floor_m;
  for (const CellIndex step : {CellIndex{1, 0}, CellIndex{0, 1}}) {
    const CellIndex a{cell.row - step.row, cell.col - step.col}, b{cell.row + step.row, cell.col + step.col};
    if (rim(map, a) && rim(map, b)) level_m = std::max(level_m, std::min(map.heights(a), map.heights(b)));
  }
  return level_m - floor_m;
}

Window sensing_window(const GridGeometry& world, Position robot, double range_m) {
  if (!(range_m >= 0.0) || !std::isfinite(range_m))
    throw InvalidArgument(fmt::format("sensing range must be finite and >= 0 m, got {}", range_m));
  if (!std::isfinite(robot.x) || !std::isfinite(robot.y) || !world.cell_at(robot))
    throw InvalidArgument(fmt::format("local map: the robot at {} is off the grid", robot));
  const double cs = world.cell_size_m;
  const int col_lo = clamp_int(std::floor((robot.x - range_m - world.xll_m) / cs), 0, world.cols - 1);
  const int col_hi = clamp_int(std::floor((robot.x + range_m - world.xll_m) / cs), 0, world.cols - 1);
  const int south_lo = clamp_int(std::floor((robot.y - range_m - world.yll_m) / cs), 0, world.rows - 1);
  const int south_hi = clamp_int(std::floor((robot.y + range_m - world.yll_m) / cs), 0, world.rows - 1);
  return {{world.rows - 1 - south_hi, col_lo}, south_hi - south_lo + 1, col_hi - col_lo + 1};
}

LocalMapSynthesizer::LocalMapSynthesizer(NavigabilityParams params, double sensing_range_m,
                                         std::optional<double> construction_kappa)
    : mars_(construction_kappa.value_or(params.kappa)), navigability_(params), sensing_range_m_(sensing_range_m) {
  if (!(sensing_range_m >= 0.0) || !std::isfinite(sensing_range_m))
    throw InvalidArgument(
        fmt::format("local map synthesizer: sensing range must be finite and >= 0 m, got {}", sensing_range_m));
}

LocalMap LocalMapSynthesizer::synthesize(const KnownMap& map, Position robot, Position target) const {
  const Window w = sensing_window(map.geometry(), robot, sensing_range_m_);
  LocalMap local;
  local.world = map.geometry();
  local.offset = w.top_left;
  local.heights = map.heights.window(w.top_left, w.rows, w.cols);
  local.known = map.known.block(w.top_left.row, w.top_left.col, w.rows, w.cols);

  // Unknown cells take the lowest known height: they then never raise the MARS bound of a known cell.
  const bool all_known = local.known.minCoeff() != 0;
  if (!all_known) {
    double lowest = std::numeric_limits<double>::infinity();
    for (int r = 0; r < w.rows; ++r)
      for (int c = 0; c < w.cols; ++c)
        if (local.known(r, c) != 0) lowest = std::min(lowest, local.heights(r, c));
    if (!std::isfinite(lowest)) lowest = 0.0;
    for (int r = 0; r < w.rows; ++r)
      for (int c = 0; c < w.cols; ++c)
        if (local.known(r, c) == 0) local.heights(r, c) = lowest;
  }

  gap_and_occupiable(local);
  // A ball that holds an unknown cell cannot be judged: treat its centre as not occupiable. No gap on unknown cells.
  local.blind = blind_cells(local.known, params().delta_m / (2.0 * local.geometry().cell_size_m));
  for (int r = 0; r < w.rows; ++r)
    for (int c = 0; c < w.cols; ++c) {
      if (local.blind(r, c) != 0) local.occupiable(r, c) = 0;
      if (local.known(r, c) == 0) local.gap(r, c) = 0.0;
    }
  local.heights_occupiable = local.occupiable;
  local.heights_navigability = params();
  if (map.overflight && !all_known) fill_under_rays(local, *map.overflight);

  // Ground the map only assumes (under and around the robot's body: KnownMap::assumed) is no deposition
  // target: building on it would never show in the map. A bound in a notch is filled up to its notch level
  // (notch_fill), a cap the map's noise margin does not shrink: the level is the lower of two readings, not a maximum
  // over many like the MARS height, and a notch left a margin deep is still one the body cannot cross.
  const auto assumed = map.assumed.block(w.top_left.row, w.top_left.col, w.rows, w.cols);
  if (map.bound.block(w.top_left.row, w.top_left.col, w.rows, w.cols).any())
    local.fill_cap = Heightmap(local.geometry(), std::numeric_limits<double>::infinity());
  for (int r = 0; r < w.rows; ++r)
    for (int c = 0; c < w.cols; ++c) {
      if (assumed(r, c) == 0) continue;
      const double fill_m = notch_fill(map, local.to_global({r, c}));
      if (!(fill_m > 0.0)) local.gap(r, c) = 0.0;
      if (local.fill_cap.rows() == w.rows) local.fill_cap(r, c) = fill_m;
    }

  local.robot = local.to_local(*map.geometry().cell_at(robot));
  // A scanned map may hold the robot's own cell not occupiable (a reading that changed under it, a face beside it);
  // the world lets a robot drive out of its own cell (docs/runtime.md#rule-2-motion), so it counts as occupiable and
  // the robot keeps its way out instead of standing still for good.
  if (map.scanned) local.occupiable(local.robot.row, local.robot.col) = 1;
  // So is every cell it stood on while its ball reads as it did then: the world put the body there, so it was
  // occupiable, and a reading a few mm off (a step within noise of eps + kappa cs) must not wall the robot in on an
  // island of its own map (docs/runtime.md#cells-stood-on).
  if (map.scanned && map.stood) open_stood_cells(local, map);
  local.navigable = NavigabilityProcessor::navigable_from(local.occupiable, local.robot);
  local.origin = local_origin(local, map.trajectory, robot, sensing_range_m_);
  const auto [goal, is_target] = local_goal(local, robot, target);
  local.goal = goal;
  local.goal_is_target = is_target;
  local.passable = local.known;
  if (!all_known && map.scanned) {
    // A scanning sensor's map has holes (between a laser's rings) and shadows (tiles always cover the window, so a
    // ground-truth robot keeps waiting for its map to grow). A path runs through known cells only, so when the goal
    // is not 8-connected to the robot through them, head for the reachable one nearest to it (ties: the first in
    // row-major order): the robot moves, its next scans fill the holes ahead. Known cells that can be judged (not
    // blind) first, and the path through them only: a path or goal on blind cells draws the robot along the edge of
    // what it knows (a structure's side, whose shadow it never sees) instead of where its map is whole. When the
    // judged cells bring the robot no nearer than a body radius, the known ones: the robot would otherwise stand
    // still, its goal reached, and a camera that sees only ahead would never learn more. A body radius, not any
    // nearer cell: a judged cell one step nearer sends the robot there, where the known cells' path leads it back one
    // step, and it shuttles between the two for good.
    const CellMask judged = (local.known.array() != 0 && local.blind.array() == 0).cast<std::uint8_t>();
    const auto distance = [&](CellIndex a) { return std::hypot(a.row - goal.row, a.col - goal.col); };
    const double radius_cells = params().delta_m / (2.0 * local.geometry().cell_size_m);
    for (const CellMask* mask : std::initializer_list<const CellMask*>{&judged, &local.known}) {
      if ((*mask)(local.robot.row, local.robot.col) == 0) continue;
      const CellMask reachable = NavigabilityProcessor::navigable_from(*mask, local.robot);
      CellIndex nearest = goal;
      if (reachable(goal.row, goal.col) == 0) {
        long long best = std::numeric_limits<long long>::max();
        for (int r = 0; r < local.rows(); ++r)
          for (int c = 0; c < local.cols(); ++c) {
            if (reachable(r, c) == 0) continue;
            const long long dr = r - goal.row, dc = c - goal.col, d = dr * dr + dc * dc;
            if (d < best) best = d, nearest = {r, c};
          }
        if (mask == &judged && distance(nearest) > distance(local.robot) - radius_cells) continue;
        local.goal_is_target = false;
      }
      local.goal = nearest;
      local.passable = *mask;
      break;
    }
  }
  return local;
}

void LocalMapSynthesizer::fill_under_rays(LocalMap& local, const Heightmap& overflight) const {
  local.overflown = CellMask::Zero(local.rows(), local.cols());
  double lowest = std::numeric_limits<double>::infinity();
  bool any = false;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      if (local.known(r, c) != 0) {
        lowest = std::min(lowest, local.heights(r, c));
      } else if (std::isfinite(overflight(local.to_global({r, c})))) {
        local.overflown(r, c) = 1;
        any = true;
      }
    }
  if (!any || !std::isfinite(lowest)) {
    local.overflown = CellMask();
    return;
  }
  // The known cells alone are the sources: an unknown cell sits below every known cell's cone anywhere in the window,
  // so it raises no bound (the window's heights put it at the lowest known height, which may lie above a known cell's
  // cone far from it). The overflight itself is no source either: it is where a ray passed, not where terrain is.
  const double cs = local.geometry().cell_size_m;
  const double below_m = mars_.kappa() * cs * std::hypot(local.rows(), local.cols()) + 1.0;
  Heightmap sources = local.heights;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (local.known(r, c) == 0) sources(r, c) = lowest - below_m;
  const Heightmap bound = mars_.project(sources, local.overflown);
  // Its height in the window is the overflight from now on, the most it can be: what is judged against another bound
  // later (the band's, executive::gap_below) is then judged from there too; blind balls stay blind.
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (local.overflown(r, c) != 0) {
        local.heights(r, c) = overflight(local.to_global({r, c}));
        local.gap(r, c) = std::max(0.0, bound(r, c) - local.heights(r, c));
      }
}

void LocalMapSynthesizer::open_stood_cells(LocalMap& local, const KnownMap& map) {
  const StoodCells& stood = *map.stood;
  const std::vector<CellIndex>& ball = stood.ball;
  const long long cols = map.heights.cols();
  // The window's cells, not every cell ever stood on: the work is bounded by the window, not by the run's length.
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      if (local.occupiable(r, c) != 0 || local.blind(r, c) != 0) continue;
      const CellIndex global = local.to_global({r, c});
      const auto found = stood.balls.find(global.row * cols + global.col);
      if (found == stood.balls.end() || found->second.size() != ball.size()) continue;
      const std::vector<double>& then = found->second;
      bool same = true;
      for (std::size_t i = 0; i < ball.size() && same; ++i) {
        const CellIndex b{global.row + ball[i].row, global.col + ball[i].col};
        if (!map.heights.contains(b)) continue;
        same = std::isfinite(then[i]) && map.known(b.row, b.col) != 0 &&
               std::abs(map.heights(b) - then[i]) <= stood.margin_m;
      }
      if (same) local.occupiable(r, c) = 1;
    }
}

void LocalMapSynthesizer::gap_and_occupiable(LocalMap& local) const {
  const double* first = local.heights.data();
  const double* last = first + static_cast<std::ptrdiff_t>(local.rows()) * local.cols();
  if (memo_.offset == local.offset && memo_.rows == local.rows() && memo_.cols == local.cols() &&
      std::equal(first, last, memo_.heights.begin(), memo_.heights.end())) {
    local.gap = memo_.gap;
    local.occupiable = memo_.occupiable;
    return;
  }
  local.gap = mars_.gap(local.heights);
  local.occupiable = occupiable_after_memo(local);
  memo_ = Memo{local.offset, local.rows(), local.cols(), std::vector<double>(first, last), local.gap, local.occupiable};
}

CellMask LocalMapSynthesizer::occupiable_after_memo(const LocalMap& local) const {
  const int rows = local.rows(), cols = local.cols();
  if (memo_.rows <= 0 || memo_.cols <= 0 || rows <= 0 || cols <= 0) return navigability_.occupiable(local.heights);
  const double cs = local.geometry().cell_size_m;
  const double radius_cells = params().delta_m / (2.0 * cs);
  const NavigabilityParams& p = params();
  if (radius_cells != ball_radius_cells_) {
    ball_ = disc_offsets(radius_cells);
    ball_radius_cells_ = radius_cells;
    ball_reach_ = 0;
    for (const CellIndex& o : ball_) ball_reach_ = std::max({ball_reach_, std::abs(o.row), std::abs(o.col)});
    // Each pair of the ball with the threshold cell_occupiable_in_ball() gives it (the processor's expression).
    ball_pairs_.clear();
    for (std::size_t a = 0; a < ball_.size(); ++a)
      for (std::size_t b = a + 1; b < ball_.size(); ++b) {
        const long long dr = ball_[a].row - ball_[b].row, dc = ball_[a].col - ball_[b].col;
        ball_pairs_.push_back({a, b, p.eps_m + p.kappa * (cs * std::sqrt(static_cast<double>(dr * dr + dc * dc))) +
                                         tolerance::kHeightM});
      }
  }
  const int reach = ball_reach_;
  // Both windows in world indices: [first, last] rows and columns.
  const int new_r0 = local.offset.row, new_c0 = local.offset.col;
  const int new_r1 = new_r0 + rows - 1, new_c1 = new_c0 + cols - 1;
  const int old_r0 = memo_.offset.row, old_c0 = memo_.offset.col;
  const int old_r1 = old_r0 + memo_.rows - 1, old_c1 = old_c0 + memo_.cols - 1;
  // A cell's ball rows clipped by the new window and by the old one are the same rows (likewise columns).
  const auto clipped_alike = [reach](int g, int new_lo, int new_hi, int old_lo, int old_hi) {
    return std::max(g - reach, new_lo) == std::max(g - reach, old_lo) &&
           std::min(g + reach, new_hi) == std::min(g + reach, old_hi);
  };
  std::vector<std::uint8_t> col_alike(static_cast<std::size_t>(cols));
  for (int c = 0; c < cols; ++c) col_alike[c] = clipped_alike(new_c0 + c, new_c0, new_c1, old_c0, old_c1);
  // near[r][c]: the square of side 2 reach + 1 around the cell holds a cell the old window did not hold at the same
  // height: the changed cells widened along rows, then along columns.
  const std::size_t n = static_cast<std::size_t>(rows) * cols;
  std::vector<std::uint8_t> along(n, 0), near(n, 0);
  for (int r = 0; r < rows; ++r) {
    const int g_row = new_r0 + r;
    const bool row_held = g_row >= old_r0 && g_row <= old_r1;
    const double* before =
        row_held ? memo_.heights.data() + static_cast<std::size_t>(g_row - old_r0) * memo_.cols : nullptr;
    for (int c = 0; c < cols; ++c) {
      const int g_col = new_c0 + c;
      if (row_held && g_col >= old_c0 && g_col <= old_c1 && before[g_col - old_c0] == local.heights(r, c)) continue;
      std::uint8_t* row = along.data() + static_cast<std::size_t>(r) * cols;
      std::fill(row + std::max(c - reach, 0), row + std::min(c + reach, cols - 1) + 1, std::uint8_t{1});
    }
  }
  for (int r = 0; r < rows; ++r) {
    const std::uint8_t* from = along.data() + static_cast<std::size_t>(r) * cols;
    for (int t = std::max(r - reach, 0); t <= std::min(r + reach, rows - 1); ++t) {
      std::uint8_t* to = near.data() + static_cast<std::size_t>(t) * cols;
      for (int c = 0; c < cols; ++c) to[c] |= from[c];
    }
  }
  CellMask out(rows, cols);
  std::vector<CellIndex> judge;
  for (int r = 0; r < rows; ++r) {
    const int g_row = new_r0 + r;
    const bool row_alike = clipped_alike(g_row, new_r0, new_r1, old_r0, old_r1);
    const std::uint8_t* near_row = near.data() + static_cast<std::size_t>(r) * cols;
    for (int c = 0; c < cols; ++c) {
      if (row_alike && col_alike[c] && near_row[c] == 0) {
        // The ball's square lies in both windows (clipped alike) with the old heights: the old answer.
        out(r, c) = memo_.occupiable(g_row - old_r0, new_c0 + c - old_c0);
        continue;
      }
      judge.push_back({r, c});
    }
  }
  // Judged one by one, a cell costs up to its ball's pairs; the whole window costs about a few of them per cell.
  if (judge.size() * 3 > n) return navigability_.occupiable(local.heights);
  // A ball whose heights spread by no more than the threshold of the nearest pair (one cell apart) passes every pair:
  // |h(a) - h(b)| <= max - min <= eps + kappa cs + tol <= each pair's threshold, each rounded alike (rounding is
  // monotone), so this is cell_occupiable_in_ball()'s answer without its pairs.
  const double nearest_threshold_m = p.eps_m + p.kappa * (cs * std::sqrt(1.0)) + tolerance::kHeightM;
  std::vector<double> hs(ball_.size());
  // Cells of a ball off the window are ignored, as the processor ignores cells off its grid: NaN there, which no
  // min, max or pair test below takes (every comparison with NaN is false).
  const double off = std::numeric_limits<double>::quiet_NaN();
  for (const CellIndex cell : judge) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t k = 0; k < ball_.size(); ++k) {
      const CellIndex b{cell.row + ball_[k].row, cell.col + ball_[k].col};
      hs[k] = local.heights.contains(b) ? local.heights(b) : off;
      lo = std::min(lo, hs[k]);
      hi = std::max(hi, hs[k]);
    }
    bool occupiable = hi - lo <= nearest_threshold_m;
    if (!occupiable) {  // every pair of cells on the window, as cell_occupiable_in_ball() checks them
      occupiable = true;
      for (const BallPair& q : ball_pairs_)
        if (std::abs(hs[q.a] - hs[q.b]) > q.threshold_m) {
          occupiable = false;
          break;
        }
    }
    out(cell.row, cell.col) = occupiable ? 1 : 0;
  }
  return out;
}

std::optional<CellIndex> LocalMapSynthesizer::local_origin(const LocalMap& local,
                                                           const std::vector<CellIndex>& trajectory, Position robot,
                                                           double range_m) {
  std::optional<CellIndex> best_navigable, best_occupiable;
  double best_navigable_d = std::numeric_limits<double>::infinity();
  double best_occupiable_d = std::numeric_limits<double>::infinity();
  const bool has_navigable = local.navigable.rows() == local.rows() && local.navigable.cols() == local.cols();
  for (const CellIndex global : trajectory) {
    const CellIndex p = local.to_local(global);
    if (!local.contains(p) || local.occupiable(p.row, p.col) == 0) continue;
    const Position c = local.center(p);
    const double d = std::min(range_m - std::abs(c.x - robot.x), range_m - std::abs(c.y - robot.y));
    if (has_navigable && local.navigable(p.row, p.col) != 0) {
      if (d < best_navigable_d) best_navigable_d = d, best_navigable = p;
    } else if (d < best_occupiable_d) {
      best_occupiable_d = d, best_occupiable = p;
    }
  }
  return best_navigable ? best_navigable : best_occupiable;
}

std::pair<CellIndex, bool> LocalMapSynthesizer::local_goal(const LocalMap& local, Position robot, Position target) {
  const GridGeometry& g = local.geometry();
  if (!std::isfinite(target.x) || !std::isfinite(target.y))
    throw InvalidArgument(fmt::format("local map: the target {} is not finite", target));
  if (const auto cell = local.cell_at(target)) return {*cell, true};

  // Clip the segment robot -> target to the rectangle of the window's cell centres.
  const double cs = g.cell_size_m;
  const double x_lo = g.xll_m + 0.5 * cs, x_hi = g.xll_m + (g.cols - 0.5) * cs;
  const double y_lo = g.yll_m + 0.5 * cs, y_hi = g.yll_m + (g.rows - 0.5) * cs;
  const Position s{std::clamp(robot.x, x_lo, x_hi), std::clamp(robot.y, y_lo, y_hi)};
  const double dx = target.x - s.x, dy = target.y - s.y;
  double t = 1.0;
  if (dx > 0.0) t = std::min(t, (x_hi - s.x) / dx);
  if (dx < 0.0) t = std::min(t, (x_lo - s.x) / dx);
  if (dy > 0.0) t = std::min(t, (y_hi - s.y) / dy);
  if (dy < 0.0) t = std::min(t, (y_lo - s.y) / dy);
  t = std::max(t, 0.0);
  const double ex = s.x + t * dx, ey = s.y + t * dy;
  // The nearest cell centre to the exit point, kept inside the window.
  const int col = std::clamp(static_cast<int>(std::lround((ex - g.xll_m) / cs - 0.5)), 0, g.cols - 1);
  const int south = std::clamp(static_cast<int>(std::lround((ey - g.yll_m) / cs - 0.5)), 0, g.rows - 1);
  return {{g.rows - 1 - south, col}, false};
}

}  // namespace marsala::agent::deliberative
