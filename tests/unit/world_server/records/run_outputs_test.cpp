// What a run leaves behind for the paper's scenarios: summary.json's completion fields, the contents of final.png
// (depositor tints, the payload's path, from/to, agents, legend), goal_vector_map.png, and final_zoom.png: its window
// (zoom_window()) against hand-derived rectangles, its options (labels and markers cropped, world overlays unchanged,
// title), and the written picture read back with libpng and checked by pixels against final.png.

#include "marsala/world_server/records/run_outputs.hpp"

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

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
  info.end_reason = completed ? protocol::EndReason::kCompleted : protocol::EndReason::kMaxSteps;
  return info;
}

bool has_legend(const render::RenderOptions& o, const std::string& text, render::Rgb colour) {
  for (const auto& e : o.legend_entries)
    if (e.text == text && e.colour == colour) return true;
  return false;
}

/// Agent 1 deposits one layer on cell (29, 18), then one idle step.
void deposit_then_idle(WorldState& s) {
  protocol::ActionRequest r = request_for(s, 1);
  r.depositions.push_back({29, 18, kLayer});
  apply_step(s, std::vector<protocol::ActionRequest>{r});
  apply_step(s, std::vector<protocol::ActionRequest>{request_for(s, 1)});
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
  Heightmap terrain = flat_terrain();
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

TEST(RunSummary, SaysWhichSlotsOfTheTeamWereNotInTheRunAtItsEnd) {
  // Three slots: agent 2 never admitted, agent 3 admitted then dropped, agent 1 in the run to the end.
  WorldState s = make_world_state(testing::small_scenario(), flat_terrain(), 3);
  admit(s, testing::hello_for(s, 1, 1001));
  admit(s, testing::hello_for(s, 3, 1003));
  s.agents[2].alive = false;
  s.agents[2].dropped = true;
  EXPECT_EQ(missing_slots(s), (std::vector<std::uint32_t>{2, 3}));
  const std::string json = summary_json(s, info_for("small", true));
  EXPECT_EQ(json_number(json, "agents"), 3.0);
  EXPECT_EQ(json_number(json, "admitted"), 2.0);
  EXPECT_EQ(json_number(json, "slots_missing"), 2.0);
  std::string compact = json;
  compact.erase(std::remove_if(compact.begin(), compact.end(), [](char c) { return c == ' ' || c == '\n'; }),
                compact.end());
  EXPECT_TRUE(has(compact, "\"missing_agents\":[2,3]")) << json;
  // The whole team in the run: nothing missing, and the field is still there (0).
  const WorldState whole = admitted_state(testing::small_scenario(), flat_terrain(), 3);
  EXPECT_TRUE(missing_slots(whole).empty());
  EXPECT_EQ(json_number(summary_json(whole, info_for("small", true)), "slots_missing"), 0.0);
}

TEST(RunSummary, AForksSlotsThatLeftAtKAreNotMissingButItsOwnDeadSlotsAre) {
  // A fork of a 3-agent run at K = 40 with a team of 2: slot 3 left at K (the user's choice); then slot 2 dies.
  WorldState s = admitted_state(testing::small_scenario(), flat_terrain(), 3);
  drop_agent(s, 3, "not in the fork's team of 2");
  RunInfo info = info_for("small", true);
  ForkOrigin fork;
  fork.parent_dir = "parent";
  fork.at_step = 40;
  fork.parent_agents = 3;
  fork.agents = 2;
  fork.overrides = {"stall_steps=50"};
  info.fork = fork;
  EXPECT_EQ(missing_slots(s), (std::vector<std::uint32_t>{3}));  // as a run that is no fork
  EXPECT_TRUE(missing_slots(s, &fork).empty());
  std::string json = summary_json(s, info);
  EXPECT_EQ(json_number(json, "slots_missing"), 0.0) << json;
  std::string compact = json;
  compact.erase(std::remove_if(compact.begin(), compact.end(), [](char c) { return c == ' ' || c == '\n'; }),
                compact.end());
  EXPECT_TRUE(has(compact, "\"left_agents\":[3]")) << json;
  EXPECT_TRUE(has(compact, "\"overrides\":[\"stall_steps=50\"]")) << json;
  drop_agent(s, 2, "request writer lost liveliness");  // a slot of the fork's own team dies for real: missing
  EXPECT_EQ(missing_slots(s, &fork), (std::vector<std::uint32_t>{2}));
  EXPECT_EQ(json_number(summary_json(s, info), "slots_missing"), 1.0);
  // A fork that grew from 1 to 3 agents: slot 3 joined at K, slot 2 did not come (missing, honestly).
  WorldState grown = make_world_state(testing::small_scenario(), flat_terrain(), 3);
  admit(grown, testing::hello_for(grown, 1, 1001));
  admit(grown, testing::hello_for(grown, 3, 1003));
  fork.parent_agents = 1;
  fork.agents = 3;
  fork.overrides.clear();
  info.fork = fork;
  EXPECT_EQ(missing_slots(grown, &fork), (std::vector<std::uint32_t>{2}));
  compact = summary_json(grown, info);
  compact.erase(std::remove_if(compact.begin(), compact.end(), [](char c) { return c == ' ' || c == '\n'; }),
                compact.end());
  EXPECT_TRUE(has(compact, "\"joined_agents\":[3]")) << compact;
  EXPECT_TRUE(has(compact, "\"left_agents\":[]")) << compact;
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
  EXPECT_EQ(o.points[3].at.x, s.agent(2).position.x);
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
  const scenario::Scenario many = scenario::parse_scenario(
      small_scenario_text_completing("goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }", agents), "many.pbtxt");
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

TEST_F(OutputFiles, ARunNeverWritesIntoAnotherRunsFolderAndLeavesNoTemporaries) {
  EXPECT_NO_THROW(check_fresh_output_dir(dir_.string()));  // missing: fresh
  fs::create_directories(dir_ / "logs");
  std::ofstream(dir_ / "spawn.log") << "not a run file\n";
  EXPECT_NO_THROW(check_fresh_output_dir(dir_.string()));  // other files do not count
  const WorldState s = admitted_state(scenario_with(site_block()), flat_terrain(), 1);
  write_initial_outputs(dir_.string(), s.terrain);
  write_final_outputs(dir_.string(), s, info_for("small", false));
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();  // every file was renamed into place
  EXPECT_EQ(run_files_in(dir_.string()),
            (std::vector<std::string>{"summary.json", "terrain_initial.asc", "terrain_final.asc", "final.png",
                                      "final_3d.png"}));
  try {
    check_fresh_output_dir(dir_.string());
    FAIL() << "no throw";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("holds another run (summary.json, terrain_initial.asc, terrain_final.asc, "
                                         "final.png, final_3d.png)"),
              std::string::npos)
        << e.what();
  }
  // --replace: the run's files (and a leftover temporary) go, everything else stays.
  std::ofstream(dir_ / "run.log.tmp") << "torn";
  clear_run_files(dir_.string());
  EXPECT_EQ(run_files_in(dir_.string()), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(dir_ / "run.log.tmp"));
  EXPECT_TRUE(fs::exists(dir_ / "spawn.log"));
  EXPECT_TRUE(fs::exists(dir_ / "logs"));
  EXPECT_NO_THROW(check_fresh_output_dir(dir_.string()));
}

TEST_F(OutputFiles, ReplaceRemovesTheTimeLapseButNothingElseInFrames) {
  fs::create_directories(dir_ / "frames");
  for (const char* name : {"frame_000000.png", "frame_000100.png", "timelapse.mp4"})
    std::ofstream(dir_ / "frames" / name) << "x";
  clear_run_files(dir_.string());
  EXPECT_FALSE(fs::exists(dir_ / "frames"));  // emptied, then removed
  fs::create_directories(dir_ / "frames");
  std::ofstream(dir_ / "frames" / "frame_000007.png") << "x";
  std::ofstream(dir_ / "frames" / "notes.txt") << "mine";
  clear_run_files(dir_.string());
  EXPECT_FALSE(fs::exists(dir_ / "frames" / "frame_000007.png"));
  EXPECT_TRUE(fs::exists(dir_ / "frames" / "notes.txt"));  // not the run's: kept, and the folder with it
}

TEST_F(OutputFiles, AnEventLogThatCannotBeWrittenIsAnErrorNotASilentLoss) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here to play a full disk";
  EventLog log("/dev/full");  // opens, but every write fails with ENOSPC
  protocol::WorldEvent e;
  e.kind = protocol::EventKind::kDeposited;
  EXPECT_THROW(log.append(e), IoError);
  EXPECT_THROW(log.note(3, "a note"), IoError);
}

