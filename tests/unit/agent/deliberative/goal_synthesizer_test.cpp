#include "marsala/agent/deliberative/goal_synthesizer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>
#include <utility>

#include "unit/agent/agent_test_support.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::deliberative {
namespace {

TEST(GoalSynthesizer, FixedTargetIsTheAdmissionsTargetWhereverTheRobotIs) {
  AgentContext context;
  context.assignment.target = {12.5, -3.25};
  const auto goal = make_goal_synthesizer("fixed_target", context);
  EXPECT_EQ(goal->name(), "fixed_target");
  for (const Position robot : {Position{0.0, 0.0}, Position{12.5, -3.25}, Position{-100.0, 7.0}}) {
    const std::optional<Position> t = goal->target({robot, {}, {}});
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->x, 12.5);
    EXPECT_EQ(t->y, -3.25);
  }
}

TEST(GoalSynthesizer, RegistryListsValidNamesOnAnUnknownOne) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  EXPECT_TRUE(registry.names().empty());
  register_builtins(registry);
  EXPECT_EQ(registry.names(), (std::vector<std::string>{"fixed_target", "goal_vector_map"}));
  EXPECT_TRUE(registry.contains("fixed_target"));
  try {
    make_goal_synthesizer("spiral", AgentContext{});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown goal synthesizer 'spiral'"), std::string::npos) << what;
    EXPECT_NE(what.find("fixed_target"), std::string::npos) << what;
  }
  // Before admission (no grid yet) a name is checked without making the variant.
  EXPECT_NO_THROW(require_goal_synthesizer("goal_vector_map"));
  EXPECT_THROW(require_goal_synthesizer("spiral"), InvalidArgument);
  EXPECT_THROW(register_builtins(registry), InvalidArgument);  // registered twice
  EXPECT_THROW(registry.add("", [](const AgentContext& c) { return std::make_unique<FixedTarget>(c); }),
               InvalidArgument);
}

// World 12 x 12 cells of 1 m at the origin; site [2, 10] x [2, 6], strips 2 m, arrows 4 m east:
//   arrow 0: (2.5, 3.5) -> (6.5, 3.5)   arrow 1: (6.5, 3.5) -> (9.5, 3.5)   (strip 0)
//   arrow 2: (2.5, 5.5) -> (6.5, 5.5)   arrow 3: (6.5, 5.5) -> (9.5, 5.5)   (strip 1)
AgentContext site_context(std::uint32_t id) {
  AgentContext c;
  c.agent_id = id;
  c.assignment.world = {12, 12, 0.0, 0.0, 1.0};
  c.type.goal_synthesizer = "goal_vector_map";
  GoalVectorMapSpec spec;
  spec.area.x0 = 2.0;
  spec.area.y0 = 2.0;
  spec.area.x1 = 10.0;
  spec.area.y1 = 6.0;
  spec.strip_width_m = 2.0;
  spec.arrow_length_m = 4.0;
  spec.heading = Heading::kEast;
  c.goal_vector_map = spec;
  return c;
}

const auto neighbour = test::neighbour_at;

// The target, which must exist, as a pair for EXPECT_EQ.
std::pair<double, double> target_of(GoalVectorMapSynthesizer& goal, Position robot,
                                    std::vector<Neighbour> neighbours = {}) {
  const std::optional<Position> t = goal.target({robot, std::move(neighbours), {}});
  if (!t) ADD_FAILURE() << "no target from (" << robot.x << ", " << robot.y << ")";
  return t ? std::make_pair(t->x, t->y) : std::make_pair(std::nan(""), std::nan(""));
}

using XY = std::pair<double, double>;

std::pair<double, double> target_of_query(GoalVectorMapSynthesizer& goal, const GoalQuery& query) {
  const std::optional<Position> t = goal.target(query);
  if (!t) ADD_FAILURE() << "no target from (" << query.robot.x << ", " << query.robot.y << ")";
  return t ? std::make_pair(t->x, t->y) : std::make_pair(std::nan(""), std::nan(""));
}

