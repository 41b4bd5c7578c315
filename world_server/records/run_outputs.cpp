#include "marsala/world_server/records/run_outputs.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <google/protobuf/util/json_util.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cerrno>
#include <cstring>
#include <limits>

#include "idl/run_summary.pb.h"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/render/perspective.hpp"
#include "marsala/render/png_writer.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/runlog/atomic_file.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/world_server/rules/arbiter.hpp"
#include "marsala/world_server/rules/construction_band.hpp"
#include "marsala/world_server/rules/material_score.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using runlog::write_atomically;

void make_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("cannot create output folder '{}': {}", dir, ec.message()));
}

std::string path_in(const std::string& dir, const char* name) { return (fs::path(dir) / name).string(); }

constexpr render::Rgb kWhite{255, 255, 255};
constexpr render::Rgb kPathYellow{255, 214, 0};
constexpr render::Rgb kFromRed{228, 26, 28};
constexpr render::Rgb kToGreen{40, 190, 60};
constexpr render::Rgb kArrowRed{220, 30, 30};

/// What the end of a run reports about the terrain, computed once.
struct FinalTerrainReport {
  std::optional<PayloadRoute> route;       ///< payload_path only
  std::vector<ConstructionSite> sites;     ///< payload_path with a route and the initial terrain known
  double site_fraction = 0.0;              ///< level_site only
  double band_width_m = 0.0;               ///< payload_path with the initial terrain known: the construction band
  double outside_band_m3 = 0.0;            ///< and the volume raised outside it (construction_band.hpp)
  std::optional<MaterialScore> material;   ///< with the initial terrain known (material_score.hpp)
};

FinalTerrainReport final_terrain_report(const WorldState& state, const RunInfo& info) {
  FinalTerrainReport report;
  if (state.completion == scenario::CompletionKind::kPayloadPath)
    report.route = payload_path(state.terrain, state.payload_path);
  if (report.route && info.initial_terrain.rows() == state.terrain.rows() &&
      info.initial_terrain.cols() == state.terrain.cols())
    report.sites = construction_sites(info.initial_terrain, state.terrain, *report.route,
                                      state.payload_path.navigability.delta_m);
  if (state.completion == scenario::CompletionKind::kPayloadPath && info.initial_terrain.rows() == state.terrain.rows() &&
      info.initial_terrain.cols() == state.terrain.cols()) {
    const BandReport band = band_report(state, info.initial_terrain, report.route);
    report.band_width_m = band.width_m;
    report.outside_band_m3 = band.outside_m3;
  }
  if (state.completion == scenario::CompletionKind::kLevelSite)
    report.site_fraction = site_level_fraction(state.terrain, state.site);
  if (info.initial_terrain.geometry() == state.terrain.geometry())
    report.material = material_score(state, info.initial_terrain, report.outside_band_m3);
  return report;
}

// The zoom window's framing (run_outputs.hpp, zoom_window()).
constexpr double kZoomMinMarginM = 3.0;
constexpr double kZoomMarginFraction = 0.15;
constexpr double kZoomMinSideM = 10.0;
constexpr double kZoomMaxAreaFraction = 0.5;
// Box edges that fall on cell edges up to rounding stay there instead of taking in one more cell.
constexpr double kCellEdgeTolerance = 1e-9;

/// An axis-aligned box in the world frame [m]; empty until something is added.
struct WorldBox {
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0;
  double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;

  bool empty() const { return !(x0 <= x1 && y0 <= y1); }
  void add(double xa, double ya, double xb, double yb) {
    x0 = std::min({x0, xa, xb});
    x1 = std::max({x1, xa, xb});
    y0 = std::min({y0, ya, yb});
    y1 = std::max({y1, ya, yb});
  }
  void add(const GridGeometry& g, CellIndex c) {
    const Position p = g.cell_center(c);
    const double half = 0.5 * g.cell_size_m;
    add(p.x - half, p.y - half, p.x + half, p.y + half);
  }
};

