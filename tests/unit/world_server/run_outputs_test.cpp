// What a run leaves behind for the paper's scenarios: summary.json's completion fields, the contents of final.png
// (depositor tints, the payload's path, from/to, agents, legend) and goal_vector_map.png.

#include "world_server/run_outputs.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/unit/world_server/world_fixtures.hpp"
#include "world_server/completion.hpp"
#include "world_server/step.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::payload_block;
using testing::request_for;
using testing::site_block;
using testing::small_scenario_text_completing;

constexpr double kSqrt2 = 1.4142135623730951;

scenario::Scenario scenario_with(const std::string& completion, const std::string& extra = "") {
  return scenario::parse_scenario(small_scenario_text_completing(completion, extra), "small.pbtxt");
}

double json_number(const std::string& json, const std::string& key) {
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = json.find(tag);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + tag.size(), nullptr);
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

RunInfo info_for(const std::string& name, bool completed) {
  RunInfo info;
  info.scenario = name;
  info.completed = completed;
  info.end_reason = completed ? "completed" : "max_steps";
  return info;
}

bool has_legend(const render::RenderOptions& o, const std::string& text, render::Rgb colour) {
  for (const auto& e : o.legend_entries)
    if (e.text == text && e.colour == colour) return true;
  return false;
}

/// Agent 1 deposits one layer on cell (29, 18), then one idle step.
void deposit_then_idle(WorldState& s) {
  bus::ActionRequest r = request_for(s, 1);
  r.depositions.push_back({29, 18, kLayer});
  apply_step(s, std::vector<bus::ActionRequest>{r});
  apply_step(s, std::vector<bus::ActionRequest>{request_for(s, 1)});
}

TEST(RunSummary, PayloadRunsReportThePathAndIdleSteps) {
  WorldState s = admitted_state(scenario_with(payload_block()), flat_terrain(), 1);
  deposit_then_idle(s);
  const std::string json = summary_json(s, info_for("small", true));
  EXPECT_TRUE(has(json, "\"completion\": \"payload_path\"")) << json;
  EXPECT_TRUE(has(json, "\"path_found\": true")) << json;
  EXPECT_TRUE(has(json, "\"idle_steps\": 1")) << json;
  EXPECT_TRUE(has(json, "\"completion_checks\": 1")) << json;  // the initial one; step 2 was not reached
  // From (0.55, 0.55) to (3.05, 3.05) on flat ground: 25 diagonal steps of 0.1 sqrt 2 m (the deposited layer of
  // 12.5 mm stays within eps).
  EXPECT_NEAR(json_number(json, "path_length_m"), 2.5 * kSqrt2, 1e-12);
  EXPECT_EQ(json_number(json, "path_length_m"), payload_path(s.terrain, s.payload_path)->length_m);
  EXPECT_EQ(json_number(json, "site_level_fraction"), 0.0);

  // A trench across the grid: no path, length 0.
  for (int r = 0; r < 40; ++r) s.terrain(r, 20) = -0.1;
  const std::string blocked = summary_json(s, info_for("small", false));
  EXPECT_TRUE(has(blocked, "\"path_found\": false")) << blocked;
  EXPECT_EQ(json_number(blocked, "path_length_m"), 0.0);
}

TEST(RunSummary, SiteRunsReportTheLevelFractionOthersTheirKind) {
  grid::Heightmap terrain = flat_terrain();
  terrain(15, 25) = -0.1;
  const WorldState site = admitted_state(scenario_with(site_block()), terrain, 1);
  const std::string json = summary_json(site, info_for("small", false));
  EXPECT_TRUE(has(json, "\"completion\": \"level_site\"")) << json;
  EXPECT_DOUBLE_EQ(json_number(json, "site_level_fraction"), 0.91);
  EXPECT_TRUE(has(json, "\"path_found\": false")) << json;

  RunInfo info = info_for("small", false);
  info.start_jitter_m = 0.25;
  info.seed = 99;
  const WorldState goal = admitted_state(testing::small_scenario(), flat_terrain(), 1);
  const std::string goal_json = summary_json(goal, info);
  EXPECT_TRUE(has(goal_json, "\"completion\": \"agents_at_goal\"")) << goal_json;
  EXPECT_TRUE(has(goal_json, "\"seed\": \"99\"")) << goal_json;
  EXPECT_EQ(json_number(goal_json, "start_jitter_m"), 0.25);
  EXPECT_EQ(json_number(goal_json, "completion_checks"), 0.0);
}

