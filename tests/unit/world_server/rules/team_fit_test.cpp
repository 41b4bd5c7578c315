#include "marsala/world_server/rules/team_fit.hpp"

#include <gtest/gtest.h>

#include <string>

#include "marsala/scenario/scenario.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

/// A flat 4 x 4 m scenario (0.1 m cells) whose robots have 0.3 m bodies, with the slots' starts `starts`.
scenario::Scenario with_starts(const std::string& starts) {
  const std::string text = std::string(R"(
name: "fit"
terrain { generator: "flat" rows: 40 cols: 40 cell_size_m: 0.1 }
robot_type { name: "r" body { delta_m: 0.3 max_step_m: 0.1 } }
)") + starts + R"(
goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }
base { x_m: 0.55 y_m: 0.55 radius_m: 0.5 }
)";
  return scenario::parse_scenario(text, "fit.pbtxt");
}

std::string slot(double x, double y) {
  return "agent { robot_type: \"r\" start { x_m: " + std::to_string(x) + " y_m: " + std::to_string(y) +
         " } target { x_m: 3.05 y_m: 2.05 } }\n";
}

TEST(TeamFit, BodiesThatTouchFitAndBodiesThatOverlapDoNot) {
  // Bodies of 0.3 m need 0.3 m between centres; touching is allowed (docs/runtime.md#collisions).
  const scenario::Scenario touching = with_starts(slot(1.05, 1.05) + slot(1.35, 1.05) + slot(1.05, 1.35));
  EXPECT_EQ(team_fit_problem(touching, scenario::build_terrain(touching), 3), "");
  const scenario::Scenario overlapping = with_starts(slot(1.05, 1.05) + slot(1.55, 1.05) + slot(1.25, 1.05));
  const Heightmap terrain = scenario::build_terrain(overlapping);
  EXPECT_EQ(team_fit_problem(overlapping, terrain, 2), "");  // the first two alone fit
  EXPECT_EQ(team_fit_problem(overlapping, terrain, 3),
            "agent[2] (agent 3).start: (1.25, 1.05) m: its body (0.3 m) overlaps agent 1's, at (1.05, 1.05) m "
            "(0.20 m apart, the bodies need 0.3 m)");
}

TEST(TeamFit, ARobotCannotStartOnACellItCannotOccupy) {
  scenario::Scenario s = with_starts(slot(1.05, 1.05) + slot(2.05, 2.05));
  Heightmap terrain = scenario::build_terrain(s);
  const CellIndex under = *terrain.cell_at({2.05, 2.05});
  terrain(under.row, under.col + 1) += 1.0;  // a 1 m spike next to the second start: its ball is not level
  const std::string problem = team_fit_problem(s, terrain, 2);
  EXPECT_EQ(problem.rfind("agent[1] (agent 2).start: (2.05, 2.05) m: cell ", 0), 0u) << problem;
  EXPECT_NE(problem.find("is not occupiable for its body"), std::string::npos) << problem;
  EXPECT_EQ(team_fit_problem(s, terrain, 1), "");
}

TEST(TeamFit, TheSmallTestScenarioFits) {
  const scenario::Scenario s = testing::small_scenario();
  EXPECT_EQ(team_fit_problem(s, scenario::build_terrain(s), 3), "");
}

}  // namespace
}  // namespace marsala::world_server
