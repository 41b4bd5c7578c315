#pragma once
// marsala-monitor replay: rebuilds a run's terrain from its output folder without any agent (docs/runtime.md#replay).
//
// The folder holds run.log (idl/run_log.proto) and terrain_initial.asc. Replay starts from the initial terrain, whose
// SHA-256 and grid must match the log's header, and applies the depositions of every accepted request of every
// StepRecord in record order (terrain(row, col) += height_m; the cell's depositor = the request's agent), exactly as
// the world's apply_request() did (docs/runtime.md#applying-requests). Each StepRecord must be the next step; its
// deposited_volume_m3 must equal the replay's running total (sum of height_m * cell_size^2 per accepted request);
// a RunEnd's terrain_sha256 must equal the replayed terrain's. Any disagreement is an error naming the byte offset.
// A damaged tail (a crash of the world) is never applied: the good steps before it are the replay.
//
// TerrainReplayer is the pure part (records in, terrain out, no IO); replay_run() is the edge that reads the files
// and writes the frames.

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "idl/run_log.pb.h"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/render/terrain_renderer.hpp"

namespace marsala::monitor {

/// What the replay knows of one agent, for the summary and the pictures.
struct ReplayedAgent {
  std::uint32_t id = 0;
  std::string name;                  ///< from its (latest) admission
  bool admitted = false;             ///< admitted at least once
  bool dropped = false;              ///< dropped and not admitted again since
  std::optional<Position> position;  ///< target of its latest accepted move; unknown before its first [m]
  std::uint64_t accepted = 0;        ///< accepted requests
  std::uint64_t rejected = 0;        ///< requests the world rejected
  double deposited_m3 = 0.0;         ///< volume of its accepted depositions [m^3]
  std::string state;                 ///< the behaviour state of its latest logged request (accepted or not)
  /// [rad from east, counter-clockwise] (docs/runtime.md#heading): towards its target from its start at admission
  /// (with a known start), then along its latest accepted motion of non-zero length; NaN while unknown.
  double heading_rad = std::numeric_limits<double>::quiet_NaN();
  /// On board [m^3] (docs/runtime.md#applying-requests): its capacity at admission, less each accepted deposition,
  /// full again on a refill; NaN without its start (TerrainReplayer::set_start).
  double material_m3 = std::numeric_limits<double>::quiet_NaN();
};

/// What the log does not say of a slot and a replay can take from the run's scenario: where it starts, where it
/// heads, what it carries.
struct SlotStart {
  std::optional<Position> start;  ///< [m]; empty when the world moved the starts (start jitter)
  Position target;                ///< its slot's target [m]
  double capacity_m3 = 0.0;       ///< its robot type's material capacity [m^3]
};

/// Throws ParseError naming `terrain_name` when `terrain` is not the initial terrain `header` describes: rows, cols,
/// cell size [m] or SHA-256 (runlog::terrain_sha256) differ.
void check_initial_terrain(const proto::LogHeader& header, const Heightmap& terrain, const std::string& terrain_name);

/// Applies a run log's records to the initial terrain, in order, and checks them against the replay as it goes.
class TerrainReplayer {
 public:
  /// Starts from `initial_terrain` (check_initial_terrain() is the caller's business); `log_name` names the log in
  /// messages.
  TerrainReplayer(const proto::LogHeader& header, Heightmap initial_terrain, std::string log_name);

  /// Gives slot `id` its start: each admission of it puts it there (when known), facing its target, full.
  void set_start(std::uint32_t id, const SlotStart& start) { starts_[id] = start; }

  /// Applies the record found at byte `offset` of the log. Throws ParseError("<log>: <record> at byte N: ...") for a
  /// second header, a step out of order (a gap or a repeat), an accepted deposition off the grid or of a non-finite
  /// height, a step whose deposited_volume_m3 differs from the replay's total by more than 1e-9 relative (and
  /// 1e-12 m^3), a RunEnd whose steps or terrain_sha256 differ from the replay's, or any record after a RunEnd.
  void apply(const proto::LogRecord& record, std::uint64_t offset);