/// The stall account of summary.json: the quiet stretch and every live robot as it stood.
void fill_stall_account(const WorldState& state, proto::StallAccount& account) {
  account.set_stall_steps(static_cast<std::uint32_t>(state.stall_steps));
  account.set_quiet_since_step(static_cast<std::uint32_t>(state.stall.quiet_since));
  account.set_best_progress(state.stall.best_progress);
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    proto::StalledAgent* p = account.add_agents();
    p->set_agent_id(a.id);
    p->set_state(a.state);
    p->set_material_m3(a.material_m3);
    p->set_x_m(a.position.x);
    p->set_y_m(a.position.y);
    p->set_z_m(a.z_m);
    p->set_waiting_for(a.waiting_for);
  }
}

/// summary.json's `fork`: where a fork came from, its own --set, the slots that left at K and the late ones that
/// joined then (docs/runtime.md#fork).
proto::ForkOrigin fork_summary(const ForkOrigin& fork, const WorldState& state) {
  proto::ForkOrigin f;
  f.set_parent(fork.parent_dir);
  f.set_parent_run_id(fork.parent_run_id);
  f.set_at_step(fork.at_step);
  f.set_parent_sha256_at_step(fork.parent_sha256_at_step);
  f.set_parent_agents(fork.parent_agents);
  f.set_agents(fork.agents);
  for (const std::string& o : fork.overrides) f.add_overrides(o);
  for (std::uint32_t id = fork.agents + 1; id <= fork.parent_agents; ++id) f.add_left_agents(id);
  for (std::uint32_t id = fork.parent_agents + 1; id <= fork.agents; ++id)
    if (state.has_agent(id) && state.agent(id).admitted) f.add_joined_agents(id);
  return f;
}

