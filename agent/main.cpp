// marsala-agent: one robot of a MARSala run. Reads its body and behaviour from its slot of the scenario, says hello
// to marsala-world over DDS, then answers every sensor frame with one action request until the run is over.
// Exit codes: 0 run over (or stopped by a signal), 1 error (one line on stderr), 2 usage, or a --dump-map folder that
// holds another run's maps (docs/runtime.md#seeing-the-map).

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <exception>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "marsala/agent/runtime/agent_runtime.hpp"
#include "marsala/agent/runtime/map_dump.hpp"
#include "marsala/cli/command_line.hpp"
#include "marsala/cli/logging.hpp"
#include "marsala/protocol/world_proof.hpp"
#include "marsala/scenario/scenario.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

}  // namespace

/// The robot type an `--id auto` agent declares: `name` (one of the scenario's slots' types), or the type of every
/// slot when they share one. Throws InvalidArgument listing the slots' types otherwise.
const marsala::RobotType& any_slot_type(const marsala::scenario::Scenario& s, const std::string& name) {
  std::vector<std::string> names;
  const marsala::RobotType* found = nullptr;
  for (const marsala::scenario::AgentSlot& slot : s.slots) {
    const marsala::RobotType& t = s.robot_for(slot.id);
    if (std::find(names.begin(), names.end(), t.name) == names.end()) names.push_back(t.name);
    if (t.name == name || (name.empty() && !found)) found = &t;
  }
  if (found && (!name.empty() || names.size() == 1)) return *found;
  throw marsala::InvalidArgument(
      name.empty()
          ? fmt::format("--id auto: the scenario's slots have several robot types ({}): give --robot-type",
                        fmt::join(names, ", "))
          : fmt::format("--robot-type '{}' is no slot's type; the slots have: {}", name, fmt::join(names, ", ")));
}

