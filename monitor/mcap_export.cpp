#include "marsala/monitor/mcap_export.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/monitor/foxglove_json.hpp"
#include "marsala/monitor/mcap_writer.hpp"
#include "marsala/monitor/replay.hpp"
#include "marsala/runlog/atomic_file.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::monitor {
namespace {

namespace fs = std::filesystem;

/// One line of events.log, as the export logs it.
struct ExportedEvent {
  std::uint64_t step = 0;
  LogLevel level = LogLevel::kInfo;
  std::string name;  ///< "agent-<id>" or "world"
  std::string text;
};

/// Kinds that say something went wrong for an agent or the run.
LogLevel level_of(const std::string& kind) {
  if (kind == "dropped" || kind == "stalled") return LogLevel::kError;
  if (kind == "rejected" || kind == "missed") return LogLevel::kWarning;
  return LogLevel::kInfo;
}

/// events.log (JSON Lines, docs/runtime.md#outputs); none when the folder has no such file.
std::vector<ExportedEvent> read_events(const std::string& path) {
  std::vector<ExportedEvent> events;
  std::ifstream in(path);
  if (!in) return events;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const nlohmann::json e = nlohmann::json::parse(line, nullptr, false);
    if (!e.is_object() || !e.contains("step") || !e["step"].is_number_unsigned() || !e.contains("kind") ||
        !e["kind"].is_string())
      throw ParseError(path, number, "not an event: a JSON object with a step and a kind was expected");
    ExportedEvent out;
    out.step = e["step"].get<std::uint64_t>();
    const std::string kind = e["kind"].get<std::string>();
    out.level = level_of(kind);
    const std::uint32_t agent = e.contains("agent") && e["agent"].is_number_unsigned() ? e["agent"].get<std::uint32_t>() : 0;
    out.name = agent > 0 ? fmt::format("agent-{}", agent) : std::string("world");
    out.text = kind;
    if (e.contains("volume_m3") && e["volume_m3"].is_number())
      out.text += fmt::format(" {:.6f} m3", e["volume_m3"].get<double>());
    if (e.contains("detail") && e["detail"].is_string() && !e["detail"].get<std::string>().empty())
      out.text += fmt::format(": {}", e["detail"].get<std::string>());
    events.push_back(std::move(out));
  }
  return events;
}

/// The bad inputs found before anything is read or written.
void check_inputs(const std::string& dir, const std::string& file, const McapExportOptions& options) {
  if (!fs::is_directory(dir)) throw InvalidArgument(fmt::format("{}: no such run folder", dir));
  for (const char* name : {runlog::kRunLogFile, "terrain_initial.asc"})
    if (!fs::exists(fs::path(dir) / name)) throw InvalidArgument(fmt::format("{}: holds no {}", dir, name));
  if (fs::exists(file) || fs::is_symlink(file))
    throw InvalidArgument(fmt::format("--mcap {}: exists; choose a new name (an export never overwrites)", file));
  if (options.terrain_every == 0) throw InvalidArgument("--every must be at least 1 step");
  if (options.step_ns == 0) throw InvalidArgument("--step-ms must be more than 0 ms");
}

/// The scenario the log's header carries, with the run's overrides.
scenario::Scenario scenario_of(const proto::LogHeader& header) {
  const std::vector<std::string> overrides(header.overrides().begin(), header.overrides().end());
  return scenario::parse_scenario(header.scenario_text(), header.scenario_file(), overrides);
}

/// Starts, targets and capacities of the run's slots.
void give_starts(TerrainReplayer& replayer, const scenario::Scenario& s) {
  for (const scenario::AgentSlot& slot : s.slots) {
    SlotStart start;
    if (s.start_jitter_m == 0.0) start.start = slot.start;
    start.target = slot.target;
    start.capacity_m3 = s.robot_for(slot.id).body.material_capacity_m3;
    replayer.set_start(slot.id, start);
  }
}

/// Body diameters (delta) of the slots [m]; 1 m for a slot the scenario does not give.
std::vector<double> body_diameters(const scenario::Scenario& s) {
  std::vector<double> d;
  for (const scenario::AgentSlot& slot : s.slots) d.push_back(s.robot_for(slot.id).body.navigability.delta_m);
  return d;
}

/// Every admitted robot with a known position, on the replay's current terrain.
std::vector<RobotPose> robots_of(const TerrainReplayer& replayer, const std::vector<double>& diameters) {
  std::vector<RobotPose> robots;
  for (const auto& [id, a] : replayer.agents()) {
    if (!a.admitted || !a.position) continue;
    RobotPose r;
    r.id = id;
    r.name = a.name;
    r.position = *a.position;
    const std::optional<CellIndex> cell = replayer.terrain().cell_at(*a.position);
    r.z_m = cell ? replayer.terrain()(*cell) : std::numeric_limits<double>::quiet_NaN();
    r.heading_rad = std::isnan(a.heading_rad) ? 0.0 : a.heading_rad;
    r.body_diameter_m = id >= 1 && id <= diameters.size() ? diameters[id - 1] : 1.0;
    r.state = a.state;
    r.material_m3 = a.material_m3;
    r.deposited_m3 = a.deposited_m3;
    r.dropped = a.dropped;
    robots.push_back(std::move(r));
  }
  return robots;
}