TEST(FinalPicture, PayloadRunsShowThePathEndsAgentsAndDepositors) {
  WorldState s = admitted_state(scenario_with(payload_block()), flat_terrain(), 2);
  deposit_then_idle(s);
  const auto route = payload_path(s.terrain, s.payload_path);
  ASSERT_TRUE(route);
  const render::RenderOptions o = final_picture_options(s, info_for("small", true), route);
  ASSERT_EQ(o.polylines.size(), 1u);
  ASSERT_EQ(o.polylines[0].points.size(), route->cells.size());
  EXPECT_EQ(o.polylines[0].points.front().x, s.terrain.cell_center(route->cells.front()).x);
  EXPECT_EQ(o.polylines[0].points.back().y, s.terrain.cell_center(route->cells.back()).y);
  ASSERT_TRUE(o.labels);
  EXPECT_EQ((*o.labels)(29, 18), 1u);
  // from (red square), to (green diamond), then the two agents (discs of their palette colour).
  ASSERT_EQ(o.points.size(), 4u);
  EXPECT_EQ(o.points[0].shape, render::PointShape::kSquare);
  EXPECT_EQ(o.points[0].at.x, 0.55);
  EXPECT_EQ(o.points[1].shape, render::PointShape::kDiamond);
  EXPECT_EQ(o.points[1].at.y, 3.05);
  EXPECT_NE(o.points[0].colour, o.points[1].colour);
  EXPECT_EQ(o.points[2].colour, render::label_colour(1));
  EXPECT_EQ(o.points[3].colour, render::label_colour(2));
  EXPECT_EQ(o.points[3].at.x, s.agent(2).x_m);
  ASSERT_EQ(o.circles.size(), 1u);
  EXPECT_EQ(o.circles[0].radius_m, 0.5);
  EXPECT_TRUE(has_legend(o, "agent 1", render::label_colour(1)));
  EXPECT_TRUE(has_legend(o, "agent 2", render::label_colour(2)));
  EXPECT_TRUE(has_legend(o, "payload path 3.54 m", o.polylines[0].colour));
  EXPECT_TRUE(has(o.title, "small: step 2, payload_path completed, path 3.54 m")) << o.title;

  // The deposited cell shows agent 1's colour: the picture's pixel is the untinted one blended 60% towards it.
  render::RenderOptions bare = o;
  bare.legend = false;
  bare.max_size_px = 400;  // 10 px per cell
  const render::Image tinted = render::render_terrain(s.terrain, bare);
  bare.labels.reset();
  const render::Image plain = render::render_terrain(s.terrain, bare);
  const std::size_t i = 3u * (static_cast<std::size_t>(29 * 10 + 5) * tinted.width + 18 * 10 + 5);
  const render::Rgb c = render::label_colour(1);
  EXPECT_NEAR(tinted.rgb[i], plain.rgb[i] + 0.6 * (c.r - plain.rgb[i]), 0.51);
  EXPECT_NEAR(tinted.rgb[i + 1], plain.rgb[i + 1] + 0.6 * (c.g - plain.rgb[i + 1]), 0.51);
  EXPECT_NEAR(tinted.rgb[i + 2], plain.rgb[i + 2] + 0.6 * (c.b - plain.rgb[i + 2]), 0.51);

  const render::RenderOptions none = final_picture_options(s, info_for("small", false), std::nullopt);
  EXPECT_TRUE(none.polylines.empty());
  EXPECT_TRUE(has(none.title, "payload_path not completed, no payload path")) << none.title;
}

