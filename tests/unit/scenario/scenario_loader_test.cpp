#include "marsala/scenario/scenario.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::scenario {
namespace {

std::string source_dir() {
  const char* dir = std::getenv("MARSALA_SOURCE_DIR");
  return dir ? dir : ".";
}

const char* const kMinimal = R"(
name: "mini"
terrain { generator: "flat" rows: 20 cols: 30 cell_size_m: 0.5 }
robot_type { name: "bot" }
agent { robot_type: "bot" start { x_m: 1 y_m: 1 } target { x_m: 10 y_m: 5 } }
goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 }
)";

/// kMinimal with `from` replaced by `to` (which must occur).
std::string edit(const std::string& from, const std::string& to) {
  std::string text = kMinimal;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

/// The message of the InvalidArgument that parsing `text` throws (fails the test when none is thrown).
std::string invalid(const std::string& text) {
  try {
    parse_scenario(text, "t.pbtxt");
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidArgument for\n" << text;
  return {};
}

TEST(ScenarioLoader, DepositorDefaultsToLayerAndReadsItsParameters) {
  const Scenario plain = parse_scenario(kMinimal, "t.pbtxt");
  EXPECT_EQ(plain.robot_types[0].depositor.kind, DepositorKind::kLayer);
  EXPECT_FALSE(plain.robot_types[0].depositor.cube_size_m);
  const Scenario cube =
      parse_scenario(edit("robot_type { name: \"bot\" }",
                          "robot_type { name: \"bot\" body { cube_size_m: 0.5 } depositor { name: \"cube\" } }"),
                     "t.pbtxt");
  EXPECT_EQ(cube.robot_types[0].depositor.kind, DepositorKind::kCube);
  EXPECT_EQ(depositor_cube_size_m(cube.robot_types[0]), 0.5);  // the body's
  const Scenario own = parse_scenario(
      edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" depositor { name: \"cube\" cube_size_m: 0.6 } }"),
      "t.pbtxt");
  EXPECT_EQ(depositor_cube_size_m(own.robot_types[0]), 0.6);
  const Scenario cone = parse_scenario(
      edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" depositor { name: \"cone\" repose_deg: 40 } }"),
      "t.pbtxt");
  EXPECT_EQ(cone.robot_types[0].depositor.kind, DepositorKind::kCone);
  EXPECT_EQ(cone.robot_types[0].depositor.repose_deg, 40.0);
  EXPECT_EQ(parse_scenario(edit("robot_type { name: \"bot\" }",
                                "robot_type { name: \"bot\" depositor { name: \"cone\" } }"),
                           "t.pbtxt")
                .robot_types[0]
                .depositor.repose_deg,
            34.0);
}

