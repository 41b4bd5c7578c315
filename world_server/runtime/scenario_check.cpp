#include "marsala/world_server/runtime/scenario_check.hpp"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <charconv>
#include <new>
#include <ostream>
#include <sstream>

#include "idl/scenario_check.pb.h"
#include "marsala/core/error.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

/// `v` in its shortest form that reads back to the same double (std::to_chars, as terrain files are written).
std::string number(double v) {
  char buf[40];
  const auto result = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, result.ptr);
}

std::string point(double x_m, double y_m) { return fmt::format("({}, {})", number(x_m), number(y_m)); }

std::string box(double x0_m, double y0_m, double x1_m, double y1_m) {
  return fmt::format("x [{}, {}] y [{}, {}] m", number(x0_m), number(x1_m), number(y0_m), number(y1_m));
}

std::string terrain_source(const scenario::Scenario& s) {
  return s.terrain.file.empty() ? fmt::format("generator {}", s.terrain.method) : scenario::resolve_terrain_path(s);
}

void set_point(proto::CheckPoint* p, double x_m, double y_m) {
  p->set_x_m(x_m);
  p->set_y_m(y_m);
}

/// The slot's start as the world places it, when the world waits for that agent.
const AgentRecord* record_of(const WorldState& state, std::uint32_t id) {
  return state.has_agent(id) ? &state.agent(id) : nullptr;
}

long long site_cell_count(const WorldState& state) { return site_cells(state.terrain.geometry(), state.site).size(); }

proto::ScenarioCheck to_message(const WorldStart& start) {
  const scenario::Scenario& s = start.scenario;
  const WorldState& state = start.state;
  const GridGeometry& g = state.terrain.geometry();
  proto::ScenarioCheck m;
  m.set_scenario(s.name);
  m.set_scenario_file(s.source_path);
  proto::TerrainCheck* t = m.mutable_terrain();
  t->set_source(terrain_source(s));
  t->set_rows(g.rows);
  t->set_cols(g.cols);
  t->set_cell_size_m(g.cell_size_m);
  t->set_x0_m(g.xll_m);
  t->set_y0_m(g.yll_m);
  t->set_width_m(g.cols * g.cell_size_m);
  t->set_height_m(g.rows * g.cell_size_m);
  t->set_min_height_m(state.terrain.min_height());
  t->set_max_height_m(state.terrain.max_height());
  for (const RobotType& type : s.robot_types) {
    proto::RobotTypeCheck* r = m.add_robot_types();
    r->set_name(type.name);
    r->set_behaviour(type.behaviour);
    r->set_kappa(type.body.navigability.kappa);
    r->set_delta_m(type.body.navigability.delta_m);
    r->set_eps_m(type.body.navigability.eps_m);
    r->set_max_step_m(type.body.max_step_m);
    r->set_cube_size_m(type.body.cube_size_m);
    r->set_goal_synthesizer(type.goal_synthesizer);
    r->set_sensor(to_string(type.sensor.kind));
    r->set_depositor(to_string(type.depositor.kind));
    r->set_localisation_noise_sd_m(type.localisation.noise_sd_m);
    if (type.sensor.casts_rays()) {
      r->set_sensor_rays(type.sensor.ray_count());
      r->set_sensor_max_range_m(type.sensor.max_range_m);
    }
  }
  for (const scenario::AgentSlot& slot : s.slots) {
    proto::SlotCheck* p = m.add_slots();
    p->set_id(slot.id);
    p->set_robot_type(slot.robot_type);
    set_point(p->mutable_start(), slot.start.x, slot.start.y);
    set_point(p->mutable_target(), slot.target.x, slot.target.y);
    if (const AgentRecord* a = record_of(state, slot.id))
      set_point(p->mutable_world_start(), a->start.x, a->start.y);
  }
  m.set_agents(static_cast<std::uint32_t>(state.agents.size()));
  m.set_completion(scenario::to_string(state.completion));
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal: {
      proto::GoalCheck* goal = m.mutable_goal();
      goal->set_x0_m(state.goal.area.x0);
      goal->set_y0_m(state.goal.area.y0);
      goal->set_x1_m(state.goal.area.x1);
      goal->set_y1_m(state.goal.area.y1);
      goal->set_min_height_m(state.goal.min_height_m);
      goal->set_target_radius_m(state.goal.target_radius_m);
      break;
    }
    case scenario::CompletionKind::kPayloadPath: {
      const scenario::PayloadPath& p = state.payload_path;
      proto::PayloadPathCheck* path = m.mutable_payload_path();
      path->set_kappa(p.navigability.kappa);
      path->set_delta_m(p.navigability.delta_m);
      path->set_eps_m(p.navigability.eps_m);
      set_point(path->mutable_from(), p.from.x, p.from.y);
      set_point(path->mutable_to(), p.to.x, p.to.y);
      path->set_check_every_steps(p.check_every_steps);
      path->set_met_at_start(state.check.met);
      path->set_target_height_m(state.check.target_initial_m);
      path->set_max_target_rise_m(state.check.max_target_rise_m);
      break;
    }
    case scenario::CompletionKind::kLevelSite: {
      const scenario::Site& p = state.site;
      proto::SiteCheck* site = m.mutable_site();
      site->set_x0_m(p.area.x0);
      site->set_y0_m(p.area.y0);
      site->set_x1_m(p.area.x1);
      site->set_y1_m(p.area.y1);
      site->set_kappa(p.navigability.kappa);
      site->set_delta_m(p.navigability.delta_m);
      site->set_eps_m(p.navigability.eps_m);
      site->set_min_fraction(p.min_fraction);
      site->set_check_every_steps(p.check_every_steps);
      site->set_cells(site_cell_count(state));
      site->set_level_fraction_at_start(state.check.level_fraction);
      site->set_met_at_start(state.check.met);
      break;
    }
  }
  set_point(m.mutable_base(), state.base.centre.x, state.base.centre.y);
  m.set_base_radius_m(state.base.radius_m);
  m.set_max_steps(start.options.max_steps);
  m.set_stall_steps(s.stall_steps);
  m.set_seed(s.seed);
  m.set_start_jitter_m(s.start_jitter_m);
  m.set_step_deadline_s(start.options.step_deadline_s);
  m.set_tile_size(state.tile_size);
  m.set_run_id(start.options.run_id);
  return m;
}

}  // namespace

