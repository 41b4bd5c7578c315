// Scenario files: protobuf text format (idl/scenario.proto) -> validated plain structs (scenario.hpp).
#include <fmt/ranges.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "idl/scenario.pb.h"
#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/terrain/generators.hpp"

namespace marsala::scenario {
namespace {

/// A text-format error that reads "FILE:LINE:COL: message" (1-based line and column).
class TextFormatError : public ParseError {
 public:
  TextFormatError(const std::string& file, int line, int column, const std::string& message)
      : ParseError(file, line, message),
        text_(fmt::format("{}:{}:{}: {}", file, line, column, message)) {}
  const char* what() const noexcept override { return text_.c_str(); }

 private:
  std::string text_;
};

/// Keeps the first error the text-format parser reports.
class FirstErrorCollector final : public google::protobuf::io::ErrorCollector {
 public:
  void AddError(int line, google::protobuf::io::ColumnNumber column, const std::string& message) override {
    if (has_error_) return;
    has_error_ = true;
    line_ = line + 1;
    column_ = column + 1;
    message_ = message;
  }
  bool has_error() const { return has_error_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  bool has_error_ = false;
  int line_ = 0;
  int column_ = 0;
  std::string message_;
};

/// Validation of one scenario: each failure names the source and the field.
class Validator {
 public:
  explicit Validator(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw InvalidArgument(fmt::format("scenario {}: {}: {}", source_, field, problem));
  }
  double finite(const std::string& field, double v) const {
    if (!std::isfinite(v) || std::abs(v) >= kMaxMagnitude)
      fail(field, fmt::format("{} must be finite and < 1e6 in magnitude", v));
    return v;
  }
  double positive(const std::string& field, double v) const {
    if (!(finite(field, v) > 0.0)) fail(field, fmt::format("{} must be > 0", v));
    return v;
  }

