#include "marsala/agent/executive/deposition_manager.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "marsala/agent/agent_context.hpp"
#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala::agent::executive {
namespace {

/// Margin kept inside the world's strict "more than delta/2 from every robot" rule [m].
constexpr double kUnderRobotMarginM = 1e-6;

/// Ball offsets nearest first (then row-major), so each path cell's footprint is visited from its centre outwards.
std::vector<CellIndex> sorted_ball(double radius_cells) {
  std::vector<CellIndex> ball = disc_offsets(radius_cells);
  std::stable_sort(ball.begin(), ball.end(), [](CellIndex a, CellIndex b) {
    return a.row * a.row + a.col * a.col < b.row * b.row + b.col * b.col;
  });
  return ball;
}

bool positive_finite(double v) { return v > 0.0 && std::isfinite(v); }

long long cells2(CellIndex a, CellIndex b) {
  const long long dr = a.row - b.row, dc = a.col - b.col;
  return dr * dr + dc * dc;
}

}  // namespace

bool DepositionManager::in_territory(const deliberative::LocalMap& map, CellIndex cell, Position centre,
                                     const Neighbourhood& neighbours, std::optional<CellIndex> self_cell) const {
  const CellIndex global = map.to_global(cell);
  for (const Neighbour& n : neighbours.others) {
    const Position p = n.position;
    if (distance(centre, p) <= params_.neighbour_keep_out_m) return false;
    // Whole-cell distances: every robot computes them exactly alike, so territories never overlap.
    const auto other = map.world.cell_at(p);
    if (!self_cell || !other) continue;
    const long long mine = cells2(global, *self_cell), theirs = cells2(global, *other);
    if (theirs < mine || (theirs == mine && n.agent_id < neighbours.self_id)) return false;
  }
  return true;
}

std::vector<CellIndex> line_cells(const deliberative::LocalMap& map, CellIndex from, Position to) {
  const Position a = map.center(from);
  const int samples = static_cast<int>(std::ceil(2.0 * distance(a, to) / map.geometry().cell_size_m));
  std::vector<CellIndex> line{from};
  for (int i = 1; i <= samples; ++i) {
    const double t = static_cast<double>(i) / samples;
    const auto cell = map.cell_at({a.x + t * (to.x - a.x), a.y + t * (to.y - a.y)});
    if (!cell) break;
    if (*cell != line.back()) line.push_back(*cell);
  }
  return line;
}

DepositionParams deposition_params(const RobotBody& body, double cell_size_m, double neighbour_keep_out_m,
                                   std::optional<double> footprint_m) {
  DepositionParams p;
  p.navigability = body.navigability;
  p.footprint_m = footprint_m.value_or(body.navigability.delta_m);
  p.reach_m = body.reach_m;
  p.max_deposit_m3 = body.max_deposit_m3;
  p.cube_layer_m = cube_layer_m(body.cube_size_m, cell_size_m);
  p.neighbour_keep_out_m = neighbour_keep_out_m;
  p.neighbour_step_m = body.max_step_m;
  return p;
}

namespace {

// The body's rule with eps widened by a scanned map's noise margin (a pair may break the rule by up to it); a margin
// that is not finite and >= 0 widens nothing (the constructor refuses it).
NavigabilityParams within_noise(const DepositionParams& params) {
  NavigabilityParams p = params.navigability;
  if (params.gap_margin_m >= 0.0 && std::isfinite(params.gap_margin_m)) p.eps_m += params.gap_margin_m;
  return p;
}

}  // namespace

