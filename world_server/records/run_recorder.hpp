#pragma once
// The run recorder: every file a run writes while it runs and at its end, in one place. run.log (every change of the
// state, recorded before its results are published) and snapshot.pb, events.log (JSON Lines), the time-lapse frames
// (--frames-every) and the final outputs (run_outputs.hpp). IO only; what to record is the runtime's.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/render/timelapse.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/records/persistence.hpp"
#include "marsala/world_server/records/run_outputs.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// Where and what a run records.
struct RecorderSetup {
  std::string out_dir;               ///< the run's output folder
  std::string run_id;                ///< named in snapshots
  std::uint64_t snapshot_every = 0;  ///< snapshot.pb after every this many steps; 0 = never
  std::uint64_t frames_every = 0;    ///< a time-lapse frame every this many steps; 0 = none
  /// Set for a resumed run: run.log's length up to its last good record (it continues there; events.log and the
  /// frames folder are continued too).
  std::optional<std::uint64_t> resume_good_bytes;
};

/// The files of one run.
class RunRecorder {
 public:
  /// A recorder for `setup`; nothing is written before open().
  explicit RunRecorder(RecorderSetup setup) : setup_(std::move(setup)) {}

  /// Opens the run's files for `state`, the initial or resumed one: a fresh run writes terrain_initial.asc, creates
  /// events.log and the frames folder (refused when it holds another run's frames) and run.log with its header from
  /// `scenario` and `start`; a resumed one appends to events.log and continues run.log. Keeps the initial terrain
  /// for the final outputs when the scenario has a goal vector map or a payload path. Throws IoError.
  void open(const scenario::Scenario& scenario, const LogStart& start, const WorldState& state);

  /// Appends a record to run.log (IoError ends the run: nothing the world does goes unrecorded).
  void record(const proto::LogRecord& record) { run_log_->append(record); }
  /// fdatasync of run.log.
  void sync() { run_log_->sync(); }
  /// An events.log line for `event` (a deposition with the cells it set).
  void event(const protocol::WorldEvent& event, const std::vector<Deposition>& cells = {});
  /// A note line in events.log.
  void note(std::uint64_t step, const std::string& text);
  /// After a recorded step: snapshot.pb when state.step is a multiple of snapshot_every (run.log synced first, so a
  /// snapshot never points past what a crash of the machine keeps).
  void after_step(const WorldState& state);
  /// The time-lapse frame of state.step when it is due (`last`: the final frame).
  void frame(const WorldState& state, const std::string& scenario_name, bool last);
  /// The final outputs (write_final_outputs(), info.initial_terrain filled in here), the last frame and
  /// timelapse.mp4 (ffmpeg on `search_path`); a time-lapse that cannot be finished is an error of the run.
  void finish(const WorldState& state, RunInfo info, const std::string& search_path);

 private:
  RecorderSetup setup_;
  std::optional<runlog::RunLogWriter> run_log_;
  std::optional<EventLog> event_log_;
  std::optional<render::FrameWriter> frames_;
  std::optional<CellRect> frame_window_;  ///< the frames' close-up; none = the whole terrain
  Heightmap initial_terrain_;             ///< for goal_vector_map.png, payload_path's construction sites, the material score
};

}  // namespace marsala::world_server
