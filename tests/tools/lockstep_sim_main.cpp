// marsala-lockstep-sim: a scenario run in one process (tests/support/lockstep_sim.hpp), for sweeps and for looking
// inside a run: prints one line at the end of each run (steps, end, volume, volume outside the construction band,
// progress, terrain sha256) and, with --show, every robot's state, position, material and request at the chosen
// steps. Lists of team sizes and seeds (--agents 1,2,6-12 --seeds 1-5) make a sweep: one run after the other, a CSV
// row each (--csv), and a table per team size at the end.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lockstep_sim.hpp"
#include "marsala/agent/reactive/path_builder.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/cli/command_line.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/world_server/rules/construction_band.hpp"
#include "marsala/world_server/rules/material_score.hpp"

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
    if (const auto* rb = dynamic_cast<const marsala::agent::reactive::RampBuilder*>(&sim.behaviour(q.agent_id))) {
      // Where a ramp builder was heading and what it found to build (world indices), to trace a stall.
      const auto& t = rb->last_trace();
      const auto o = t.window_offset;
      fmt::print("      goal ({}, {}) path found {} cells {}", o.row + t.local_goal.row, o.col + t.local_goal.col,
                 t.plan.found, t.plan.path.size());
      if (!t.plan.path.empty())
        fmt::print(" ({}, {}) -> ({}, {})", o.row + t.plan.path.front().row, o.col + t.plan.path.front().col,
                   o.row + t.plan.path.back().row, o.col + t.plan.path.back().col);
      fmt::print(" origin {} navigable {} candidates {} dropped for the way back {}\n",
                 t.local_origin ? fmt::format("({}, {})", o.row + t.local_origin->row, o.col + t.local_origin->col)
                                : "-",
                 t.navigable_cells, t.deposition.candidates, t.deposition.dropped_for_way_back);
    }
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


/// "1-5", "1,3,6-12": the listed numbers, in order, each at least 1; throws InvalidArgument naming `option`.
std::vector<std::uint64_t> parse_list(const std::string& text, const std::string& option) {
  std::vector<std::uint64_t> out;
  std::size_t at = 0;
  const auto bad = [&]() {
    return marsala::InvalidArgument(
        fmt::format("{} '{}': expected numbers >= 1 and ranges, e.g. 1,2,6-12", option, text));
  };
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, end - at);
    const std::size_t dash = item.find('-');
    try {
      std::size_t used = 0, used2 = 0;
      const std::string first = item.substr(0, dash);
      const unsigned long long a = std::stoull(first, &used);
      const unsigned long long b = dash == std::string::npos ? a : std::stoull(item.substr(dash + 1), &used2);
      if (used != first.size() || (dash != std::string::npos && used2 != item.size() - dash - 1) || a < 1 || b < a ||
          b - a > 100000 || first.find_first_not_of("0123456789") != std::string::npos)
        throw bad();
      for (unsigned long long v = a; v <= b; ++v) out.push_back(v);
    } catch (const std::logic_error&) {
      throw bad();
    }
    at = end + 1;
  }
  return out;
}

/// What one run ended with.
struct RunResult {
  std::uint32_t agents = 0;
  std::uint64_t seed = 0;
  std::string end;
  std::uint64_t steps = 0;
  double volume_m3 = 0.0;
  double outside_band_m3 = 0.0;  // payload_path runs: raised outside the construction band (construction_band.hpp)
  double band_width_m = 0.0;
  double progress = 0.0;
  std::string sha256;
  marsala::world_server::MaterialScore material;  // docs/runtime.md#material-score
};

/// Requests the world refused and what a run built above the MARS bound (docs/runtime.md#deposit-bound): the bound
/// of the initial terrain at the smallest construction kappa of the run's robots.
struct Refusals {
  std::uint64_t requests = 0;  // requests applied [count]
  std::uint64_t refused = 0;   // of them rejected by a rule [count]