TEST(ScenarioLoader, BadDepositorsNameTheFieldAndTheRobotType) {
  const auto with = [](const std::string& depositor) {
    return invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" depositor { " + depositor + " } }"));
  };
  EXPECT_EQ(with("name: \"shovel\""),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.name: unknown depositor 'shovel'; valid: cone, cube, layer");
  EXPECT_EQ(with("name: \"cone\" repose_deg: nan"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.repose_deg: nan must be finite and < 1e6 in magnitude");
  EXPECT_EQ(with("name: \"cone\" repose_deg: 90"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.repose_deg: 90 must be in (0, 90) degrees");
  EXPECT_EQ(with("name: \"cone\" repose_deg: 0"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.repose_deg: 0 must be in (0, 90) degrees");
  EXPECT_EQ(with("name: \"cube\" cube_size_m: -0.1"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.cube_size_m: -0.1 must be > 0");
  EXPECT_EQ(with("name: \"cone\" cube_size_m: 0.1"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.cube_size_m: applies to the 'cube' depositor only");
  EXPECT_EQ(with("repose_deg: 30"),
            "scenario t.pbtxt: robot_type[0] (bot).depositor.repose_deg: applies to the 'cone' depositor only");
}

TEST(ScenarioLoader, TheRampScenarioLoadsWithEveryValue) {
  const Scenario s = load_scenario(source_dir() + "/deploy/scenarios/ramp.pbtxt");
  EXPECT_EQ(s.name, "ramp");
  EXPECT_EQ(s.terrain.method, "platform");
  EXPECT_EQ(s.terrain.rows, 200);
  EXPECT_EQ(s.terrain.cols, 300);
  EXPECT_EQ(s.terrain.cell_size_m, 0.1);
  EXPECT_EQ(s.terrain.seed, 1u);
  EXPECT_EQ(s.terrain.params.at("height"), 1.5);
  EXPECT_EQ(s.terrain.params.at("centre_x"), 23.0);
  EXPECT_TRUE(s.terrain.file.empty());
  ASSERT_EQ(s.robot_types.size(), 1u);
  const RobotType& husky = s.robot_types[0];
  EXPECT_EQ(husky.name, "husky");
  EXPECT_EQ(husky.behaviour, "ramp_builder");
  EXPECT_EQ(husky.body.navigability.kappa, 0.3);
  EXPECT_EQ(husky.body.navigability.delta_m, 1.0);
  EXPECT_EQ(husky.body.navigability.eps_m, 0.05);
  EXPECT_EQ(husky.body.max_step_m, 0.2);
  EXPECT_EQ(husky.body.max_deposit_m3, 0.02);
  EXPECT_EQ(husky.body.material_capacity_m3, 10.0);
  EXPECT_EQ(husky.body.reach_m, 1.5);
  EXPECT_EQ(husky.body.sensing_range_m, 4.0);
  EXPECT_EQ(husky.body.proximity_range_m, 3.0);
  EXPECT_EQ(husky.body.cube_size_m, 0.05);
  ASSERT_EQ(s.slots.size(), 3u);
  for (std::uint32_t id = 1; id <= 3; ++id) {
    const AgentSlot& slot = s.slots[id - 1];
    EXPECT_EQ(slot.id, id);
    EXPECT_EQ(slot.robot_type, "husky");
    EXPECT_EQ(slot.start.x, 5.05);
    EXPECT_EQ(slot.target.x, 22.05);
    EXPECT_EQ(slot.start.y, slot.target.y);  // straight ahead
    EXPECT_EQ(&s.robot_for(id), &s.robot_types[0]);
  }
  EXPECT_NEAR(s.slots[1].start.y - s.slots[0].start.y, 3.0, 1e-12);  // spaced 3 m along the platform
  EXPECT_EQ(s.goal.area.x0, 18.0);
  EXPECT_EQ(s.goal.area.x1, 28.0);
  EXPECT_EQ(s.goal.area.y0, 3.0);
  EXPECT_EQ(s.goal.area.y1, 17.0);
  EXPECT_EQ(s.goal.min_height_m, 1.4);
  EXPECT_EQ(s.goal.target_radius_m, 0.25);
  EXPECT_EQ(s.base.centre.x, 3.05);
  EXPECT_EQ(s.base.radius_m, 1.5);
  EXPECT_EQ(s.max_steps, 4000u);
  EXPECT_EQ(s.step_deadline_s, 10.0);
  EXPECT_EQ(s.tile_size, 16);
  EXPECT_EQ(s.seed, 1u);
  EXPECT_THROW(s.robot_for(0), InvalidArgument);
  EXPECT_THROW(s.robot_for(4), InvalidArgument);
  // The kappa variants differ only in kappa and name.
  for (const auto& [file, kappa] : {std::pair<const char*, double>{"ramp_k0.2.pbtxt", 0.2}, {"ramp_k0.5.pbtxt", 0.5}}) {
    const Scenario v = load_scenario(source_dir() + "/deploy/scenarios/" + file);
    EXPECT_EQ(v.robot_types[0].body.navigability.kappa, kappa);
    EXPECT_EQ(v.robot_types[0].body.navigability.delta_m, 1.0);
    EXPECT_EQ(v.slots.size(), 3u);
  }
}

TEST(ScenarioLoader, DefaultsFillWhatIsLeftOut) {
  const Scenario s = parse_scenario(kMinimal, "mini.pbtxt");
  const RobotBody defaults;
  EXPECT_EQ(s.source_path, "mini.pbtxt");
  EXPECT_EQ(s.robot_types[0].behaviour, "ramp_builder");
  EXPECT_EQ(s.robot_types[0].body.navigability.kappa, defaults.navigability.kappa);
  EXPECT_EQ(s.robot_types[0].body.reach_m, defaults.reach_m);
  EXPECT_EQ(s.robot_types[0].body.material_capacity_m3, defaults.material_capacity_m3);
  EXPECT_EQ(s.terrain.seed, 1u);
  EXPECT_EQ(s.goal.min_height_m, -1e9);
  EXPECT_EQ(s.goal.target_radius_m, 0.0);  // no target condition
  EXPECT_EQ(s.base.radius_m, 1.0);
  EXPECT_EQ(s.max_steps, 5000u);
  EXPECT_EQ(s.step_deadline_s, 10.0);
  EXPECT_EQ(s.tile_size, 16);
  EXPECT_EQ(s.seed, 1u);
  // Generator defaults: 100 x 100 cells of 0.1 m.
  const Scenario d = parse_scenario(R"(
name: "d"
terrain { generator: "flat" }
robot_type { name: "bot" }
agent { robot_type: "bot" start { x_m: 1 y_m: 1 } target { x_m: 9.95 y_m: 9.95 } }
goal { x0_m: 9 y0_m: 9 x1_m: 10 y1_m: 10 })",
                                    "d.pbtxt");
  EXPECT_EQ(d.terrain.rows, 100);
  EXPECT_EQ(d.terrain.cols, 100);
  EXPECT_EQ(d.terrain.cell_size_m, 0.1);
  // Heterogeneous teams: slots name different robot types.
  const Scenario h = parse_scenario(std::string(kMinimal) + R"(
robot_type { name: "digger" behaviour: "digger" body { kappa: 0.5 reach_m: 2 } }
agent { id: 2 robot_type: "digger" start { x_m: 2 y_m: 2 } target { x_m: 3 y_m: 3 } })",
                                    "h.pbtxt");
  EXPECT_EQ(h.robot_for(1).name, "bot");
  EXPECT_EQ(h.robot_for(2).behaviour, "digger");
  EXPECT_EQ(h.robot_for(2).body.navigability.kappa, 0.5);
  EXPECT_EQ(h.robot_for(2).body.reach_m, 2.0);
}

TEST(ScenarioLoader, SyntaxErrorsNameFileLineAndColumn) {
  try {
    parse_scenario("name: \"x\"\n\nterrain { rows: 12 \n  cols: abc }\n", "broken.pbtxt");
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("broken.pbtxt:4:", 0), 0u) << e.what();
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.file(), "broken.pbtxt");
  }
  try {
    parse_scenario(std::string(kMinimal) + "\nspeed: 3\n", "unknown.pbtxt");
    FAIL() << "expected a ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("unknown.pbtxt:8:", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("speed"), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      parse_scenario(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { wheels: 4 } }"), "t"),
      ParseError);
  EXPECT_THROW(parse_scenario(edit("name: \"mini\"", "name: \"mini\" name: \"again\""), "t"), ParseError);
  EXPECT_THROW(load_scenario("/nonexistent/scenario.pbtxt"), IoError);
}

TEST(ScenarioLoader, BadValuesNameTheField) {
  EXPECT_NE(invalid(edit("robot_type: \"bot\"", "robot_type: \"tank\""))
                .find("agent[0] (agent 1).robot_type: unknown robot type 'tank'; valid: bot"),
            std::string::npos);
  EXPECT_NE(invalid(edit("\"flat\"", "\"volcano\""))
                .find("terrain.generator: unknown generator 'volcano'; valid generators:"),
            std::string::npos);
  EXPECT_NE(invalid(edit("target { x_m: 10 y_m: 5 }", "target { x_m: 16 y_m: 5 }"))
                .find("agent[0] (agent 1).target: (16, 5) is off the terrain"),
            std::string::npos);
  EXPECT_NE(invalid(edit("start { x_m: 1 y_m: 1 }", "start { x_m: 1 y_m: -0.1 }")).find(".start"), std::string::npos);
  EXPECT_NE(invalid(edit("start { x_m: 1 y_m: 1 }", "start { x_m: nan y_m: 1 }")).find("start.x_m: nan must be finite"),
            std::string::npos);
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { kappa: nan } }"))
                .find("robot_type[0].body: kappa"),
            std::string::npos);
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { reach_m: inf } }"))
                .find("reach_m"),
            std::string::npos);
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { delta_m: -1 } }"))
                .find("delta_m = -1"),
            std::string::npos);
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { max_step_m: 2e6 } }"))
                .find("max_step_m"),
            std::string::npos);
  // A step longer than half the body (delta 1 m) could carry it over a wall: refused, naming the bound.
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { max_step_m: 3 } }"))
                .find("max_step_m = 3: exceeds half the body length (delta_m / 2 = 0.5 m)"),
            std::string::npos);
  EXPECT_NO_THROW(parse_scenario(
      edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" body { max_step_m: 0.5 } }"), "t.pbtxt"));
  // Zero agents, no robot types.
  const std::string no_agents =
      edit("agent { robot_type: \"bot\" start { x_m: 1 y_m: 1 } target { x_m: 10 y_m: 5 } }", "");
  EXPECT_NE(invalid(no_agents).find("agent: at least one agent slot"), std::string::npos);
  EXPECT_NE(invalid(edit("robot_type { name: \"bot\" }", "")).find("robot_type: at least one"), std::string::npos);
  // Negative and zero sizes.
  EXPECT_NE(invalid(edit("rows: 20", "rows: -20")).find("terrain.rows: -20 must be > 0"), std::string::npos);
  EXPECT_NE(invalid(edit("cols: 30", "cols: 0")).find("terrain.cols: 0 must be > 0"), std::string::npos);
  EXPECT_NE(invalid(edit("cell_size_m: 0.5", "cell_size_m: -0.5")).find("terrain.cell_size_m: -0.5 must be > 0"),
            std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "tile_size: 0").find("tile_size"), std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "max_steps: 0").find("max_steps"), std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "step_deadline_s: -1").find("step_deadline_s"), std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "base { x_m: 1 y_m: 1 radius_m: 0 }").find("base.radius_m"),
            std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "base { x_m: 100 y_m: 1 }").find("base: (100, 1) is off the terrain"),
            std::string::npos);
  // Structure.
  EXPECT_NE(invalid(edit("goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 }", "goal { x0_m: 11 y0_m: 4 x1_m: 9 y1_m: 6 }"))
                .find("goal"),
            std::string::npos);
  EXPECT_NE(invalid(edit("goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 }", "goal { x0_m: 9 y0_m: 4 x1_m: 16 y1_m: 6 }"))
                .find("not inside the terrain"),
            std::string::npos);
  EXPECT_NE(invalid(edit("goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 }", "")).find("goal: give exactly one of"),
            std::string::npos);
  // A target radius must be > 0, and every agent's target must lie in the box it completes in.
  EXPECT_NE(invalid(edit("y1_m: 6 }", "y1_m: 6 target_radius_m: 0 }")).find("goal.target_radius_m: 0 must be > 0"),
            std::string::npos);
  EXPECT_EQ(parse_scenario(edit("y1_m: 6 }", "y1_m: 6 target_radius_m: 0.5 }"), "t.pbtxt").goal.target_radius_m, 0.5);
  EXPECT_NE(invalid(edit("x1_m: 11 y1_m: 6 }", "x1_m: 11 y1_m: 4.5 target_radius_m: 0.5 }"))
                .find("agent[0] (agent 1).target: (10, 5) lies outside the goal box"),
            std::string::npos);
  EXPECT_NE(invalid(edit("name: \"mini\"", "name: \"a b\"")).find("name"), std::string::npos);
  EXPECT_NE(invalid(edit("name: \"mini\"", "")).find("name"), std::string::npos);
  EXPECT_NE(invalid(edit("generator: \"flat\"", "generator: \"flat\" file: \"x.asc\"")).find("exactly one"),
            std::string::npos);
  EXPECT_NE(invalid(edit("robot_type: \"bot\"", "id: 2 robot_type: \"bot\"")).find("differs from its position"),
            std::string::npos);
  EXPECT_NE(invalid(std::string(kMinimal) + "robot_type { name: \"bot\" }").find("defined twice"), std::string::npos);
  EXPECT_NE(invalid(edit(" target { x_m: 10 y_m: 5 }", "")).find("target: missing"), std::string::npos);
}

