#pragma once
// What a run leaves in its output folder: summary.json (protobuf RunSummary as JSON, proto field names),
// terrain_initial.asc, terrain_final.asc, final.png, final_zoom.png (when zoom_window() finds a close-up),
// final_3d.png, goal_vector_map.png (scenarios with a goal vector map) and events.log (JSON Lines, one object per event or
// note). IO at the edge.
//
// final.png: the hillshaded final terrain; every cell raised by a deposition tinted with its depositor's colour
// (render::default_palette(): agent id k -> entry (k - 1) mod 12: 1 red, 2 blue, 3 green, 4 orange, 5 purple, 6 cyan,
// 7 magenta, 8 lime, 9 brown, 10 pink, 11 teal, 12 lavender, then again from red); agents as discs of their colour;
// the base station as a white circle of its radius; agents_at_goal: the goal rectangle outlined in white and its
// centre crossed; payload_path: the constructed path as a yellow line, `from` as a red square, `to` as a green
// diamond; level_site: the site outlined in white; a title with scenario, step and completion; a legend.
//
// final_zoom.png: the same picture of the zoom window only (what was built, the payload's path and ends, the site and
// the base, with a margin), so that a 24 m path on a 160 m terrain fills the picture; titled
// "<scenario>: close-up x X0..X1 m, y Y0..Y1 m". Not written when the window would hold more than half the terrain.
//
// final_3d.png: a perspective view (render::render_perspective, from the south-west, 35 deg up) of the zoom window,
// or of the whole terrain when there is none, every cell a deposition raised tinted orange.

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/goal_vector_map.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/construction_sites.hpp"
#include "marsala/protocol/end_reason.hpp"
#include "marsala/world_server/rules/occupancy_cache.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// What the summary reports besides the world state.
struct RunInfo {
  std::string scenario;  ///< scenario name
  std::string scenario_file;
  std::vector<std::string> overrides;  ///< --set FIELD=VALUE applied to the scenario file
  std::string run_id;
  std::string dds;  ///< cyclone, fastdds or inprocess
  std::uint64_t seed = 0;
  bool completed = false;
  protocol::EndReason end_reason = protocol::EndReason::kSignal;  ///< why the run ended
  double wall_seconds = 0.0;                  ///< [s]
  double step_wall_median_ms = 0.0;           ///< median wall time of one lockstep step [ms]
  double step_wall_p90_ms = 0.0;              ///< its 90th percentile [ms]
  double step_world_median_ms = 0.0;   ///< median of the world's own part of a step (the step less its waits) [ms]
  double step_world_p90_ms = 0.0;      ///< its 90th percentile [ms]
  double world_cpu_ms_per_step = 0.0;  ///< the world process's CPU time (all threads) over the steps / steps [ms]
  double admit_seconds = 0.0;          ///< from the start of admission to the first frame [s]
  std::uint32_t connected = 0;         ///< agents admitted and connected when the first frame went out
  double start_jitter_m = 0.0;         ///< the scenario's start jitter [m]
  /// The scenario's goal vector map, drawn into goal_vector_map.png when set.
  std::optional<GoalVectorMapSpec> goal_vector_map;
  /// The terrain before the run (goal_vector_map.png, payload_path's construction sites); empty = unknown (the
  /// final one is drawn, no sites are reported).
  Heightmap initial_terrain;
  std::optional<ForkOrigin> fork;  ///< where a fork came from (none: no fork)
};

/// The ids of the slots of `state`'s team not in the run now (never admitted, or dropped and not back), in order. For a
/// fork (`fork` not null) the slots above its team (fork->agents + 1 .. fork->parent_agents), which left at its K by
/// the user's choice (docs/runtime.md#fork), are not missing.
std::vector<std::uint32_t> missing_slots(const WorldState& state, const ForkOrigin* fork = nullptr);

/// summary.json's text: every field present (zeros included); steps = state.step; terrain_sha256 of state.terrain;
/// payload_path: path_found and path_length_m of payload_path() on state.terrain; level_site: site_level_fraction()
/// on state.terrain.
std::string summary_json(const WorldState& state, const RunInfo& info);

/// Writes terrain_initial.asc into `dir` (created when missing); throws IoError.
void write_initial_outputs(const std::string& dir, const Heightmap& terrain);