  /// Counts the last step's requests and those the world rejected.
  void count(const LockstepSim& sim) {
    for (const auto& q : sim.last_requests()) {
      ++requests;
      if (sim.state().agent(q.agent_id).last_result == marsala::protocol::ActionResult::kRejected) ++refused;
    }
  }

  /// "refused requests R of N, cells above the MARS bound C (up to H m)", the bound of `initial` with tolerance 1e-9 m.
  std::string describe(const LockstepSim& sim, const marsala::Heightmap& initial) const {
    double kappa = 1e300;
    for (const auto& a : sim.state().agents) kappa = std::min(kappa, marsala::construction_params(a.type).kappa);
    const marsala::Heightmap bound = marsala::MarsProcessor(kappa).project(initial);
    const auto& terrain = sim.state().terrain;
    int above = 0;
    double most = 0.0;
    for (int r = 0; r < terrain.rows(); ++r)
      for (int c = 0; c < terrain.cols(); ++c)
        if (terrain(r, c) > bound(r, c) + 1e-9) ++above, most = std::max(most, terrain(r, c) - bound(r, c));
    return fmt::format("refused requests {} of {} ({:.2f} %), cells above the MARS bound {} (up to {:.3f} m)", refused,
                       requests, requests > 0 ? 100.0 * refused / requests : 0.0, above, most);
  }
};

/// Each agent's own map into `dir` (docs/runtime.md#seeing-the-map): agent-<id>-height.asc, its heights, NODATA where
/// it knows nothing, and agent-<id>-assumed.asc, 1 where the height is no surface a sensor read, 0 elsewhere.
void write_agent_maps(const LockstepSim& sim, const std::string& dir) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& a : sim.state().agents) {
    const auto map = sim.behaviour(a.id).known_map();
    if (!map) continue;
    marsala::Heightmap heights = map->heights, assumed = map->heights;
    for (int r = 0; r < heights.rows(); ++r)
      for (int c = 0; c < heights.cols(); ++c) {
        if (map->known(r, c) == 0) heights(r, c) = nan;
        assumed(r, c) = map->known(r, c) == 0 ? nan : map->assumed(r, c) != 0 ? 1.0 : 0.0;
      }
    marsala::terrain::write_asc(heights, fmt::format("{}/agent-{}-height.asc", dir, a.id));
    marsala::terrain::write_asc(assumed, fmt::format("{}/agent-{}-assumed.asc", dir, a.id));
  }
}

/// What to run and print.
struct RunOptions {
  std::uint64_t max_steps = 0;    // 0: the scenario's
  std::uint64_t stall_steps = 0;  // 0: never
  std::set<std::uint64_t> shown;
  std::string write_dir;
  bool right_of_way = true;  // builders keep the right of way unless the scenario turns it off (right_of_way: false)
};