// --set FIELD=VALUE (marsala-world and marsala-agent): fields of the file changed before validation.
const char* const kTwoTypes = R"(
name: "two"
terrain { generator: "flat" rows: 20 cols: 30 cell_size_m: 0.5 }
robot_type { name: "a" body { sensing_range_m: 3 } }
robot_type { name: "b" body { kappa: 0.4 } }
agent { robot_type: "a" start { x_m: 1 y_m: 1 } target { x_m: 10 y_m: 5 } }
agent { robot_type: "b" start { x_m: 2 y_m: 1 } target { x_m: 10 y_m: 5 } }
goal { x0_m: 9 y0_m: 4 x1_m: 11 y1_m: 6 }
)";

/// The message of the InvalidArgument that parsing kTwoTypes with `overrides` throws (fails the test when none).
std::string invalid_override(const std::vector<std::string>& overrides) {
  try {
    parse_scenario(kTwoTypes, "t.pbtxt", overrides);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidArgument for " << overrides.front();
  return {};
}

TEST(ScenarioOverrides, ARepeatedFieldChangesInEveryElementOrInTheIndexedOne) {
  const Scenario all = parse_scenario(kTwoTypes, "t.pbtxt", {"robot_type.body.sensing_range_m=5.5"});
  EXPECT_EQ(all.robot_types[0].body.sensing_range_m, 5.5);
  EXPECT_EQ(all.robot_types[1].body.sensing_range_m, 5.5);
  EXPECT_EQ(all.robot_types[1].body.navigability.kappa, 0.4);  // the rest of the block is kept
  EXPECT_EQ(all.overrides, std::vector<std::string>{"robot_type.body.sensing_range_m=5.5"});

  const Scenario one = parse_scenario(kTwoTypes, "t.pbtxt", {"robot_type[1].body.kappa=0.2", "max_steps=123"});
  EXPECT_EQ(one.robot_types[0].body.navigability.kappa, 0.3);  // the default, untouched
  EXPECT_EQ(one.robot_types[1].body.navigability.kappa, 0.2);
  EXPECT_EQ(one.max_steps, 123u);
  EXPECT_TRUE(parse_scenario(kTwoTypes, "t.pbtxt").overrides.empty());
}

TEST(ScenarioOverrides, StringsNeedNoQuotesAndLaterOverridesWin) {
  const Scenario s = parse_scenario(kTwoTypes, "t.pbtxt",
                                    {"robot_type[0].behaviour=idle", "seed=7", "seed=9", "robot_type[1].behaviour=\"idle\""});
  EXPECT_EQ(s.robot_types[0].behaviour, "idle");
  EXPECT_EQ(s.robot_types[1].behaviour, "idle");
  EXPECT_EQ(s.seed, 9u);
}

TEST(ScenarioOverrides, BadOverridesNameTheOverrideAndWhatIsWrong) {
  const auto has = [](const std::string& message, const std::string& part) {
    return message.find(part) != std::string::npos;
  };
  std::string m = invalid_override({"robot_type.body.sensing=5"});
  EXPECT_TRUE(has(m, "--set 'robot_type.body.sensing=5'")) << m;
  EXPECT_TRUE(has(m, "Body has no field 'sensing'; valid: kappa, delta_m")) << m;
  m = invalid_override({"robot_type.body=5"});
  EXPECT_TRUE(has(m, "'body' is a message: name one of its fields (kappa")) << m;
  m = invalid_override({"robot_type[2].body.kappa=0.1"});
  EXPECT_TRUE(has(m, "robot_type[2] does not exist (the scenario has 2)")) << m;
  m = invalid_override({"robot_type.body.kappa=steep"});
  EXPECT_TRUE(has(m, "'steep' is not a valid double for 'kappa'")) << m;
  m = invalid_override({"max_steps[0]=5"});
  EXPECT_TRUE(has(m, "'max_steps' is not repeated")) << m;
  m = invalid_override({"terrain.params=5"});
  EXPECT_TRUE(has(m, "'params' is a map")) << m;
  m = invalid_override({"max_steps.x=5"});
  EXPECT_TRUE(has(m, "'max_steps' is a value: it has no fields")) << m;
  EXPECT_TRUE(has(invalid_override({"max_steps"}), "expected FIELD=VALUE"));
  EXPECT_TRUE(has(invalid_override({"=5"}), "expected FIELD=VALUE"));
  EXPECT_TRUE(has(invalid_override({"robot_type..body=5"}), "empty field name"));
  EXPECT_TRUE(has(invalid_override({"robot_type[x].body.kappa=5"}), "is not FIELD or FIELD[INDEX]"));
  // A well-formed override still meets the scenario's validation.
  m = invalid_override({"robot_type[1].body.sensing_range_m=-1"});
  EXPECT_TRUE(has(m, "robot_type[1].body")) << m;
  m = invalid_override({"robot_type.body.kappa=nan"});
  EXPECT_TRUE(has(m, "kappa = nan")) << m;
}

TEST(ScenarioLoader, SensorsTakeTheirNamedDefaultsAndTheFileOnTop) {
  const Scenario plain = parse_scenario(kMinimal, "t.pbtxt");
  EXPECT_EQ(plain.robot_types[0].sensor.kind, SensorKind::kGroundTruth);
  EXPECT_FALSE(plain.robot_types[0].sensor.casts_rays());

  const Scenario laser =
      parse_scenario(edit("robot_type { name: \"bot\" }",
                          "robot_type { name: \"bot\" sensor { name: \"laser\" max_range_m: 5 scan_every_steps: 3 } }"),
                     "t.pbtxt");
  const SensorSpec& l = laser.robot_types[0].sensor;
  EXPECT_EQ(l.kind, SensorKind::kLaser);
  EXPECT_EQ(l.max_range_m, 5.0);
  EXPECT_EQ(l.scan_every_steps, 3);
  EXPECT_EQ(l.horizontal_fov_deg, sensor_defaults(SensorKind::kLaser).horizontal_fov_deg);
  EXPECT_EQ(l.vertical_min_deg, sensor_defaults(SensorKind::kLaser).vertical_min_deg);

  const Scenario rgbd = parse_scenario(
      edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" sensor { name: \"rgbd\" } }"), "t.pbtxt");
  const SensorSpec& c = rgbd.robot_types[0].sensor;
  EXPECT_EQ(c.kind, SensorKind::kRgbd);
  EXPECT_EQ(c.horizontal_fov_deg, 87.0);
  EXPECT_EQ(c.ray_count(), 64 * 48);
  EXPECT_GT(c.noise_sd_at(6.0), c.noise_sd_at(1.0));  // a depth camera's noise grows with range
}