/// "140.25" (no trailing zeros, no rounding noise of the cell arithmetic).
std::string summary_text(const WorldState& state, const RunInfo& info, const FinalTerrainReport& report) {
  proto::RunSummary s;
  s.set_scenario(info.scenario);
  s.set_scenario_file(info.scenario_file);
  for (const std::string& o : info.overrides) s.add_overrides(o);
  if (info.fork) *s.mutable_fork() = fork_summary(*info.fork, state);
  s.set_run_id(info.run_id);
  s.set_seed(info.seed);
  s.set_dds(info.dds);
  s.set_completed(info.completed);
  s.set_end_reason(to_string(info.end_reason));
  s.set_steps(static_cast<std::uint32_t>(state.step));
  s.set_wall_seconds(info.wall_seconds);
  s.set_step_wall_median_ms(info.step_wall_median_ms);
  s.set_step_wall_p90_ms(info.step_wall_p90_ms);
  s.set_step_world_median_ms(info.step_world_median_ms);
  s.set_step_world_p90_ms(info.step_world_p90_ms);
  s.set_world_cpu_ms_per_step(info.world_cpu_ms_per_step);
  s.set_admit_seconds(info.admit_seconds);
  s.set_connected(info.connected);
  s.set_deposited_volume_m3(state.deposited_volume_m3);
  s.set_agents(static_cast<std::uint32_t>(state.agents.size()));
  std::uint32_t admitted = 0, dropped = 0, missed = 0, rejected = 0;
  for (const AgentRecord& a : state.agents) {
    admitted += a.admitted ? 1 : 0;
    dropped += a.dropped ? 1 : 0;
    missed += a.missed;
    rejected += a.rejected;
    proto::AgentSummary* p = s.add_per_agent();
    p->set_agent_id(a.id);
    p->set_name(a.name);
    p->set_robot_type(a.type.name);
    p->set_admitted(a.admitted);
    p->set_accepted(a.accepted);
    p->set_rejected(a.rejected);
    p->set_missed(a.missed);
    p->set_deposited_m3(a.deposited_m3);
    p->set_at_goal(a.at_goal);
    p->set_dropped(a.dropped);
    p->set_drop_reason(a.drop_reason);
    p->set_x_m(a.position.x);
    p->set_y_m(a.position.y);
    p->set_z_m(a.z_m);
    p->set_material_m3(a.material_m3);
    p->set_state(a.state);
    p->set_waiting_for(a.waiting_for);
  }
  s.set_admitted(admitted);
  s.set_dropped(dropped);
  const std::vector<std::uint32_t> missing = missing_slots(state, info.fork ? &*info.fork : nullptr);
  s.set_slots_missing(static_cast<std::uint32_t>(missing.size()));
  for (std::uint32_t id : missing) s.add_missing_agents(id);
  s.set_missed_deadlines(missed);
  s.set_rejected_requests(rejected);
  s.set_terrain_sha256(runlog::terrain_sha256(state.terrain));
  s.set_rows(state.terrain.rows());
  s.set_cols(state.terrain.cols());
  s.set_cell_size_m(state.terrain.cell_size_m());
  s.set_completion(scenario::to_string(state.completion));
  s.set_idle_steps(static_cast<std::uint32_t>(state.idle_steps));
  s.set_unattributed_rejections(state.unattributed_rejections);
  s.set_surplus_requests(state.surplus_requests);
  s.set_resumes(state.resumes);
  s.set_close_passes(state.close_passes);
  s.set_overlap_pair_steps(state.overlap_pair_steps);
  s.set_rejected_motions(state.rejected_motions);
  s.set_stall_steps(static_cast<std::uint32_t>(state.stall_steps));
  s.set_longest_quiet_steps(static_cast<std::uint32_t>(state.stall.longest_quiet));
  if (info.end_reason == protocol::EndReason::kStalled) fill_stall_account(state, *s.mutable_stall());
  std::uint32_t readmissions = 0;
  for (const AgentRecord& a : state.agents) readmissions += a.readmissions;
  s.set_readmissions(readmissions);
  s.set_path_found(report.route.has_value());
  s.set_path_length_m(report.route ? report.route->length_m : 0.0);
  s.set_site_level_fraction(report.site_fraction);
  s.set_construction_band_width_m(report.band_width_m);
  s.set_deposited_outside_band_m3(report.outside_band_m3);
  if (report.material) {
    proto::MaterialScore* m = s.mutable_material();
    m->set_deposited_m3(report.material->deposited_m3);
    m->set_needed_m3(report.material->needed_m3);
    m->set_ratio(report.material->ratio);
    m->set_off_band_m3(report.material->off_band_m3);
  }
  for (const ConstructionSite& site : report.sites) {
    proto::ConstructionSite* p = s.add_construction_sites();
    p->set_from_m(site.from_m);
    p->set_to_m(site.to_m);
    p->set_volume_m3(site.volume_m3);
    p->set_cells(static_cast<std::uint32_t>(site.cells));
  }
  if (state.completion == scenario::CompletionKind::kPayloadPath) {
    s.set_target_rise_m(target_rise_m(state));
    s.set_max_target_rise_m(state.check.max_target_rise_m);
    s.set_completion_detail(payload_completion_detail(state, report.route.has_value()));
  }
  s.set_completion_checks(state.check.evaluations);
  s.set_progress(progress(state));
  s.set_progress_detail(progress_detail(state));
  s.set_start_jitter_m(info.start_jitter_m);

  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(s, &json, options);
  if (!status.ok()) throw IoError(fmt::format("cannot print the run summary as JSON: {}", status.ToString()));
  return json;
}

}  // namespace