TEST(EventLogLines, AreJsonObjectsWithTheDepositedCells) {
  protocol::WorldEvent e;
  e.step = 42;
  e.agent_id = 3;
  e.kind = protocol::EventKind::kDeposited;
  e.volume_m3 = 0.000125;
  e.detail = "2 cells";
  EXPECT_EQ(event_json(e, {{10, 11, 0.05}, {10, 12, 0.1}}),
            "{\"step\":42,\"agent\":3,\"kind\":\"deposited\",\"volume_m3\":0.000125,\"detail\":\"2 cells\","
            "\"cells\":[[10,11,0.05],[10,12,0.1]]}");
  protocol::WorldEvent over;
  over.step = 7;
  over.kind = protocol::EventKind::kRunOver;
  over.detail = "a \"quoted\"\nreason";
  EXPECT_EQ(event_json(over), "{\"step\":7,\"agent\":0,\"kind\":\"run_over\",\"detail\":\"a \\\"quoted\\\"\\nreason\"}");
  EXPECT_EQ(note_json(5, "agent 2: request for past step 4 dropped"),
            "{\"step\":5,\"kind\":\"note\",\"detail\":\"agent 2: request for past step 4 dropped\"}");
}

TEST_F(OutputFiles, GoalVectorMapPictureOnlyWhenTheScenarioHasOne) {
  const WorldState s = admitted_state(scenario_with(site_block()), flat_terrain(), 1);
  RunInfo info = info_for("small", false);
  write_final_outputs(dir_.string(), s, info);
  for (const char* name : {"summary.json", "terrain_final.asc", "final.png"}) EXPECT_TRUE(fs::exists(dir_ / name));
  EXPECT_FALSE(fs::exists(dir_ / "goal_vector_map.png"));

  GoalVectorMapSpec spec;
  spec.area.x0 = 2.0;
  spec.area.y0 = 2.0;
  spec.area.x1 = 3.0;
  spec.area.y1 = 3.0;
  spec.strip_width_m = 0.5;
  spec.arrow_length_m = 0.5;
  info.goal_vector_map = spec;
  info.initial_terrain = flat_terrain(0.2);
  write_final_outputs(dir_.string(), s, info);
  EXPECT_GT(fs::file_size(dir_ / "goal_vector_map.png"), 500u);

  const GoalVectorMap map(spec, s.terrain.geometry());
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

/// A flat state of rows x cols cells of cs metres with its lower-left corner at (xll, yll): nothing deposited, no
/// agents, the base station at (bx, by) with radius br.
WorldState flat_state(int rows, int cols, double cs, double xll, double yll, double bx, double by, double br) {
  WorldState s;
  s.terrain = Heightmap(GridGeometry{rows, cols, xll, yll, cs}, 0.0);
  s.depositor = AgentIdGrid::Zero(rows, cols);
  s.base = {bx, by, br};
  return s;
}

/// Makes `s` a level_site run on the site [x0, x1] x [y0, y1] [m].
void level_site_on(WorldState& s, double x0, double y0, double x1, double y1) {
  s.completion = scenario::CompletionKind::kLevelSite;
  s.site.area.x0 = x0;
  s.site.area.y0 = y0;
  s.site.area.x1 = x1;
  s.site.area.y1 = y1;
}

/// Marks rows r0..r1 x cols c0..c1 (inclusive) as raised by agent `id`.
void deposit(WorldState& s, int r0, int r1, int c0, int c1, std::uint32_t id) {
  for (int r = r0; r <= r1; ++r)
    for (int c = c0; c <= c1; ++c) s.depositor(r, c) = id;
}

void expect_window(const std::optional<CellRect>& w, CellIndex first, int rows, int cols) {
  ASSERT_TRUE(w);
  EXPECT_EQ(w->first, first);
  EXPECT_EQ(w->rows, rows);
  EXPECT_EQ(w->cols, cols);
}

// 50 x 50 m (100 x 100 cells of 0.5 m); agent 1 raised rows 2..5, cols 94..97 (x, y in [47, 49] m); base (46, 46)
// r 1. Box [45, 49]^2 (4 m), margin max(3, 0.6) = 3 -> [42, 52]^2, already 10 m; clipped at the north and east
// edges (50 m): cols 84..99, rows 0..15.
WorldState corner_state() {
  WorldState s = flat_state(100, 100, 0.5, 0.0, 0.0, 46.0, 46.0, 1.0);
  deposit(s, 2, 5, 94, 97, 1);
  return s;
}

TEST(ZoomWindow, CornerDepositsAreFramedWithTheMarginAndClippedAtTheGridEdge) {
  const WorldState s = corner_state();
  const auto w = zoom_window(s, std::nullopt);
  expect_window(w, {0, 84}, 16, 16);
  // The crop keeps world coordinates: x in [42, 50], y in [42, 50].
  const Heightmap crop = s.terrain.window(w->first, w->rows, w->cols);
  EXPECT_EQ(crop.geometry().xll_m, 42.0);
  EXPECT_EQ(crop.geometry().yll_m, 42.0);
  EXPECT_EQ(crop.cell_center({0, 0}).x, s.terrain.cell_center({0, 84}).x);
  EXPECT_EQ(crop.cell_center({0, 0}).y, s.terrain.cell_center({0, 84}).y);
}

TEST(ZoomWindow, LongBoxesGetFifteenPercentMarginAndGrowToASquare) {
  // 100 x 100 m of 0.5 m cells; row 60, cols 20..79 raised: x [10, 40], y [69.5, 70]; base (12, 70) r 1.
  // Box [10, 40] x [69, 71]: 30 x 2 m; margin 0.15 * 30 = 4.5 -> 39 x 11 m; square 39 m about y 70 -> [50.5, 89.5];
  // cols floor(11) .. ceil(89) -> 11..88, rows floor((100 - 89.5) / 0.5) = 21 .. ceil(99) -> 21..98.
  WorldState s = flat_state(200, 200, 0.5, 0.0, 0.0, 12.0, 70.0, 1.0);
  deposit(s, 60, 60, 20, 79, 3);
  expect_window(zoom_window(s, std::nullopt), {21, 11}, 78, 78);
}

TEST(ZoomWindow, SmallBoxesGrowToTenMetresRoundedOutwardsToWholeCells) {
  // 50 x 50 m of 0.25 m cells at (100, 200); cell (100, 100) raised: x [125, 125.25], y [224.75, 225]; base at its
  // centre, r 0.5. Box 1 x 1 m, margin 3 -> 7 m, grown to 10 m about (125.125, 224.875): x [120.125, 130.125] ->
  // cells 80.5..120.5 -> cols 80..120; y [219.875, 229.875] -> rows (250 - y) / 0.25: 80.5..120.5 -> rows 80..120.
  WorldState s = flat_state(200, 200, 0.25, 100.0, 200.0, 125.125, 224.875, 0.5);
  deposit(s, 100, 100, 100, 100, 2);
  expect_window(zoom_window(s, std::nullopt), {80, 80}, 41, 41);
}

TEST(ZoomWindow, PayloadRunsFrameTheRouteAndBothEnds) {
  // 100 x 100 m of 0.5 m cells; from (20.25, 20.25) = cell (159, 40), base there r 2; to (30.25, 40.25).
  WorldState s = flat_state(200, 200, 0.5, 0.0, 0.0, 20.25, 20.25, 2.0);
  s.completion = scenario::CompletionKind::kPayloadPath;
  s.payload_path = {0.2, 2.0, 0.05, 20.25, 20.25, 30.25, 40.25, 10};  // kappa, delta, eps, from, to, every
  // No route: box x [18.25, 30.25], y [18.25, 40.25] (12 x 22 m); margin 3.3 -> side 28.6 about (24.25, 29.25):
  // x [9.95, 38.55] -> cols 19..77; y [14.95, 43.55] -> rows floor(112.9) = 112 .. ceil(170.1) - 1 = 170.
  expect_window(zoom_window(s, std::nullopt), {112, 19}, 59, 59);
  // A route swinging east past `to`, through cell (119, 90) (x [45, 45.5], y [40, 40.5]): box x [18.25, 45.5],
  // y [18.25, 40.5] (27.25 x 22.25 m); margin 4.0875 -> side 35.425 about (31.875, 29.375): x [14.1625, 49.5875] ->
  // cols 28..99; y [11.6625, 47.0875] -> rows floor(105.825) = 105 .. ceil(176.675) - 1 = 176.
  PayloadRoute route;
  route.cells = {{159, 40}, {119, 90}, {119, 60}};
  expect_window(zoom_window(s, route), {105, 28}, 72, 72);
}

TEST(ZoomWindow, NoWindowWhenItWouldHoldMoreThanHalfTheTerrain) {
  // 100 x 100 m of 1 m cells, base (50, 50) r 1, a site centred on it.
  WorldState s = flat_state(100, 100, 1.0, 0.0, 0.0, 50.0, 50.0, 1.0);
  level_site_on(s, 25.0, 25.0, 75.0, 75.0);
  // 50 m: margin 7.5 -> [17.5, 82.5]^2 -> cells 17..82: 66^2 = 4356 <= 5000 cells.
  expect_window(zoom_window(s, std::nullopt), {17, 17}, 66, 66);
  // 56 m: margin 8.4 -> [13.6, 86.4]^2 -> cells 13..86: 74^2 = 5476 > 5000.
  level_site_on(s, 22.0, 22.0, 78.0, 78.0);
  EXPECT_FALSE(zoom_window(s, std::nullopt));

  // Deposits in opposite corners, or everywhere: the window is the whole grid.
  WorldState spread = corner_state();
  deposit(spread, 99, 99, 0, 0, 2);
  EXPECT_FALSE(zoom_window(spread, std::nullopt));
  deposit(spread, 0, 99, 0, 99, 4);
  EXPECT_FALSE(zoom_window(spread, std::nullopt));
}

TEST(ZoomWindow, NothingToFrameWithoutDepositsRouteOrSite) {
  // agents_at_goal with nothing deposited: the base alone is no subject.
  WorldState s = flat_state(100, 100, 0.5, 0.0, 0.0, 46.0, 46.0, 1.0);
  s.goal = {10.0, 10.0, 12.0, 12.0, -1e9};
  EXPECT_FALSE(zoom_window(s, std::nullopt));
  s.depositor.resize(0, 0);  // a state without a depositor grid
  EXPECT_FALSE(zoom_window(s, std::nullopt));
  EXPECT_FALSE(zoom_window(WorldState{}, std::nullopt));  // no terrain at all
}

TEST(FinalPicture, AGoalWithATargetRadiusDrawsEachAdmittedAgentsTarget) {
  WorldState s = flat_state(100, 100, 0.5, 0.0, 0.0, 46.0, 46.0, 1.0);
  s.goal = {10.0, 10.0, 20.0, 20.0, -1e9, 0.25};
  for (std::uint32_t id = 1; id <= 3; ++id) {
    AgentRecord a;
    a.id = id;
    a.admitted = id != 2;  // slot 2 never joined: no ring for it
    a.target.x = 15.0;
    a.target.y = 10.0 + 2.0 * id;
    s.agents.push_back(a);
  }
  const render::RenderOptions o = final_picture_options(s, info_for("targets", false), std::nullopt);
  ASSERT_EQ(o.circles.size(), 3u);  // the base, then the targets of agents 1 and 3
  EXPECT_EQ(o.circles[1].centre.y, 12.0);
  EXPECT_EQ(o.circles[2].centre.y, 16.0);
  EXPECT_EQ(o.circles[2].radius_m, 0.25);
  EXPECT_TRUE(has_legend(o, "targets (0.25 m)", o.circles[1].colour));
  s.goal.target_radius_m = 0.0;  // the box alone: no target rings
  EXPECT_EQ(final_picture_options(s, info_for("targets", false), std::nullopt).circles.size(), 1u);
}

TEST(ZoomPicture, OptionsCropLabelsAndMarkersKeepWorldOverlaysAndSayCloseUp) {
  WorldState s = corner_state();
  s.goal = {47.0, 47.0, 48.5, 48.5, -1e9};  // centre (47.75, 47.75): cell (4, 95)
  const auto w = zoom_window(s, std::nullopt);
  ASSERT_TRUE(w);
  const render::RenderOptions whole = final_picture_options(s, info_for("corner", false), std::nullopt);
  const render::RenderOptions zoom = final_picture_options(s, info_for("corner", false), std::nullopt, w);

  ASSERT_TRUE(zoom.labels);
  EXPECT_EQ(zoom.labels->rows(), 16);
  EXPECT_EQ(zoom.labels->cols(), 16);
  EXPECT_EQ(zoom.labels->sum(), 16u);    // the 4 x 4 raised cells, all inside
  EXPECT_EQ((*zoom.labels)(2, 10), 1u);  // cell (2, 94)
  EXPECT_EQ((*zoom.labels)(5, 13), 1u);  // cell (5, 97)
  EXPECT_EQ((*zoom.labels)(6, 13), 0u);
  ASSERT_EQ(whole.markers.size(), 1u);
  EXPECT_EQ(whole.markers[0], (CellIndex{4, 95}));
  ASSERT_EQ(zoom.markers.size(), 1u);
  EXPECT_EQ(zoom.markers[0], (CellIndex{4, 11}));

  // The world-coordinate overlays and the legend are final.png's.
  ASSERT_EQ(zoom.rectangles.size(), whole.rectangles.size());
  EXPECT_EQ(zoom.rectangles[0].a.x, 47.0);
  ASSERT_EQ(zoom.circles.size(), 1u);
  EXPECT_EQ(zoom.circles[0].centre.x, 46.0);
  ASSERT_EQ(zoom.legend_entries.size(), whole.legend_entries.size());
  for (std::size_t k = 0; k < zoom.legend_entries.size(); ++k)
    EXPECT_EQ(zoom.legend_entries[k].text, whole.legend_entries[k].text);
  EXPECT_EQ(zoom.title, "corner: close-up x 42..50 m, y 42..50 m");
  EXPECT_EQ(whole.title, "corner: step 0, agents_at_goal not completed");

  // A goal centre outside the window leaves no marker in the close-up.
  s.goal = {5.0, 5.0, 7.0, 7.0, -1e9};
  EXPECT_TRUE(final_picture_options(s, info_for("corner", false), std::nullopt, w).markers.empty());
  EXPECT_EQ(final_picture_options(s, info_for("corner", false), std::nullopt).markers.size(), 1u);

  const RunInfo info = info_for("corner", false);
  EXPECT_THROW(final_picture_options(s, info, std::nullopt, CellRect{{90, 90}, 16, 16}), InvalidArgument);
  EXPECT_THROW(final_picture_options(s, info, std::nullopt, CellRect{{0, 0}, 0, 5}), InvalidArgument);
  EXPECT_THROW(final_picture_options(s, info, std::nullopt, CellRect{{-1, 0}, 5, 5}), InvalidArgument);
}

/// final_zoom.png and final.png decoded by libpng's simplified API (not the project's writer) as 8-bit RGB.
render::Image decoded(const fs::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  render::Image out;
  const bool opened = png_image_begin_read_from_file(&png, path.c_str()) != 0;
  if (opened) {
    png.format = PNG_FORMAT_RGB;
    out = {static_cast<int>(png.width), static_cast<int>(png.height), std::vector<std::uint8_t>(PNG_IMAGE_SIZE(png))};
    if (png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr) != 0) return out;
  }
  ADD_FAILURE() << "cannot decode " << path << ": " << png.message;
  if (opened) png_image_free(&png);
  return {};
}