/// The export's channels on one writer, and what went on each.
class ExportChannels {
 public:
  explicit ExportChannels(McapWriter& w) : w_(w) {
    const auto channel = [&w](const JsonSchema& s, const char* topic) {
      return w.add_channel(w.add_schema(s.name, "jsonschema", s.text), topic, "json");
    };
    terrain_ = channel(grid_schema(), "/terrain");
    robots_ = channel(scene_update_schema(), "/robots");
    events_ = channel(log_schema(), "/events");
  }
  void terrain(const Heightmap& t, std::uint64_t time_ns) { w_.write_message(terrain_, time_ns, grid_message(t, time_ns)); }
  void robots(const std::vector<RobotPose>& r, std::uint64_t time_ns) {
    w_.write_message(robots_, time_ns, scene_update_message(r, time_ns));
  }
  void event(const ExportedEvent& e, std::uint64_t time_ns) {
    w_.write_message(events_, time_ns, log_message(time_ns, e.level, e.name, e.text));
  }
  std::uint64_t count(bool terrain, bool robots) const {
    return w_.statistics().per_channel.at(terrain ? terrain_ : robots ? robots_ : events_);
  }

 private:
  McapWriter& w_;
  std::uint16_t terrain_ = 0;
  std::uint16_t robots_ = 0;
  std::uint16_t events_ = 0;
};

/// Replays the log into `out` (an open file): the pass that writes every message.
void write_run(std::ostream& out, const std::string& dir, const McapExportOptions& options, McapExportReport& report) {
  const std::string log_path = (fs::path(dir) / runlog::kRunLogFile).string();
  const std::string terrain_path = (fs::path(dir) / "terrain_initial.asc").string();
  runlog::RunLogReader reader(log_path);
  Heightmap initial = terrain::read_asc(terrain_path);
  check_initial_terrain(reader.header(), initial, terrain_path);
  TerrainReplayer replayer(reader.header(), std::move(initial), log_path);
  const scenario::Scenario scenario = scenario_of(reader.header());
  give_starts(replayer, scenario);
  const std::vector<double> diameters = body_diameters(scenario);
  const std::vector<ExportedEvent> events = read_events((fs::path(dir) / "events.log").string());

  McapWriter writer(out, "marsala-monitor export");
  ExportChannels channels(writer);
  std::size_t next_event = 0;
  // Events of step s at (s + 1) x step: with that step's outcome. Sorted by step, as events.log is.
  const auto events_until = [&](std::uint64_t time_ns) {
    for (; next_event < events.size() && (events[next_event].step + 1) * options.step_ns <= time_ns; ++next_event)
      channels.event(events[next_event], (events[next_event].step + 1) * options.step_ns);
  };
  proto::LogRecord record;
  bool started = false;
  std::uint64_t last_terrain_step = 0;
  for (std::uint64_t at = reader.offset(); reader.next(record); at = reader.offset()) {
    if (record.has_step() && !started) {  // the start: after the admissions, before the first step
      channels.terrain(replayer.terrain(), 0);
      channels.robots(robots_of(replayer, diameters), 0);
      started = true;
    }
    replayer.apply(record, at);
    if (!record.has_step()) continue;
    const std::uint64_t steps = replayer.steps();
    const std::uint64_t time_ns = steps * options.step_ns;
    channels.robots(robots_of(replayer, diameters), time_ns);
    if (steps % options.terrain_every == 0) {
      channels.terrain(replayer.terrain(), time_ns);
      last_terrain_step = steps;
    }
    events_until(time_ns);
  }
  if (!reader.tail_problem().empty())
    throw ParseError(log_path, 0, fmt::format("{}: a damaged log is not exported", reader.tail_problem()));
  const std::uint64_t end_ns = replayer.steps() * options.step_ns;
  if (!started) {
    channels.terrain(replayer.terrain(), 0);
    channels.robots(robots_of(replayer, diameters), 0);
  } else if (last_terrain_step != replayer.steps()) {
    channels.terrain(replayer.terrain(), end_ns);
  }
  for (; next_event < events.size(); ++next_event)  // the run's end and what followed it
    channels.event(events[next_event], std::min((events[next_event].step + 1) * options.step_ns, end_ns));
  writer.finish();
  report.steps = replayer.steps();
  report.terrains = channels.count(true, false);
  report.robot_updates = channels.count(false, true);
  report.events = channels.count(false, false);
  report.bytes = writer.bytes();
}

}  // namespace

McapExportReport export_mcap(const std::string& dir, const std::string& file, const McapExportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_inputs(dir, file, options);
  McapExportReport report;
  report.path = file;
  runlog::write_atomically(file, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(fmt::format("cannot create '{}'", tmp));
    write_run(out, dir, options, report);
    out.close();
    if (!out) throw IoError(fmt::format("cannot write '{}' (disk full?)", tmp));
  });
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

std::string format_export_report(const McapExportReport& r) {
  return fmt::format("exported {} steps to {}: {} terrains, {} robot updates, {} events, {} bytes, {:.2f} s\n", r.steps,
                     r.path, r.terrains, r.robot_updates, r.events, r.bytes, r.seconds);
}

}  // namespace marsala::monitor
