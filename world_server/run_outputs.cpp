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

constexpr render::Rgb kWhite{255, 255, 255};
constexpr render::Rgb kPathYellow{255, 214, 0};
constexpr render::Rgb kFromRed{228, 26, 28};
constexpr render::Rgb kToGreen{40, 190, 60};
constexpr render::Rgb kArrowRed{220, 30, 30};

/// What the end of a run reports about the terrain, computed once.
struct FinalTerrainReport {
  std::optional<PayloadRoute> route;  ///< payload_path only
  double site_fraction = 0.0;         ///< level_site only
};

FinalTerrainReport final_terrain_report(const WorldState& state) {
  FinalTerrainReport report;
  if (state.completion == scenario::CompletionKind::kPayloadPath)
    report.route = payload_path(state.terrain, state.payload_path);
  if (state.completion == scenario::CompletionKind::kLevelSite)
    report.site_fraction = site_level_fraction(state.terrain, state.site);
  return report;
}

std::string format_number(const char* format, double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string summary_text(const WorldState& state, const RunInfo& info, const FinalTerrainReport& report) {
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
  s.set_completion(scenario::to_string(state.completion));
  s.set_idle_steps(static_cast<std::uint32_t>(state.idle_steps));
  s.set_path_found(report.route.has_value());
  s.set_path_length_m(report.route ? report.route->length_m : 0.0);
  s.set_site_level_fraction(report.site_fraction);
  s.set_completion_checks(state.check.evaluations);
  s.set_start_jitter_m(info.start_jitter_m);

  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(s, &json, options);
  if (!status.ok()) throw IoError("cannot print the run summary as JSON: " + status.ToString());
  return json;
}

}  // namespace

std::string summary_json(const WorldState& state, const RunInfo& info) {
  return summary_text(state, info, final_terrain_report(state));
}

render::RenderOptions final_picture_options(const WorldState& state, const RunInfo& info,
                                            const std::optional<PayloadRoute>& route) {
  render::RenderOptions o;
  const grid::Heightmap& t = state.terrain;
  if (state.depositor.rows() == t.rows() && state.depositor.cols() == t.cols() && state.depositor.maxCoeff() > 0)
    o.labels = state.depositor;
  o.circles.push_back({{state.base.x_m, state.base.y_m}, state.base.radius_m, kWhite, 0.0});
  o.legend_entries.push_back({"base station", kWhite, render::LegendSwatch::kRing});
  std::string outcome = info.completed ? "completed" : "not completed";
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal: {
      const scenario::Goal& g = state.goal;
      o.rectangles.push_back({{g.x0_m, g.y0_m}, {g.x1_m, g.y1_m}, kWhite, 0.0});
      if (const auto cell = t.cell_at({0.5 * (g.x0_m + g.x1_m), 0.5 * (g.y0_m + g.y1_m)})) o.markers.push_back(*cell);
      o.legend_entries.push_back({"goal", kWhite, render::LegendSwatch::kOutline});
      break;
    }
    case scenario::CompletionKind::kPayloadPath: {
      const scenario::PayloadPath& p = state.payload_path;
      if (route) {
        render::Polyline line;
        line.colour = kPathYellow;
        for (const CellIndex& c : route->cells) line.points.push_back(t.cell_center(c));
        if (line.points.size() == 1) line.points.push_back(line.points.front());
        o.polylines.push_back(std::move(line));
        o.legend_entries.push_back(
            {"payload path " + format_number("%.2f m", route->length_m), kPathYellow, render::LegendSwatch::kLine});
        outcome += ", path " + format_number("%.2f m", route->length_m);
      } else {
        outcome += ", no payload path";
      }
      o.points.push_back({{p.from_x_m, p.from_y_m}, kFromRed, render::PointShape::kSquare, 0.0});
      o.points.push_back({{p.to_x_m, p.to_y_m}, kToGreen, render::PointShape::kDiamond, 0.0});
      o.legend_entries.push_back({"payload from", kFromRed, render::LegendSwatch::kSquare});
      o.legend_entries.push_back({"payload to", kToGreen, render::LegendSwatch::kDiamond});
      break;
    }
    case scenario::CompletionKind::kLevelSite: {
      const scenario::Site& site = state.site;
      o.rectangles.push_back({{site.x0_m, site.y0_m}, {site.x1_m, site.y1_m}, kWhite, 0.0});
      o.legend_entries.push_back({"site", kWhite, render::LegendSwatch::kOutline});
      outcome += ", level " + format_number("%.1f%%", 100.0 * state.check.level_fraction);
      break;
    }
  }
  // Agents: discs of their colour; the legend lists each colour once with the ids that share it.
  std::vector<std::string> ids_of_colour(render::default_palette().size());
  for (const AgentRecord& a : state.agents) {
    if (!a.admitted) continue;
    o.points.push_back({{a.x_m, a.y_m}, render::label_colour(a.id), render::PointShape::kDisc, 0.0});
    std::string& ids = ids_of_colour[(a.id - 1) % ids_of_colour.size()];
    ids += (ids.empty() ? "" : ", ") + std::to_string(a.id);
  }
  for (std::size_t k = 0; k < ids_of_colour.size(); ++k)
    if (!ids_of_colour[k].empty())
      o.legend_entries.push_back({(ids_of_colour[k].find(',') == std::string::npos ? "agent " : "agents ") +
                                      ids_of_colour[k],
                                  render::default_palette()[k], render::LegendSwatch::kDisc});
  o.title = info.scenario + ": step " + std::to_string(state.step) + ", " + scenario::to_string(state.completion) +
            " " + outcome;
  return o;
}