render::Rgb pixel(const render::Image& img, int x, int y) {
  const std::size_t i = 3u * (static_cast<std::size_t>(y) * img.width + x);
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

/// The terrain area of a picture with a legend: inside the grey frame the renderer draws around it, whose top-left
/// corner is the first frame-grey pixel in row-major order (the title above it is dark ink).
struct TerrainArea {
  int x = 0, y = 0, width = 0, height = 0;
};

TerrainArea terrain_area(const render::Image& img) {
  constexpr render::Rgb kFrame{80, 80, 80};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (pixel(img, x, y) != kFrame) continue;
      int w = 0, h = 0;
      while (x + w < img.width && pixel(img, x + w, y) == kFrame) ++w;
      while (y + h < img.height && pixel(img, x, y + h) == kFrame) ++h;
      return {x + 1, y + 1, w - 2, h - 2};
    }
  ADD_FAILURE() << "no terrain frame";
  return {};
}

int count_in(const render::Image& img, const TerrainArea& a, render::Rgb colour) {
  int n = 0;
  for (int y = a.y; y < a.y + a.height; ++y)
    for (int x = a.x; x < a.x + a.width; ++x) n += pixel(img, x, y) == colour ? 1 : 0;
  return n;
}

/// `tinted` is `plain` blended 60 % towards agent `id`'s colour (up to the rounding of both to 8 bits).
void expect_tint(render::Rgb tinted, render::Rgb plain, std::uint32_t id) {
  const render::Rgb c = render::label_colour(id);
  EXPECT_NEAR(tinted.r, plain.r + 0.6 * (c.r - plain.r), 1.0);
  EXPECT_NEAR(tinted.g, plain.g + 0.6 * (c.g - plain.g), 1.0);
  EXPECT_NEAR(tinted.b, plain.b + 0.6 * (c.b - plain.b), 1.0);
}