std::vector<std::uint32_t> missing_slots(const WorldState& state, const ForkOrigin* fork) {
  const auto left_at_fork = [&](std::uint32_t id) { return fork && id > fork->agents && id <= fork->parent_agents; };
  std::vector<std::uint32_t> ids;
  for (const AgentRecord& a : state.agents)
    if (!a.alive && !left_at_fork(a.id)) ids.push_back(a.id);  // alive: admitted and not dropped (world_state.hpp)
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::string summary_json(const WorldState& state, const RunInfo& info) {
  return summary_text(state, info, final_terrain_report(state, info));
}

std::optional<CellRect> zoom_window(const WorldState& state, const std::optional<PayloadRoute>& route) {
  const GridGeometry& g = state.terrain.geometry();
  if (g.size() <= 0) return std::nullopt;
  WorldBox box;
  if (state.depositor.rows() == g.rows && state.depositor.cols() == g.cols)
    for (int r = 0; r < g.rows; ++r)
      for (int c = 0; c < g.cols; ++c)
        if (state.depositor(r, c) > 0) box.add(g, {r, c});
  if (route)
    for (const CellIndex& c : route->cells) box.add(g, c);
  if (state.completion == scenario::CompletionKind::kPayloadPath) {
    const scenario::PayloadPath& p = state.payload_path;
    box.add(p.from.x, p.from.y, p.to.x, p.to.y);
  }
  if (state.completion == scenario::CompletionKind::kLevelSite)
    box.add(state.site.area.x0, state.site.area.y0, state.site.area.x1, state.site.area.y1);
  if (box.empty()) return std::nullopt;
  const scenario::BaseStation& b = state.base;
  box.add(b.centre.x - b.radius_m, b.centre.y - b.radius_m, b.centre.x + b.radius_m, b.centre.y + b.radius_m);

  const double margin = std::max(kZoomMinMarginM, kZoomMarginFraction * std::max(box.x1 - box.x0, box.y1 - box.y0));
  const double side = std::max(std::max(box.x1 - box.x0, box.y1 - box.y0) + 2.0 * margin, kZoomMinSideM);
  const double cx = 0.5 * (box.x0 + box.x1), cy = 0.5 * (box.y0 + box.y1);
  const double y_top = g.yll_m + g.rows * g.cell_size_m;
  // Cell units: columns count east from xll, rows south from the top edge; rounded outwards, then clipped.
  const auto lower = [&](double cells, int count) {
    return static_cast<int>(std::clamp(std::floor(cells + kCellEdgeTolerance), 0.0, static_cast<double>(count)));
  };
  const auto upper = [&](double cells, int count) {
    return static_cast<int>(std::clamp(std::ceil(cells - kCellEdgeTolerance), 0.0, static_cast<double>(count)));
  };
  const int c0 = lower((cx - 0.5 * side - g.xll_m) / g.cell_size_m, g.cols);
  const int c1 = upper((cx + 0.5 * side - g.xll_m) / g.cell_size_m, g.cols);
  const int r0 = lower((y_top - (cy + 0.5 * side)) / g.cell_size_m, g.rows);
  const int r1 = upper((y_top - (cy - 0.5 * side)) / g.cell_size_m, g.rows);
  const CellRect window{{r0, c0}, r1 - r0, c1 - c0};
  if (window.empty() || window.size() > kZoomMaxAreaFraction * g.size()) return std::nullopt;
  return window;
}

render::RenderOptions final_picture_options(const WorldState& state, const RunInfo& info,
                                            const std::optional<PayloadRoute>& route,
                                            const std::optional<CellRect>& window) {
  render::RenderOptions o;
  const Heightmap& t = state.terrain;
  const CellRect area = window ? *window : CellRect{{0, 0}, t.rows(), t.cols()};
  const CellIndex last{area.first.row + area.rows - 1, area.first.col + area.cols - 1};
  if (area.empty() || !t.contains(area.first) || !t.contains(last))
    throw InvalidArgument(fmt::format("final_picture_options: window of {} x {} cells at {} leaves the {} x {} grid",
                                      area.rows, area.cols, area.first, t.rows(), t.cols()));
  if (state.depositor.rows() == t.rows() && state.depositor.cols() == t.cols()) {
    const render::CellLabels labels = state.depositor.block(area.first.row, area.first.col, area.rows, area.cols);
    if (labels.maxCoeff() > 0) o.labels = labels;
  }
  o.circles.push_back({{state.base.centre.x, state.base.centre.y}, state.base.radius_m, kWhite, 0.0});
  o.legend_entries.push_back({"base station", kWhite, render::LegendSwatch::kRing});
  std::string outcome = info.completed ? "completed" : "not completed";
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal: {
      const scenario::Goal& g = state.goal;
      o.rectangles.push_back({{g.area.x0, g.area.y0}, {g.area.x1, g.area.y1}, kWhite, 0.0});
      const auto cell = t.cell_at({0.5 * (g.area.x0 + g.area.x1), 0.5 * (g.area.y0 + g.area.y1)});
      if (cell && area.contains(*cell)) o.markers.push_back({cell->row - area.first.row, cell->col - area.first.col});
      o.legend_entries.push_back({"goal", kWhite, render::LegendSwatch::kOutline});
      if (g.target_radius_m > 0.0) {  // each agent's own target: the ring it must end in
        for (const AgentRecord& a : state.agents)
          if (a.admitted) o.circles.push_back({a.target, g.target_radius_m, kToGreen, 0.0});
        o.legend_entries.push_back(
            {fmt::format("targets ({:g} m)", g.target_radius_m), kToGreen, render::LegendSwatch::kRing});
      }
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
            {fmt::format("payload path {:.2f} m", route->length_m), kPathYellow, render::LegendSwatch::kLine});
        outcome += fmt::format(", path {:.2f} m", route->length_m);
        const double rise = target_rise_m(state);
        if (rise > state.check.max_target_rise_m + tolerance::kLengthM)
          outcome += fmt::format(", target raised {:.2f} m", rise);
      } else {
        outcome += ", no payload path";
      }
      o.points.push_back({{p.from.x, p.from.y}, kFromRed, render::PointShape::kSquare, 0.0});
      o.points.push_back({{p.to.x, p.to.y}, kToGreen, render::PointShape::kDiamond, 0.0});
      o.legend_entries.push_back({"payload from", kFromRed, render::LegendSwatch::kSquare});
      o.legend_entries.push_back({"payload to", kToGreen, render::LegendSwatch::kDiamond});
      break;
    }
    case scenario::CompletionKind::kLevelSite: {
      const scenario::Site& site = state.site;
      o.rectangles.push_back({{site.area.x0, site.area.y0}, {site.area.x1, site.area.y1}, kWhite, 0.0});
      o.legend_entries.push_back({"site", kWhite, render::LegendSwatch::kOutline});
      outcome += fmt::format(", level {:.1f}%", 100.0 * state.check.level_fraction);
      break;
    }
  }
  // Agents: discs of their colour; the legend lists each colour once with the ids that share it.
  std::vector<std::string> ids_of_colour(render::default_palette().size());
  for (const AgentRecord& a : state.agents) {
    if (!a.admitted) continue;
    o.points.push_back({a.position, render::label_colour(a.id), render::PointShape::kDisc, 0.0});
    std::string& ids = ids_of_colour[(a.id - 1) % ids_of_colour.size()];
    ids += fmt::format("{}{}", ids.empty() ? "" : ", ", a.id);
  }
  for (std::size_t k = 0; k < ids_of_colour.size(); ++k)
    if (!ids_of_colour[k].empty())
      o.legend_entries.push_back(
          {(ids_of_colour[k].find(',') == std::string::npos ? "agent " : "agents ") + ids_of_colour[k],
           render::default_palette()[k], render::LegendSwatch::kDisc});
  if (window) {
    const double cs = t.cell_size_m();
    const double x0 = t.geometry().xll_m + area.first.col * cs;
    const double y1 = t.geometry().yll_m + (t.rows() - area.first.row) * cs;
    o.title = fmt::format("{}: close-up x {:.10g}..{:.10g} m, y {:.10g}..{:.10g} m", info.scenario, x0,
                          x0 + area.cols * cs, y1 - area.rows * cs, y1);
  } else {
    o.title = fmt::format("{}: step {}, {} {}", info.scenario, state.step, scenario::to_string(state.completion),
                          outcome);
  }
  return o;
}