TEST(GoalVectorMapSynthesizer, CompilesTheScenariosMap) {
  const auto goal = make_goal_synthesizer("goal_vector_map", site_context(1));
  EXPECT_EQ(goal->name(), "goal_vector_map");
  const auto& gvm = dynamic_cast<const GoalVectorMapSynthesizer&>(*goal);
  ASSERT_EQ(gvm.map().arrows().size(), 4u);
  EXPECT_EQ(gvm.map().strips(), 2);
  EXPECT_EQ(gvm.map().arrows()[3].tail.x, 6.5);
  EXPECT_EQ(gvm.map().arrows()[3].tail.y, 5.5);
  EXPECT_EQ(gvm.map().arrows()[3].head.x, 9.5);
  EXPECT_FALSE(gvm.current_arrow().has_value());
  EXPECT_EQ(gvm.finished(), std::vector<bool>(4, false));
}

// One robot through the whole table: nearest tail, tail -> head, head -> chained head, strip end -> nearest
// unfinished tail, a next arrow it already finished -> nearest unfinished tail, all finished -> nullopt.
TEST(GoalVectorMapSynthesizer, WalksTheArrowsAsTheTableSays) {
  GoalVectorMapSynthesizer goal(site_context(1));
  // Nearest tail from (0.5, 0.5): arrow 0 (squared distance 13; arrow 2: 29).
  EXPECT_EQ(target_of(goal, {0.5, 0.5}), XY(2.5, 3.5));
  EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(0));
  EXPECT_TRUE(goal.heading_for_tail());
  // Just outside the tail's cell (0.51 m east of its centre): still the tail.
  EXPECT_EQ(target_of(goal, {3.01, 3.5}), XY(2.5, 3.5));
  // Within half a cell of the tail (Chebyshev): the head.
  EXPECT_EQ(target_of(goal, {2.9, 3.1}), XY(6.5, 3.5));
  EXPECT_FALSE(goal.heading_for_tail());
  EXPECT_EQ(target_of(goal, {4.5, 3.5}), XY(6.5, 3.5));
  // On the head: arrow 0 is finished, arrow 1 continues at once (its head).
  EXPECT_EQ(target_of(goal, {6.5, 3.5}), XY(9.5, 3.5));
  EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(1));
  EXPECT_FALSE(goal.heading_for_tail());
  EXPECT_EQ(goal.finished(), (std::vector<bool>{true, false, false, false}));
  // End of strip 0: the nearest unfinished tail is arrow 3's (squared distance 13; arrow 2's: 53).
  EXPECT_EQ(target_of(goal, {9.5, 3.5}), XY(6.5, 5.5));
  EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(3));
  EXPECT_TRUE(goal.heading_for_tail());
  EXPECT_EQ(target_of(goal, {6.5, 5.5}), XY(9.5, 5.5));
  // End of strip 1: arrow 2 is left.
  EXPECT_EQ(target_of(goal, {9.5, 5.5}), XY(2.5, 5.5));
  EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(2));
  EXPECT_EQ(target_of(goal, {2.5, 5.5}), XY(6.5, 5.5));
  // Arrow 2's next arrow (3) is finished already: nothing is left.
  EXPECT_FALSE(goal.target({{6.5, 5.5}, {}, {}}).has_value());
  EXPECT_EQ(goal.finished(), std::vector<bool>(4, true));
  EXPECT_FALSE(goal.current_arrow().has_value());
  EXPECT_FALSE(goal.target({{0.5, 0.5}, {}, {}}).has_value());
}

// Walks the robot to every target it is given (standing on it) until it has none: every arrow is finished.
void finish_every_arrow(GoalVectorMapSynthesizer& goal) {
  Position robot{0.5, 0.5};
  for (int i = 0; i < 100; ++i) {
    const std::optional<Position> t = goal.target({robot, {}, {}});
    if (!t) break;
    robot = *t;
  }
  ASSERT_EQ(goal.finished(), std::vector<bool>(goal.map().arrows().size(), true));
}