int main(int argc, char** argv) {
  using namespace marsala;
  CLI::App app{"marsala-agent: one robot of a MARSala run (body and behaviour from its scenario slot)"};
  std::string scenario_file;
  marsala::cli::LogOptions log_options;
  marsala::cli::DdsOptions dds;
  std::string id_text, robot_type;
  double admit_timeout_s = 60.0, world_timeout_s = 600.0;
  app.add_option("--scenario", scenario_file, "scenario file (protobuf text format)")->required();
  app.add_option("--id", id_text,
                 "agent id: the scenario slot, 1..N, or `auto`: the world assigns the lowest free slot of the robot\n"
                 "type (--robot-type, or the scenario's only type)")
      ->required()
      ->check(CLI::IsMember({"auto"}) | CLI::Range(1u, 1000000u));
  app.add_option("--robot-type", robot_type, "with --id auto: the robot type whose slot to take");
  marsala::cli::add_dds_options(app, dds);
  std::optional<std::uint64_t> seed;
  app.add_option("--seed", seed, "override the scenario's seed (marsala-world must get the same)");
  std::vector<std::string> overrides;
  app.add_option("--set", overrides,
                 "change a field of the scenario, FIELD=VALUE, e.g. robot_type.body.sensing_range_m=5 (repeatable;\n"
                 "marsala-world must get the same)")
      ->type_name("FIELD=VALUE");
  marsala::cli::add_log_options(app, log_options);
  app.add_option("--admit-timeout", admit_timeout_s,
                 "give up when not admitted within this [s] of the first hello or of the latest agent seen admitted\n"
                 "(five times this from the first hello at the most)")
      ->check(marsala::cli::seconds_within(1e-3, 1e9));
  app.add_option("--world-timeout", world_timeout_s,
                 "give up when no frame comes for this long [s] (0: never); a silent world (paused, cut off,\n"
                 "restarted with --resume) is waited for until then, never given up on earlier")
      ->capture_default_str()
      ->check(marsala::cli::seconds_within(0.0, 1e9, " (0: wait forever)"));
  std::string dump_dir, run_key;
  app.add_option("--run-key", run_key,
                 "the run's key (the world's OUT/run.key): believe only the world that proves it, never a stranger\n"
                 "answering first (default: the first world that proves any key, pinned; docs/runtime.md#who-wrote-it)")
      ->type_name("FILE");
  app.add_option("--dump-map", dump_dir,
                 "when its admitted run ends, write the robot's map into DIR: agent-<id>-height.asc (NODATA: unknown)\n"
                 "and agent-<id>-map.json; a DIR holding another run's maps is refused (exit 2)")
      ->type_name("DIR");
  if (const auto code = marsala::cli::parse_command_line(app, argc, argv, "marsala-agent", std::cout, std::cerr))
    return *code;

  const std::uint32_t id = id_text == "auto" ? 0u : static_cast<std::uint32_t>(std::stoul(id_text));
  marsala::cli::setup_logging("agent", id, log_options);
  std::shared_ptr<agent::runtime::MapDump> dump;
  std::string world_key;
  const bus::BusConfig bus_config{bus::vendor_from_string(dds.vendor), dds.domain, dds.profile, bus::Role::kClient,
                                  bus::Security::of(dds.security, dds.identity, fmt::format("agent-{}", id)),
                                  dds.peers};
  try {
    if (!dds.security.empty() && id == 0 && dds.identity.empty())
      throw InvalidArgument(
          "--id auto with --security needs --identity: the identity cannot follow a slot not yet "
          "assigned");
    bus::check_config(bus_config);  // a bad profile or identity folder: refused before anything runs
  } catch (const InvalidArgument& e) {
    marsala::cli::write_exit_error(std::cerr, fmt::format("marsala-agent: {}", e.what()));
    return marsala::cli::kExitUsage;
  }
  try {
    if (!dump_dir.empty()) dump = std::make_shared<agent::runtime::MapDump>(dump_dir);
    if (!run_key.empty()) world_key = protocol::world_key_of(protocol::load_run_key(run_key));
  } catch (const Error& e) {
    marsala::cli::write_exit_error(std::cerr,
                                   fmt::format("marsala-agent: {}{}", run_key.empty() ? "" : "--run-key ", e.what()));
    return marsala::cli::kExitUsage;
  }
  try {
    const scenario::Scenario s = scenario::load_scenario(scenario_file, overrides);
    const RobotType& type = id != 0 ? s.robot_for(id) : any_slot_type(s, robot_type);
    // Keep-out around neighbours: the largest body and step of the whole team (bodies may differ per slot).
    double max_delta = 0.0, max_step = 0.0;
    for (const scenario::AgentSlot& slot : s.slots) {
      max_delta = std::max(max_delta, s.robot_for(slot.id).body.navigability.delta_m);
      max_step = std::max(max_step, s.robot_for(slot.id).body.max_step_m);
    }
    agent::runtime::RuntimeConfig config;
    config.agent_id = id;
    config.on_assigned = [](std::uint32_t assigned) { marsala::cli::set_log_agent_id(assigned); };
    if (id != 0) config.name = fmt::format("{}-{}", type.name, id);
    config.type = type;
    config.neighbour_keep_out_m = agent::neighbour_keep_out_m(max_delta, max_step);
    config.seed = seed.value_or(s.seed);
    if (s.has_goal_vector_map) config.goal_vector_map = s.goal_vector_map;
    config.right_of_way = s.right_of_way;
    config.admit_timeout = std::chrono::milliseconds(static_cast<long long>(admit_timeout_s * 1000.0));
    config.world_timeout = std::chrono::milliseconds(static_cast<long long>(world_timeout_s * 1000.0));
    config.world_key = world_key;
    if (dump) agent::runtime::dump_maps_into(dump, config);

    const auto participant = bus::make_participant(bus_config);
    agent::runtime::AgentRuntime agent(*participant, config);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const agent::runtime::RunResult result = agent.run(g_stop);
    if (result.outcome == agent::runtime::RunOutcome::kRunOver) return 0;
    if (result.outcome == agent::runtime::RunOutcome::kOutputRefused) {
      marsala::cli::write_exit_error(std::cerr, fmt::format("marsala-agent: agent {}: {}", id, result.message));
      return marsala::cli::kExitUsage;
    }
    if (result.outcome == agent::runtime::RunOutcome::kStopped) {
      spdlog::info("agent {}: {}", id, result.message);
      return 0;
    }
    // Discovery by unicast reaches only the hosts listed: say which were tried (docs/runtime.md#peers).
    const std::string tried = result.outcome == agent::runtime::RunOutcome::kAdmitTimeout && !dds.peers.empty()
                                  ? fmt::format("; no world answered at --peers {} on domain {} ({})",
                                                fmt::join(dds.peers, ","), dds.domain, dds.vendor)
                                  : "";
    marsala::cli::write_exit_error(std::cerr, fmt::format("marsala-agent: agent {}: {}{}", id, result.message, tried));
    return 1;
  } catch (const std::exception& e) {
    marsala::cli::write_exit_error(std::cerr, fmt::format("marsala-agent: {}", e.what()));
    return 1;
  }
}
