#include "marsala/world_server/rules/material_score.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <utility>

#include "marsala/core/error.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigable_path_planner.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/construction_band.hpp"

namespace marsala::world_server {
namespace {

MaterialNeed empty_need(const Heightmap& initial) {
  return {CellMask::Zero(initial.rows(), initial.cols()), initial};
}

/// payload_path: the route band and its bounds, as planned when the state was made.
MaterialNeed payload_need(const WorldState& state, const Heightmap& initial) {
  MaterialNeed need = empty_need(initial);
  const RouteGap& route = state.check.route;
  for (std::size_t i = 0; i < route.cells.size(); ++i) {
    const auto row = static_cast<int>(route.cells[i] / initial.cols());
    const auto col = static_cast<int>(route.cells[i] % initial.cols());
    need.band(row, col) = 1;
    need.ceiling(row, col) = route.ceiling_m[i];
  }
  return need;
}

/// level_site: the crop, to the MARS bound of the crop alone at the site's kappa.
MaterialNeed site_need(const WorldState& state, const Heightmap& initial) {
  MaterialNeed need = empty_need(initial);
  const CellRect rect = site_cells(initial.geometry(), state.site);
  if (rect.empty()) return need;
  const Heightmap bound =
      MarsProcessor(state.site.navigability.kappa).project(initial.window(rect.first, rect.rows, rect.cols));
  for (int r = 0; r < rect.rows; ++r)
    for (int c = 0; c < rect.cols; ++c) {
      need.band(rect.first.row + r, rect.first.col + c) = 1;
      need.ceiling(rect.first.row + r, rect.first.col + c) = bound(r, c);
    }
  return need;
}

/// agents_at_goal: every slot's route band from its start to its target, to the MARS bound at its construction kappa.
MaterialNeed goal_need(const WorldState& state, const Heightmap& initial) {
  MaterialNeed need = empty_need(initial);
  const double cs = initial.cell_size_m();
  // Per kappa, one MARS bound and its gap over the initial terrain for the whole team.
  struct Bound {
    Heightmap height, gap;
  };
  std::map<double, Bound> bounds;
  const CellMask everywhere = CellMask::Ones(initial.rows(), initial.cols());
  for (const AgentRecord& a : state.agents) {
    const std::optional<CellIndex> from = initial.cell_at(a.start);
    const std::optional<CellIndex> to = initial.cell_at(a.target);
    if (!from || !to) continue;
    const NavigabilityParams body = construction_params(a.type);
    auto it = bounds.find(body.kappa);
    if (it == bounds.end()) {
      Heightmap height = MarsProcessor(body.kappa).project(initial);
      Heightmap gap(initial.geometry(), (height.heights() - initial.heights()).cwiseMax(0.0));
      it = bounds.emplace(body.kappa, Bound{std::move(height), std::move(gap)}).first;
    }
    const Bound& bound = it->second;
    const PlannerResult plan =
        NavigablePathPlanner(default_planner_params(body.delta_m, cs)).plan(bound.gap, everywhere, *from, *to);
    if (!plan.found) continue;
    const CellMask band = construction_band(plan.path, initial.rows(), initial.cols(), cs, body.delta_m);
    for (int r = 0; r < initial.rows(); ++r)
      for (int c = 0; c < initial.cols(); ++c) {
        if (band(r, c) == 0) continue;
        need.ceiling(r, c) = need.band(r, c) != 0 ? std::max(need.ceiling(r, c), bound.height(r, c)) : bound.height(r, c);
        need.band(r, c) = 1;
      }
  }
  return need;
}

}  // namespace

MaterialNeed material_need(const WorldState& state, const Heightmap& initial) {
  if (!(initial.geometry() == state.terrain.geometry()))
    throw InvalidArgument(fmt::format("material score: the initial terrain is {} x {} cells, the run's {} x {}",
                                      initial.rows(), initial.cols(), state.terrain.rows(), state.terrain.cols()));
  switch (state.completion) {
    case scenario::CompletionKind::kPayloadPath: return payload_need(state, initial);
    case scenario::CompletionKind::kLevelSite: return site_need(state, initial);
    case scenario::CompletionKind::kAgentsAtGoal: break;
  }
  return goal_need(state, initial);
}

double needed_m3(const MaterialNeed& need, const Heightmap& initial) {
  double sum = 0.0;
  for (int r = 0; r < initial.rows(); ++r)
    for (int c = 0; c < initial.cols(); ++c)
      if (need.band(r, c) != 0) sum += std::max(0.0, need.ceiling(r, c) - initial(r, c));
  return sum * initial.cell_size_m() * initial.cell_size_m();
}

MaterialScore material_score(const WorldState& state, const Heightmap& initial, double payload_outside_band_m3) {
  const MaterialNeed need = material_need(state, initial);
  MaterialScore s;
  s.deposited_m3 = state.deposited_volume_m3;
  s.needed_m3 = needed_m3(need, initial);
  s.ratio = s.needed_m3 > 0.0 ? s.deposited_m3 / s.needed_m3 : 0.0;
  s.off_band_m3 = state.completion == scenario::CompletionKind::kPayloadPath
                      ? payload_outside_band_m3
                      : deposited_outside_band_m3(initial, state.terrain, need.band);
  return s;
}

}  // namespace marsala::world_server