// A robot that finished every arrow while its map shows ground not level opens again the arrows whose stretch holds
// it, and builds along them; with a level map (or nobody to ask) it is done.
TEST(GoalVectorMapSynthesizer, OpensAgainTheArrowsWhoseStretchTheMapShowsNotLevel) {
  GoalVectorMapSynthesizer goal(site_context(1));
  finish_every_arrow(goal);
  // The site [2, 10] x [2, 6] on the 12 x 12 grid of 1 m: cell centres at x 2.5 .. 9.5 (cols 2-9) and y 5.5 .. 2.5
  // (rows 6-9).
  CellRect asked;
  std::vector<CellIndex> unlevel{{3, 5}};  // area cell: world cell (9, 7), centre (7.5, 2.5): strip 0, past 6.5
  GoalQuery query{{9.5, 5.5}, {}, [&](const CellRect& area) {
                    asked = area;
                    CellMask mask = CellMask::Zero(area.rows, area.cols);
                    for (const CellIndex c : unlevel) mask(c.row, c.col) = 1;
                    return mask;
                  }};
  EXPECT_EQ(target_of_query(goal, query), XY(6.5, 3.5));  // arrow 1's tail
  EXPECT_EQ(asked.first, (CellIndex{6, 2}));
  EXPECT_EQ(asked.rows, 4);
  EXPECT_EQ(asked.cols, 8);
  EXPECT_EQ(goal.finished(), (std::vector<bool>{true, false, true, true}));
  EXPECT_EQ(goal.reopenings(), 1);
  query.robot = {6.5, 3.5};
  EXPECT_EQ(target_of_query(goal, query), XY(9.5, 3.5));
  // Still not level when it gets there: the same arrow again, from its tail.
  query.robot = {9.5, 3.5};
  EXPECT_EQ(target_of_query(goal, query), XY(6.5, 3.5));
  EXPECT_EQ(goal.reopenings(), 2);
  // Area cell (0, 0): world cell (6, 2), centre (2.5, 5.5): strip 1, before arrow 2's head.
  finish_every_arrow(goal);
  unlevel = {{0, 0}};
  query.robot = {9.5, 5.5};
  EXPECT_EQ(target_of_query(goal, query), XY(2.5, 5.5));
  EXPECT_EQ(goal.finished(), (std::vector<bool>{true, true, false, true}));
  // Level: done, and it stays where it is.
  finish_every_arrow(goal);
  unlevel.clear();
  EXPECT_FALSE(goal.target(query).has_value());
  EXPECT_FALSE(goal.target({{9.5, 5.5}, {}, {}}).has_value());
  // A mask of another size is a broken contract.
  query.unlevel = [](const CellRect&) { return CellMask::Zero(2, 2); };
  EXPECT_THROW(goal.target(query), InvalidArgument);
}

