// marsala-lockstep-sim: a scenario run in one process (tests/support/lockstep_sim.hpp), for sweeps and for looking
// inside a run: prints one line at the end (steps, end, volume, progress, terrain sha256) and, with --show, every
// robot's state, position, material and request at the chosen steps.

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "lockstep_sim.hpp"
#include "marsala/agent/reactive/path_builder.hpp"
#include "marsala/cli/command_line.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace {

using marsala::test::LockstepSim;

void show(const LockstepSim& sim) {
  const auto& st = sim.state();
  fmt::print("step {}: {:.3f} m3 deposited, progress {:.4f}\n", st.step, st.deposited_volume_m3,
             marsala::world_server::progress(st));
  for (const auto& q : sim.last_requests()) {
    const auto& a = st.agent(q.agent_id);
    double dep = 0.0;
    for (const auto& d : q.depositions) dep += d.height_m;
    fmt::print("  {:3} {:15} ({:.3f}, {:.3f}) z {:.2f} mat {:.3f} last {} {} | move {} ({:.3f}, {:.3f}) deps {} {}{}{}\n",
               a.id, q.state, a.position.x, a.position.y, a.z_m, a.material_m3,
               static_cast<int>(a.last_result), a.last_reason, q.move, q.target_x_m, q.target_y_m,
               q.depositions.size() + q.deposits.size(), q.refill ? "refill" : "",
               q.waiting_for.empty() ? "" : " | waits: ", q.waiting_for);
    if (const auto* pb = dynamic_cast<const marsala::agent::reactive::PathBuilder*>(&sim.behaviour(q.agent_id))) {
      const auto& t = pb->last_trace();
      const auto front = pb->pipeline().front({a.position.x, a.position.y}, a.target);
      fmt::print("      role {} planned {} found {} path {} navigable {} goal {} front {} returning:", 
                 t.role ? marsala::agent::reactive::to_string(*t.role) : "-", t.planned, t.plan.found,
                 t.plan.path.size(), t.navigable_cells, t.window_offset.row + t.local_goal.row,
                 front ? static_cast<int>(front->agent_id) : 0);
      for (const auto& o : st.agents)
        if (o.id != a.id && pb->pipeline().returning(o.id)) fmt::print(" {}", o.id);
      fmt::print("\n");
    }
  }
}

