#include "marsala/world_server/world_cli.hpp"

#include <spdlog/spdlog.h>

#include <ostream>

#include "marsala/bus/bus.hpp"
#include "marsala/cli/command_line.hpp"
#include "marsala/core/error.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/scenario_check.hpp"
#include "marsala/world_server/world_runtime.hpp"

namespace marsala::world_server {

int run_world_cli(int argc, const char* const* argv, const std::atomic<bool>& stop, std::ostream& out,
                  std::ostream& err) {
  CLI::App app{"marsala-world: the authoritative world server. Loads a scenario, admits agents over DDS, runs the\n"
               "lockstep (frames, requests, validation in agent-id order) and writes summary.json, terrain_initial.asc,\n"
               "terrain_final.asc, final.png, events.log, final_zoom.png (a close-up of what was built, unless it would\n"
               "cover more than half the terrain) and goal_vector_map.png (when the scenario has one) into --out.\n"
               "The run id (partition prefix) defaults to <scenario name>-d<domain>.",
               "marsala-world"};
  std::string scenario_path, dds = "cyclone";
  RuntimeOptions options;
  int domain = 0;
  bool quiet = false;
  std::string positional_scenario;
  bool check = false, json = false;
  app.add_option("--scenario", scenario_path, "scenario file (protobuf text format)");
  app.add_option("scenario_file", positional_scenario, "the scenario file, with --check");
  app.add_flag("--check", check,
               "validate the scenario as the world would at start (no DDS), print its slots, robot types and "
               "completion, and exit: 0 valid, 1 not (the error names file, line and field)");
  app.add_flag("--json", json, "with --check: print one JSON object instead of text");
  app.add_option("--agents", options.agents, "agents to wait for, ids 1..N (default: every slot of the scenario)")
      ->check(CLI::Range(1u, 100000u));
  app.add_option("--dds", dds, "DDS vendor")->check(CLI::IsMember({"cyclone", "fastdds", "inprocess"}))
      ->capture_default_str();
  app.add_option("--domain", domain, "DDS domain id")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--out", options.out_dir, "output folder")->capture_default_str();
  app.add_option("--run-id", options.run_id, "run id, the prefix of every agent partition");
  app.add_option("--admit-timeout", options.admit_timeout_s, "seconds to wait for all agents")
      ->check(CLI::Range(0.0, 86400.0))->capture_default_str();
  app.add_option("--max-steps", options.max_steps, "override the scenario's max_steps")->check(CLI::Range(1ull, 1ull << 40));
  std::uint64_t seed = 0;
  const CLI::Option* seed_option =
      app.add_option("--seed", seed, "override the scenario's seed (start jitter); summary.json reports the seed used");
  app.add_flag("--quiet", quiet, "log warnings and errors only");
  if (const auto code = cli::parse_command_line(app, argc, argv, "marsala-world", out, err)) return *code;

  if (scenario_path.empty()) scenario_path = positional_scenario;
  if (scenario_path.empty() || (!positional_scenario.empty() && scenario_path != positional_scenario) ||
      (!check && !positional_scenario.empty()) || (json && !check)) {
    err << "marsala-world: give the scenario as --scenario FILE, or as --check [--json] FILE (run with --help for "
           "usage)\n";
    return cli::kExitUsage;
  }
  if (check) {
    try {
      const CheckedScenario checked = check_scenario(scenario_path);
      out << (json ? describe_json(checked) : describe_text(checked));
      return 0;
    } catch (const Error& e) {
      err << "marsala-world: error: " << e.what() << "\n";
      return 1;
    }
  }
  if (seed_option->count() > 0) options.seed = seed;
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ world: %v");
  spdlog::set_level(quiet ? spdlog::level::warn : spdlog::level::info);
  try {
    const scenario::Scenario scenario = scenario::load_scenario(scenario_path);
    Heightmap terrain = scenario::build_terrain(scenario);
    const auto participant = bus::make_participant({bus::vendor_from_string(dds), domain});
    WorldRuntime runtime(scenario, std::move(terrain), options, *participant);
    const RunResult result = runtime.run(stop);
    out << "run " << runtime.run_id() << ": " << to_string(result.end_reason) << " after " << result.steps << " steps, "
        << result.admitted << " agents, terrain sha256 " << result.terrain_sha256 << "\n";
  } catch (const Error& e) {
    err << "marsala-world: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    err << "marsala-world: error: out of memory\n";
    return 1;
  }
  return 0;
}

}  // namespace marsala::world_server