RunResult run_one(marsala::scenario::Scenario s, const marsala::Heightmap& initial, std::uint32_t agents,
                  std::uint64_t seed, const RunOptions& o) {
  using namespace marsala;
  s.seed = seed;
  if (agents == 0 || agents > s.slots.size())
    throw InvalidArgument(fmt::format("--agents {}: the scenario has {} slots", agents, s.slots.size()));
  const std::uint64_t max_steps = o.max_steps > 0 ? o.max_steps : s.max_steps;
  LockstepSim sim(s, initial, agents, o.right_of_way);
  std::uint64_t last_change = 0;
  Refusals refusals;
  RunResult r;
  r.agents = agents, r.seed = seed, r.end = "max_steps";
  while (sim.state().step < max_steps) {
    if (world_server::is_completed(sim.state())) {
      r.end = "completed";
      break;
    }
    const auto outcome = sim.step();
    refusals.count(sim);
    if (!outcome.changed_tiles.empty()) last_change = sim.state().step;
    if (o.shown.count(sim.state().step) > 0) show(sim);
    if (o.stall_steps > 0 && sim.state().step - last_change >= o.stall_steps) {
      r.end = "stalled";
      break;
    }
  }
  if (o.shown.count(0) > 0) show(sim), reach_base(sim);
  const auto& st = sim.state();
  r.steps = st.step;
  r.volume_m3 = st.deposited_volume_m3;
  r.progress = world_server::progress(st);
  r.sha256 = runlog::terrain_sha256(st.terrain);
  if (st.completion == scenario::CompletionKind::kPayloadPath) {
    const world_server::BandReport band =
        world_server::band_report(st, initial, world_server::payload_path(st.terrain, st.payload_path));
    r.band_width_m = band.width_m;
    r.outside_band_m3 = band.outside_m3;
  }
  r.material = world_server::material_score(st, initial, r.outside_band_m3);
  fmt::print("{} agents {} seed {}: {} after {} steps, {:.3f} m3, outside band {:.3f} m3, progress {:.4f}, last "
             "change {}, rejected motions {}, sha256 {}\n",
             s.name, agents, seed, r.end, st.step, st.deposited_volume_m3, r.outside_band_m3, r.progress, last_change,
             st.rejected_motions, r.sha256);
  fmt::print("  {}\n", refusals.describe(sim, initial));
  fmt::print("  material: {:.3f} of {:.3f} m3 needed (ratio {:.3f}), {:.3f} m3 off the band\n", r.material.deposited_m3,
             r.material.needed_m3, r.material.ratio, r.material.off_band_m3);
  std::fflush(stdout);
  if (!o.write_dir.empty()) {
    terrain::write_asc(st.terrain, o.write_dir + "/terrain_final.asc");
    Heightmap built = st.terrain;
    for (int row = 0; row < built.rows(); ++row)
      for (int c = 0; c < built.cols(); ++c) built(row, c) -= initial(row, c);
    terrain::write_asc(built, o.write_dir + "/built.asc");
    write_agent_maps(sim, o.write_dir);
  }
  return r;
}

std::string csv_row(const std::string& scenario, const RunResult& r) {
  return fmt::format("{},{},{},{},{},{:.3f},{:.3f},{:.1f},{:.4f},{},{:.3f},{:.3f},{:.4f},{:.3f}\n", scenario, r.agents,
                     r.seed, r.end, r.steps, r.volume_m3, r.outside_band_m3, r.band_width_m, r.progress, r.sha256,
                     r.material.deposited_m3, r.material.needed_m3, r.material.ratio, r.material.off_band_m3);
}

