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

TEST(TeamFit, StartsThatTouchAreAPlacementAndOverlappingOnesAreNot) {
  // Bodies of 0.3 m need 0.3 m between centres; touching is allowed (docs/runtime.md#collisions).
  const scenario::Scenario touching = with_starts(slot(1.05, 1.05) + slot(1.35, 1.05) + slot(1.05, 1.35));
  const Heightmap flat = scenario::build_terrain(touching);
  EXPECT_EQ(start_placement_problem(touching, flat, 3), "");
  EXPECT_EQ(team_fit_problem(touching, flat, 3), "");
  const scenario::Scenario overlapping = with_starts(slot(1.05, 1.05) + slot(1.55, 1.05) + slot(1.25, 1.05));
  EXPECT_EQ(start_placement_problem(overlapping, flat, 2), "");  // the first two alone are a placement
  EXPECT_EQ(start_placement_problem(overlapping, flat, 3),
            "agent[2] (agent 3).start: (1.25, 1.05) m: its body (0.3 m) overlaps agent 1's, at (1.05, 1.05) m "
            "(0.20 m apart, the bodies need 0.3 m)");
  // The world separates overlapping starts (rule 2.5); the start area (1.03 m round the base) has room for three.
  EXPECT_EQ(team_fit_problem(overlapping, flat, 3), "");
  EXPECT_EQ(greedy_placed(overlapping, flat, 3, 1.03), 3u);
}

TEST(TeamFit, ARobotCannotStartOnACellItCannotOccupy) {
  scenario::Scenario s = with_starts(slot(1.05, 1.05) + slot(2.05, 2.05));
  Heightmap terrain = scenario::build_terrain(s);
  const CellIndex under = *terrain.cell_at({2.05, 2.05});
  terrain(under.row, under.col + 1) += 1.0;  // a 1 m spike next to the second start: its ball is not level
  const std::string problem = start_placement_problem(s, terrain, 2);
  EXPECT_EQ(problem.rfind("agent[1] (agent 2).start: (2.05, 2.05) m: cell ", 0), 0u) << problem;
  EXPECT_NE(problem.find("is not occupiable for its body"), std::string::npos) << problem;
  EXPECT_EQ(team_fit_problem(s, terrain, 2), "");  // there is room elsewhere on the base
}

TEST(TeamFit, ThreeBodiesOfAMetreDoNotFitWithinHalfAMetre) {
  // Three centres in a disc of radius 0.5 m are at most sqrt(3) / 2 = 0.87 m apart pairwise, and 1 m bodies need
  // 1 m: at most two fit (the ends of a diameter, touching). The starts all sit near the base's centre.
  const std::string text = R"(
name: "crowded"
terrain { generator: "flat" rows: 40 cols: 40 cell_size_m: 0.1 }
robot_type { name: "r" body { delta_m: 1.0 max_step_m: 0.2 } }
agent { robot_type: "r" start { x_m: 1.55 y_m: 1.55 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "r" start { x_m: 1.65 y_m: 1.55 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "r" start { x_m: 1.55 y_m: 1.65 } target { x_m: 3.05 y_m: 2.05 } }
goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }
base { x_m: 1.55 y_m: 1.55 radius_m: 0.5 }
)";
  const scenario::Scenario s = scenario::parse_scenario(text, "crowded.pbtxt");
  const Heightmap flat = scenario::build_terrain(s);
  EXPECT_EQ(greedy_placed(s, flat, 3, 0.5), 2u);
  EXPECT_EQ(team_fit_problem(s, flat, 2), "");  // two fit
  EXPECT_EQ(team_fit_problem(s, flat, 3),
            "agent (3 robots): only 2 of their bodies find room, disjoint, on cells occupiable for them within 0.50 m "
            "of the base's centre (the base and its farthest start), and the slots' starts are no placement either: "
            "agent[1] (agent 2).start: (1.65, 1.55) m: its body (1 m) overlaps agent 1's, at (1.55, 1.55) m (0.10 m "
            "apart, the bodies need 1 m)");
}

TEST(TeamFit, TheSmallTestScenarioFits) {
  const scenario::Scenario s = testing::small_scenario();
  EXPECT_EQ(team_fit_problem(s, scenario::build_terrain(s), 3), "");
}

}  // namespace
}  // namespace marsala::world_server