DepositionManager::DepositionManager(DepositionParams params)
    : params_(params), navigability_(params.navigability), within_noise_(within_noise(params)) {
  if (!positive_finite(params.reach_m) || !positive_finite(params.max_deposit_m3) ||
      !positive_finite(params.cube_layer_m) || !positive_finite(params.max_height_m) ||
      !positive_finite(params.footprint_m) || !(params.neighbour_keep_out_m >= 0.0) ||
      !std::isfinite(params.neighbour_keep_out_m) || !(params.neighbour_step_m >= 0.0) ||
      !std::isfinite(params.neighbour_step_m) || !(params.pad_radius_m >= 0.0) || !std::isfinite(params.pad_radius_m) ||
      !std::isfinite(params.pad_centre.x) || !std::isfinite(params.pad_centre.y) || !(params.gap_margin_m >= 0.0) ||
      !std::isfinite(params.gap_margin_m))
    throw InvalidArgument(fmt::format(
        "deposition manager: reach ({} m), max deposit ({} m^3), cube layer ({} m) and max height ({} m) must be "
        "finite and > 0, neighbour keep-out, step and pad radius ({} m) finite and >= 0, gap margin ({} m) finite and "
        ">= 0",
        params.reach_m, params.max_deposit_m3, params.cube_layer_m, params.max_height_m, params.pad_radius_m,
        params.gap_margin_m));
}

std::vector<DepositionCandidate> DepositionManager::candidates(const deliberative::LocalMap& map,
                                                               const std::vector<CellIndex>& path, Position robot,
                                                               double material_m3,
                                                               const Neighbourhood& neighbours) const {
  std::vector<DepositionCandidate> out;
  const double budget_m3 = std::min(params_.max_deposit_m3, std::max(material_m3, 0.0));
  const double cs = map.geometry().cell_size_m;
  const double area = cs * cs;
  const double q = params_.cube_layer_m;
  const double layer_volume = q * area;
  const int max_layers = static_cast<int>(std::floor(params_.max_height_m / q + 1e-9));
  const double clear_m = clearance_m(map, robot);
  const auto ball = sorted_ball(params_.footprint_m / (2.0 * cs));
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(map.rows()) * map.cols(), 0);
  const std::optional<CellIndex> self_cell = map.world.cell_at(neighbours.self);
  double total_m3 = 0.0;
  for (const CellIndex p : path) {
    for (const CellIndex o : ball) {
      const CellIndex cell{p.row + o.row, p.col + o.col};
      if (!map.contains(cell)) continue;
      std::uint8_t& s = seen[static_cast<std::size_t>(cell.row) * map.cols() + cell.col];
      if (s) continue;
      s = 1;
      if (!deliberative::may_fill(map, cell)) continue;
      // Whole layers, rounded down: never above the local MARS height (1e-9 absorbs rounding in gaps that are
      // exact multiples).
      int layers = std::min(
          static_cast<int>(std::floor(deliberative::rise_wanted_m(map, cell, params_.gap_margin_m) / q + 1e-9)),
          max_layers);
      if (layers < 1) continue;
      const Position centre = map.center(cell);
      const double d = distance(centre, robot);
      if (d > params_.reach_m || d <= clear_m) continue;
      if (!in_territory(map, cell, centre, neighbours, self_cell)) continue;
      if (params_.pad_radius_m > 0.0 && distance(centre, params_.pad_centre) <= params_.pad_radius_m) continue;
      const int fit = static_cast<int>(std::floor((budget_m3 - total_m3) / layer_volume + 1e-9));
      layers = std::min(layers, fit);
      if (layers < 1) return out;
      const double height = layers * q;
      total_m3 += height * area;
      out.push_back({cell, layers, height});
    }
  }
  return out;
}

double DepositionManager::clearance_m(const deliberative::LocalMap& map, Position robot) const {
  const NavigabilityParams& body = params_.navigability;
  const double under_m = 0.5 * body.delta_m + kUnderRobotMarginM;
  if (!(params_.exit_margin_m > 0.0)) return under_m;
  const auto cell = map.cell_at(robot);
  if (!cell) return under_m;
  NavigabilityParams sure = body;
  sure.eps_m = std::max(0.0, body.eps_m - params_.exit_margin_m);
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex n{cell->row + dr, cell->col + dc};
      if ((dr == 0 && dc == 0) || !map.contains(n) || map.blind(n.row, n.col) != 0 || map.known(n.row, n.col) == 0)
        continue;
      if (cell_occupiable(map.heights, n, sure)) return under_m;
    }
  return under_m + std::sqrt(2.0) * map.geometry().cell_size_m;
}

