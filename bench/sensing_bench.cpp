// The cost of ray-cast sensing and OctoMap mapping per robot step at the default resolutions (docs/runtime.md#sensing):
//   scan:    the world's ray casting of one scan (common/core/ray_caster.hpp), laser and rgbd;
//   insert:  the agent's OctoMap insertion of one scan and the heightmap derivation (MappingSystem::integrate_scan);
//   step:    both, for a robot that moves 0.2 m per step along a line, scanning every step;
//   OctreeInsertion: the baseline in the same run: one scan's points into an octomap::OcTree (insertPointCloud, lazy,
//            then updateInnerOccupancy, as the mapping system did before) against the flat leaves that replaced it
//            (agent/executive/detail/voxel_occupancy.hpp), both holding the 10 scans before;
//   ScanningRobotStep: a scanning robot's whole step in a real run (the ramp scenario, 3 robots, seed 1, in one
//            process, tests/support/lockstep_sim.hpp), per robot and step over steps 100..299 (robots driving to the
//            platform's wall and building before it): medians of the scan (the world's frame, its ray casting), the
//            insertion into the octree, the height map's derivation, the decision (the behaviour's decide() less its
//            mapping) and the whole step (frame + decide()); their sum is a robot's step (docs/runtime.md#mapping).
//            The same for ground-truth robots (tiles, no scan) as the baseline of the decision's cost.
// Terrain: the ramp scenario's platform (1.5 m high) on a 30 x 20 m grid of 0.1 m cells, and a generated "mix"
// terrain of the same size; the robot 3 m before the platform, facing it. Medians of repetitions (bench/run.sh).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <vector>

#include "marsala/agent/executive/detail/voxel_occupancy.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/core/cpu_time.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/terrain/generators.hpp"
#include "support/lockstep_sim.hpp"