// unlevel_cells against eq. 1 checked pair by pair on the map cut to the area, where every cell of the ball is read.
TEST(GoalVectorMapSynthesizer, UnlevelCellsMatchAPairByPairCheckOfTheReadBalls) {
  std::mt19937 rng(11);
  const GridGeometry grid{14, 16, 0.0, 0.0, 0.25};
  const NavigabilityParams level{0.1, 1.0, 0.05};
  long long unlevel_seen = 0, level_seen = 0, unjudged_seen = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Heightmap heights(grid);
    CellMask known = CellMask::Ones(grid.rows, grid.cols), assumed = CellMask::Zero(grid.rows, grid.cols);
    CellMask bound = CellMask::Zero(grid.rows, grid.cols);
    std::uniform_real_distribution<double> bump(-0.03, 0.03), coin(0.0, 1.0);
    const double tilt = 0.05 * (trial % 5);
    for (int r = 0; r < grid.rows; ++r)
      for (int c = 0; c < grid.cols; ++c) {
        heights(r, c) = tilt * c * grid.cell_size_m + (coin(rng) < 0.15 ? bump(rng) * 4.0 : bump(rng) * 0.2);
        if (coin(rng) < 0.04) known(r, c) = 0, heights(r, c) = 0.0;
        else if (coin(rng) < 0.03) assumed(r, c) = 1;
      }
    const std::vector<CellIndex> trajectory;
    const KnownMap map{heights, known, assumed, bound, trajectory};
    const CellRect area{{2, 1}, 10, 13};
    const CellMask got = unlevel_cells(map, area, level);
    ASSERT_EQ(got.rows(), area.rows);
    ASSERT_EQ(got.cols(), area.cols);
    const double r2 = 0.25 * level.delta_m * level.delta_m;
    for (int r = 0; r < area.rows; ++r)
      for (int c = 0; c < area.cols; ++c) {
        std::vector<CellIndex> ball;  // area cells whose centres lie within delta/2 of (r, c)'s
        for (int rr = 0; rr < area.rows; ++rr)
          for (int cc = 0; cc < area.cols; ++cc) {
            const double dy = (rr - r) * grid.cell_size_m, dx = (cc - c) * grid.cell_size_m;
            if (dx * dx + dy * dy <= r2 + 1e-12) ball.push_back({rr, cc});
          }
        bool read = true, occupiable = true;
        for (const CellIndex a : ball) {
          const int ar = area.first.row + a.row, ac = area.first.col + a.col;
          read = read && known(ar, ac) != 0 && assumed(ar, ac) == 0;
          for (const CellIndex b : ball) {
            const int br = area.first.row + b.row, bc = area.first.col + b.col;
            const double d = grid.cell_size_m * std::hypot(a.row - b.row, a.col - b.col);
            if (std::abs(heights(ar, ac) - heights(br, bc)) > level.eps_m + level.kappa * d + 1e-9) occupiable = false;
          }
        }
        const int expected = read && !occupiable ? 1 : 0;
        EXPECT_EQ(got(r, c), expected) << "trial " << trial << " cell (" << r << ", " << c << ")";
        unlevel_seen += expected;
        level_seen += read && occupiable;
        unjudged_seen += !read;
      }
  }
  // The draws hold all three kinds, so the check tells them apart.
  EXPECT_GT(unlevel_seen, 500);
  EXPECT_GT(level_seen, 500);
  EXPECT_GT(unjudged_seen, 500);
  const Heightmap heights(grid);
  const CellMask ones = CellMask::Ones(grid.rows, grid.cols);
  const std::vector<CellIndex> trajectory;
  const KnownMap map{heights, ones, ones, ones, trajectory};
  EXPECT_THROW(unlevel_cells(map, {{10, 10}, 5, 2}, level), InvalidArgument);
  EXPECT_THROW(unlevel_cells(map, {{0, 0}, 0, 3}, level), InvalidArgument);
}

TEST(GoalVectorMapSynthesizer, SkipsATailANeighbourIsNearerTo) {
  // Alone at (0.5, 3.5): arrow 0's tail (squared distance 4).
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 3.5}), XY(2.5, 3.5));
  }
  // A neighbour at (2.5, 2.5) is nearer to arrow 0's tail (1 < 4) but not to arrow 2's (9 > 8).
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 3.5}, {neighbour(1, 2.5, 2.5)}), XY(2.5, 5.5));
    EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(2));
  }
  // A neighbour at (2.5, 1.5) is as near to arrow 0's tail (4 = 4): the lower id takes it.
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 3.5}, {neighbour(1, 2.5, 1.5)}), XY(2.5, 5.5));
  }
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 3.5}, {neighbour(3, 2.5, 1.5)}), XY(2.5, 3.5));
  }
  // Its own id in the neighbour list is not a neighbour.
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 3.5}, {neighbour(2, 2.5, 2.5)}), XY(2.5, 3.5));
  }
  // A neighbour at (4.5, 4.5) is nearer to every tail: the robot still has work and takes the nearest one.
  {
    GoalVectorMapSynthesizer goal(site_context(2));
    EXPECT_EQ(target_of(goal, {0.5, 0.5}, {neighbour(1, 4.5, 4.5)}), XY(2.5, 3.5));
  }
}