TEST_F(OutputFiles, TheCloseUpShowsTheTintedDepositLargerAtItsWorldPlace) {
  // 100 x 100 m of 0.5 m cells at (1000, 2000); site [1070, 1080] x [2070, 2080]; agent 2 raised rows 50..53,
  // cols 150..153 (x [1075, 1077], y [2073, 2075]); base (1072, 2072) r 2. Box = the site, margin 3 -> [1067, 1083]^2:
  // cols (1067 - 1000) / 0.5 = 134 .. 165, rows (2100 - 2083) / 0.5 = 34 .. 65.
  WorldState s = flat_state(200, 200, 0.5, 1000.0, 2000.0, 1072.0, 2072.0, 2.0);
  level_site_on(s, 1070.0, 2070.0, 1080.0, 2080.0);
  deposit(s, 50, 53, 150, 153, 2);
  expect_window(zoom_window(s, std::nullopt), {34, 134}, 32, 32);

  write_final_outputs(dir_.string(), s, info_for("site", false));
  const render::Image whole = decoded(dir_ / "final.png");
  const render::Image zoom = decoded(dir_ / "final_zoom.png");
  ASSERT_GT(zoom.width, 0);
  const TerrainArea wa = terrain_area(whole), za = terrain_area(zoom);
  // Terrain areas of max_size_px 1024: 200 cells at floor(1024 / 200) = 5 px, 32 cells at 1024 / 32 = 32 px.
  EXPECT_EQ(wa.width, 1000);
  EXPECT_EQ(wa.height, 1000);
  EXPECT_EQ(za.width, 1024);
  EXPECT_EQ(za.height, 1024);

  // Cell (51, 151) is window cell (17, 17); cell (36, 136) = window (2, 2) and cell (100, 20) are untouched ground.
  const render::Rgb zoom_deposit = pixel(zoom, za.x + 17 * 32 + 16, za.y + 17 * 32 + 16);
  const render::Rgb zoom_plain = pixel(zoom, za.x + 2 * 32 + 16, za.y + 2 * 32 + 16);
  const render::Rgb whole_deposit = pixel(whole, wa.x + 151 * 5 + 2, wa.y + 51 * 5 + 2);
  const render::Rgb whole_plain = pixel(whole, wa.x + 20 * 5 + 2, wa.y + 100 * 5 + 2);
  EXPECT_EQ(zoom_plain, whole_plain);
  EXPECT_NE(zoom_deposit, zoom_plain);
  expect_tint(zoom_deposit, zoom_plain, 2);
  EXPECT_EQ(zoom_deposit, whole_deposit);
  // The 16 raised cells cover 16 x 32^2 pixels of the close-up, 16 x 5^2 of final.png; the cells beside the raised
  // block are plain: the tint sits where the world puts it.
  EXPECT_EQ(count_in(zoom, za, zoom_deposit), 16 * 32 * 32);
  EXPECT_EQ(count_in(whole, wa, zoom_deposit), 16 * 5 * 5);
  EXPECT_EQ(pixel(zoom, za.x + 16 * 32 - 1, za.y + 17 * 32 + 16), zoom_plain);   // window col 15 = cell 149
  EXPECT_EQ(pixel(zoom, za.x + 20 * 32 + 16, za.y + 20 * 32 + 16), zoom_plain);  // cell (54, 154)
  EXPECT_EQ(pixel(zoom, za.x + 20 * 32 - 1, za.y + 20 * 32 - 1), zoom_deposit);  // cell (53, 153)
}

TEST_F(OutputFiles, NoCloseUpWhenTheWindowWouldHoldMostOfTheTerrain) {
  // The 4 x 4 m test world: any window is at least 10 m, i.e. the whole grid.
  const WorldState s = testing::admitted_state(scenario::parse_scenario(testing::small_scenario_text(), "small.pbtxt"),
                                               testing::flat_terrain(), 1);
  write_final_outputs(dir_.string(), s, info_for("small", false));
  EXPECT_TRUE(fs::exists(dir_ / "final.png"));
  EXPECT_FALSE(fs::exists(dir_ / "final_zoom.png"));
}

}  // namespace
}  // namespace marsala::world_server