namespace {

using namespace marsala;

Heightmap terrain_named(int which) {
  terrain::GeneratorSpec spec;
  spec.rows = 200;
  spec.cols = 300;
  spec.cell_size_m = 0.1;
  spec.seed = 1;
  if (which == 0) {
    spec.params = {{"height", 1.5}, {"width", 10.0}, {"depth", 14.0}, {"centre_x", 23.0}, {"centre_y", 10.0}};
    return terrain::generate_terrain("platform", spec);
  }
  return terrain::generate_terrain("mix", spec);
}

const char* kTerrainNames[] = {"platform", "mix"};
const char* kSensorNames[] = {"laser", "rgbd"};

void BM_Scan(benchmark::State& state) {
  const Heightmap terrain = terrain_named(static_cast<int>(state.range(1)));
  const SensorSpec sensor = sensor_defaults(sensor_kind(kSensorNames[state.range(0)]));
  const Point3 origin = sensor_origin(terrain, 15.05, 10.05, sensor);
  std::uint64_t step = 0;
  std::size_t points = 0;
  for (auto _ : state) {
    const std::vector<ScanPoint> scan = cast_scan(terrain, origin, 0.0, sensor, scan_seed(1, 1, ++step));
    points = scan.size();
    benchmark::DoNotOptimize(scan.data());
  }
  state.counters["rays"] = static_cast<double>(sensor.ray_count());
  state.counters["points"] = static_cast<double>(points);
  state.SetLabel(std::string(kSensorNames[state.range(0)]) + " on " + kTerrainNames[state.range(1)]);
}

// One scan into a map that already holds the scans of the 10 steps before (a robot on its way).
void BM_InsertAndDerive(benchmark::State& state) {
  const Heightmap terrain = terrain_named(static_cast<int>(state.range(1)));
  const SensorSpec sensor = sensor_defaults(sensor_kind(kSensorNames[state.range(0)]));
  agent::executive::MappingSystem warm(terrain.geometry(), 16, sensor);
  for (int k = 0; k < 10; ++k) {
    const Point3 o = sensor_origin(terrain, 13.05 + 0.2 * k, 10.05, sensor);
    warm.integrate_scan(cast_scan(terrain, o, 0.0, sensor, scan_seed(1, 1, k)), o);
  }
  const Point3 origin = sensor_origin(terrain, 15.05, 10.05, sensor);
  const std::vector<ScanPoint> scan = cast_scan(terrain, origin, 0.0, sensor, scan_seed(1, 1, 10));
  for (auto _ : state) {
    state.PauseTiming();
    agent::executive::MappingSystem map = warm;
    state.ResumeTiming();
    map.integrate_scan(scan, origin);
    benchmark::DoNotOptimize(map.heights().data());
  }
  state.counters["points"] = static_cast<double>(scan.size());
  state.SetLabel(std::string(kSensorNames[state.range(0)]) + " on " + kTerrainNames[state.range(1)]);
}

// The scans of InsertAndDerive's robot (10 steps on its way, then the measured one) as clouds in the octree's frame.
std::vector<octomap::Pointcloud> clouds_on_the_way(const Heightmap& terrain, const SensorSpec& sensor,
                                                   std::vector<octomap::point3d>& origins) {
  std::vector<octomap::Pointcloud> clouds;
  const GridGeometry& g = terrain.geometry();
  for (int k = 0; k <= 10; ++k) {
    const Point3 o = sensor_origin(terrain, k < 10 ? 13.05 + 0.2 * k : 15.05, 10.05, sensor);
    octomap::Pointcloud cloud;
    for (const ScanPoint& p : cast_scan(terrain, o, 0.0, sensor, scan_seed(1, 1, k)))
      cloud.push_back(static_cast<float>(o.x + p.x_m - g.xll_m), static_cast<float>(o.y + p.y_m - g.yll_m),
                      static_cast<float>(o.z + p.z_m));
    clouds.push_back(cloud);
    origins.emplace_back(static_cast<float>(o.x - g.xll_m), static_cast<float>(o.y - g.yll_m),
                         static_cast<float>(o.z));
  }
  return clouds;
}

// range(0): sensor, range(1): 0 the OcTree (before), 1 the flat leaves (now); on the platform terrain.
void BM_OctreeInsertion(benchmark::State& state) {
  const Heightmap terrain = terrain_named(0);
  const SensorSpec sensor = sensor_defaults(sensor_kind(kSensorNames[state.range(0)]));
  std::vector<octomap::point3d> origins;
  const std::vector<octomap::Pointcloud> clouds = clouds_on_the_way(terrain, sensor, origins);
  const double cs = terrain.cell_size_m();
  octomap::OcTree tree(cs);
  tree.setClampingThresMin(0.4);
  agent::executive::detail::VoxelOccupancy flat(cs, terrain.rows(), terrain.cols(), 0.4);
  for (int k = 0; k < 10; ++k) {
    tree.insertPointCloud(clouds[k], origins[k], -1.0, true, true);
    tree.updateInnerOccupancy();
    flat.insert(clouds[k], origins[k]);
  }
  for (auto _ : state) {
    if (state.range(1) == 0) {
      state.PauseTiming();
      octomap::OcTree copy(tree);
      state.ResumeTiming();
      copy.insertPointCloud(clouds[10], origins[10], -1.0, true, true);
      copy.updateInnerOccupancy();
      benchmark::DoNotOptimize(copy.size());
    } else {
      state.PauseTiming();
      agent::executive::detail::VoxelOccupancy copy(flat);
      state.ResumeTiming();
      copy.insert(clouds[10], origins[10]);
      benchmark::DoNotOptimize(copy.leaves());
    }
  }
  state.counters["points"] = static_cast<double>(clouds[10].size());
  state.SetLabel(std::string(kSensorNames[state.range(0)]) + (state.range(1) == 0 ? ": OcTree" : ": flat leaves"));
}

// A robot step: the world's scan, then the agent's insertion and derivation, moving 0.2 m per step.
void BM_RobotStep(benchmark::State& state) {
  const Heightmap terrain = terrain_named(static_cast<int>(state.range(1)));
  const SensorSpec sensor = sensor_defaults(sensor_kind(kSensorNames[state.range(0)]));
  agent::executive::MappingSystem map(terrain.geometry(), 16, sensor);
  int k = 0;
  for (auto _ : state) {
    const Point3 o = sensor_origin(terrain, 6.05 + 0.2 * (k % 60), 10.05, sensor);
    map.integrate_scan(cast_scan(terrain, o, 0.0, sensor, scan_seed(1, 1, static_cast<std::uint64_t>(k))), o);
    ++k;
  }
  state.counters["known_cells"] = static_cast<double>(map.known_cells());
  state.counters["octree_leaves"] = static_cast<double>(map.octree_leaves());
  state.SetLabel(std::string(kSensorNames[state.range(0)]) + " on " + kTerrainNames[state.range(1)]);
}

void sensors_and_terrains(benchmark::internal::Benchmark* b) {
  for (int sensor = 0; sensor < 2; ++sensor)
    for (int terrain = 0; terrain < 2; ++terrain) b->Args({sensor, terrain});
  b->Unit(benchmark::kMillisecond);
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The shipped ramp scenario with every robot scanning: each robot's frame and decision timed by the sim, and a shadow
// map fed the same frames (the behaviour's own mapping calls) splits the mapping off the decision.
void BM_ScanningRobotStep(benchmark::State& state) {
  const char* kRunSensors[] = {"laser", "rgbd", "ground_truth"};
  const std::string sensor = kRunSensors[state.range(0)];
  const bool scanning = sensor != "ground_truth";
  constexpr std::uint64_t kFrom = 100, kTo = 300;
  std::vector<double> scan, insertion, heights, decision, whole;
  for (auto _ : state) {
    scenario::Scenario s = scenario::load_scenario(std::string(MARSALA_SOURCE_DIR) + "/deploy/scenarios/ramp.pbtxt",
                                                   {"robot_type.sensor.name=" + sensor});
    s.seed = 1;
    test::LockstepSim sim(s, scenario::build_terrain(s), 3);
    const RobotType& type = sim.state().agents.front().type;
    std::vector<agent::executive::MappingSystem> shadows(3, agent::executive::MappingSystem(
                                                                sim.state().terrain.geometry(), 16, type.sensor));
    std::vector<test::LockstepSim::AgentStepCost> costs;
    while (sim.state().step < kTo) {
      const bool timed = sim.state().step >= kFrom;
      sim.step_timed(costs);
      for (const auto& c : costs) {
        agent::executive::MappingSystem& map = shadows[c.agent_id - 1];
        const Position robot{c.frame.x_m, c.frame.y_m};
        const double began = thread_cpu_ms();
        map.integrate(c.frame.tiles, robot);
        if (c.frame.scanned)
          map.integrate_scan(c.frame.points, agent::executive::believed_sensor_origin(robot, c.frame.z_m, type.sensor));
        map.assume_ground(robot, c.frame.z_m, 0.5 * type.body.navigability.delta_m + type.body.max_step_m);
        const double mapping = thread_cpu_ms() - began;
        if (!timed || c.frame.scanned != scanning) continue;
        scan.push_back(c.frame_ms);
        insertion.push_back(map.last_scan_cost().insertion_ms);
        heights.push_back(map.last_scan_cost().heights_ms);
        decision.push_back(std::max(0.0, c.decide_ms - mapping));
        whole.push_back(c.frame_ms + c.decide_ms);
      }
    }
  }
  state.counters["scan_ms"] = median_of(scan);
  state.counters["insertion_ms"] = median_of(insertion);
  state.counters["heights_ms"] = median_of(heights);
  state.counters["decision_ms"] = median_of(decision);
  state.counters["step_ms"] = median_of(whole);
  state.counters["robot_steps"] = static_cast<double>(whole.size());
  state.SetLabel(sensor + " robots on ramp.pbtxt, steps 100..299");
}

BENCHMARK(BM_Scan)->Apply(sensors_and_terrains);
BENCHMARK(BM_InsertAndDerive)->Apply(sensors_and_terrains);
BENCHMARK(BM_OctreeInsertion)->Args({0, 0})->Args({0, 1})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RobotStep)->Apply(sensors_and_terrains)->Iterations(100);
BENCHMARK(BM_ScanningRobotStep)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
