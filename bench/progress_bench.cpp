// What the progress of a payload_path run costs the world (docs/runtime.md#progress), on the shipped
// path_generated scenario (640 x 640 cells): planning the payload's route and its band once at the start, and the
// sum of the gap left on the band at each completion check, beside the check itself (occupancy update of a few
// changed cells and the connectivity search) for scale.

#include <benchmark/benchmark.h>

#include <string>

#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/initial_state.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace {

using namespace marsala;

const scenario::Scenario& path_generated() {
  static const scenario::Scenario s =
      scenario::load_scenario(std::string(MARSALA_SOURCE_DIR) + "/deploy/scenarios/path_generated.pbtxt");
  return s;
}

const Heightmap& terrain() {
  static const Heightmap h = scenario::build_terrain(path_generated());
  return h;
}

void BM_PlanRouteGap(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(world_server::plan_route_gap(terrain(), path_generated().payload_path));
  const world_server::RouteGap route = world_server::plan_route_gap(terrain(), path_generated().payload_path);
  state.counters["route_cells"] = static_cast<double>(route.route.size());
  state.counters["band_cells"] = static_cast<double>(route.cells.size());
  state.counters["initial_m3"] = route.initial_m3;
}
BENCHMARK(BM_PlanRouteGap)->Unit(benchmark::kMillisecond);

void BM_RouteGapPerCheck(benchmark::State& state) {
  const world_server::RouteGap route = world_server::plan_route_gap(terrain(), path_generated().payload_path);
  for (auto _ : state) benchmark::DoNotOptimize(world_server::route_gap_m3(terrain(), route));
  state.counters["band_cells"] = static_cast<double>(route.cells.size());
}
BENCHMARK(BM_RouteGapPerCheck)->Unit(benchmark::kMicrosecond);

// The whole check as the world runs it after a step that raised one cell on the route (the usual case).
void BM_CompletionCheckAfterOneDeposit(benchmark::State& state) {
  world_server::WorldState w = world_server::make_world_state(path_generated(), terrain(), 1);
  const CellIndex cell = w.check.route.route[w.check.route.route.size() / 2];
  for (auto _ : state) {
    w.terrain(cell) += 1e-6;
    w.check.occupancy.mark_changed(cell);
    world_server::evaluate_completion(w);
  }
}
BENCHMARK(BM_CompletionCheckAfterOneDeposit)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
