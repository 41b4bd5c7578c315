#include "marsala/monitor/replay.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/render/timelapse.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::monitor {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// Agreement of the log's deposited volume with the replay's: the world sums the same terms in the same order, so
/// they agree bit for bit unless the log lies; the tolerance only forgives a writer that rounds differently.
constexpr double kVolumeRelativeTolerance = 1e-9;
constexpr double kVolumeAbsoluteToleranceM3 = 1e-12;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// A record's kind as messages name it.
const char* record_kind(const proto::LogRecord& record) {
  switch (record.record_case()) {
    case proto::LogRecord::kHeader: return "header";
    case proto::LogRecord::kAdmitted: return "admission";
    case proto::LogRecord::kDropped: return "drop";
    case proto::LogRecord::kStep: return "step";
    case proto::LogRecord::kEnd: return "run end";
    case proto::LogRecord::kResumed: return "resumption";
    case proto::LogRecord::RECORD_NOT_SET: break;
  }
  return "empty";
}

}  // namespace

void check_initial_terrain(const proto::LogHeader& header, const Heightmap& terrain, const std::string& terrain_name) {
  if (terrain.rows() != header.rows() || terrain.cols() != header.cols() ||
      terrain.cell_size_m() != header.cell_size_m())
    throw ParseError(terrain_name, 0,
                     fmt::format("{} x {} cells of {} m, but the run log's header says {} x {} cells of {} m: not "
                                 "this run's initial terrain",
                                 terrain.rows(), terrain.cols(), terrain.cell_size_m(), header.rows(), header.cols(),
                                 header.cell_size_m()));
  const std::string sha = runlog::terrain_sha256(terrain);
  if (sha != header.initial_terrain_sha256())
    throw ParseError(terrain_name, 0,
                     fmt::format("SHA-256 {}, but the run log's header says {}: not this run's initial terrain", sha,
                                 header.initial_terrain_sha256()));
}

TerrainReplayer::TerrainReplayer(const proto::LogHeader& header, Heightmap initial_terrain, std::string log_name)
    : header_(header),
      terrain_(std::move(initial_terrain)),
      depositor_(render::CellLabels::Zero(terrain_.rows(), terrain_.cols())),
      log_name_(std::move(log_name)) {}

ReplayedAgent& TerrainReplayer::agent(std::uint32_t id) {
  ReplayedAgent& a = agents_[id];
  a.id = id;
  return a;
}

void TerrainReplayer::admit(const proto::AgentAdmitted& admitted) {
  ReplayedAgent& a = agent(admitted.agent_id());
  a.name = admitted.name();
  a.admitted = true;
  a.dropped = false;
  const auto start = starts_.find(admitted.agent_id());
  if (start == starts_.end()) return;
  // The world (re-)admits an agent at its start, facing its target, full (docs/runtime.md#heading, #admission).
  a.material_m3 = start->second.capacity_m3;
  if (!start->second.start) return;
  a.position = start->second.start;
  const double dx = start->second.target.x - a.position->x;
  const double dy = start->second.target.y - a.position->y;
  a.heading_rad = dx == 0.0 && dy == 0.0 ? 0.0 : std::atan2(dy, dx);
}

void TerrainReplayer::apply(const proto::LogRecord& record, std::uint64_t offset) {
  const std::string where = fmt::format("{} record at byte {}", record_kind(record), offset);
  if (run_end_)
    throw ParseError(log_name_, 0,
                     fmt::format("{}: a record after the run's end (RunEnd after {} steps)", where, run_end_->steps()));
  switch (record.record_case()) {
    case proto::LogRecord::kHeader: throw ParseError(log_name_, 0, fmt::format("{}: a second header", where));
    case proto::LogRecord::kAdmitted: admit(record.admitted()); return;
    case proto::LogRecord::kDropped: agent(record.dropped().agent_id()).dropped = true; return;
    case proto::LogRecord::kResumed: ++resumptions_; return;
    case proto::LogRecord::kStep: apply_step(record.step(), where); return;
    case proto::LogRecord::kEnd: {
      const proto::RunEnd& end = record.end();
      if (end.steps() != steps_)
        throw ParseError(log_name_, 0,
                         fmt::format("{}: the log says {} steps, the replay applied {}", where, end.steps(), steps_));
      const std::string sha = runlog::terrain_sha256(terrain_);
      if (end.terrain_sha256() != sha)
        throw ParseError(log_name_, 0,
                         fmt::format("{}: the log's final terrain sha256 {} differs from the replayed terrain's {}",
                                     where, end.terrain_sha256(), sha));
      run_end_ = end;
      return;
    }
    case proto::LogRecord::RECORD_NOT_SET: break;
  }
  throw ParseError(log_name_, 0, fmt::format("{}: an empty record", where));
}

