#pragma once
// What a run leaves in its output folder: summary.json (protobuf RunSummary as JSON, proto field names),
// terrain_initial.asc, terrain_final.asc, final.png, and events.log (one text line per event). IO at the edge.

#include <cstdint>
#include <fstream>
#include <string>

#include "common/bus/messages.hpp"
#include "common/grid/heightmap.hpp"
#include "world_server/world_state.hpp"

namespace marsala::world_server {

/// What the summary reports besides the world state.
struct RunInfo {
  std::string scenario;        ///< scenario name
  std::string scenario_file;
  std::string run_id;
  std::string dds;             ///< cyclone, fastdds or inprocess
  std::uint64_t seed = 0;
  bool completed = false;
  std::string end_reason;      ///< completed, max_steps, signal, no_live_agents
  double wall_seconds = 0.0;   ///< [s]
  double step_wall_median_ms = 0.0;  ///< median wall time of one lockstep step [ms]
  double step_wall_p90_ms = 0.0;     ///< its 90th percentile [ms]
};

/// summary.json's text: every field present (zeros included); steps = state.step; terrain_sha256 of state.terrain.
std::string summary_json(const WorldState& state, const RunInfo& info);

/// Writes terrain_initial.asc into `dir` (created when missing); throws IoError.
void write_initial_outputs(const std::string& dir, const grid::Heightmap& terrain);

/// Writes summary.json, terrain_final.asc and final.png (agents and the goal centre marked) into `dir`; throws IoError.
void write_final_outputs(const std::string& dir, const WorldState& state, const RunInfo& info);

/// One event as a log line: "step 12 agent 2 deposited 0.000125 m3: 1 cells".
std::string format_event(const bus::WorldEvent& event);

/// events.log: appends one line per event or note, flushed at once so that a crash keeps what happened.
class EventLog {
 public:
  /// Creates (truncates) the file; throws IoError.
  explicit EventLog(const std::string& path);
  void append(const bus::WorldEvent& event);
  /// A line that is not an event, e.g. "step 7 note: agent 2: request for past step 5 dropped".
  void note(std::uint64_t step, const std::string& text);

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace marsala::world_server
