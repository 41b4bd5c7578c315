#include "marsala/world_server/rules/completion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/navigable_path_planner.hpp"
#include "marsala/world_server/rules/arbiter.hpp"
#include "marsala/world_server/rules/construction_band.hpp"

namespace marsala::world_server {
namespace {

CellIndex cell_of(const Heightmap& terrain, double x_m, double y_m, const char* what) {
  const auto cell = terrain.cell_at({x_m, y_m});
  if (!cell)
    throw InvalidArgument(fmt::format("{} {} is off the {} x {} grid", what, Position{x_m, y_m}, terrain.rows(),
                                      terrain.cols()));
  return *cell;
}

CellRect site_rect_or_throw(const Heightmap& terrain, const scenario::Site& site) {
  const CellRect rect = site_cells(terrain.geometry(), site);
  if (rect.empty())
    throw InvalidArgument(fmt::format("site [{}, {}] x [{}, {}] holds no cell centre of the grid", site.area.x0,
                                      site.area.x1, site.area.y0, site.area.y1));
  return rect;
}

void check_on_mask(const CellMask& mask, CellIndex c, const char* what) {
  if (c.row < 0 || c.col < 0 || c.row >= mask.rows() || c.col >= mask.cols())
    throw InvalidArgument(fmt::format("{} cell {} is off the {} x {} mask", what, c, mask.rows(), mask.cols()));
}

}  // namespace

bool at_goal(const WorldState& state, const AgentRecord& agent) {
  constexpr double tol = tolerance::kLengthM;
  const scenario::Goal& g = state.goal;
  const bool inside = agent.position.x >= g.area.x0 - tol && agent.position.x <= g.area.x1 + tol &&
                      agent.position.y >= g.area.y0 - tol && agent.position.y <= g.area.y1 + tol;
  if (!inside) return false;
  const double h = height_under(state.terrain, agent.position.x, agent.position.y);
  if (!(h >= g.min_height_m - tol)) return false;  // also for NaN (off the grid)
  return g.target_radius_m <= 0.0 ||
         std::hypot(agent.position.x - agent.target.x, agent.position.y - agent.target.y) <= g.target_radius_m + tol;
}

bool is_completed(const WorldState& state) {
  if (state.completion != scenario::CompletionKind::kAgentsAtGoal) return state.check.met;
  bool any = false;
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    if (!at_goal(state, a)) return false;
    any = true;
  }
  return any;
}

/// The live agents and how many of them are at the goal.
static std::pair<int, int> live_agents_at_goal(const WorldState& state) {
  int live = 0, done = 0;
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    ++live;
    done += at_goal(state, a) ? 1 : 0;
  }
  return {live, done};
}

double progress(const WorldState& state) {
  switch (state.completion) {
    case scenario::CompletionKind::kPayloadPath: {
      const CompletionCheck& check = state.check;
      if (check.met) return 1.0;
      if (!(check.route.initial_m3 > 0.0)) return 0.0;
      return std::clamp(1.0 - check.route_gap_m3 / check.route.initial_m3, 0.0, 0.999);  // 1 is for completion
    }
    case scenario::CompletionKind::kLevelSite: return state.check.level_fraction;
    case scenario::CompletionKind::kAgentsAtGoal: break;
  }
  const auto [live, done] = live_agents_at_goal(state);
  return live == 0 ? 0.0 : static_cast<double>(done) / live;
}

void start_completion_check(WorldState& state) {
  CompletionCheck& check = state.check;
  check = {};
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal: return;
    case scenario::CompletionKind::kPayloadPath: {
      const scenario::PayloadPath& p = state.payload_path;
      check.from = cell_of(state.terrain, p.from.x, p.from.y, "payload_path.from");
      check.to = cell_of(state.terrain, p.to.x, p.to.y, "payload_path.to");
      check.occupancy =
          OccupancyCache(state.terrain, {{0, 0}, state.terrain.rows(), state.terrain.cols()}, p.navigability);
      check.target_initial_m = state.terrain(check.to.row, check.to.col);
      check.max_target_rise_m = largest_cube_layer_m(state);
      check.route = plan_route_gap(state.terrain, p);
      break;
    }
    case scenario::CompletionKind::kLevelSite:
      check.occupancy =
          OccupancyCache(state.terrain, site_rect_or_throw(state.terrain, state.site), state.site.navigability);
      break;
  }
  evaluate_completion(state);
}