void TerrainReplayer::apply_step(const proto::StepRecord& step, const std::string& where) {
  if (step.step() != steps_)
    throw ParseError(log_name_, 0,
                     fmt::format("{}: step {} where step {} was due ({})", where, step.step(), steps_,
                                 step.step() > steps_ ? "a gap" : "a repeat"));
  const double cs = terrain_.cell_size_m();
  for (const proto::LoggedRequest& r : step.requests()) {
    ++requests_;
    if (!r.accepted()) {
      if (r.channel_id() != 0) {
        ReplayedAgent& sender = agent(r.channel_id());
        ++sender.rejected;
        sender.state = r.state();
      }
      continue;
    }
    ++accepted_requests_;
    // What apply_request() does for an accepted request (docs/runtime.md#applying-requests), minus what no picture
    // needs (material, heights under the agents).
    ReplayedAgent& me = agent(r.agent_id());
    ++me.accepted;
    me.state = r.state();
    if (r.move()) {
      const Position to{r.target_x_m(), r.target_y_m()};
      if (me.position && (to.x != me.position->x || to.y != me.position->y))
        me.heading_rad = std::atan2(to.y - me.position->y, to.x - me.position->x);
      me.position = to;
    }
    double volume_m3 = 0.0;
    // A layer depositor's depositions say their cells; a cube or cone depositor's deposits were shaped by the world,
    // which logged the cells it raised.
    for (const proto::LoggedDeposition& d : r.depositions_size() > 0 ? r.depositions() : r.raised()) {
      if (!terrain_.contains({d.row(), d.col()}) || !std::isfinite(d.height_m()))
        throw ParseError(log_name_, 0,
                         fmt::format("{}: step {}: agent {} deposited {} m on cell {}, off the {} x {} grid or not a "
                                     "height, yet the world accepted it",
                                     where, step.step(), r.agent_id(), d.height_m(), CellIndex{d.row(), d.col()},
                                     terrain_.rows(), terrain_.cols()));
      terrain_(d.row(), d.col()) += d.height_m();
      depositor_(d.row(), d.col()) = r.agent_id();
      volume_m3 += d.height_m() * cs * cs;
    }
    me.deposited_m3 += volume_m3;
    deposited_volume_m3_ += volume_m3;
    const auto start = starts_.find(r.agent_id());
    if (start != starts_.end() && !std::isnan(me.material_m3)) {
      me.material_m3 = std::max(0.0, me.material_m3 - volume_m3);
      if (r.refill()) me.material_m3 = start->second.capacity_m3;
    }
  }
  const double logged = step.deposited_volume_m3();
  const double tolerance =
      std::max(kVolumeAbsoluteToleranceM3,
               kVolumeRelativeTolerance * std::max(std::abs(logged), std::abs(deposited_volume_m3_)));
  if (!(std::abs(logged - deposited_volume_m3_) <= tolerance))
    throw ParseError(log_name_, 0,
                     fmt::format("{}: step {}: the log says {} m3 deposited in the run, the replay {} m3: the log and "
                                 "the replay disagree",
                                 where, step.step(), logged, deposited_volume_m3_));
  ++steps_;
}

render::RenderOptions replay_picture_options(const TerrainReplayer& replayer) {
  render::RenderOptions o;
  if (replayer.depositor().size() > 0 && replayer.depositor().maxCoeff() > 0) o.labels = replayer.depositor();
  const std::vector<render::Rgb>& palette = render::default_palette();
  // Every slot gets its legend line from the first frame on, so that the legend (and the picture's size) stays put.
  std::vector<std::string> ids_of_colour(palette.size());
  auto list_id = [&](std::uint32_t id) {
    std::string& ids = ids_of_colour[(id - 1) % ids_of_colour.size()];
    ids += fmt::format("{}{}", ids.empty() ? "" : ", ", id);
  };
  for (std::uint32_t id = 1; id <= replayer.header().agents(); ++id) list_id(id);
  for (const auto& [id, a] : replayer.agents()) {
    if (id == 0) continue;
    if (id > replayer.header().agents()) list_id(id);
    if (a.admitted && a.position)
      o.points.push_back({*a.position, render::label_colour(id), render::PointShape::kDisc, 0.0});
  }
  for (std::size_t k = 0; k < ids_of_colour.size(); ++k)
    if (!ids_of_colour[k].empty())
      o.legend_entries.push_back(
          {fmt::format("{} {}", ids_of_colour[k].find(',') == std::string::npos ? "agent" : "agents", ids_of_colour[k]),
           palette[k], render::LegendSwatch::kDisc});
  o.title = fmt::format("{}: step {}", replayer.header().scenario(), replayer.steps());
  return o;
}