render::RenderOptions goal_vector_map_picture_options(const WorldState& state, const RunInfo& info,
                                                      const GoalVectorMap& map) {
  render::RenderOptions o;
  const GoalVectorMapSpec& spec = map.spec();
  o.rectangles.push_back({{spec.area.x0, spec.area.y0}, {spec.area.x1, spec.area.y1}, kWhite, 0.0});
  if (state.completion == scenario::CompletionKind::kLevelSite)
    o.rectangles.push_back(
        {{state.site.area.x0, state.site.area.y0}, {state.site.area.x1, state.site.area.y1}, kWhite, 0.0});
  for (const GoalArrow& a : map.arrows()) o.arrows.push_back({a.tail, a.head, kArrowRed, 0.0});
  o.legend_entries.push_back({"tail -> head", kArrowRed, render::LegendSwatch::kArrow});
  o.legend_entries.push_back({"site", kWhite, render::LegendSwatch::kOutline});
  o.title = fmt::format("{}: goal vector map, {} arrows in {} strips, heading {}", info.scenario, map.arrows().size(),
                        map.strips(), to_string(spec.heading));
  return o;
}

render::PerspectiveOptions perspective_options(const WorldState& state, const RunInfo& info, const CellRect& window) {
  render::PerspectiveOptions o;
  Heightmap built(state.terrain.window(window.first, window.rows, window.cols).geometry());
  for (int r = 0; r < window.rows; ++r)
    for (int c = 0; c < window.cols; ++c)
      built(r, c) = state.depositor(window.first.row + r, window.first.col + c) > 0 ? 1.0 : 0.0;
  o.deposit = std::move(built);
  // The robots where they ended, in their colours (as in final.png): a box 0.8 of the body long, 0.4 of it high.
  for (const AgentRecord& a : state.agents)
    if (a.admitted)
      o.bodies.push_back({a.position.x, a.position.y, 0.8 * a.type.body.navigability.delta_m,
                          0.4 * a.type.body.navigability.delta_m, render::label_colour(a.id)});
  o.title = fmt::format("{}: step {}, built material in orange", info.scenario, state.step);
  return o;
}