void evaluate_completion(WorldState& state) {
  if (state.completion == scenario::CompletionKind::kAgentsAtGoal) return;
  CompletionCheck& check = state.check;
  check.occupancy.update(state.terrain);
  const CellMask& mask = check.occupancy.occupiable();
  if (state.completion == scenario::CompletionKind::kPayloadPath) {
    check.path_found = connected(mask, check.from, check.to);
    check.met = check.path_found && target_rise_m(state) <= check.max_target_rise_m + tolerance::kLengthM;
    check.route_gap_m3 = route_gap_m3(state.terrain, check.route);
  } else {
    check.level_fraction =
        static_cast<double>(largest_component(mask)) / static_cast<double>(check.occupancy.area().size());
    check.met = check.level_fraction >= state.site.min_fraction;
  }
  ++check.evaluations;
}

double target_rise_m(const WorldState& state) {
  return state.terrain(state.check.to.row, state.check.to.col) - state.check.target_initial_m;
}

std::string payload_completion_detail(const WorldState& state, bool found) {
  if (state.completion != scenario::CompletionKind::kPayloadPath) return {};
  if (!found) return "no payload path from base to target";
  const double rise = target_rise_m(state), allowed = state.check.max_target_rise_m;
  if (rise > allowed + tolerance::kLengthM)
    return fmt::format("payload path found, but the target's cell stands {:.4g} m above its initial height (at most "
                       "{:.4g} m allowed)",
                       rise, allowed);
  return fmt::format("payload path found, target's cell within {:.4g} m of its initial height", allowed);
}

double largest_cube_layer_m(const WorldState& state) {
  double layer = 0.0;
  for (const AgentRecord& a : state.agents)
    layer = std::max(layer, cube_layer_m(a.type.body.cube_size_m, state.terrain.cell_size_m()));
  return layer;
}

CellRect site_cells(const GridGeometry& grid, const scenario::Site& site) {
  return cells_centred_in(grid, site.area);
}

long long largest_component(const CellMask& mask) {
  const int rows = static_cast<int>(mask.rows()), cols = static_cast<int>(mask.cols());
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(rows) * cols, 0);
  std::vector<int> stack;
  long long best = 0;
  for (int start = 0; start < rows * cols; ++start) {
    if (seen[start] || mask(start / cols, start % cols) == 0) continue;
    long long size = 0;
    seen[start] = 1;
    stack.assign(1, start);
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      ++size;
      const int r = k / cols, c = k % cols;
      for (int rr = std::max(0, r - 1); rr <= std::min(rows - 1, r + 1); ++rr)
        for (int cc = std::max(0, c - 1); cc <= std::min(cols - 1, c + 1); ++cc) {
          const int n = rr * cols + cc;
          if (!seen[n] && mask(rr, cc) != 0) {
            seen[n] = 1;
            stack.push_back(n);
          }
        }
    }
    best = std::max(best, size);
  }
  return best;
}

bool connected(const CellMask& passable, CellIndex from, CellIndex to) {
  check_on_mask(passable, from, "connected: from");
  check_on_mask(passable, to, "connected: to");
  return NavigabilityProcessor::navigable_from(passable, from)(to.row, to.col) != 0;
}

bool payload_path_navigable(const Heightmap& terrain, const scenario::PayloadPath& path) {
  const CellIndex from = cell_of(terrain, path.from.x, path.from.y, "payload_path.from");
  const CellIndex to = cell_of(terrain, path.to.x, path.to.y, "payload_path.to");
  return connected(NavigabilityProcessor(path.navigability).occupiable(terrain), from, to);
}

double site_level_fraction(const Heightmap& terrain, const scenario::Site& site) {
  const CellRect rect = site_rect_or_throw(terrain, site);
  const CellMask mask =
      NavigabilityProcessor(site.navigability).occupiable(terrain.window(rect.first, rect.rows, rect.cols));
  return static_cast<double>(largest_component(mask)) / static_cast<double>(rect.size());
}