render::RenderOptions goal_vector_map_picture_options(const WorldState& state, const RunInfo& info,
                                                      const processing::GoalVectorMap& map) {
  render::RenderOptions o;
  const processing::GoalVectorMapSpec& spec = map.spec();
  o.rectangles.push_back({{spec.x0_m, spec.y0_m}, {spec.x1_m, spec.y1_m}, kWhite, 0.0});
  if (state.completion == scenario::CompletionKind::kLevelSite)
    o.rectangles.push_back({{state.site.x0_m, state.site.y0_m}, {state.site.x1_m, state.site.y1_m}, kWhite, 0.0});
  for (const processing::GoalArrow& a : map.arrows()) o.arrows.push_back({a.tail, a.head, kArrowRed, 0.0});
  o.legend_entries.push_back({"tail -> head", kArrowRed, render::LegendSwatch::kArrow});
  o.legend_entries.push_back({"site", kWhite, render::LegendSwatch::kOutline});
  o.title = info.scenario + ": goal vector map, " + std::to_string(map.arrows().size()) + " arrows in " +
            std::to_string(map.strips()) + " strips, heading " + processing::to_string(spec.heading);
  return o;
}

void write_initial_outputs(const std::string& dir, const grid::Heightmap& terrain) {
  make_dir(dir);
  terrain::write_asc(terrain, path_in(dir, "terrain_initial.asc"));
}

void write_final_outputs(const std::string& dir, const WorldState& state, const RunInfo& info) {
  make_dir(dir);
  terrain::write_asc(state.terrain, path_in(dir, "terrain_final.asc"));

  const FinalTerrainReport report = final_terrain_report(state);
  render::write_png(render::render_terrain(state.terrain, final_picture_options(state, info, report.route)),
                    path_in(dir, "final.png"));

  const std::string path = path_in(dir, "summary.json");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << summary_text(state, info, report);
  out.close();
  if (!out) throw IoError("cannot write '" + path + "'");

  if (info.goal_vector_map) {
    const grid::Heightmap& initial = info.initial_terrain.size() > 0 ? info.initial_terrain : state.terrain;
    const processing::GoalVectorMap map(*info.goal_vector_map, initial.geometry());
    render::write_png(render::render_terrain(initial, goal_vector_map_picture_options(state, info, map)),
                      path_in(dir, "goal_vector_map.png"));
  }
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