TEST(GoalVectorMapSynthesizer, GivesUpATailWhenANeighbourComesNearerAndKeepsTheNewOne) {
  GoalVectorMapSynthesizer goal(site_context(1));
  // From (0.5, 4.5) arrows 0 and 2 are equally near (5): the lower index.
  EXPECT_EQ(target_of(goal, {0.5, 4.5}), XY(2.5, 3.5));
  // A neighbour arrives next to arrow 0's tail (1.25 < 5); arrow 2's stays the robot's (9.25 > 5).
  EXPECT_EQ(target_of(goal, {0.5, 4.5}, {neighbour(2, 3.0, 2.5)}), XY(2.5, 5.5));
  EXPECT_EQ(goal.current_arrow(), std::optional<std::size_t>(2));
  // The neighbour leaves: the robot keeps arrow 2 although arrow 0 ties and has the lower index.
  EXPECT_EQ(target_of(goal, {0.5, 4.5}), XY(2.5, 5.5));
  // On its tail, a neighbour nearby no longer matters: the head.
  EXPECT_EQ(target_of(goal, {2.5, 5.5}, {neighbour(2, 2.6, 5.5)}), XY(6.5, 5.5));
}

// Two robots that see each other and jump onto their targets each frame: never the same tail at once, every arrow
// finished by each, within 2 frames per arrow plus one; the same inputs give the same targets (no randomness).
TEST(GoalVectorMapSynthesizer, TwoRobotsFinishEveryArrowDeterministically) {
  const auto run = [](std::vector<std::pair<double, double>>& trace) {
    GoalVectorMapSynthesizer a(site_context(1)), b(site_context(2));
    Position pa{0.5, 0.5}, pb{0.5, 7.5};
    bool a_done = false, b_done = false;
    int frames = 0;
    while ((!a_done || !b_done) && frames < 100) {
      ++frames;
      std::optional<Position> ta, tb;
      if (!a_done) ta = a.target({pa, {neighbour(2, pb.x, pb.y)}, {}});
      if (!b_done) tb = b.target({pb, {neighbour(1, pa.x, pa.y)}, {}});
      if (ta && tb && a.heading_for_tail() && b.heading_for_tail()) {
        EXPECT_NE(a.current_arrow(), b.current_arrow()) << "frame " << frames;
      }
      a_done = !ta;
      b_done = !tb;
      if (ta) pa = *ta;
      if (tb) pb = *tb;
      trace.emplace_back(pa.x, pa.y);
      trace.emplace_back(pb.x, pb.y);
    }
    EXPECT_EQ(a.finished(), std::vector<bool>(4, true));
    EXPECT_EQ(b.finished(), std::vector<bool>(4, true));
    EXPECT_LE(frames, 2 * 4 + 1);
  };
  std::vector<std::pair<double, double>> first, second;
  run(first);
  run(second);
  EXPECT_EQ(first, second);
  // Robot 1 starts at arrow 0's tail, robot 2 (from the north) at arrow 2's.
  ASSERT_GE(first.size(), 2u);
  EXPECT_EQ(first[0], XY(2.5, 3.5));
  EXPECT_EQ(first[1], XY(2.5, 5.5));
}

TEST(GoalVectorMapSynthesizer, RejectsAContextWithoutAUsableMap) {
  AgentContext no_spec = site_context(1);
  no_spec.goal_vector_map.reset();
  try {
    make_goal_synthesizer("goal_vector_map", no_spec);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("goal_vector_map block"), std::string::npos) << e.what();
  }
  EXPECT_THROW(GoalVectorMapSynthesizer{no_spec}, InvalidArgument);
  AgentContext outside = site_context(1);
  outside.goal_vector_map->area.x1 = 12.5;  // the world ends at x = 12
  EXPECT_THROW(GoalVectorMapSynthesizer{outside}, InvalidArgument);
  AgentContext no_grid = site_context(1);
  no_grid.assignment.world.cell_size_m = 0.0;
  EXPECT_THROW(GoalVectorMapSynthesizer{no_grid}, InvalidArgument);
  GoalVectorMapSynthesizer goal(site_context(1));
  EXPECT_THROW(goal.target({{std::nan(""), 1.0}, {}, {}}), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::deliberative