RouteGap plan_route_gap(const Heightmap& terrain, const scenario::PayloadPath& path) {
  const CellIndex from = cell_of(terrain, path.from.x, path.from.y, "payload_path.from");
  const CellIndex to = cell_of(terrain, path.to.x, path.to.y, "payload_path.to");
  const NavigabilityParams& body = path.navigability;
  const double cs = terrain.cell_size_m();
  const Heightmap ceiling = MarsProcessor(body.kappa).project(terrain);
  Heightmap gap(terrain.geometry(), (ceiling.heights() - terrain.heights()).cwiseMax(0.0));
  // The route the agents' own planner would choose with the whole terrain known: the shortest path that weighs the
  // gap its footprint must fill against its length; every cell is allowed, since filling the gap makes it passable.
  const NavigablePathPlanner planner(default_planner_params(body.delta_m, cs));
  const CellMask everywhere = CellMask::Ones(terrain.rows(), terrain.cols());
  PlannerResult plan = planner.plan(gap, everywhere, from, to);
  if (!plan.found) throw Error(fmt::format("payload route from {} to {}: the planner found none", from, to));
  RouteGap out;
  out.route = std::move(plan.path);
  const CellMask band = construction_band(out.route, terrain.rows(), terrain.cols(), cs, body.delta_m);
  for (int r = 0; r < terrain.rows(); ++r)
    for (int c = 0; c < terrain.cols(); ++c)
      if (band(r, c) != 0) {
        out.cells.push_back(static_cast<std::int64_t>(r) * terrain.cols() + c);
        out.ceiling_m.push_back(ceiling(r, c));
      }
  out.initial_m3 = route_gap_m3(terrain, out);
  return out;
}

double route_gap_m3(const Heightmap& terrain, const RouteGap& route) {
  const double* h = terrain.data();
  double sum = 0.0;
  for (std::size_t i = 0; i < route.cells.size(); ++i) sum += std::max(0.0, route.ceiling_m[i] - h[route.cells[i]]);
  return sum * terrain.cell_size_m() * terrain.cell_size_m();
}

std::string progress_detail(const WorldState& state) {
  switch (state.completion) {
    case scenario::CompletionKind::kPayloadPath:
      if (state.check.met) return "the payload's path is navigable";
      if (state.check.path_found)
        return fmt::format("the payload's path is navigable, but the target's cell stands {:.3f} m above its initial "
                           "height",
                           target_rise_m(state));
      return fmt::format("{:.2f} of {:.2f} m3 of MARS gap left on the route", state.check.route_gap_m3,
                         state.check.route.initial_m3);
    case scenario::CompletionKind::kLevelSite:
      return fmt::format("site {:.1f} % level ({:.1f} % needed)", 100.0 * state.check.level_fraction,
                         100.0 * state.site.min_fraction);
    case scenario::CompletionKind::kAgentsAtGoal: break;
  }
  const auto [live, done] = live_agents_at_goal(state);
  return fmt::format("{} of {} live agents at the goal", done, live);
}

std::optional<PayloadRoute> shortest_path(const CellMask& passable, CellIndex from, CellIndex to, double cell_size_m) {
  check_on_mask(passable, from, "shortest_path: from");
  check_on_mask(passable, to, "shortest_path: to");
  if (!(cell_size_m > 0.0) || !std::isfinite(cell_size_m))
    throw InvalidArgument(fmt::format("shortest_path: cell size {} m must be finite and > 0", cell_size_m));
  // The agents' planner with no construction cost (alpha = 0) on a zero gap: a shortest 8-connected path, found by
  // the one A* of the project. delta_m only sizes the (unused) footprint: one cell.
  const NavigablePathPlanner planner({0.0, 1.0, cell_size_m});
  const GridGeometry geometry{static_cast<int>(passable.rows()), static_cast<int>(passable.cols()), 0.0, 0.0,
                              cell_size_m};
  const PlannerResult found = planner.plan(Heightmap(geometry, 0.0), passable, from, to);
  if (!found.found) return std::nullopt;
  return PayloadRoute{found.path, found.length_m};
}

std::optional<PayloadRoute> payload_path(const Heightmap& terrain, const scenario::PayloadPath& path) {
  const CellIndex from = cell_of(terrain, path.from.x, path.from.y, "payload_path.from");
  const CellIndex to = cell_of(terrain, path.to.x, path.to.y, "payload_path.to");
  return shortest_path(NavigabilityProcessor(path.navigability).occupiable(terrain), from, to, terrain.cell_size_m());
}

}  // namespace marsala::world_server