bool DepositionManager::may_raise(const deliberative::LocalMap& map, CellIndex cell, Position robot,
                                  const Neighbourhood& neighbours, double clearance_m) const {
  if (!map.contains(cell) || !deliberative::may_fill(map, cell)) return false;
  const Position centre = map.center(cell);
  if (distance(centre, robot) <= clearance_m) return false;
  if (params_.pad_radius_m > 0.0 && distance(centre, params_.pad_centre) <= params_.pad_radius_m) return false;
  return in_territory(map, cell, centre, neighbours, map.world.cell_at(neighbours.self));
}

std::vector<WantedCell> DepositionManager::wanted(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                                  Position robot, const Neighbourhood& neighbours) const {
  return wanted(map, path, robot, neighbours, clearance_m(map, robot));
}

std::vector<WantedCell> DepositionManager::wanted(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                                  Position robot, const Neighbourhood& neighbours,
                                                  double clear_m) const {
  std::vector<WantedCell> out;
  const double cs = map.geometry().cell_size_m;
  const auto ball = sorted_ball(params_.footprint_m / (2.0 * cs));
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(map.rows()) * map.cols(), 0);
  for (const CellIndex p : path)
    for (const CellIndex o : ball) {
      const CellIndex cell{p.row + o.row, p.col + o.col};
      if (!map.contains(cell)) continue;
      std::uint8_t& s = seen[static_cast<std::size_t>(cell.row) * map.cols() + cell.col];
      if (s) continue;
      s = 1;
      const double rise_m = deliberative::rise_wanted_m(map, cell, 0.0);
      if (!(rise_m > 0.0) || !may_raise(map, cell, robot, neighbours, clear_m)) continue;
      out.push_back({cell, rise_m});
    }
  return out;
}

namespace {

bool reaches_border(const CellMask& reach) {
  const auto rows = reach.rows(), cols = reach.cols();
  if (rows == 0 || cols == 0) return false;
  return reach.row(0).any() || reach.row(rows - 1).any() || reach.col(0).any() || reach.col(cols - 1).any();
}

}  // namespace

bool DepositionManager::keeps_way_back(const deliberative::LocalMap& map, Position robot,
                                       const std::vector<DepositionCandidate>& depositions,
                                       const Neighbourhood& neighbours) const {
  if (!map.cell_at(robot)) return false;
  if (depositions.empty()) return true;
  WayBack context = way_back(map, robot, neighbours);
  return keeps_way_back(context, depositions);
}

DepositionManager::WayBack DepositionManager::way_back(const deliberative::LocalMap& map, Position robot,
                                                       const Neighbourhood& neighbours) const {
  WayBack w;
  w.map = &map;
  w.neighbours = &neighbours;
  w.cell = map.cell_at(robot);
  return w;
}