/// The close-up of final_zoom.png, in whole cells of state.terrain: the bounding box of every cell a deposition raised
/// (state.depositor > 0), the route's cells, payload_path's `from` and `to`, level_site's site and the base station's
/// disc; widened by max(3 m, 15 % of the box's longer side) on each side, grown about its centre to a square at least
/// 10 m a side, rounded outwards to whole cells and clipped to the grid. nullopt when there is nothing to frame (no
/// deposit, no route, no payload ends, no site: the base alone is no subject) or when the window holds more than half
/// of the terrain's cells (final.png shows it well enough then).
std::optional<CellRect> zoom_window(const WorldState& state, const std::optional<PayloadRoute>& route);

/// The options of final.png (see the top of this file) for the final state and the payload's constructed path; with
/// `window`, those of final_zoom.png, to be drawn on state.terrain.window(window): labels and markers cropped to the
/// window (a marker outside it dropped), the world-coordinate overlays unchanged (the crop keeps its cells' world
/// positions; the renderer clips what lies off it), the close-up title. Throws InvalidArgument when the window is
/// empty or leaves the grid.
render::RenderOptions final_picture_options(const WorldState& state, const RunInfo& info,
                                            const std::optional<PayloadRoute>& route,
                                            const std::optional<CellRect>& window = std::nullopt);

/// The options of goal_vector_map.png: the arrows of GoalVectorMap(spec, grid).arrows() in red, the
/// map's rectangle (and a level_site's site) outlined in white, a title with the arrow count.
render::RenderOptions goal_vector_map_picture_options(const WorldState& state, const RunInfo& info,
                                                      const GoalVectorMap& map);

/// Writes summary.json, terrain_final.asc, final.png, final_zoom.png when zoom_window() gives a window, final_3d.png
/// and, when info.goal_vector_map is set, goal_vector_map.png (on info.initial_terrain, or the final terrain when that
/// is empty) into `dir`; the payload's path is computed once. Throws IoError; a goal vector map that does not fit the
/// grid throws InvalidArgument after the other files are written.
void write_final_outputs(const std::string& dir, const WorldState& state, const RunInfo& info);

/// The files a run writes into its output folder (docs/runtime.md#outputs).
inline constexpr const char* kRunFiles[] = {
    "summary.json",   "events.log",   "terrain_initial.asc", "terrain_final.asc", "final.png",
    "final_zoom.png", "final_3d.png", "goal_vector_map.png", kRunLogFile,         kSnapshotFile};

/// The kRunFiles present in `dir` (none when it does not exist).
std::vector<std::string> run_files_in(const std::string& dir);

/// Throws IoError naming them when `dir` holds any of a run's files: a run never mixes its outputs with another's.
void check_fresh_output_dir(const std::string& dir);

/// Removes the kRunFiles (and their temporary .tmp names) from `dir`, and the frames and timelapse.mp4 of dir/frames
/// (--frames-every; the folder too when nothing else is in it) (marsala-world --replace); throws IoError.
void clear_run_files(const std::string& dir);

/// One events.log line (without its newline): a JSON object (docs/runtime.md#outputs), e.g.
///   {"step":42,"agent":3,"kind":"deposited","volume_m3":0.000125,"detail":"2 cells","cells":[[10,11,0.05],[10,12,0.05]]}
/// `cells` (row, col, new height [m], heights to 17 digits) only for a deposition; agent 0 = the world.
std::string event_json(const protocol::WorldEvent& event, const std::vector<Deposition>& cells = {});
/// A note as an events.log line: {"step":7,"kind":"note","detail":"agent 2: request for past step 5 dropped"}.
std::string note_json(std::uint64_t step, const std::string& text);

/// events.log, JSON Lines: appends one object per event or note, flushed at once so that a crash keeps what happened;
/// a line that cannot be written throws IoError (the run then ends with an error).
class EventLog {
 public:
  /// Creates (truncates) the file, or with `append` continues it (a resumed run); throws IoError.
  explicit EventLog(const std::string& path, bool append = false);
  /// An event; for a deposition `cells` are the cells it set.
  void append(const protocol::WorldEvent& event, const std::vector<Deposition>& cells = {});
  /// A line that is not an event, e.g. a request for a past step dropped.
  void note(std::uint64_t step, const std::string& text);

 private:
  /// Writes and flushes one line; throws IoError when it cannot (a lost event log is an error, never silent).
  void write_line(const std::string& line);
  std::string path_;
  std::ofstream out_;
};

}  // namespace marsala::world_server