void write_initial_outputs(const std::string& dir, const Heightmap& terrain) {
  make_dir(dir);
  write_atomically(path_in(dir, "terrain_initial.asc"), [&](const std::string& p) { terrain::write_asc(terrain, p); });
}

void write_final_outputs(const std::string& dir, const WorldState& state, const RunInfo& info) {
  make_dir(dir);
  write_atomically(path_in(dir, "terrain_final.asc"),
                   [&](const std::string& p) { terrain::write_asc(state.terrain, p); });

  const FinalTerrainReport report = final_terrain_report(state, info);
  write_atomically(path_in(dir, "final.png"), [&](const std::string& p) {
    render::write_png(render::render_terrain(state.terrain, final_picture_options(state, info, report.route)), p);
  });
  const std::optional<CellRect> window = zoom_window(state, report.route);
  const CellRect window3d = window.value_or(CellRect{CellIndex{0, 0}, state.terrain.rows(), state.terrain.cols()});
  if (window)
    write_atomically(path_in(dir, "final_zoom.png"), [&](const std::string& p) {
      render::write_png(render::render_terrain(state.terrain.window(window->first, window->rows, window->cols),
                                               final_picture_options(state, info, report.route, window)),
                        p);
    });

  write_atomically(path_in(dir, "final_3d.png"), [&](const std::string& p) {
    render::write_png(render::render_perspective(state.terrain.window(window3d.first, window3d.rows, window3d.cols),
                                                 perspective_options(state, info, window3d)),
                      p);
  });

  const std::string summary = summary_text(state, info, report);
  write_atomically(path_in(dir, "summary.json"), [&](const std::string& p) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << summary;
    out.close();
    if (!out) throw IoError(fmt::format("cannot write '{}'", p));
  });

  if (info.goal_vector_map) {
    const Heightmap& initial = info.initial_terrain.size() > 0 ? info.initial_terrain : state.terrain;
    const GoalVectorMap map(*info.goal_vector_map, initial.geometry());
    write_atomically(path_in(dir, "goal_vector_map.png"), [&](const std::string& p) {
      render::write_png(render::render_terrain(initial, goal_vector_map_picture_options(state, info, map)), p);
    });
  }
}