ReplayReport replay_run(const std::string& dir, const ReplayOptions& options) {
  const auto start = Clock::now();
  const std::string log_path = (fs::path(dir) / runlog::kRunLogFile).string();
  const std::string terrain_path = (fs::path(dir) / "terrain_initial.asc").string();
  ReplayReport report;
  report.log_path = log_path;

  std::optional<render::FrameWriter> frames;
  if (options.frames_every > 0) {
    report.frames_dir = options.frames_dir.empty() ? (fs::path(dir) / "replay").string() : options.frames_dir;
    render::check_fresh_frames_dir(report.frames_dir, "a replay");
  }

  runlog::RunLogReader reader(log_path);
  const proto::LogHeader& header = reader.header();
  Heightmap initial = terrain::read_asc(terrain_path);
  check_initial_terrain(header, initial, terrain_path);
  TerrainReplayer replayer(header, std::move(initial), log_path);

  if (options.frames_every > 0) frames.emplace(report.frames_dir, options.frames_every);
  const auto draw = [&replayer] {
    return render::render_terrain(replayer.terrain(), replay_picture_options(replayer));
  };

  proto::LogRecord record;
  for (std::uint64_t at = reader.offset(); reader.next(record); at = reader.offset()) {
    if (record.has_step()) {
      // The state the world had when it awaited this step: drawn before the step, and the place --to-step stops.
      if (options.to_step && replayer.steps() == *options.to_step) break;
      if (frames) frames->maybe_write(replayer.steps(), false, draw);
    }
    replayer.apply(record, at);
  }
  report.tail_problem = reader.tail_problem();
  if (options.to_step && replayer.steps() < *options.to_step)
    throw InvalidArgument(fmt::format("{} holds {} steps{}; --to-step {} is beyond it", log_path, replayer.steps(),
                                      report.tail_problem.empty() ? "" : " before its damaged tail", *options.to_step));
  if (frames) frames->maybe_write(replayer.steps(), true, draw);

  report.scenario = header.scenario();
  report.run_id = header.run_id();
  report.steps = replayer.steps();
  report.slots = header.agents();
  for (const auto& [id, a] : replayer.agents()) {
    report.admitted += a.admitted ? 1 : 0;
    report.dropped += a.dropped ? 1 : 0;
  }
  report.requests = replayer.requests();
  report.accepted = replayer.accepted_requests();
  report.resumptions = replayer.resumptions();
  report.deposited_volume_m3 = replayer.deposited_volume_m3();
  if (replayer.run_end()) report.end_reason = replayer.run_end()->end_reason();
  report.terrain = replayer.terrain();
  report.terrain_sha256 = runlog::terrain_sha256(report.terrain);

  if (frames) {
    report.frames = frames->names().size();
    report.frame_seconds = frames->seconds();
    const render::TimelapseResult video = frames->finish(options.search_path);
    report.timelapse = video.path;
    report.timelapse_note = video.note;
    report.timelapse_seconds = video.seconds;
  }
  report.replay_seconds = seconds_since(start) - report.frame_seconds - report.timelapse_seconds;
  return report;
}

std::string format_replay_report(const ReplayReport& r) {
  std::string text = fmt::format("replay {}: scenario {}, run {}\n", r.log_path, r.scenario, r.run_id);
  text += fmt::format("steps {}, agents {} admitted of {} slots ({} dropped), requests {} ({} accepted){}\n", r.steps,
                      r.admitted, r.slots, r.dropped, r.requests, r.accepted,
                      r.resumptions > 0 ? fmt::format(", resumed {} times", r.resumptions) : std::string());
  text += fmt::format("deposited {:.6f} m3\n", r.deposited_volume_m3);
  text += r.end_reason ? fmt::format("run end: {}, final terrain sha256 matches the log\n", *r.end_reason)
                       : std::string("run end: not reached\n");
  const double speed = r.replay_seconds > 0.0 ? static_cast<double>(r.steps) / r.replay_seconds : 0.0;
  text += fmt::format("wall {:.3f} s, replay speed {:.0f} steps/s (frames excluded)\n",
                      r.replay_seconds + r.frame_seconds + r.timelapse_seconds, speed);
  if (!r.frames_dir.empty()) {
    text += fmt::format("frames: {} in {} ({:.3f} s, {:.1f} ms per frame)\n", r.frames, r.frames_dir, r.frame_seconds,
                        r.frames > 0 ? 1e3 * r.frame_seconds / static_cast<double>(r.frames) : 0.0);
    text += r.timelapse.empty() ? fmt::format("{}\n", r.timelapse_note)
                                : fmt::format("timelapse: {} ({:.3f} s with ffmpeg)\n", r.timelapse, r.timelapse_seconds);
  }
  text += fmt::format("terrain_sha256 {}\n", r.terrain_sha256);
  return text;
}

}  // namespace marsala::monitor