/// Per team size: runs, completed, mean / min / max of steps, volume and volume outside the band.
void print_team_table(const std::vector<RunResult>& results) {
  std::map<std::uint32_t, std::vector<const RunResult*>> teams;
  for (const RunResult& r : results) teams[r.agents].push_back(&r);
  fmt::print("agents runs completed | steps mean min max | m3 mean min max | outside band m3 mean\n");
  for (const auto& [agents, runs] : teams) {
    double steps = 0, volume = 0, outside = 0, smin = 1e300, smax = 0, vmin = 1e300, vmax = 0;
    int completed = 0;
    for (const RunResult* r : runs) {
      completed += r->end == "completed" ? 1 : 0;
      steps += r->steps, volume += r->volume_m3, outside += r->outside_band_m3;
      smin = std::min(smin, double(r->steps)), smax = std::max(smax, double(r->steps));
      vmin = std::min(vmin, r->volume_m3), vmax = std::max(vmax, r->volume_m3);
    }
    const double n = static_cast<double>(runs.size());
    fmt::print("{:6} {:4} {:9} | {:5.0f} {:5.0f} {:5.0f} | {:6.1f} {:6.1f} {:6.1f} | {:6.1f}\n", agents, runs.size(),
               completed, steps / n, smin, smax, volume / n, vmin, vmax, outside / n);
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace marsala;
  CLI::App app{"marsala-lockstep-sim: a scenario run in one process, without a bus; lists of team sizes and seeds "
               "make a sweep"};
  std::string scenario_file, agents_text, seeds_text, csv_file;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> overrides;
  std::vector<std::uint64_t> show_steps;
  RunOptions o;
  app.add_option("--scenario", scenario_file, "scenario file")->required();
  app.add_option("--agents", agents_text, "team sizes, e.g. 5 or 1,2,3,6-12 (default: every slot)");
  app.add_option("--seed", seed, "run seed");
  app.add_option("--seeds", seeds_text, "run seeds, e.g. 1-5 (instead of --seed)");
  app.add_option("--csv", csv_file,
                 "write one row per run: scenario,agents,seed,end_reason,steps,volume_m3,outside_band_m3,"
                 "band_width_m,progress,terrain_sha256,material_deposited_m3,material_needed_m3,material_ratio,"
                 "material_off_band_m3 (FILE.partial while the sweep runs)");
  app.add_option("--max-steps", o.max_steps, "step limit (default: the scenario's)");
  app.add_option("--stall-steps", o.stall_steps, "end after this many steps without a terrain change (0: never)");
  app.add_option("--set", overrides, "FIELD=VALUE");
  app.add_option("--write", o.write_dir,
                 "write terrain_final.asc, built.asc (final - initial) and each agent's own map "
                 "(agent-<id>-height.asc, -assumed.asc) into this folder");
  app.add_option("--show", show_steps, "print every robot after these steps");
  app.add_flag("--right-of-way,!--no-right-of-way", o.right_of_way,
               "builders keep the right of way unless the scenario turns it off (right_of_way: false; "
               "docs/runtime.md#right-of-way; the default); --no-right-of-way turns it off whatever the scenario says");
  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-lockstep-sim", std::cout, std::cerr))
    return *code;
  std::vector<RunResult> results;
  try {
    const scenario::Scenario s = scenario::load_scenario(scenario_file, overrides);
    if (seed && !seeds_text.empty()) throw InvalidArgument("--seed and --seeds: give one of them");
    const std::vector<std::uint64_t> seeds =
        !seeds_text.empty() ? parse_list(seeds_text, "--seeds") : std::vector<std::uint64_t>{seed.value_or(s.seed)};
    const std::vector<std::uint64_t> teams = !agents_text.empty() ? parse_list(agents_text, "--agents")
                                                                  : std::vector<std::uint64_t>{s.slots.size()};
    for (const std::uint64_t n : teams)
      if (n > s.slots.size())
        throw InvalidArgument(fmt::format("--agents {}: the scenario has {} slots", n, s.slots.size()));
    o.shown = std::set<std::uint64_t>(show_steps.begin(), show_steps.end());
    const Heightmap initial = scenario::build_terrain(s);
    std::ofstream csv;
    if (!csv_file.empty()) {
      csv.open(csv_file + ".partial");
      if (!csv) throw IoError(fmt::format("--csv {}: cannot be written", csv_file));
      csv << "scenario,agents,seed,end_reason,steps,volume_m3,outside_band_m3,band_width_m,progress,terrain_sha256,"
             "material_deposited_m3,material_needed_m3,material_ratio,material_off_band_m3\n";
    }
    for (const std::uint64_t n : teams)
      for (const std::uint64_t sd : seeds) {
        results.push_back(run_one(s, initial, static_cast<std::uint32_t>(n), sd, o));
        if (csv.is_open()) csv << csv_row(s.name, results.back()) << std::flush;
      }
    if (csv.is_open()) {
      csv.close();
      std::filesystem::rename(csv_file + ".partial", csv_file);
    }
    if (results.size() > 1) print_team_table(results);
  } catch (const InvalidArgument& e) {  // bad options or scenario values
    std::cerr << "marsala-lockstep-sim: " << e.what() << "\n";
    return 2;
  } catch (const ParseError& e) {  // a scenario file that does not parse
    std::cerr << "marsala-lockstep-sim: " << e.what() << "\n";
    return 2;
  } catch (const IoError& e) {  // a scenario, terrain or --csv file that cannot be read or written
    std::cerr << "marsala-lockstep-sim: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "marsala-lockstep-sim: " << e.what() << "\n";
    return 1;
  }
  const bool all = std::all_of(results.begin(), results.end(), [](const RunResult& r) { return r.end == "completed"; });
  return all ? 0 : 3;
}