  const proto::LogHeader& header() const { return header_; }
  /// The replayed terrain [m].
  const Heightmap& terrain() const { return terrain_; }
  /// Per cell the id of the agent whose accepted deposition last raised it; 0 = never raised.
  const render::CellLabels& depositor() const { return depositor_; }
  /// Steps applied so far (= the step the world awaited next).
  std::uint64_t steps() const { return steps_; }
  /// Total volume of the accepted depositions [m^3].
  double deposited_volume_m3() const { return deposited_volume_m3_; }
  /// Agents by id: every agent admitted or named by a request.
  const std::map<std::uint32_t, ReplayedAgent>& agents() const { return agents_; }
  /// Requests logged in the applied steps, and how many of them the world accepted.
  std::uint64_t requests() const { return requests_; }
  std::uint64_t accepted_requests() const { return accepted_requests_; }
  /// Times a resumed world took over.
  std::uint32_t resumptions() const { return resumptions_; }
  /// The RunEnd record, once applied (its sha and steps were checked).
  const std::optional<proto::RunEnd>& run_end() const { return run_end_; }

 private:
  void apply_step(const proto::StepRecord& step, const std::string& where);
  ReplayedAgent& agent(std::uint32_t id);
  void admit(const proto::AgentAdmitted& admitted);

  proto::LogHeader header_;
  Heightmap terrain_;
  render::CellLabels depositor_;
  std::string log_name_;
  std::uint64_t steps_ = 0;
  double deposited_volume_m3_ = 0.0;
  std::map<std::uint32_t, ReplayedAgent> agents_;
  std::map<std::uint32_t, SlotStart> starts_;
  std::uint64_t requests_ = 0;
  std::uint64_t accepted_requests_ = 0;
  std::uint32_t resumptions_ = 0;
  std::optional<proto::RunEnd> run_end_;
};

/// A replay frame's picture, drawn like the world's final.png (world_server/run_outputs.hpp) as far as the log
/// tells: hillshaded terrain, every raised cell tinted with its depositor's palette colour, agents with a known
/// position as discs of their colour, a legend line per colour of every slot 1..header.agents (so that every frame of
/// a replay has the same key), the title "<scenario>: step N".
render::RenderOptions replay_picture_options(const TerrainReplayer& replayer);

/// How to replay.
struct ReplayOptions {
  std::optional<std::uint64_t> to_step;  ///< stop after this many steps (steps 0..N-1); empty = the whole log
  std::uint64_t frames_every = 0;        ///< a frame every K steps and the last one; 0 = no frames
  std::string frames_dir;                ///< where the frames go; empty = "<dir>/replay"
  std::string search_path;               ///< the PATH in which to look for ffmpeg; empty = no timelapse
};

/// What a replay did.
struct ReplayReport {
  std::string log_path;
  std::string scenario;
  std::string run_id;
  std::uint64_t steps = 0;                ///< steps applied
  std::uint32_t slots = 0;                ///< agent slots of the run (header.agents)
  std::uint32_t admitted = 0;             ///< agents admitted at least once
  std::uint32_t dropped = 0;              ///< agents dropped at the end of the replay
  std::uint64_t requests = 0;             ///< requests of the applied steps
  std::uint64_t accepted = 0;             ///< of which accepted
  std::uint32_t resumptions = 0;          ///< Resumed records met
  double deposited_volume_m3 = 0.0;       ///< [m^3]
  std::optional<std::string> end_reason;  ///< the RunEnd's, when the replay reached it
  std::string tail_problem;               ///< the damaged tail left unapplied; empty when none was met
  double replay_seconds = 0.0;            ///< wall time reading and applying records (frames excluded) [s]
  double frame_seconds = 0.0;             ///< wall time drawing and writing frames [s]
  double timelapse_seconds = 0.0;         ///< wall time of ffmpeg [s]
  std::uint64_t frames = 0;               ///< frames written
  std::string frames_dir;                 ///< where (empty without frames)
  std::string timelapse;                  ///< the MP4's path when written; empty otherwise
  std::string timelapse_note;             ///< why no MP4 was made, when frames were written without one
  Heightmap terrain;                      ///< the replayed terrain [m]
  std::string terrain_sha256;             ///< its SHA-256
};

/// Replays `<dir>/run.log` on `<dir>/terrain_initial.asc`, writing frames when asked (each to "<name>.tmp", then
/// renamed; a frames folder that already holds frame_*.png or timelapse.mp4 is refused before anything is read).
/// Throws Error (IoError, ParseError, InvalidArgument) saying what and where; a --to-step beyond the log's steps
/// says how many it holds. A damaged tail is not an error: it ends up in tail_problem.
ReplayReport replay_run(const std::string& dir, const ReplayOptions& options);

/// The summary replay prints on stdout; its last line is "terrain_sha256 <64 hex>".
std::string format_replay_report(const ReplayReport& report);

}  // namespace marsala::monitor