void DepositionManager::prepare(WayBack& w) const {
  const deliberative::LocalMap& map = *w.map;
  w.ready = true;
  const double cs = map.geometry().cell_size_m;
  // The heights' own occupiable cells: the synthesizer's when it judged them for this body, else computed here.
  if (map.heights_navigability == params_.navigability && map.heights_occupiable.rows() == map.rows() &&
      map.heights_occupiable.cols() == map.cols()) {
    w.occupiable = map.heights_occupiable;
  } else {
    w.occupiable = navigability_.occupiable(map.heights);
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (map.blind(r, c) != 0) w.occupiable(r, c) = 0;
  }
  // The cells a scanned map opens beyond its heights (the robot's own cell, cells stood on:
  // docs/runtime.md#cells-stood-on) stay open until a deposit lands in their ball, which judges them again on the
  // heights: the reaches before the depositions, read on map.occupiable, and after them are read on the same cells.
  if (map.heights_occupiable.rows() == map.rows() && map.heights_occupiable.cols() == map.cols() &&
      map.occupiable.rows() == map.rows() && map.occupiable.cols() == map.cols())
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (map.occupiable(r, c) != 0 && map.heights_occupiable(r, c) == 0) w.occupiable(r, c) = 1;
  w.occupiable_is_map = w.occupiable == map.occupiable;
  w.after = map.heights;
  w.ball = disc_offsets(params_.navigability.delta_m / (2.0 * cs));
  w.touched.assign(static_cast<std::size_t>(map.rows()) * map.cols(), 0);
  if (!w.cell) return;
  const CellIndex cell = *w.cell;
  // Robots whose way back must survive: this one at its new position, then the neighbours in the window.
  w.robots.push_back(cell);
  const auto step_disc = disc_offsets(params_.neighbour_step_m / cs);
  for (const Neighbour& n : w.neighbours->others)
    if (const auto c = map.cell_at(n.position))
      for (const CellIndex o : step_disc) {
        const CellIndex p{c->row + o.row, c->col + o.col};
        if (map.contains(p)) w.robots.push_back(p);
      }
  w.has_origin = map.origin && map.occupiable(map.origin->row, map.origin->col) != 0;
  if (w.has_origin) w.before = NavigabilityProcessor::navigable_from(map.occupiable, *map.origin);
  // The reach before the depositions is the local map's own navigable mask when the robot stays on its cell.
  w.had_way_out = map.occupiable(cell.row, cell.col) != 0 &&
                  reaches_border(cell == map.robot && map.navigable.size() == map.occupiable.size()
                                     ? map.navigable
                                     : NavigabilityProcessor::navigable_from(map.occupiable, cell));
  if (!w.had_way_out && params_.keep_reach_without_way_out) {
    // Read within the map's noise: a pair may break the rule by up to the noise margin (a cell the map holds just
    // not occupiable may be the real way back, and the robot's own depositions must not close it for real).
    w.within_noise = within_noise_.occupiable(map.heights);
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (map.blind(r, c) != 0) w.within_noise(r, c) = 0;
    w.within_noise(cell.row, cell.col) = 1;
    w.reach = NavigabilityProcessor::navigable_from(w.within_noise, cell);
    // The cells it keeps are its way back, those no nearer its goal than it stands: what lies ahead is what it builds.
    const auto to_goal = [&](CellIndex p) {
      const long long dr = p.row - map.goal.row, dc = p.col - map.goal.col;
      return dr * dr + dc * dc;
    };
    const long long here = to_goal(cell);
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (w.reach(r, c) != 0 && to_goal({r, c}) < here) w.reach(r, c) = 0;
  }
}

CellMask DepositionManager::occupiable_after(WayBack& w, const std::vector<DepositionCandidate>& depositions) const {
  if (!w.ready) prepare(w);
  return raised_occupiable(w, depositions, navigability_, w.occupiable);
}

CellMask DepositionManager::raised_occupiable(WayBack& w, const std::vector<DepositionCandidate>& depositions,
                                              const NavigabilityProcessor& rule, const CellMask& before,
                                              bool* unchanged) const {
  const deliberative::LocalMap& map = *w.map;
  for (const auto& d : depositions) w.after(d.cell) += d.height_m;
  // A cell's occupiability reads only the heights in its body ball: the cells whose ball holds a raised cell.
  std::vector<CellIndex> changed;
  for (const auto& d : depositions)
    for (const CellIndex o : w.ball) {
      const CellIndex p{d.cell.row - o.row, d.cell.col - o.col};
      if (!map.contains(p)) continue;
      std::uint8_t& t = w.touched[static_cast<std::size_t>(p.row) * map.cols() + p.col];
      if (t != 0) continue;
      t = 1;
      changed.push_back(p);
    }
  for (const CellIndex p : changed) w.touched[static_cast<std::size_t>(p.row) * map.cols() + p.col] = 0;
  // Only those cells are judged again; the others keep `before`, which may hold cells the map opened.
  CellMask occupiable = before;
  // Each pair check costs the ball's size squared: beyond about the whole window's worth, the processor's full pass.
  const double pair_work = static_cast<double>(changed.size()) * static_cast<double>(w.ball.size()) *
                           static_cast<double>(w.ball.size());
  if (pair_work > 64.0 * static_cast<double>(map.rows()) * map.cols()) {
    const CellMask full = rule.occupiable(w.after);
    for (const CellIndex p : changed)
      occupiable(p.row, p.col) = map.blind(p.row, p.col) == 0 && full(p.row, p.col) != 0 ? 1 : 0;
  } else {
    for (const CellIndex p : changed)
      occupiable(p.row, p.col) =
          map.blind(p.row, p.col) == 0 && cell_occupiable_in_ball(w.after, p, rule.params(), w.ball) ? 1 : 0;
  }
  for (const auto& d : depositions) w.after(d.cell) = map.heights(d.cell);
  if (unchanged) {
    *unchanged = true;
    for (const CellIndex p : changed) *unchanged = *unchanged && occupiable(p.row, p.col) == before(p.row, p.col);
  }
  return occupiable;
}