TEST(ScenarioLoader, BadSensorsNameTheRobotTypeAndField) {
  const auto with = [](const std::string& sensor) {
    return invalid(edit("robot_type { name: \"bot\" }", "robot_type { name: \"bot\" sensor { " + sensor + " } }"));
  };
  std::string what = with("name: \"sonar\"");
  EXPECT_NE(what.find("robot_type[0].sensor.name: unknown sensor 'sonar'; valid: ground_truth, laser, rgbd"),
            std::string::npos)
      << what;
  what = with("name: \"laser\" max_range_m: nan");
  EXPECT_NE(what.find("robot_type[0].sensor.max_range_m: nan must be in (min_range_m, 10000] m"), std::string::npos)
      << what;
  what = with("name: \"laser\" min_range_m: 9");  // beyond the default max range of 8 m
  EXPECT_NE(what.find("robot_type[0].sensor.max_range_m"), std::string::npos) << what;
  what = with("name: \"rgbd\" noise_sd_m: -0.1");
  EXPECT_NE(what.find("robot_type[0].sensor.noise_sd_m: -0.1 must be in [0, 10] m"), std::string::npos) << what;
  what = with("name: \"laser\" horizontal_resolution_deg: 0");
  EXPECT_NE(what.find("robot_type[0].sensor.horizontal_resolution_deg"), std::string::npos) << what;
  what = with("name: \"laser\" vertical_min_deg: 20 vertical_max_deg: 10");
  EXPECT_NE(what.find("robot_type[0].sensor.vertical_max_deg"), std::string::npos) << what;
  what = with("name: \"laser\" vertical_min_deg: -91");
  EXPECT_NE(what.find("robot_type[0].sensor.vertical_min_deg"), std::string::npos) << what;
  what = with("name: \"laser\" scan_every_steps: 0");
  EXPECT_NE(what.find("robot_type[0].sensor.scan_every_steps: 0 must be in [1, 1000000]"), std::string::npos) << what;
  what = with("name: \"laser\" mount_height_m: inf");
  EXPECT_NE(what.find("robot_type[0].sensor.mount_height_m"), std::string::npos) << what;
  what = with("name: \"laser\" horizontal_resolution_deg: 0.01 vertical_resolution_deg: 0.01");
  EXPECT_NE(what.find("robot_type[0].sensor.resolution"), std::string::npos) << what;
  what = with("max_range_m: 3");
  EXPECT_NE(what.find("robot_type[0].sensor: ground_truth takes no parameters"), std::string::npos) << what;
}

