#pragma once
// What a run starts from, decided before the world touches the bus: the options resolved against the scenario, the
// initial state (or, for --resume, the state rebuilt from the run's log), so that marsala-world --check runs the
// same start without DDS.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/protocol/world_proof.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/records/fork_replay.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// How to run.
struct RuntimeOptions {
  std::uint32_t agents = 0;             ///< expected agents, ids 1..agents; 0 = every slot of the scenario
  std::string run_id;                   ///< names the run's partitions; empty = default_run_id(scenario, domain)
  double admit_timeout_s = 60.0;        ///< how long to wait for all agents before starting with those admitted,
                                        ///< counted from the latest admission (protocol::AdmitDeadline) [s]
  std::uint64_t max_steps = 0;          ///< 0 = the scenario's max_steps
  double step_deadline_s = 0.0;         ///< 0 = the scenario's step_deadline_s [s]
  std::string out_dir = "out/run";      ///< summary.json, terrain_*.asc, final*.png, goal_vector_map.png, events.log
  double linger_s = 2.0;                ///< after the run_over frames, wait up to this long for agents to leave [s]
  double silence_timeout_s = 600.0;     ///< how long a step is held while no live agent is heard; 0 = for ever [s]
  std::optional<std::uint64_t> seed;    ///< overrides the scenario's seed (start jitter; reported in summary.json)
  std::uint64_t snapshot_every = 1000;  ///< write snapshot.pb after every this many steps; 0 = never
  std::uint64_t frames_every = 0;       ///< a PNG frame every this many steps and the last in out_dir/frames; 0 = none
  std::string search_path;              ///< where to look for ffmpeg (the timelapse.mp4 of the frames); empty = none
  std::string scenario_text;           ///< the scenario file's text, recorded in run.log so that --resume needs no file
  std::vector<std::string> overrides;  ///< --set FIELD=VALUE applied to scenario_text (recorded in run.log too)
  bool replace = false;  ///< out_dir may hold another run's files: the caller clears them (clear_run_files())
  /// The run key the world proves itself with (records/run_key_file.hpp); none: a random one, kept nowhere.
  std::optional<protocol::RunKey> run_key;
};

/// Where a resumed run picks up (prepare_resume()).
struct ResumeInfo {
  std::uint64_t good_bytes = 0;     ///< run.log's length up to its last good record; anything after it is cut
  std::uint64_t snapshot_step = 0;  ///< the snapshot restored (0: replayed from the header)
  std::uint64_t records = 0;        ///< records replayed
  std::string tail_problem;         ///< run.log's damaged tail, cut and never applied (empty: clean)
  std::string snapshot_problem;     ///< why snapshot.pb was not used, when present and unusable
  double rebuild_seconds = 0.0;     ///< wall time to rebuild the state [s]
};

/// The default run id: "<scenario name>-d<domain id>", so runs of one scenario on different domains never share
/// partitions.
std::string default_run_id(const std::string& scenario_name, int domain_id);

/// Throws InvalidArgument unless `run_id` is non-empty letters, digits, '_', '-', '.' (no partition wildcards).
void check_run_id(const std::string& run_id);

/// What a run starts from, decided before the world touches the bus.
struct WorldStart {
  scenario::Scenario scenario;       ///< with the seed in use (RuntimeOptions::seed when given)
  RuntimeOptions options;            ///< resolved: agents, run id, max_steps and step deadline filled in and checked
  WorldState state;                  ///< the initial state (make_world_state(): start jitter, completion check set up)
  std::optional<ResumeInfo> resume;  ///< set by prepare_resume(): `state` is the rebuilt one
  std::optional<ForkReplay> fork;    ///< set by prepare_fork(): replay the parent's first K steps (fork_start.hpp)
};

/// Everything the world checks and decides at start before it admits agents, on the run's terrain: applies the seed
/// override, resolves the options (agents 0 = every slot, run id empty = default_run_id(scenario, domain_id), max_steps
/// and step deadline 0 = the scenario's) and makes the initial state. Throws InvalidArgument when the agent count
/// exceeds the scenario's slots, the run id or a timeout is invalid, or make_world_state() rejects the scenario
/// (payload's `from` or `to` off the grid, a site with no cell on the grid).
WorldStart prepare_world_start(const scenario::Scenario& scenario, Heightmap terrain, RuntimeOptions options,
                               int domain_id);

/// The start of `marsala-world --resume DIR` (docs/runtime.md#resume): the scenario from run.log's header (its text,
/// not the file), the terrain from DIR/terrain_initial.asc (checked against the header's digest), the options the run
/// had (agents, run id, seed, max_steps and step deadline; options.max_steps > 0 raises the limit) and the state
/// rebuilt by rebuild_state() from snapshot.pb and run.log. Throws Error when there is nothing to resume (no log, the
/// run ended, no scenario text) and ParseError/IoError on files that cannot be read or disagree.
WorldStart prepare_resume(const std::string& dir, RuntimeOptions options, int domain_id);

}  // namespace marsala::world_server
