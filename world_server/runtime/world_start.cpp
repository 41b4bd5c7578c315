#include "marsala/world_server/runtime/world_start.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <utility>

#include "marsala/core/error.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/records/run_outputs.hpp"
#include "marsala/world_server/rules/initial_state.hpp"
#include "marsala/world_server/rules/team_fit.hpp"

namespace marsala::world_server {

std::string default_run_id(const std::string& scenario_name, int domain_id) {
  return fmt::format("{}-d{}", scenario_name, domain_id);
}

void check_run_id(const std::string& run_id) {
  const bool ok = !run_id.empty() && std::all_of(run_id.begin(), run_id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (!ok) throw InvalidArgument(fmt::format("run id '{}' must be non-empty letters, digits, '_', '-', '.'", run_id));
}

WorldStart prepare_world_start(const scenario::Scenario& s, Heightmap terrain, RuntimeOptions options, int domain_id) {
  WorldStart start{s, std::move(options), {}, std::nullopt, std::nullopt};
  RuntimeOptions& o = start.options;
  if (o.seed) start.scenario.seed = *o.seed;
  const std::uint32_t agents = o.agents == 0 ? static_cast<std::uint32_t>(s.slots.size()) : o.agents;
  if (agents > s.slots.size())
    throw InvalidArgument(
        fmt::format("--agents {} exceeds the {} agent slots of scenario '{}'", agents, s.slots.size(), s.name));
  o.agents = agents;
  if (o.run_id.empty()) o.run_id = default_run_id(s.name, domain_id);
  check_run_id(o.run_id);
  if (!(o.admit_timeout_s >= 0.0) || !std::isfinite(o.admit_timeout_s))
    throw InvalidArgument("admit timeout must be finite and >= 0 s");
  if (o.max_steps == 0) o.max_steps = s.max_steps;
  if (o.step_deadline_s == 0.0) o.step_deadline_s = s.step_deadline_s;
  if (!(o.step_deadline_s > 0.0) || !std::isfinite(o.step_deadline_s))
    throw InvalidArgument("step deadline must be finite and > 0 s");
  // Every builder computes MARS at its construction kappa on windows of this terrain, whose heights grow as it is
  // built, up to the world's height limit (kMaxMagnitude): refuse combinations that doubles cannot compute there
  // (docs/runtime.md#scenario-validation) instead of letting an agent's processor fail mid-run.
  const double height_limit_m = kMaxMagnitude;
  for (std::uint32_t id = 1; id <= agents; ++id) {
    const RobotType& type = s.robot_for(id);
    const std::string problem = mars_problem(construction_params(type).kappa, terrain.cell_size_m(), height_limit_m,
                                             terrain.rows(), terrain.cols());
    if (!problem.empty())
      throw InvalidArgument(
          fmt::format("scenario {}: robot type '{}': construction kappa: {}", s.source_path, type.name, problem));
  }
  if (const std::string problem = team_fit_problem(s, terrain, agents); !problem.empty())
    throw InvalidArgument(fmt::format("the team does not fit on its base: {}", problem));
  if (!o.out_dir.empty() && !o.replace) check_fresh_output_dir(o.out_dir);
  start.state = make_world_state(start.scenario, std::move(terrain), agents);
  return start;
}

WorldStart prepare_resume(const std::string& dir, RuntimeOptions options, int domain_id) {
  namespace fs = std::filesystem;
  const auto began = std::chrono::steady_clock::now();
  const std::string log_path = (fs::path(dir) / kRunLogFile).string();
  if (!fs::exists(log_path))
    throw Error(fmt::format("--resume {}: no {} there (only runs of this version can be resumed)", dir, kRunLogFile));
  runlog::RunLogReader reader(log_path);
  const proto::LogHeader& h = reader.header();
  if (h.scenario_text().empty())
    throw Error(
        fmt::format("{}: the header holds no scenario text (the run was started without a scenario file)", log_path));
  const std::vector<std::string> overrides(h.overrides().begin(), h.overrides().end());
  const scenario::Scenario scenario = scenario::parse_scenario(h.scenario_text(), h.scenario_file(), overrides);
  const std::string terrain_path = (fs::path(dir) / "terrain_initial.asc").string();
  Heightmap terrain = terrain::read_asc(terrain_path);
  if (terrain.rows() != h.rows() || terrain.cols() != h.cols() || terrain.cell_size_m() != h.cell_size_m() ||
      runlog::terrain_sha256(terrain) != h.initial_terrain_sha256())
    throw ParseError(terrain_path, 0,
                     "it is not the initial terrain run.log was written from (grid or SHA-256 differs)");
  options.agents = h.agents();
  options.run_id = h.run_id();
  options.seed = h.seed();
  if (options.max_steps == 0) options.max_steps = h.max_steps();
  options.step_deadline_s = h.step_deadline_s();
  options.scenario_text = h.scenario_text();
  options.overrides = overrides;
  const std::string out_dir = dir;
  options.out_dir.clear();  // the folder holds this run's files: no freshness check
  WorldStart start = prepare_world_start(scenario, std::move(terrain), std::move(options), domain_id);
  start.options.out_dir = out_dir;
  RebuiltState rebuilt = rebuild_state(dir, std::move(start.state), reader);
  if (rebuilt.ended)
    throw Error(fmt::format("--resume {}: the run ended ({}) after {} steps; there is nothing to resume", dir,
                            rebuilt.end_reason, rebuilt.state.step));
  for (const char* name : {"summary.json", "terrain_final.asc"})
    if (fs::exists(fs::path(dir) / name))
      throw Error(fmt::format("--resume {}: {} exists, so the run ended; there is nothing to resume", dir, name));
  start.state = std::move(rebuilt.state);
  ResumeInfo info;
  info.good_bytes = rebuilt.good_bytes;
  info.snapshot_step = rebuilt.snapshot_step;
  info.records = rebuilt.records;
  info.tail_problem = rebuilt.tail_problem;
  info.snapshot_problem = rebuilt.snapshot_problem;
  info.rebuild_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  start.resume = info;
  return start;
}

}  // namespace marsala::world_server