/// Per robot: the 8-connected BFS distance over cells occupiable for its body on the true terrain from its cell to
/// the base's cell, without and with the other robots' cells (a disc of their two radii) taken out [m].
void reach_base(const LockstepSim& sim) {
  const auto& st = sim.state();
  const auto& g = st.terrain.geometry();
  for (const auto& a : st.agents) {
    const auto occ0 = marsala::NavigabilityProcessor(a.type.body.navigability).occupiable(st.terrain);
    for (int with_others = 0; with_others < 2; ++with_others) {
      auto occ = occ0;
      if (with_others)
        for (const auto& o : st.agents)
          if (o.id != a.id)
            for (int r = 0; r < g.rows; ++r)
              for (int c = 0; c < g.cols; ++c) {
                const auto p = st.terrain.cell_center({r, c});
                if (std::hypot(p.x - o.position.x, p.y - o.position.y) < a.type.body.navigability.delta_m) occ(r, c) = 0;
              }
      const auto from = *st.terrain.cell_at(a.position);
      const auto to = *st.terrain.cell_at(st.base.centre);
      std::vector<int> dist(static_cast<std::size_t>(g.rows) * g.cols, -1);
      std::vector<marsala::CellIndex> queue{from};
      dist[static_cast<std::size_t>(from.row) * g.cols + from.col] = 0;
      for (std::size_t i = 0; i < queue.size(); ++i) {
        const auto c = queue[i];
        for (int dr = -1; dr <= 1; ++dr)
          for (int dc = -1; dc <= 1; ++dc) {
            const marsala::CellIndex n{c.row + dr, c.col + dc};
            if (n.row < 0 || n.col < 0 || n.row >= g.rows || n.col >= g.cols || occ(n.row, n.col) == 0) continue;
            auto& d = dist[static_cast<std::size_t>(n.row) * g.cols + n.col];
            if (d >= 0) continue;
            d = dist[static_cast<std::size_t>(c.row) * g.cols + c.col] + 1;
            queue.push_back(n);
          }
      }
      fmt::print("  agent {} {}: base {} cells away (occupiable here {})\n", a.id, with_others ? "among robots" : "alone",
                 dist[static_cast<std::size_t>(to.row) * g.cols + to.col], occ0(from.row, from.col));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace marsala;
  CLI::App app{"marsala-lockstep-sim: a scenario run in one process, without a bus"};
  std::string scenario_file;
  std::uint32_t agents = 0;
  std::uint64_t max_steps = 0, stall_steps = 0;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> overrides;
  std::vector<std::uint64_t> show_steps;
  std::string write_dir;
  app.add_option("--scenario", scenario_file, "scenario file")->required();
  app.add_option("--agents", agents, "agents (default: every slot)");
  app.add_option("--seed", seed, "run seed");
  app.add_option("--max-steps", max_steps, "step limit (default: the scenario's)");
  app.add_option("--stall-steps", stall_steps, "end after this many steps without a terrain change (0: never)");
  app.add_option("--set", overrides, "FIELD=VALUE");
  app.add_option("--write", write_dir, "write terrain_final.asc and built.asc (final - initial) into this folder");
  app.add_option("--show", show_steps, "print every robot after these steps");
  bool right_of_way = false;
  app.add_flag("--right-of-way", right_of_way, "ramp builders keep the right of way (docs/runtime.md#right-of-way)");
  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-lockstep-sim", std::cout, std::cerr))
    return *code;
  try {
    scenario::Scenario s = scenario::load_scenario(scenario_file, overrides);
    if (seed) s.seed = *seed;
    if (agents == 0) agents = static_cast<std::uint32_t>(s.slots.size());
    if (max_steps == 0) max_steps = s.max_steps;
    const Heightmap initial = scenario::build_terrain(s);
    LockstepSim sim(s, initial, agents, right_of_way);
    const std::set<std::uint64_t> shown(show_steps.begin(), show_steps.end());
    std::uint64_t last_change = 0;
    std::string end = "max_steps";
    while (sim.state().step < max_steps) {
      if (world_server::is_completed(sim.state())) {
        end = "completed";
        break;
      }
      const auto outcome = sim.step();
      if (!outcome.changed_tiles.empty()) last_change = sim.state().step;
      if (shown.count(sim.state().step) > 0) show(sim);
      if (stall_steps > 0 && sim.state().step - last_change >= stall_steps) {
        end = "stalled";
        break;
      }
    }
    if (shown.count(0) > 0) show(sim), reach_base(sim);
    const auto& st = sim.state();
    fmt::print("{} agents {} seed {}: {} after {} steps, {:.3f} m3, progress {:.4f}, last change {}, rejected motions "
               "{}, sha256 {}\n",
               s.name, agents, s.seed, end, st.step, st.deposited_volume_m3, world_server::progress(st), last_change,
               st.rejected_motions, runlog::terrain_sha256(st.terrain));
    if (!write_dir.empty()) {
      terrain::write_asc(st.terrain, write_dir + "/terrain_final.asc");
      Heightmap built = st.terrain;
      for (int r = 0; r < built.rows(); ++r)
        for (int c = 0; c < built.cols(); ++c) built(r, c) -= initial(r, c);
      terrain::write_asc(built, write_dir + "/built.asc");
    }
    return end == "completed" ? 0 : 3;
  } catch (const std::exception& e) {
    std::cerr << "marsala-lockstep-sim: " << e.what() << "\n";
    return 1;
  }
}