std::string event_json(const protocol::WorldEvent& e, const std::vector<Deposition>& cells) {
  nlohmann::ordered_json line = {{"step", e.step}, {"agent", e.agent_id}, {"kind", protocol::to_string(e.kind)}};
  const bool deposited = e.kind == protocol::EventKind::kDeposited;
  if (deposited) line["volume_m3"] = e.volume_m3;
  if (!e.detail.empty()) line["detail"] = e.detail;
  if (deposited) {
    nlohmann::ordered_json& set = line["cells"] = nlohmann::ordered_json::array();
    for (const Deposition& d : cells) set.push_back({d.row, d.col, d.height_m});
  }
  return line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

std::string note_json(std::uint64_t step, const std::string& text) {
  const nlohmann::ordered_json line = {{"step", step}, {"kind", "note"}, {"detail", text}};
  return line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

EventLog::EventLog(const std::string& path, bool append) : path_(path) {
  make_dir(fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path().string());
  out_.open(path, append ? std::ios::app : std::ios::trunc);
  if (!out_) throw IoError(fmt::format("cannot write '{}'", path));
}

void EventLog::append(const protocol::WorldEvent& event, const std::vector<Deposition>& cells) {
  write_line(event_json(event, cells));
}

void EventLog::note(std::uint64_t step, const std::string& text) { write_line(note_json(step, text)); }

void EventLog::write_line(const std::string& line) {
  errno = 0;
  out_ << line << std::endl;
  if (!out_)
    throw IoError(fmt::format("cannot write '{}': {}; the run's record is lost", path_,
                              errno != 0 ? std::strerror(errno) : "disk full or the file gone?"));
}

std::vector<std::string> run_files_in(const std::string& dir) {
  std::vector<std::string> found;
  for (const char* name : kRunFiles) {
    std::error_code ec;
    if (fs::exists(fs::path(dir) / name, ec)) found.push_back(name);
  }
  return found;
}

void clear_run_files(const std::string& dir) {
  for (const char* name : kRunFiles)
    for (const std::string& file : {std::string(name), std::string(name) + ".tmp"}) {
      std::error_code ec;
      fs::remove(fs::path(dir) / file, ec);
      if (ec)
        throw IoError(fmt::format("cannot remove '{}' (--replace): {}", (fs::path(dir) / file).string(), ec.message()));
    }
  // The time-lapse of --frames-every: its frames and video only, then the folder when nothing else is in it.
  const fs::path frames = fs::path(dir) / "frames";
  std::error_code ec;
  if (!fs::is_directory(frames, ec)) return;
  std::vector<fs::path> doomed;
  for (const fs::directory_entry& e : fs::directory_iterator(frames, ec)) {
    const std::string name = e.path().filename().string();
    if ((name.rfind("frame_", 0) == 0 && e.path().extension() == ".png") || name == "timelapse.mp4")
      doomed.push_back(e.path());
  }
  for (const fs::path& p : doomed) {
    fs::remove(p, ec);
    if (ec) throw IoError(fmt::format("cannot remove '{}' (--replace): {}", p.string(), ec.message()));
  }
  fs::remove(frames, ec);  // fails, and is meant to, when the folder holds anything else
}

void check_fresh_output_dir(const std::string& dir) {
  const std::vector<std::string> found = run_files_in(dir);
  if (found.empty()) return;
  throw IoError(fmt::format(
      "output folder '{}' holds another run ({}): give a fresh --out, or --replace to remove them first", dir,
      fmt::join(found, ", ")));
}

}  // namespace marsala::world_server
