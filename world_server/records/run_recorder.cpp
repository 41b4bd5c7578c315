#include "marsala/world_server/records/run_recorder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <utility>

#include "marsala/render/terrain_renderer.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

std::string file_in(const std::string& dir, const std::string& name) {
  return (std::filesystem::path(dir) / name).string();
}

/// A time-lapse frame: the terrain now, drawn like final_zoom.png (depositors' colours, agents, base, target; no
/// route, which would cost a payload plan per frame) on `window`, or like final.png without one.
render::Image frame_picture(const WorldState& state, const std::string& scenario_name,
                            const std::optional<CellRect>& window, bool last) {
  RunInfo info;
  info.scenario = fmt::format("{}, step {}", scenario_name, state.step);  // the close-up's title names no step
  info.completed = last && is_completed(state);
  if (!window) return render::render_terrain(state.terrain, final_picture_options(state, info, std::nullopt));
  const CellRect& w = *window;
  return render::render_terrain(state.terrain.window(w.first, w.rows, w.cols),
                                final_picture_options(state, info, std::nullopt, w));
}

}  // namespace

void RunRecorder::open(const scenario::Scenario& scenario, const LogStart& start, const WorldState& state) {
  const bool resumed = setup_.resume_good_bytes.has_value();
  const std::string& dir = setup_.out_dir;
  // make_world_state() keeps the terrain as given: the state's terrain is still the initial one, unless resumed.
  // Kept for every kind: the material score (material_score.hpp) needs it at the end.
  initial_terrain_ = resumed ? terrain::read_asc(file_in(dir, "terrain_initial.asc")) : state.terrain;
  if (!resumed) write_initial_outputs(dir, state.terrain);
  event_log_.emplace(file_in(dir, "events.log"), resumed);
  if (setup_.frames_every > 0) {
    // A resumed run goes on adding frames to its folder; a fresh one never mixes its frames with another's.
    const std::string frames_dir = file_in(dir, "frames");
    if (!resumed) render::check_fresh_frames_dir(frames_dir, "another run's time-lapse");
    frames_.emplace(frames_dir, setup_.frames_every);
    // One window for every frame, so that the time-lapse does not jump: the close-up of the base and the payload
    // ends or the site (and what was built before a resume), as final_zoom.png frames them.
    frame_window_ = zoom_window(state, std::nullopt);
  }
  const std::string log_path = file_in(dir, kRunLogFile);
  if (resumed)
    run_log_ = runlog::RunLogWriter::continue_at(log_path, *setup_.resume_good_bytes);
  else
    run_log_ = runlog::RunLogWriter::create(log_path, log_header(scenario, start, state.terrain));
}

void RunRecorder::event(const protocol::WorldEvent& event, const std::vector<Deposition>& cells) {
  if (event_log_) event_log_->append(event, cells);
}

void RunRecorder::note(std::uint64_t step, const std::string& text) {
  if (event_log_) event_log_->note(step, text);
}

void RunRecorder::after_step(const WorldState& state) {
  if (setup_.snapshot_every == 0 || state.step % setup_.snapshot_every != 0) return;
  run_log_->sync();
  write_snapshot(file_in(setup_.out_dir, kSnapshotFile), make_snapshot(state, setup_.run_id, run_log_->bytes()));
}

void RunRecorder::frame(const WorldState& state, const std::string& scenario_name, bool last) {
  if (frames_)
    frames_->maybe_write(state.step, last, [&] { return frame_picture(state, scenario_name, frame_window_, last); });
}

void RunRecorder::finish(const WorldState& state, RunInfo info, const std::string& search_path) {
  const std::string scenario_name = info.scenario;
  info.initial_terrain = std::move(initial_terrain_);
  write_final_outputs(setup_.out_dir, state, info);
  if (!frames_) return;
  frame(state, scenario_name, true);
  const render::TimelapseResult video = frames_->finish(search_path);
  spdlog::info(
      "time-lapse: {} frames in {} ({:.3f} s drawing){}", frames_->names().size(), frames_->dir(), frames_->seconds(),
      video.path.empty() ? fmt::format("; {}", video.note) : fmt::format(", {} ({:.3f} s)", video.path, video.seconds));
}

}  // namespace marsala::world_server