WorldStart check_scenario(const std::string& scenario_path, const RuntimeOptions& options, int domain_id) {
  // What run_world_cli() does before it makes a participant, then what WorldRuntime's constructor does.
  const scenario::Scenario scenario = scenario::load_scenario(scenario_path, options.overrides);
  Heightmap terrain = scenario::build_terrain(scenario);
  try {
    return prepare_world_start(scenario, std::move(terrain), options, domain_id);
  } catch (const InvalidArgument& e) {
    // The loader's and the terrain builder's messages name the file; these (completion set-up, options) do not.
    throw InvalidArgument(fmt::format("scenario {}: {}", scenario.source_path, e.what()));
  }
}

std::string scenario_check_text(const WorldStart& start) {
  const scenario::Scenario& s = start.scenario;
  const WorldState& state = start.state;
  const GridGeometry& g = state.terrain.geometry();
  std::ostringstream out;
  out << "scenario " << s.name << " (" << s.source_path << "): valid\n";
  out << "terrain: " << g.rows << " x " << g.cols << " cells of " << number(g.cell_size_m) << " m, "
      << box(g.xll_m, g.yll_m, g.xll_m + g.cols * g.cell_size_m, g.yll_m + g.rows * g.cell_size_m) << ", heights ["
      << number(state.terrain.min_height()) << ", " << number(state.terrain.max_height()) << "] m ("
      << terrain_source(s) << ")\n";
  out << "robot types (" << s.robot_types.size() << "):\n";
  for (const RobotType& t : s.robot_types)
    out << "  " << t.name << ": behaviour " << t.behaviour << ", kappa " << number(t.body.navigability.kappa)
        << ", delta_m " << number(t.body.navigability.delta_m) << ", eps_m " << number(t.body.navigability.eps_m)
        << ", max_step_m " << number(t.body.max_step_m) << ", cube_size_m " << number(t.body.cube_size_m)
        << ", goal_synthesizer " << t.goal_synthesizer << ", sensor " << to_string(t.sensor.kind)
        << (t.sensor.casts_rays() ? fmt::format(" ({} rays, {}-{} m)", t.sensor.ray_count(),
                                                number(t.sensor.min_range_m), number(t.sensor.max_range_m))
                                  : "")
        << ", depositor " << to_string(t.depositor.kind)
        << (t.localisation.noise_sd_m > 0.0
                ? fmt::format(", localisation noise {} m", number(t.localisation.noise_sd_m))
                : "")
        << "\n";
  out << "slots (" << s.slots.size() << "; the world waits for agents 1.." << state.agents.size() << "):\n";
  for (const scenario::AgentSlot& slot : s.slots) {
    out << "  " << slot.id << " " << slot.robot_type << ": start " << point(slot.start.x, slot.start.y)
        << " target " << point(slot.target.x, slot.target.y);
    const AgentRecord* a = record_of(state, slot.id);
    if (a && (a->start.x != slot.start.x || a->start.y != slot.start.y))
      out << ", jittered start " << point(a->start.x, a->start.y);
    out << "\n";
  }
  out << "completion: " << scenario::to_string(state.completion);
  switch (state.completion) {
    case scenario::CompletionKind::kAgentsAtGoal:
      out << ", goal " << box(state.goal.area.x0, state.goal.area.y0, state.goal.area.x1, state.goal.area.y1)
          << ", min_height_m " << number(state.goal.min_height_m);
      if (state.goal.target_radius_m > 0.0)
        out << ", each agent within " << number(state.goal.target_radius_m) << " m of its target";
      out << "\n";
      break;
    case scenario::CompletionKind::kPayloadPath: {
      const scenario::PayloadPath& p = state.payload_path;
      out << ", payload kappa " << number(p.navigability.kappa) << ", delta_m " << number(p.navigability.delta_m)
          << ", eps_m " << number(p.navigability.eps_m) << ", from " << point(p.from.x, p.from.y) << " to "
          << point(p.to.x, p.to.y) << " (its cell " << number(state.check.target_initial_m)
          << " m high, to end at most " << number(state.check.max_target_rise_m) << " m higher), checked every "
          << p.check_every_steps
          << " steps; at start: " << (state.check.met ? "navigable (the run ends at once)" : "not navigable") << "\n";
      break;
    }
    case scenario::CompletionKind::kLevelSite: {
      const scenario::Site& p = state.site;
      out << ", site " << box(p.area.x0, p.area.y0, p.area.x1, p.area.y1) << " (" << site_cell_count(state)
          << " cells), kappa " << number(p.navigability.kappa) << ", delta_m " << number(p.navigability.delta_m)
          << ", eps_m " << number(p.navigability.eps_m) << ", min_fraction " << number(p.min_fraction)
          << ", checked every " << p.check_every_steps << " steps; at start: level fraction "
          << number(state.check.level_fraction) << (state.check.met ? " (the run ends at once)" : "") << "\n";
      break;
    }
  }
  out << "base: " << point(state.base.centre.x, state.base.centre.y) << " m, radius " << number(state.base.radius_m)
      << " m\n";
  out << "max_steps " << start.options.max_steps << ", stall_steps " << s.stall_steps << ", seed " << s.seed
      << ", start_jitter_m " << number(s.start_jitter_m) << ", step_deadline_s "
      << number(start.options.step_deadline_s) << ", tile_size " << state.tile_size << ", run id "
      << start.options.run_id << "\n";
  return out.str();
}

std::string scenario_check_json(const WorldStart& start) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(to_message(start), &json, options);
  if (!status.ok()) throw Error(fmt::format("cannot print the scenario check as JSON: {}", status.ToString()));
  if (json.empty() || json.back() != '\n') json += '\n';
  return json;
}

int run_scenario_check(const std::string& scenario_path, const RuntimeOptions& options, int domain_id, bool json,
                       std::ostream& out, std::ostream& err) {
  try {
    const WorldStart start = check_scenario(scenario_path, options, domain_id);
    out << (json ? scenario_check_json(start) : scenario_check_text(start));
  } catch (const Error& e) {
    err << "marsala-world: error: " << e.what() << "\n";
    return kExitInvalidScenario;
  } catch (const std::bad_alloc&) {
    err << "marsala-world: error: out of memory\n";
    return 1;
  }
  return 0;
}

}  // namespace marsala::world_server