bool DepositionManager::keeps_way_back(WayBack& w, const std::vector<DepositionCandidate>& depositions) const {
  if (!w.cell) return false;
  if (depositions.empty()) return true;
  if (!w.ready) prepare(w);
  const deliberative::LocalMap& map = *w.map;
  const CellIndex cell = *w.cell;
  bool unchanged = false;
  const CellMask occupiable = raised_occupiable(w, depositions, navigability_, w.occupiable, &unchanged);
  // Depositions that change no cell's occupiability leave every reach below as it was: the robot's own cell, its way
  // out (had_way_out was read on these cells) and the reach from the origin (`before`) stay.
  if (unchanged && w.occupiable_is_map && w.reach.size() == 0) return true;
  // This robot's own cell must stay occupiable if it was (the world checks only motion targets, but a robot on a
  // cell it cannot occupy has no navigable move).
  if (map.occupiable(cell.row, cell.col) != 0 && occupiable(cell.row, cell.col) == 0) return false;
  // And it must keep a way out of the window if it had one: near the start of its trajectory the local origin may
  // be its own cell, and a ring of deposits around it would pass the origin test below.
  if (w.had_way_out && !reaches_border(NavigabilityProcessor::navigable_from(occupiable, cell))) return false;
  // Without one, it keeps every cell it can still reach: a robot whose own depositions took its last moves stood
  // walled in for good, the drops that close its neighbour cells lying under its own body, where it may not build.
  if (w.reach.size() > 0) {
    CellMask within_noise = raised_occupiable(w, depositions, within_noise_, w.within_noise);
    within_noise(cell.row, cell.col) = 1;
    if ((w.reach.array() > NavigabilityProcessor::navigable_from(within_noise, cell).array()).any()) return false;
  }
  if (!w.has_origin) return true;
  const CellMask reach = NavigabilityProcessor::navigable_from(occupiable, *map.origin);
  for (const CellIndex p : w.robots)
    if (w.before(p.row, p.col) != 0 && reach(p.row, p.col) == 0) return false;
  return true;
}

DepositionPlan DepositionManager::plan(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                       Position robot, double material_m3, const Neighbourhood& neighbours) const {
  DepositionPlan plan;
  std::vector<DepositionCandidate> chosen = candidates(map, path, robot, material_m3, neighbours);
  plan.candidates = static_cast<int>(chosen.size());
  WayBack way = way_back(map, robot, neighbours);
  if (!keeps_way_back(way, chosen)) {
    // The longest prefix that keeps the way back (the empty one always does): binary search.
    std::size_t good = 0, bad = chosen.size();
    while (bad - good > 1) {
      const std::size_t mid = good + (bad - good) / 2;
      if (keeps_way_back(way, {chosen.begin(), chosen.begin() + static_cast<std::ptrdiff_t>(mid)}))
        good = mid;
      else
        bad = mid;
    }
    chosen.resize(good);
    plan.dropped_for_way_back = plan.candidates - static_cast<int>(good);
  }
  const double area = map.geometry().cell_size_m * map.geometry().cell_size_m;
  for (const auto& c : chosen) {
    const CellIndex g = map.to_global(c.cell);
    plan.depositions.push_back({g.row, g.col, c.height_m});
    plan.volume_m3 += c.height_m * area;
  }
  return plan;
}

}  // namespace marsala::agent::executive
