#include "world_server/run_outputs.hpp"

#include <google/protobuf/util/json_util.h>

#include <cstdio>
#include <filesystem>

#include "common/error.hpp"
#include "common/render/png_writer.hpp"
#include "common/render/terrain_renderer.hpp"
#include "common/terrain/asc_io.hpp"
#include "idl/run_summary.pb.h"
#include "world_server/sha256.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;

void make_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError("cannot create output folder '" + dir + "': " + ec.message());
}

std::string path_in(const std::string& dir, const char* name) { return (fs::path(dir) / name).string(); }

}  // namespace

std::string summary_json(const WorldState& state, const RunInfo& info) {
  proto::RunSummary s;
  s.set_scenario(info.scenario);
  s.set_scenario_file(info.scenario_file);
  s.set_run_id(info.run_id);
  s.set_seed(info.seed);
  s.set_dds(info.dds);
  s.set_completed(info.completed);
  s.set_end_reason(info.end_reason);
  s.set_steps(static_cast<std::uint32_t>(state.step));
  s.set_wall_seconds(info.wall_seconds);
  s.set_step_wall_median_ms(info.step_wall_median_ms);
  s.set_step_wall_p90_ms(info.step_wall_p90_ms);
  s.set_deposited_volume_m3(state.deposited_volume_m3);
  s.set_agents(static_cast<std::uint32_t>(state.agents.size()));
  std::uint32_t admitted = 0, missed = 0, rejected = 0;
  for (const AgentRecord& a : state.agents) {
    admitted += a.admitted ? 1 : 0;
    missed += a.missed;
    rejected += a.rejected;
    proto::AgentSummary* p = s.add_per_agent();
    p->set_agent_id(a.id);
    p->set_name(a.name);
    p->set_robot_type(a.robot_type);
    p->set_admitted(a.admitted);
    p->set_accepted(a.accepted);
    p->set_rejected(a.rejected);
    p->set_missed(a.missed);
    p->set_deposited_m3(a.deposited_m3);
    p->set_at_goal(a.at_goal);
    p->set_dropped(a.dropped);
    p->set_drop_reason(a.drop_reason);
    p->set_x_m(a.x_m);
    p->set_y_m(a.y_m);
    p->set_z_m(a.z_m);
    p->set_material_m3(a.material_m3);
  }
  s.set_admitted(admitted);
  s.set_missed_deadlines(missed);
  s.set_rejected_requests(rejected);
  s.set_terrain_sha256(terrain_sha256(state.terrain));
  s.set_rows(state.terrain.rows());
  s.set_cols(state.terrain.cols());
  s.set_cell_size_m(state.terrain.cell_size_m());

  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(s, &json, options);
  if (!status.ok()) throw IoError("cannot print the run summary as JSON: " + status.ToString());
  return json;
}

void write_initial_outputs(const std::string& dir, const grid::Heightmap& terrain) {
  make_dir(dir);
  terrain::write_asc(terrain, path_in(dir, "terrain_initial.asc"));
}

void write_final_outputs(const std::string& dir, const WorldState& state, const RunInfo& info) {
  make_dir(dir);
  terrain::write_asc(state.terrain, path_in(dir, "terrain_final.asc"));

  render::RenderOptions options;
  for (const AgentRecord& a : state.agents)
    if (a.admitted)
      if (const auto cell = state.terrain.cell_at({a.x_m, a.y_m})) options.markers.push_back(*cell);
  const Position goal_centre{0.5 * (state.goal.x0_m + state.goal.x1_m), 0.5 * (state.goal.y0_m + state.goal.y1_m)};
  if (const auto cell = state.terrain.cell_at(goal_centre)) options.markers.push_back(*cell);
  options.title = info.scenario + ": step " + std::to_string(state.step) + (info.completed ? ", completed" : "");
  render::write_png(render::render_terrain(state.terrain, options), path_in(dir, "final.png"));

  const std::string path = path_in(dir, "summary.json");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << summary_json(state, info);
  out.close();
  if (!out) throw IoError("cannot write '" + path + "'");
}

std::string format_event(const bus::WorldEvent& e) {
  std::string line = "step " + std::to_string(e.step) + " agent " + std::to_string(e.agent_id) + " " +
                     bus::to_string(e.kind);
  if (e.kind == bus::EventKind::kDeposited) {
    char buf[40];
    std::snprintf(buf, sizeof buf, " %.9g m3", e.volume_m3);
    line += buf;
  }
  if (!e.detail.empty()) line += ": " + e.detail;
  return line;
}

EventLog::EventLog(const std::string& path) : path_(path) {
  make_dir(fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path().string());
  out_.open(path, std::ios::trunc);
  if (!out_) throw IoError("cannot write '" + path + "'");
}

void EventLog::append(const bus::WorldEvent& event) { out_ << format_event(event) << std::endl; }

void EventLog::note(std::uint64_t step, const std::string& text) {
  out_ << "step " << step << " note: " << text << std::endl;
}

}  // namespace marsala::world_server
