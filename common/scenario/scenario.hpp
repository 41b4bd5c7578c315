#pragma once
// A scenario as plain C++: terrain source, robot types, agent slots, goal, base station, clock settings.
// Loaded from protobuf text format (schema idl/scenario.proto) by load_scenario(); protobuf types never leave
// common/scenario.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "marsala/core/goal_vector_map.hpp"
#include "marsala/core/robot_type.hpp"

namespace marsala::scenario {

/// Where the world's terrain comes from: a generator (common/terrain/generators.hpp) or a file.
struct TerrainSource {
  // Generated terrain (used when `file` is empty).
  std::string method = "flat";  ///< generator name
  int rows = 100;
  int cols = 100;
  double cell_size_m = 0.1;
  std::uint64_t seed = 1;
  std::map<std::string, double> params;  ///< generator parameters
  // Or a terrain file (.asc or .tif), relative paths resolved against the scenario file's folder.
  std::string file;
  bool has_crop = false;
  double crop_x0_m = 0.0, crop_y0_m = 0.0, crop_width_m = 0.0, crop_height_m = 0.0;
  double resample_cell_size_m = 0.0;  ///< 0 = keep the file's cell size
  bool zero_base = false;             ///< shift so the lowest cell is at 0 m
};

/// One agent of the team: agent id (slot index + 1), robot type, start and target [m].
struct AgentSlot {
  std::uint32_t id = 0;
  std::string robot_type;  ///< a RobotType name
  Position start;   ///< [m]
  Position target;  ///< [m]
};

/// Completion: every live agent inside `area` standing at >= min_height_m and, when target_radius_m > 0, within
/// target_radius_m of its own slot's target.
struct Goal {
  Rect area;  ///< [m]
  double min_height_m = -1e9;
  double target_radius_m = 0.0;  ///< 0 = no target condition (the box alone) [m]
};

/// How the world decides that a run is complete.
enum class CompletionKind : std::uint8_t {
  kAgentsAtGoal = 0,  ///< every live agent inside the goal rectangle (Scenario::goal)
  kPayloadPath = 1,   ///< a payload has a navigable path (Scenario::payload_path)
  kLevelSite = 2,     ///< the site is level (Scenario::site)
};
/// "agents_at_goal", "payload_path", "level_site".
std::string to_string(CompletionKind kind);

/// A payload robot's navigable path from `from` to `to` [m] for kappa, delta, eps.
struct PayloadPath {
  NavigabilityParams navigability{0.2, 2.0, 0.05};  ///< the payload's kappa [m/m], delta_m [m], eps_m [m]
  Position from;  ///< [m]
  Position to;    ///< [m]
  std::uint32_t check_every_steps = 10;
};

/// A level site: `area`, at least min_fraction of its cells occupiable (kappa, delta, eps) and connected.
struct Site {
  Rect area;  ///< [m]
  NavigabilityParams navigability{0.1, 1.0, 0.05};  ///< what "level" means: kappa [m/m], delta_m [m], eps_m [m]
  double min_fraction = 1.0;
  std::uint32_t check_every_steps = 10;
};

/// The base station: material is refilled only within radius of its centre.
struct BaseStation {
  Position centre;  ///< [m]
  double radius_m = 1.0;
};

/// Default of Scenario::stall_steps: over 6 times the longest stretch without progress or terrain change of the
/// shipped runs (317 steps, site_rough with 11 robots; README "Stalls") [steps].
inline constexpr std::uint64_t kDefaultStallSteps = 2000;
/// The largest stall_steps a scenario may give [steps].
inline constexpr std::uint64_t kMaxStallSteps = 1000000000;

/// A whole scenario.
struct Scenario {
  std::string name;
  std::string source_path;  ///< the file it was loaded from (for messages and relative paths)
  std::vector<std::string> overrides;  ///< the "FIELD=VALUE" overrides applied to the file (load_scenario)
  TerrainSource terrain;
  std::vector<RobotType> robot_types;
  std::vector<AgentSlot> slots;  ///< slots[i].id == i + 1
  CompletionKind completion = CompletionKind::kAgentsAtGoal;
  Goal goal;                 ///< kAgentsAtGoal
  PayloadPath payload_path;  ///< kPayloadPath
  Site site;                 ///< kLevelSite
  bool has_goal_vector_map = false;
  GoalVectorMapSpec goal_vector_map;
  double start_jitter_m = 0.0;  ///< the world moves each start by up to this much (seeded) [m]
  BaseStation base;
  std::uint64_t max_steps = 5000;
  /// The run ends "stalled" after this many steps without a rise of its progress or a change of its terrain; 0: never
  /// (docs/runtime.md#stall) [steps].
  std::uint64_t stall_steps = kDefaultStallSteps;
  /// Builders keep the right-of-way protocol (docs/runtime.md#right-of-way); on by default, false turns it off.
  bool right_of_way = true;
  /// The world takes an agent's standing answer for it until a frame would tell it something new, writing it no frame
  /// meanwhile (docs/runtime.md#standing-answers); false: every live agent gets a frame every step.
  bool standing_answers = true;
  double step_deadline_s = 10.0;
  std::int32_t tile_size = 16;
  std::uint64_t seed = 1;

  /// The robot type of slot `id`; throws InvalidArgument when there is no such slot.
  const RobotType& robot_for(std::uint32_t id) const;
};

/// Loads and validates a scenario (protobuf text format). Throws ParseError with file and line for syntax
/// errors and unknown fields, InvalidArgument naming the field for bad values (non-positive sizes, unknown
/// robot type or generator, slots outside the terrain, NaN).
/// `overrides` ("FIELD=VALUE", marsala-world/marsala-agent --set) change fields of the file before validation: FIELD
/// is a dot-separated path of field names of idl/scenario.proto's Scenario; a repeated field applies to every element,
/// or to one with [i] (0-based, in file order), e.g. "robot_type.body.sensing_range_m=5",
/// "robot_type[1].body.kappa=0.2", "max_steps=20000"; VALUE is a scalar in text format (number, bool, string without
/// quotes). An override naming an unknown field (the valid ones are listed), a message, a map, a repeated value or an
/// index out of range, or with a value of the wrong type, throws InvalidArgument naming it.
Scenario load_scenario(const std::string& path, const std::vector<std::string>& overrides = {});
/// The text of a scenario file; throws IoError when it cannot be read.
std::string read_scenario_text(const std::string& path);
/// Same from text; `source_name` names it in messages and anchors relative terrain paths.
Scenario parse_scenario(const std::string& text, const std::string& source_name,
                        const std::vector<std::string>& overrides = {});

}  // namespace marsala::scenario