 private:
  std::string source_;
};

TerrainSource to_terrain(const proto::TerrainSource& p, const Validator& check) {
  TerrainSource t;
  const bool has_generator = !p.generator().empty();
  const bool has_file = !p.file().empty();
  if (has_generator == has_file) check.fail("terrain", "give exactly one of 'generator' and 'file'");
  if (has_generator) {
    const std::vector<std::string> names = terrain::generator_names();
    if (std::find(names.begin(), names.end(), p.generator()) == names.end()) {
      std::string valid;
      for (const auto& n : names) valid += (valid.empty() ? "" : ", ") + n;
      check.fail("terrain.generator",
                 fmt::format("unknown generator '{}'; valid generators: {}", p.generator(), valid));
    }
    t.method = p.generator();
    if (p.has_rows()) t.rows = p.rows();
    if (p.has_cols()) t.cols = p.cols();
    if (t.rows <= 0) check.fail("terrain.rows", fmt::format("{} must be > 0", t.rows));
    if (t.cols <= 0) check.fail("terrain.cols", fmt::format("{} must be > 0", t.cols));
    if (p.has_cell_size_m()) t.cell_size_m = check.positive("terrain.cell_size_m", p.cell_size_m());
    if (p.has_seed()) t.seed = p.seed();
    for (const auto& [key, value] : p.params()) t.params[key] = check.finite("terrain.params['" + key + "']", value);
    if (p.has_crop() || p.resample_cell_size_m() != 0.0 || p.zero_base())
      check.fail("terrain", "crop, resample_cell_size_m and zero_base apply to a terrain file only");
  } else {
    if (p.has_rows() || p.has_cols() || p.has_cell_size_m() || p.has_seed() || !p.params().empty())
      check.fail("terrain", "rows, cols, cell_size_m, seed and params apply to a generator only");
    t.method.clear();
    t.file = p.file();
    if (p.has_crop()) {
      t.has_crop = true;
      t.crop_x0_m = check.finite("terrain.crop.x0_m", p.crop().x0_m());
      t.crop_y0_m = check.finite("terrain.crop.y0_m", p.crop().y0_m());
      t.crop_width_m = check.positive("terrain.crop.width_m", p.crop().width_m());
      t.crop_height_m = check.positive("terrain.crop.height_m", p.crop().height_m());
    }
    t.resample_cell_size_m = check.finite("terrain.resample_cell_size_m", p.resample_cell_size_m());
    if (t.resample_cell_size_m < 0.0) check.fail("terrain.resample_cell_size_m", "must be >= 0 (0 = keep)");
    t.zero_base = p.zero_base();
  }
  return t;
}

RobotBody to_body(const proto::Body& p) {
  RobotBody b;
  if (p.has_kappa()) b.navigability.kappa = p.kappa();
  if (p.has_delta_m()) b.navigability.delta_m = p.delta_m();
  if (p.has_eps_m()) b.navigability.eps_m = p.eps_m();
  if (p.has_max_step_m()) b.max_step_m = p.max_step_m();
  if (p.has_max_deposit_m3()) b.max_deposit_m3 = p.max_deposit_m3();
  if (p.has_material_capacity_m3()) b.material_capacity_m3 = p.material_capacity_m3();
  if (p.has_reach_m()) b.reach_m = p.reach_m();
  if (p.has_sensing_range_m()) b.sensing_range_m = p.sensing_range_m();
  if (p.has_proximity_range_m()) b.proximity_range_m = p.proximity_range_m();
  if (p.has_cube_size_m()) b.cube_size_m = p.cube_size_m();
  return b;
}

/// The named sensor's defaults with the file's values on top; every failure names the robot type's field.
SensorSpec to_sensor(const proto::Sensor& p, const std::string& field, const Validator& check) {
  SensorKind kind = SensorKind::kGroundTruth;
  if (p.has_name()) {
    try {
      kind = sensor_kind(p.name());
    } catch (const InvalidArgument& e) {
      check.fail(field + ".name", e.what());
    }
  }
  SensorSpec s = sensor_defaults(kind);
  if (p.has_mount_height_m()) s.mount_height_m = p.mount_height_m();
  if (p.has_horizontal_fov_deg()) s.horizontal_fov_deg = p.horizontal_fov_deg();
  if (p.has_horizontal_resolution_deg()) s.horizontal_resolution_deg = p.horizontal_resolution_deg();
  if (p.has_vertical_min_deg()) s.vertical_min_deg = p.vertical_min_deg();
  if (p.has_vertical_max_deg()) s.vertical_max_deg = p.vertical_max_deg();
  if (p.has_vertical_resolution_deg()) s.vertical_resolution_deg = p.vertical_resolution_deg();
  if (p.has_min_range_m()) s.min_range_m = p.min_range_m();
  if (p.has_max_range_m()) s.max_range_m = p.max_range_m();
  if (p.has_noise_sd_m()) s.noise_sd_m = p.noise_sd_m();
  if (p.has_noise_sd_per_m2()) s.noise_sd_per_m2 = p.noise_sd_per_m2();
  if (p.has_scan_every_steps())
    s.scan_every_steps = static_cast<int>(std::min<std::uint32_t>(p.scan_every_steps(), 2000000000u));
  const bool any_parameter = p.has_mount_height_m() || p.has_horizontal_fov_deg() ||
                             p.has_horizontal_resolution_deg() || p.has_vertical_min_deg() ||
                             p.has_vertical_max_deg() || p.has_vertical_resolution_deg() || p.has_min_range_m() ||
                             p.has_max_range_m() || p.has_noise_sd_m() || p.has_noise_sd_per_m2() ||
                             p.has_scan_every_steps();
  if (!s.casts_rays() && any_parameter)
    check.fail(field, "ground_truth takes no parameters (they apply to 'laser' and 'rgbd')");
  const std::string problem = sensor_problem(s);
  // sensor_problem() says "<field>: <problem>".
  if (!problem.empty()) {
    const std::size_t colon = problem.find(": ");
    check.fail(field + "." + problem.substr(0, colon), problem.substr(colon + 2));
  }
  return s;
}

DepositorSpec to_depositor(const proto::Depositor& p, const RobotBody& body, const std::string& field,
                           const Validator& check) {
  DepositorSpec d;
  if (p.has_name()) {
    try {
      d.kind = depositor_kind(p.name());
    } catch (const InvalidArgument& e) {
      check.fail(field + ".name", e.what());
    }
  }
  if (p.has_cube_size_m()) {
    if (d.kind != DepositorKind::kCube) check.fail(field + ".cube_size_m", "applies to the 'cube' depositor only");
    d.cube_size_m = check.positive(field + ".cube_size_m", p.cube_size_m());
  }
  if (d.kind == DepositorKind::kCube && !(body.cube_size_m > 0.0)) check.fail(field + ".cube_size_m", "the body's must be > 0");
  if (p.has_repose_deg()) {
    if (d.kind != DepositorKind::kCone) check.fail(field + ".repose_deg", "applies to the 'cone' depositor only");
    d.repose_deg = check.finite(field + ".repose_deg", p.repose_deg());
    if (!(d.repose_deg > 0.0 && d.repose_deg < 90.0))
      check.fail(field + ".repose_deg", fmt::format("{} must be in (0, 90) degrees", d.repose_deg));
  }
  return d;
}

bool valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

/// The construction a robot type builds: its body's unless the file says otherwise, checked against what the body can
/// climb and reach.
NavigabilityParams to_construction(const proto::Construction& cp, const RobotBody& body, const std::string& field,
                                   const Validator& check) {
  // Unset fields build for the robot's own body (kappa, eps, and its length as the band's width).
  NavigabilityParams build = body.navigability;
  if (cp.has_kappa()) build.kappa = check.positive(field + ".construction.kappa", cp.kappa());
  if (cp.has_eps_m()) build.eps_m = check.finite(field + ".construction.eps_m", cp.eps_m());
  if (build.eps_m < 0.0) check.fail(field + ".construction.eps_m", "must be >= 0");
  if (cp.has_width_m()) build.delta_m = check.positive(field + ".construction.width_m", cp.width_m());
  if (build.kappa > body.navigability.kappa)
    check.fail(field + ".construction.kappa",
               fmt::format("{} exceeds the body's kappa {}: the builder could not climb what it builds", build.kappa,
                           body.navigability.kappa));
  const double reach_band_m = 2.0 * body.reach_m + body.navigability.delta_m;
  if (build.delta_m > reach_band_m)
    check.fail(field + ".construction.width_m",
               fmt::format("{} is wider than the robot can reach from its path (delta + 2 reach = {} m)",
                           build.delta_m, reach_band_m));
  return build;
}

Pipeline to_pipeline(const proto::Pipeline& pp, const std::string& field, const Validator& check) {
  Pipeline pipeline;
  if (pp.has_separation_m())
    pipeline.separation_m = check.positive(field + ".pipeline.separation_m", pp.separation_m());
  if (pp.has_lane_offset_m())
    pipeline.lane_offset_m = check.finite(field + ".pipeline.lane_offset_m", pp.lane_offset_m());
  if (pipeline.lane_offset_m < 0.0) check.fail(field + ".pipeline.lane_offset_m", "must be >= 0");
  return pipeline;
}

Localisation to_localisation(const proto::Localisation& lp, const std::string& field, const Validator& check) {
  Localisation l;
  if (lp.has_noise_sd_m()) l.noise_sd_m = check.finite(field + ".localisation.noise_sd_m", lp.noise_sd_m());
  if (l.noise_sd_m < 0.0 || l.noise_sd_m > 10.0)
    check.fail(field + ".localisation.noise_sd_m", fmt::format("{} must be in [0, 10] m", l.noise_sd_m));
  if (lp.has_correlation_steps())
    l.correlation_steps = check.finite(field + ".localisation.correlation_steps", lp.correlation_steps());
  if (l.correlation_steps < 1.0 || l.correlation_steps > 1e5)
    check.fail(field + ".localisation.correlation_steps",
               fmt::format("{} must be in [1, 1e5] steps", l.correlation_steps));
  return l;
}

/// Robot type `i` of the file; `earlier` are the types before it (names are unique).
RobotType to_robot_type(const proto::Scenario& p, int i, const std::vector<RobotType>& earlier,
                        const Validator& check) {
  const proto::RobotType& rp = p.robot_type(i);
  const std::string field = fmt::format("robot_type[{}]", i);
  RobotType t;
  if (rp.name().empty()) check.fail(field + ".name", "missing");
  for (const RobotType& e : earlier)
    if (e.name == rp.name()) check.fail(field + ".name", fmt::format("robot type '{}' is defined twice", rp.name()));
  t.name = rp.name();
  if (rp.has_behaviour()) t.behaviour = rp.behaviour();
  if (t.behaviour.empty()) check.fail(field + ".behaviour", "must not be empty");
  t.body = to_body(rp.body());
  const std::string problem = body_problem(t.body);
  if (!problem.empty()) check.fail(field + ".body", problem);
  t.construction = to_construction(rp.construction(), t.body, field, check);
  t.pipeline = to_pipeline(rp.pipeline(), field, check);
  t.localisation = to_localisation(rp.localisation(), field, check);
  if (rp.has_goal_synthesizer()) t.goal_synthesizer = rp.goal_synthesizer();
  if (t.goal_synthesizer.empty()) check.fail(field + ".goal_synthesizer", "must not be empty");
  if (t.goal_synthesizer == "goal_vector_map" && !p.has_goal_vector_map())
    check.fail(field + ".goal_synthesizer", "'goal_vector_map' needs the scenario's goal_vector_map block");
  t.sensor = to_sensor(rp.sensor(), field + ".sensor", check);
  t.depositor = to_depositor(rp.depositor(), t.body, fmt::format("{} ({}).depositor", field, t.name), check);
  return t;
}

/// The field name of agent slot `id` in messages: "agent[i] (agent id)".
std::string slot_field(std::uint32_t id) { return fmt::format("agent[{}] (agent {})", id - 1, id); }

/// A point of the file, each coordinate finite ("<field>.x_m", "<field>.y_m").
Position to_position(const proto::Point& pp, const std::string& field, const Validator& check) {
  return {check.finite(field + ".x_m", pp.x_m()), check.finite(field + ".y_m", pp.y_m())};
}

/// A rectangle of the file (fields x0_m, y0_m, x1_m, y1_m of `block`), finite and not empty.
template <typename Block>
Rect to_rect(const Block& b, const std::string& block, const Validator& check) {
  const Rect r{check.finite(block + ".x0_m", b.x0_m()), check.finite(block + ".y0_m", b.y0_m()),
               check.finite(block + ".x1_m", b.x1_m()), check.finite(block + ".y1_m", b.y1_m())};
  if (!(r.x0 < r.x1) || !(r.y0 < r.y1)) check.fail(block, "the rectangle needs x0_m < x1_m and y0_m < y1_m");
  return r;
}

AgentSlot to_slot(const proto::AgentSlot& ap, std::uint32_t id, const std::vector<RobotType>& types,
                  const Validator& check) {
  const std::string field = slot_field(id);
  if (ap.has_id() && ap.id() != id)
    check.fail(field + ".id", fmt::format("{} differs from its position in the file ({})", ap.id(), id));
  AgentSlot slot;
  slot.id = id;
  slot.robot_type = ap.robot_type();
  const bool known = std::any_of(types.begin(), types.end(),
                                 [&](const RobotType& t) { return t.name == slot.robot_type; });
  if (!known) {
    std::vector<std::string> valid;
    for (const RobotType& t : types) valid.push_back(t.name);
    check.fail(field + ".robot_type",
               fmt::format("unknown robot type '{}'; valid: {}", slot.robot_type, fmt::join(valid, ", ")));
  }
  if (!ap.has_start()) check.fail(field + ".start", "missing");
  if (!ap.has_target()) check.fail(field + ".target", "missing");
  slot.start = to_position(ap.start(), field + ".start", check);
  slot.target = to_position(ap.target(), field + ".target", check);
  return slot;
}

Goal to_goal(const proto::Goal& gp, const std::vector<AgentSlot>& slots, const Validator& check) {
  Goal goal;
  goal.area = to_rect(gp, "goal", check);
  if (gp.has_min_height_m()) goal.min_height_m = check.finite("goal.min_height_m", gp.min_height_m());
  if (gp.has_target_radius_m()) goal.target_radius_m = check.positive("goal.target_radius_m", gp.target_radius_m());
  // With a target condition every agent must be able to meet both: its target lies in the box.
  if (goal.target_radius_m > 0.0)
    for (const AgentSlot& slot : slots)
      if (slot.target.x < goal.area.x0 || slot.target.x > goal.area.x1 || slot.target.y < goal.area.y0 ||
          slot.target.y > goal.area.y1)
        check.fail(slot_field(slot.id) + ".target",
                   fmt::format("({}, {}) lies outside the goal box, so the agent could never complete with "
                               "goal.target_radius_m",
                               slot.target.x, slot.target.y));
  return goal;
}

PayloadPath to_payload_path(const proto::PayloadPath& pp, const Validator& check) {
  PayloadPath path;
  const RobotBody body = to_body(pp.body());
  path.navigability.kappa = check.positive("payload_path.body.kappa", body.navigability.kappa);
  path.navigability.delta_m = check.positive("payload_path.body.delta_m", body.navigability.delta_m);
  path.navigability.eps_m = check.finite("payload_path.body.eps_m", body.navigability.eps_m);
  if (path.navigability.eps_m < 0.0) check.fail("payload_path.body.eps_m", "must be >= 0");
  if (!pp.has_from()) check.fail("payload_path.from", "missing");
  if (!pp.has_to()) check.fail("payload_path.to", "missing");
  path.from = to_position(pp.from(), "payload_path.from", check);
  path.to = to_position(pp.to(), "payload_path.to", check);
  if (pp.has_check_every_steps()) path.check_every_steps = pp.check_every_steps();
  if (path.check_every_steps == 0) check.fail("payload_path.check_every_steps", "must be >= 1");
  return path;
}

Site to_site(const proto::Site& sp, const Validator& check) {
  Site site;
  site.area = to_rect(sp, "site", check);
  if (sp.has_kappa()) site.navigability.kappa = check.positive("site.kappa", sp.kappa());
  if (sp.has_delta_m()) site.navigability.delta_m = check.positive("site.delta_m", sp.delta_m());
  if (sp.has_eps_m()) site.navigability.eps_m = check.finite("site.eps_m", sp.eps_m());
  if (site.navigability.eps_m < 0.0) check.fail("site.eps_m", "must be >= 0");
  if (sp.has_min_fraction()) site.min_fraction = check.finite("site.min_fraction", sp.min_fraction());
  if (!(site.min_fraction > 0.0 && site.min_fraction <= 1.0))
    check.fail("site.min_fraction", fmt::format("{} must be in (0, 1]", site.min_fraction));
  if (sp.has_check_every_steps()) site.check_every_steps = sp.check_every_steps();
  if (site.check_every_steps == 0) check.fail("site.check_every_steps", "must be >= 1");
  return site;
}

GoalVectorMapSpec to_goal_vector_map(const proto::GoalVectorMap& gp, const Validator& check) {
  GoalVectorMapSpec map;
  map.area = to_rect(gp, "goal_vector_map", check);
  map.strip_width_m = check.positive("goal_vector_map.strip_width_m", gp.strip_width_m());
  map.arrow_length_m = check.positive("goal_vector_map.arrow_length_m", gp.arrow_length_m());
  if (gp.has_heading()) {
    try {
      map.heading = heading_from_string(gp.heading());
    } catch (const InvalidArgument& e) {
      check.fail("goal_vector_map.heading", e.what());
    }
  }
  return map;
}

/// How the run completes: exactly one of goal, payload_path and site.
void read_completion(const proto::Scenario& p, Scenario& s, const Validator& check) {
  const int completions = (p.has_goal() ? 1 : 0) + (p.has_payload_path() ? 1 : 0) + (p.has_site() ? 1 : 0);
  if (completions != 1)
    check.fail("goal", "give exactly one of 'goal', 'payload_path' and 'site' (how the run completes)");
  if (p.has_goal()) {
    s.completion = CompletionKind::kAgentsAtGoal;
    s.goal = to_goal(p.goal(), s.slots, check);
  }
  if (p.has_payload_path()) {
    s.completion = CompletionKind::kPayloadPath;
    s.payload_path = to_payload_path(p.payload_path(), check);
  }
  if (p.has_site()) {
    s.completion = CompletionKind::kLevelSite;
    s.site = to_site(p.site(), check);
  }
}

/// The run's settings: start jitter, base, step limits, tiles, seed.
void read_run_settings(const proto::Scenario& p, Scenario& s, const Validator& check) {
  if (p.has_start_jitter_m()) s.start_jitter_m = check.finite("start_jitter_m", p.start_jitter_m());
  if (s.start_jitter_m < 0.0) check.fail("start_jitter_m", "must be >= 0");
  if (p.has_base()) {
    s.base.centre = {check.finite("base.x_m", p.base().x_m()), check.finite("base.y_m", p.base().y_m())};
    if (p.base().has_radius_m()) s.base.radius_m = check.positive("base.radius_m", p.base().radius_m());
  }
  if (p.has_max_steps()) s.max_steps = p.max_steps();
  if (s.max_steps == 0) check.fail("max_steps", "must be >= 1");
  if (p.has_stall_steps()) {
    if (p.stall_steps() < 0 || static_cast<std::uint64_t>(p.stall_steps()) > kMaxStallSteps)
      check.fail("stall_steps", fmt::format("{} must be 0 (never) or in 1..{}", p.stall_steps(), kMaxStallSteps));
    s.stall_steps = static_cast<std::uint64_t>(p.stall_steps());
  }
  if (p.has_step_deadline_s()) s.step_deadline_s = check.positive("step_deadline_s", p.step_deadline_s());
  if (p.has_tile_size()) s.tile_size = p.tile_size();
  if (s.tile_size < 1 || s.tile_size > 4096) check.fail("tile_size", fmt::format("{} must be in 1..4096", s.tile_size));
  if (p.has_seed()) s.seed = p.seed();
  if (p.has_right_of_way()) s.right_of_way = p.right_of_way();
  if (p.has_standing_answers()) s.standing_answers = p.standing_answers();
}

Scenario to_scenario(const proto::Scenario& p, const std::string& source) {
  const Validator check(source);
  Scenario s;
  s.source_path = source;
  if (!valid_name(p.name()))
    check.fail("name", fmt::format("'{}' must be non-empty letters, digits, '_', '-', '.'", p.name()));
  s.name = p.name();
  if (!p.has_terrain()) check.fail("terrain", "missing");
  s.terrain = to_terrain(p.terrain(), check);

  if (p.robot_type_size() == 0) check.fail("robot_type", "at least one robot type is required");
  for (int i = 0; i < p.robot_type_size(); ++i) s.robot_types.push_back(to_robot_type(p, i, s.robot_types, check));
  if (p.agent_size() == 0) check.fail("agent", "at least one agent slot is required");
  for (int i = 0; i < p.agent_size(); ++i)
    s.slots.push_back(to_slot(p.agent(i), static_cast<std::uint32_t>(i) + 1, s.robot_types, check));
  read_completion(p, s, check);
  if (p.has_goal_vector_map()) {
    s.has_goal_vector_map = true;
    s.goal_vector_map = to_goal_vector_map(p.goal_vector_map(), check);
  }
  read_run_settings(p, s, check);

  // Generated terrains have a known extent: check placements now. File terrains are checked by build_terrain().
  if (!s.terrain.method.empty()) {
    GridGeometry g;
    g.rows = s.terrain.rows;
    g.cols = s.terrain.cols;
    g.cell_size_m = s.terrain.cell_size_m;
    check_placement(s, g);
  }
  return s;
}

}  // namespace

std::string to_string(CompletionKind kind) {
  static constexpr EnumName<CompletionKind> kNames[] = {{CompletionKind::kAgentsAtGoal, "agents_at_goal"},
                                                        {CompletionKind::kPayloadPath, "payload_path"},
                                                        {CompletionKind::kLevelSite, "level_site"}};
  return enum_to_string(kNames, kind);
}

namespace {

proto::Scenario parse_message(const std::string& text, const std::string& source_name) {
  proto::Scenario message;
  google::protobuf::TextFormat::Parser parser;
  FirstErrorCollector errors;
  parser.RecordErrorsTo(&errors);
  parser.AllowUnknownField(false);
  if (!parser.ParseFromString(text, &message)) {
    if (errors.has_error()) throw TextFormatError(source_name, errors.line(), errors.column(), errors.message());
    throw ParseError(source_name, 0, "not a valid scenario (protobuf text format)");
  }
  return message;
}

/// The field names of `type`, joined for messages.
std::string field_names(const google::protobuf::Descriptor& type) {
  std::string names;
  for (int i = 0; i < type.field_count(); ++i) names += (i == 0 ? "" : ", ") + type.field(i)->name();
  return names;
}

/// Sets FIELD (the path's remaining parts from `part`) to `value` in `message` and every element it selects.
void apply_override(google::protobuf::Message& message, const std::vector<std::string>& parts, std::size_t part,
                    const std::string& value, const std::string& where) {
  using google::protobuf::FieldDescriptor;
  std::string name = parts[part];
  std::optional<int> index;
  if (const std::size_t open = name.find('['); open != std::string::npos) {
    const std::string digits = name.substr(open + 1, name.size() - open - 2);
    if (name.back() != ']' || digits.empty() || digits.size() > 6 ||
        !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; }))
      throw InvalidArgument(fmt::format("{}: '{}' is not FIELD or FIELD[INDEX]", where, name));
    index = std::stoi(digits);
    name = name.substr(0, open);
  }
  const google::protobuf::Descriptor& type = *message.GetDescriptor();
  const FieldDescriptor* field = type.FindFieldByName(name);
  if (field == nullptr)
    throw InvalidArgument(
        fmt::format("{}: {} has no field '{}'; valid: {}", where, type.name(), name, field_names(type)));
  const google::protobuf::Reflection& reflection = *message.GetReflection();
  const bool last = part + 1 == parts.size();
  const bool is_message = field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE;
  if (field->is_map())
    throw InvalidArgument(fmt::format("{}: '{}' is a map; edit the scenario file instead", where, name));
  if (last == is_message)
    throw InvalidArgument(is_message ? fmt::format("{}: '{}' is a message: name one of its fields ({})", where, name,
                                                   field_names(*field->message_type()))
                                     : fmt::format("{}: '{}' is a value: it has no fields", where, name));
  if (index && !field->is_repeated()) throw InvalidArgument(fmt::format("{}: '{}' is not repeated", where, name));
  if (field->is_repeated()) {
    const int size = reflection.FieldSize(message, field);
    if (index && *index >= size)
      throw InvalidArgument(fmt::format("{}: {}[{}] does not exist (the scenario has {})", where, name, *index, size));
    if (last)
      throw InvalidArgument(fmt::format("{}: repeated values cannot be set; edit the scenario file instead", where));
    for (int i = index.value_or(0); i < (index ? *index + 1 : size); ++i)
      apply_override(*reflection.MutableRepeatedMessage(&message, field, i), parts, part + 1, value, where);
    return;
  }
  if (!last) {
    apply_override(*reflection.MutableMessage(&message, field), parts, part + 1, value, where);
    return;
  }
  // A scalar: the text format's own parser, as if the file said `name: value` (strings may go without quotes).
  std::string literal = value;
  if (field->cpp_type() == FieldDescriptor::CPPTYPE_STRING && (literal.empty() || literal.front() != '"'))
    literal = fmt::format("\"{}\"", literal);
  google::protobuf::TextFormat::Parser parser;
  FirstErrorCollector errors;  // keeps protobuf's own message off stderr: ours says it
  parser.RecordErrorsTo(&errors);
  if (!parser.ParseFieldValueFromString(literal, field, &message))
    throw InvalidArgument(
        fmt::format("{}: '{}' is not a valid {} for '{}'", where, value, field->cpp_type_name(), name));
}

void apply_overrides(proto::Scenario& message, const std::vector<std::string>& overrides) {
  for (const std::string& override : overrides) {
    const std::string where = fmt::format("--set '{}'", override);
    const std::size_t equals = override.find('=');
    if (equals == std::string::npos || equals == 0)
      throw InvalidArgument(fmt::format("{}: expected FIELD=VALUE", where));
    const std::string path = override.substr(0, equals);
    if (path.back() == '.') throw InvalidArgument(fmt::format("{}: the field path ends with '.'", where));
    std::vector<std::string> parts;
    std::stringstream names(path);
    for (std::string part; std::getline(names, part, '.');) {
      if (part.empty()) throw InvalidArgument(fmt::format("{}: empty field name in '{}'", where, path));
      parts.push_back(part);
    }
    apply_override(message, parts, 0, override.substr(equals + 1), where);
  }
}

}  // namespace

Scenario parse_scenario(const std::string& text, const std::string& source_name,
                        const std::vector<std::string>& overrides) {
  proto::Scenario message = parse_message(text, source_name);
  apply_overrides(message, overrides);
  Scenario s = to_scenario(message, source_name);
  s.overrides = overrides;
  return s;
}

std::string read_scenario_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot open scenario file '{}'", path));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError(fmt::format("cannot read scenario file '{}'", path));
  return text.str();
}

Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_scenario(read_scenario_text(path), path, overrides);
}

}  // namespace marsala::scenario