TEST(FinalPicture, SitesAndGoalsAreOutlinedAndColoursRepeatAfterTwelveAgents) {
  const WorldState site = admitted_state(scenario_with(site_block()), flat_terrain(), 1);
  const render::RenderOptions so = final_picture_options(site, info_for("small", false), std::nullopt);
  ASSERT_EQ(so.rectangles.size(), 1u);
  EXPECT_EQ(so.rectangles[0].a.x, 2.0);
  EXPECT_EQ(so.rectangles[0].b.y, 3.0);
  EXPECT_FALSE(so.labels);  // nothing deposited
  EXPECT_TRUE(has(so.title, "level_site not completed, level 100.0%")) << so.title;

  std::string agents;
  for (int i = 0; i < 13; ++i)
    agents += "agent { robot_type: \"tester\" start { x_m: " + std::to_string(0.25 + 0.3 * i) +
              " y_m: 3.5 } target { x_m: 3 y_m: 3 } }\n";
  const scenario::Scenario many =
      scenario::parse_scenario(small_scenario_text_completing("goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }",
                                                              agents),
                               "many.pbtxt");
  const WorldState s = admitted_state(many, flat_terrain(), 16);
  const render::RenderOptions o = final_picture_options(s, info_for("many", false), std::nullopt);
  EXPECT_TRUE(has_legend(o, "agents 1, 13", render::label_colour(1)));
  EXPECT_TRUE(has_legend(o, "agents 4, 16", render::label_colour(4)));
  EXPECT_TRUE(has_legend(o, "agent 12", render::label_colour(12)));
  ASSERT_EQ(o.rectangles.size(), 1u);  // the goal
  ASSERT_EQ(o.markers.size(), 1u);     // its centre
  EXPECT_EQ(o.markers[0], (CellIndex{19, 30}));
}

class OutputFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("marsala_run_outputs_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(OutputFiles, GoalVectorMapPictureOnlyWhenTheScenarioHasOne) {
  const WorldState s = admitted_state(scenario_with(site_block()), flat_terrain(), 1);
  RunInfo info = info_for("small", false);
  write_final_outputs(dir_.string(), s, info);
  for (const char* name : {"summary.json", "terrain_final.asc", "final.png"}) EXPECT_TRUE(fs::exists(dir_ / name));
  EXPECT_FALSE(fs::exists(dir_ / "goal_vector_map.png"));

  processing::GoalVectorMapSpec spec;
  spec.x0_m = 2.0;
  spec.y0_m = 2.0;
  spec.x1_m = 3.0;
  spec.y1_m = 3.0;
  spec.strip_width_m = 0.5;
  spec.arrow_length_m = 0.5;
  info.goal_vector_map = spec;
  info.initial_terrain = flat_terrain(0.2);
  write_final_outputs(dir_.string(), s, info);
  EXPECT_GT(fs::file_size(dir_ / "goal_vector_map.png"), 500u);

  const processing::GoalVectorMap map(spec, s.terrain.geometry());
  const render::RenderOptions o = goal_vector_map_picture_options(s, info, map);
  EXPECT_EQ(o.arrows.size(), map.arrows().size());
  for (std::size_t k = 0; k < map.arrows().size(); ++k) {
    EXPECT_EQ(o.arrows[k].tail.x, map.arrows()[k].tail.x);
    EXPECT_EQ(o.arrows[k].head.y, map.arrows()[k].head.y);
  }
  ASSERT_GE(o.rectangles.size(), 1u);
  EXPECT_EQ(o.rectangles[0].a.x, 2.0);
  EXPECT_EQ(o.rectangles[0].b.x, 3.0);
  EXPECT_TRUE(has(o.title, "small: goal vector map, " + std::to_string(map.arrows().size()) + " arrows")) << o.title;
}

}  // namespace
}  // namespace marsala::world_server
