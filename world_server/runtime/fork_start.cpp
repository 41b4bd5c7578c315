#include "marsala/world_server/runtime/fork_start.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/records/run_outputs.hpp"
#include "marsala/world_server/rules/initial_state.hpp"

namespace marsala::world_server {
namespace {

/// True when `overrides` ("FIELD=VALUE") set the top-level scenario field `name`.
bool sets(const std::vector<std::string>& overrides, const std::string& name) {
  return std::any_of(overrides.begin(), overrides.end(),
                     [&](const std::string& o) { return o.compare(0, name.size() + 1, name + "=") == 0; });
}

/// A larger team at a fork (docs/runtime.md#fork): its late slots are in the world's state from step 0, unadmitted;
/// the rules must judge the parent's team as they did (the same starts, the same deposit bound). Throws
/// InvalidArgument naming the slot that would change them.
void check_late_slots(const WorldStart& start, std::uint32_t parent_agents, const std::string& dir) {
  const WorldState parent = make_world_state(start.scenario, start.state.terrain, parent_agents);
  for (std::uint32_t id = 1; id <= parent_agents; ++id)
    if (!(parent.agent(id).start == start.state.agent(id).start))
      throw InvalidArgument(fmt::format("--fork {} --agents {}: agent {} would start elsewhere than in the parent", dir,
                                        start.state.agents.size(), id));
  if (parent.deposit_bound_kappa != start.state.deposit_bound_kappa)
    throw InvalidArgument(fmt::format(
        "--fork {} --agents {}: the late slots' robot types change the world's deposit bound (kappa {} instead of "
        "the parent's {}) from step 0, so the replay would differ; join robots of the parent's types",
        dir, start.state.agents.size(), start.state.deposit_bound_kappa, parent.deposit_bound_kappa));
}

}  // namespace

std::string fork_override_problem(const std::string& field_value) {
  const std::string field = field_value.substr(0, field_value.find('='));
  const std::string top = field.substr(0, field.find_first_of(".["));
  for (const char* name : kForkSettableFields)
    if (top == name) return {};
  return fmt::format(
      "--set {}: the agents read {} from step 0, so their requests up to K would differ from the parent's; a fork "
      "may --set only what the world alone reads: {}",
      field_value, top, fmt::join(kForkSettableFields, ", "));
}

WorldStart prepare_fork(const std::string& dir, std::uint64_t at, RuntimeOptions options, int domain_id) {
  namespace fs = std::filesystem;
  const std::string log_path = (fs::path(dir) / kRunLogFile).string();
  if (!fs::is_regular_file(log_path))
    throw InvalidArgument(fmt::format("--fork {}: no {} there: not a run folder", dir, kRunLogFile));
  if (options.seed)
    throw InvalidArgument(fmt::format(
        "--fork {}: --seed may not change at a fork (the agents replay the parent's seed from step 0); --agents "
        "(fewer or more), --max-steps, --step-deadline and --set of world-only fields may",
        dir));
  std::error_code ec;
  if (!options.out_dir.empty() && fs::exists(options.out_dir) && fs::equivalent(options.out_dir, dir, ec))
    throw InvalidArgument(fmt::format("--fork {}: --out must be another folder than the parent's", dir));
  const proto::LogHeader h = runlog::RunLogReader(log_path).header();
  if (h.scenario_text().empty())
    throw InvalidArgument(fmt::format("--fork {}: run.log's header holds no scenario text", dir));
  const std::vector<std::string> fork_overrides = options.overrides;
  std::vector<std::string> overrides(h.overrides().begin(), h.overrides().end());
  overrides.insert(overrides.end(), fork_overrides.begin(), fork_overrides.end());
  const scenario::Scenario scenario = scenario::parse_scenario(h.scenario_text(), h.scenario_file(), overrides);
  for (const std::string& o : fork_overrides)
    if (const std::string problem = fork_override_problem(o); !problem.empty())
      throw InvalidArgument(fmt::format("--fork {}: {}", dir, problem));
  Heightmap terrain = scenario::build_terrain(scenario);
  if (runlog::terrain_sha256(terrain) != h.initial_terrain_sha256())
    throw InvalidArgument(fmt::format("--fork {}: the header's scenario builds another terrain than the run's", dir));
  const std::uint32_t fork_agents = options.agents;
  options.agents = std::max(h.agents(), fork_agents);  // a larger team: its late slots join at K
  options.seed = h.seed();
  // The parent's limits, unless the fork gives its own (--max-steps, --step-deadline, or --set of the field).
  if (options.max_steps == 0) options.max_steps = sets(fork_overrides, "max_steps") ? scenario.max_steps : h.max_steps();
  if (options.step_deadline_s == 0.0)
    options.step_deadline_s =
        sets(fork_overrides, "step_deadline_s") ? scenario.step_deadline_s : h.step_deadline_s();
  if (options.max_steps < at)
    throw InvalidArgument(fmt::format("--fork {} --at {}: max_steps {} would end the fork before it goes live at {}",
                                      dir, at, options.max_steps, at));
  options.scenario_text = h.scenario_text();
  options.overrides = overrides;
  const std::string out_dir = options.out_dir;
  options.out_dir.clear();  // checked below, once the fork is known to be possible
  WorldStart start = prepare_world_start(scenario, std::move(terrain), std::move(options), domain_id);
  if (fork_agents > h.agents()) check_late_slots(start, h.agents(), dir);
  start.fork.emplace(read_fork(dir, at, fork_agents, start.state));
  start.fork->set_overrides(fork_overrides);
  start.options.out_dir = out_dir;
  if (out_dir.empty()) return start;  // a check: no folder
  if (start.options.replace)
    clear_run_files(out_dir);
  else
    check_fresh_output_dir(out_dir);
  return start;
}

}  // namespace marsala::world_server