TEST(ScenarioLoader, StallStepsDefaultsAndRange) {
  EXPECT_EQ(parse_scenario(kMinimal, "t.pbtxt").stall_steps, kDefaultStallSteps);
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + "stall_steps: 0", "t.pbtxt").stall_steps, 0u);  // never
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + "stall_steps: 1", "t.pbtxt").stall_steps, 1u);
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + "stall_steps: 1000000000", "t.pbtxt").stall_steps, 1000000000u);
  EXPECT_EQ(parse_scenario(kMinimal, "t.pbtxt", {"stall_steps=25"}).stall_steps, 25u);
  // One line naming the field, for a negative and an absurd value, from the file and from --set.
  EXPECT_EQ(invalid(std::string(kMinimal) + "stall_steps: -5"),
            "scenario t.pbtxt: stall_steps: -5 must be 0 (never) or in 1..1000000000");
  EXPECT_EQ(invalid(std::string(kMinimal) + "stall_steps: 1000000001"),
            "scenario t.pbtxt: stall_steps: 1000000001 must be 0 (never) or in 1..1000000000");
  EXPECT_NE(invalid_override({"stall_steps=-1"}).find("stall_steps: -1 must be 0 (never)"), std::string::npos);
}

TEST(ScenarioLoader, StandingAnswersOnUnlessTurnedOff) {
  EXPECT_TRUE(parse_scenario(kMinimal, "t.pbtxt").standing_answers);
  EXPECT_FALSE(parse_scenario(std::string(kMinimal) + "standing_answers: false", "t.pbtxt").standing_answers);
  EXPECT_FALSE(parse_scenario(kMinimal, "t.pbtxt", {"standing_answers=false"}).standing_answers);
  EXPECT_NE(invalid_override({"standing_answers=maybe"}).find("standing_answers"), std::string::npos);
}

TEST(ScenarioLoader, RightOfWayOnUnlessTurnedOff) {
  EXPECT_TRUE(parse_scenario(kMinimal, "t.pbtxt").right_of_way);
  EXPECT_FALSE(parse_scenario(std::string(kMinimal) + "right_of_way: false", "t.pbtxt").right_of_way);
  EXPECT_TRUE(parse_scenario(std::string(kMinimal) + "right_of_way: true", "t.pbtxt").right_of_way);
  EXPECT_TRUE(parse_scenario(kMinimal, "t.pbtxt", {"right_of_way=true"}).right_of_way);
  EXPECT_FALSE(
      parse_scenario(std::string(kMinimal) + "right_of_way: true", "t.pbtxt", {"right_of_way=false"}).right_of_way);
}

}  // namespace
}  // namespace marsala::scenario
