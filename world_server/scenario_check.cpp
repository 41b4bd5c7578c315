#include "marsala/world_server/scenario_check.hpp"

#include <fmt/format.h>

#include "marsala/core/format.hpp"
#include "marsala/scenario/terrain_builder.hpp"

namespace marsala::world_server {
namespace {

/// A JSON string literal of `s` (RFC 8259 escapes; bytes >= 0x80 pass through as UTF-8).
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      out += fmt::format("\\u{:04x}", c);
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string completion_json(const scenario::Scenario& s) {
  const std::string kind = json_string(scenario::to_string(s.completion));
  switch (s.completion) {
    case scenario::CompletionKind::kAgentsAtGoal:
      return fmt::format(R"({{"kind": {}, "x0_m": {}, "y0_m": {}, "x1_m": {}, "y1_m": {}, "min_height_m": {}}})", kind,
                         s.goal.x0_m, s.goal.y0_m, s.goal.x1_m, s.goal.y1_m, s.goal.min_height_m);
    case scenario::CompletionKind::kPayloadPath: {
      const scenario::PayloadPath& p = s.payload_path;
      return fmt::format(
          R"({{"kind": {}, "kappa": {}, "delta_m": {}, "eps_m": {}, "from_m": [{}, {}], "to_m": [{}, {}]}})", kind,
          p.navigability.kappa, p.navigability.delta_m, p.navigability.eps_m, p.from_x_m, p.from_y_m, p.to_x_m, p.to_y_m);
    }
    case scenario::CompletionKind::kLevelSite: {
      const scenario::Site& t = s.site;
      return fmt::format(
          R"({{"kind": {}, "kappa": {}, "delta_m": {}, "eps_m": {}, "x0_m": {}, "y0_m": {}, "x1_m": {}, "y1_m": {}, )"
          R"("min_fraction": {}}})",
          kind, t.navigability.kappa, t.navigability.delta_m, t.navigability.eps_m, t.x0_m, t.y0_m, t.x1_m, t.y1_m, t.min_fraction);
    }
  }
  return fmt::format(R"({{"kind": {}}})", kind);
}

}  // namespace

CheckedScenario check_scenario(const std::string& path) {
  CheckedScenario checked{scenario::load_scenario(path), {}};
  const scenario::Scenario& s = checked.scenario;
  checked.state = make_world_state(s, scenario::build_terrain(s), static_cast<std::uint32_t>(s.slots.size()));
  return checked;
}

std::string describe_text(const CheckedScenario& checked) {
  const scenario::Scenario& s = checked.scenario;
  const GridGeometry g = checked.state.terrain.geometry();
  std::string out = fmt::format("scenario {} ({}): valid\n", s.name, s.source_path);
  out += fmt::format("terrain: {} x {} cells of {} m, lower-left corner ({}, {}) m\n", g.rows, g.cols, g.cell_size_m,
                     g.xll_m, g.yll_m);
  for (const RobotType& t : s.robot_types)
    out += fmt::format("robot type {}: behaviour {}, {}, max_step {} m, cube {} m, goal synthesizer {}\n", t.name,
                       t.behaviour, t.body.navigability, t.body.max_step_m, t.body.cube_size_m, t.goal_synthesizer);
  for (const AgentRecord& a : checked.state.agents)
    out += fmt::format("slot {}: {} from ({}, {}) m to ({}, {}) m\n", a.id, a.robot_type, a.start_x_m, a.start_y_m,
                       a.target_x_m, a.target_y_m);
  out += fmt::format("completion: {}\n", scenario::to_string(s.completion));
  out += fmt::format("max_steps {}, step deadline {} s, seed {}, start jitter {} m\n", s.max_steps,
                     s.step_deadline_s, s.seed, s.start_jitter_m);
  return out;
}

std::string describe_json(const CheckedScenario& checked) {
  const scenario::Scenario& s = checked.scenario;
  const GridGeometry g = checked.state.terrain.geometry();
  std::string types, slots;
  for (const RobotType& t : s.robot_types) {
    const NavigabilityParams& n = t.body.navigability;
    types += fmt::format(
        R"({}{{"name": {}, "behaviour": {}, "kappa": {}, "delta_m": {}, "eps_m": {}, "max_step_m": {}, )"
        R"("cube_size_m": {}, "goal_synthesizer": {}}})",
        types.empty() ? "" : ", ", json_string(t.name), json_string(t.behaviour), n.kappa, n.delta_m, n.eps_m,
        t.body.max_step_m, t.body.cube_size_m, json_string(t.goal_synthesizer));
  }
  for (const AgentRecord& a : checked.state.agents)
    slots += fmt::format(R"({}{{"id": {}, "robot_type": {}, "start_m": [{}, {}], "target_m": [{}, {}]}})",
                         slots.empty() ? "" : ", ", a.id, json_string(a.robot_type), a.start_x_m, a.start_y_m,
                         a.target_x_m, a.target_y_m);
  return fmt::format(
      R"({{"scenario": {}, "source": {}, "terrain": {{"rows": {}, "cols": {}, "cell_size_m": {}, "xll_m": {}, )"
      R"("yll_m": {}}}, "robot_types": [{}], "slots": [{}], "completion": {}, "max_steps": {}, )"
      R"("step_deadline_s": {}, "seed": {}, "start_jitter_m": {}}})"
      "\n",
      json_string(s.name), json_string(s.source_path), g.rows, g.cols, g.cell_size_m, g.xll_m, g.yll_m, types, slots,
      completion_json(s), s.max_steps, s.step_deadline_s, s.seed, s.start_jitter_m);
}

}  // namespace marsala::world_server
