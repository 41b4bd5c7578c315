// Rule 3 for cube and cone depositors (docs/runtime.md#rule-3-deposits): each condition accepted and rejected with
// its reason, and what an accepted request writes checked against the shape functions and the volume.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/world_server/rules/arbiter.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::admitted_state;
using testing::flat_terrain;
using testing::request_for;

// Agent 1 builds with cubes of side 0.1 m (one cell; 0.001 m^3 each), agent 2 with cones at 34 deg, agent 3 with
// layers. Bodies as the tester's: delta 1 m, reach 1.2 m, 0.02 m^3 a step, 0.05 m^3 on board.
const char* const kScenario = R"(
name: "deposits"
terrain { generator: "flat" rows: 40 cols: 40 cell_size_m: 0.1 }
robot_type {
  name: "cuber"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cube" cube_size_m: 0.1 }
}
robot_type {
  name: "piler"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cone" repose_deg: 34 }
}
robot_type {
  name: "layerer"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
}
agent { robot_type: "cuber" start { x_m: 1.05 y_m: 1.05 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "piler" start { x_m: 2.85 y_m: 1.05 } target { x_m: 3.05 y_m: 2.05 } }
agent { robot_type: "layerer" start { x_m: 1.05 y_m: 3.05 } target { x_m: 3.05 y_m: 2.05 } }
goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }
base { x_m: 0.55 y_m: 0.55 radius_m: 0.5 }
tile_size: 16
)";

const GridGeometry kGrid{40, 40, 0.0, 0.0, 0.1};

class DepositsTest : public ::testing::Test {
 protected:
  // These tests are about the shapes and rules 3d.1-3d.9 on flat ground, whose MARS bound (the flat ground itself)
  // would refuse every deposit: their bound stands 10 m high. Rule 3d.10 has its own tests (DepositBound below).
  DepositsTest()
      : scenario_(scenario::parse_scenario(kScenario, "deposits.pbtxt")),
        state_(admitted_state(scenario_, flat_terrain(), 3)) {
    state_.deposit_bound = flat_terrain(10.0);
  }
  protocol::ActionRequest deposit(std::uint32_t id, std::vector<Deposit> deposits) {
    protocol::ActionRequest r = request_for(state_, id);
    r.deposits = std::move(deposits);
    return r;
  }
  void expect_rejected(const protocol::ActionRequest& r, const std::string& words) {
    const Verdict v = validate_request(state_, r.agent_id, r);
    EXPECT_FALSE(v.accepted) << "expected a rejection mentioning '" << words << "'";
    EXPECT_NE(v.reason.find(words), std::string::npos) << v.reason;
  }
  scenario::Scenario scenario_;
  WorldState state_;
};

TEST_F(DepositsTest, ACubeColumnOnACellCentreRaisesThatCellBySidePerCube) {
  const Position at = kGrid.cell_center({30, 18});  // (1.85, 0.95): 0.8 m east of agent 1
  const protocol::ActionRequest r = deposit(1, {{at.x, at.y, 0.003}});
  const Verdict v = validate_request(state_, 1, r);
  ASSERT_TRUE(v.accepted) << v.reason;
  std::vector<CellIndex> changed;
  apply_request(state_, r, v, changed);
  EXPECT_DOUBLE_EQ(state_.terrain(30, 18), 0.3);
  EXPECT_NEAR(state_.terrain.heights().sum() * 0.01, 0.003, 1e-15);  // nothing else moved
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(changed[0], (CellIndex{30, 18}));
  EXPECT_EQ(state_.depositor(30, 18), 1u);
  EXPECT_NEAR(state_.agent(1).material_m3, 0.05 - 0.003, 1e-15);
  EXPECT_NEAR(state_.deposited_volume_m3, 0.003, 1e-15);
  EXPECT_EQ(state_.agent(1).deposited_m3, v.volume_m3);
}

TEST_F(DepositsTest, AStraddlingCubeIsAppliedAsItsShape) {
  const Position at{1.8, 1.0};  // on the corner of four cells: a quarter of the cube on each
  const protocol::ActionRequest r = deposit(1, {{at.x, at.y, 0.001}});
  const Verdict v = validate_request(state_, 1, r);
  ASSERT_TRUE(v.accepted) << v.reason;
  std::vector<CellIndex> changed;
  apply_request(state_, r, v, changed);
  const DepositShape shape = cube_column_shape(kGrid, at, 0.1, 1);
  ASSERT_EQ(shape.rises.size(), 4u);
  ASSERT_EQ(changed.size(), 4u);
  for (const CellRise& c : shape.rises) {
    EXPECT_EQ(state_.terrain(c.cell), c.rise_m);
    EXPECT_NEAR(c.rise_m, 0.025, 1e-15);
  }
}

TEST_F(DepositsTest, CubeRulesRejectWithTheirReasons) {
  const Position at = kGrid.cell_center({30, 18});
  expect_rejected(deposit(1, {{at.x, at.y, 0.0015}}), "is not a whole number of cubes of side 0.1 m");
  expect_rejected(deposit(1, {{at.x, at.y, 0.0}}), "is not > 0");
  expect_rejected(deposit(1, {{at.x, at.y, -0.001}}), "is not > 0");
  expect_rejected(deposit(1, {{2.45, 1.05, 0.001}}), "beyond reach_m 1.2");
  expect_rejected(deposit(1, {{at.x, at.y, 0.011}, {at.x, at.y + 0.2, 0.011}}), "exceeds max_deposit_m3 0.02");
  state_.agent(1).material_m3 = 0.0025;
  expect_rejected(deposit(1, {{at.x, at.y, 0.003}}), "exceeds the material on board 0.0025");
  state_.agent(1).material_m3 = 0.05;
  // Within 0.5 m of its own centre: under itself.
  expect_rejected(deposit(1, {{1.35, 1.05, 0.001}}), "under agent 1");
  // The footprint leaves the grid on the west edge (x = 0).
  expect_rejected(deposit(1, {{0.02, 1.55, 0.001}}), "would leave the grid");
  // 11 cubes on one cell: 1.1 m.
  expect_rejected(deposit(1, {{at.x, at.y, 0.011}}), "more than 1 m");
  // Two columns on one cell add up: 6 + 6 cubes.
  expect_rejected(deposit(1, {{at.x, at.y, 0.006}, {at.x, at.y, 0.006}}), "more than 1 m");
  EXPECT_TRUE(validate_request(state_, 1, deposit(1, {{at.x, at.y, 0.005}, {at.x, at.y, 0.005}})).accepted);
}

TEST_F(DepositsTest, ADepositUnderAnotherRobotIsRejected) {
  // Agent 2 stands at (2.45, 1.05) now; a cube 0.3 m west of it (1.1 m from agent 1: within reach).
  EXPECT_TRUE(validate_request(state_, 1, deposit(1, {{2.15, 1.05, 0.001}})).accepted);
  state_.agent(2).position.x = 2.45;
  expect_rejected(deposit(1, {{2.15, 1.05, 0.001}}), "raises cell (29, 21), under agent 2");
}

TEST_F(DepositsTest, EachDepositorSendsOnlyItsOwnKind) {
  protocol::ActionRequest r = request_for(state_, 1);
  r.depositions = {{30, 18, 0.0125}};
  expect_rejected(r, "robot type 'cuber' has the cube depositor: it sends deposits, not depositions");
  r.agent_id = 2;
  r.session = state_.agent(2).session;
  expect_rejected(r, "robot type 'piler' has the cone depositor: it sends deposits, not depositions");
  expect_rejected(deposit(3, {{1.05, 2.05, 0.001}}),
                  "robot type 'layerer' has the layer depositor: it sends depositions, not deposits");
}

TEST_F(DepositsTest, NonFiniteHugeOrTooManyDepositsAreRejectedInTheEnvelope) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const Deposit& d : {Deposit{nan, 1.0, 0.001}, Deposit{1.0, inf, 0.001}, Deposit{1.5, 1.0, nan},
                           Deposit{1.5, 1.0, 1e300}, Deposit{-1e7, 1.0, 0.001}}) {
    const Verdict v = validate_request(state_, 1, deposit(1, {d}));
    EXPECT_FALSE(v.accepted);
    EXPECT_EQ(v.rule, 1);
    EXPECT_NE(v.reason.find("is not finite or too large"), std::string::npos) << v.reason;
  }
  expect_rejected(deposit(1, std::vector<Deposit>(257, Deposit{1.85, 0.95, 0.001})),
                  "257 deposits exceed the limit of 256 per request");
  // The same for the cone robot, and nothing changed.
  const Verdict v = validate_request(state_, 2, deposit(2, {{nan, nan, nan}}));
  EXPECT_FALSE(v.accepted);
  EXPECT_EQ(state_.terrain.heights().sum(), 0.0);
}

TEST_F(DepositsTest, AConeIsAppliedAsItsShapeAndConservesVolume) {
  const Position at = kGrid.cell_center({20, 28});  // (2.85, 1.95): 0.9 m north of agent 2
  const protocol::ActionRequest r = deposit(2, {{at.x, at.y, 0.004}});
  const Verdict v = validate_request(state_, 2, r);
  ASSERT_TRUE(v.accepted) << v.reason;
  const DepositShape shape = cone_pile_shape(flat_terrain(), at, 0.004, 34.0);
  std::vector<CellIndex> changed;
  apply_request(state_, r, v, changed);
  ASSERT_EQ(changed.size(), shape.rises.size());
  for (const CellRise& c : shape.rises) EXPECT_EQ(state_.terrain(c.cell), c.rise_m);
  EXPECT_NEAR(state_.terrain.heights().sum() * 0.01, 0.004, 1e-12);
  EXPECT_NEAR(state_.deposited_volume_m3, 0.004, 1e-12);
  EXPECT_NEAR(state_.agent(2).material_m3, 0.046, 1e-12);
}

TEST_F(DepositsTest, TwoConesInOneRequestLandOneOnTheOther) {
  const Position at = kGrid.cell_center({20, 28});
  const Verdict both = validate_request(state_, 2, deposit(2, {{at.x, at.y, 0.003}, {at.x, at.y, 0.003}}));
  ASSERT_TRUE(both.accepted) << both.reason;
  // The reference: the first pile applied, then the second computed on it.
  Heightmap expected = flat_terrain();
  for (int i = 0; i < 2; ++i)
    for (const CellRise& c : cone_pile_shape(expected, at, 0.003, 34.0).rises) expected(c.cell) += c.rise_m;
  std::vector<CellIndex> changed;
  apply_request(state_, deposit(2, {{at.x, at.y, 0.003}, {at.x, at.y, 0.003}}), both, changed);
  EXPECT_EQ(state_.terrain.heights(), expected.heights());
}

TEST_F(DepositsTest, ConeRulesRejectWithTheirReasons) {
  // 0.02 m^3 settles about 0.3 m around the dump point: dumped 0.7 m from the agent it reaches under its body.
  expect_rejected(deposit(2, {{2.85, 1.75, 0.02}}), "under agent 2");
  expect_rejected(deposit(2, {{2.85, 2.05, 0.021}}), "exceeds max_deposit_m3");
  expect_rejected(deposit(2, {{2.85, 2.05, -0.001}}), "is not > 0");
  expect_rejected(deposit(2, {{2.85, 2.45, 0.001}}), "beyond reach_m");
  // Dumped next to the east edge (x = 4 m): the pile reaches the border cells.
  expect_rejected(deposit(2, {{3.85, 1.05, 0.01}}), "would leave the grid");
  // Any volume is fine for a cone (no whole cubes).
  EXPECT_TRUE(validate_request(state_, 2, deposit(2, {{2.85, 2.05, 0.0012345}})).accepted);
}

// Rule 3d.10 (docs/runtime.md#deposit-bound): deposits are judged against the MARS bound of the initial terrain, which
// the team's own deposits cannot raise. The terrain: flat ground at 0 m with a one-cell hole 0.2 m deep at cell
// (20, 28), (2.85, 1.95), 0.9 m north of the cone robot (agent 2). Its MARS bound at kappa 0.3: the hole's
// neighbours are 0.1 m away, so P = 0 - 0.3 * 0.1 = -0.03 m over the hole and 0 m everywhere else. One cell alone
// holds a pile until its apex reaches the neighbours' base, 0 + tan(34 deg) * 0.1 = 0.067 m: every pile below
// (0.067 + 0.2) * 0.01 = 0.00267 m^3 fills the hole alone, its apex at -0.2 + V / 0.01 m.
class DepositBound : public ::testing::Test {
 protected:
  static Heightmap holed() {
    Heightmap h = flat_terrain();
    h(kHole) = -0.2;
    return h;
  }
  DepositBound()
      : scenario_(scenario::parse_scenario(kScenario, "deposits.pbtxt")),
        state_(admitted_state(scenario_, holed(), 3)) {}
  protocol::ActionRequest pile(double volume_m3) {
    protocol::ActionRequest r = request_for(state_, 2);
    r.deposits = {{kGrid.cell_center(kHole).x, kGrid.cell_center(kHole).y, volume_m3}};
    return r;
  }
  static constexpr CellIndex kHole{20, 28};
  static constexpr double kBoundM = -0.03;    // P over the hole [m]
  static constexpr double kAllowedM = 0.005;  // 0.1 eps of the cone robot's body (eps 0.05 m) [m]
  scenario::Scenario scenario_;
  WorldState state_;
};

TEST_F(DepositBound, IsTheInitialTerrainsMarsAtTheTeamsKappa) {
  EXPECT_EQ(state_.deposit_bound_kappa, 0.3);
  ASSERT_EQ(state_.deposit_bound.rows(), 40);
  EXPECT_NEAR(state_.deposit_bound(kHole), kBoundM, 1e-9);
  EXPECT_NEAR(state_.deposit_bound(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(state_.deposit_bound(kHole.row, kHole.col + 1), 0.0, 1e-12);
}

TEST_F(DepositBound, APileWithinTheBoundIsAcceptedOneAboveItIsRefused) {
  // Apex -0.2 + 0.165 = -0.035 m: under the bound.
  const Verdict under = validate_request(state_, 2, pile(0.00165));
  ASSERT_TRUE(under.accepted) << under.reason;
  // Apex -0.2 + 0.1745 = -0.0255 m: 0.0045 m above the bound, within 0.1 eps.
  EXPECT_TRUE(validate_request(state_, 2, pile(0.001745)).accepted);
  // Apex -0.2 + 0.1755 = -0.0245 m: 0.0055 m above the bound.
  const Verdict over = validate_request(state_, 2, pile(0.001755));
  EXPECT_FALSE(over.accepted);
  EXPECT_EQ(over.rule, 3);
  EXPECT_NE(over.reason.find("would leave cell (20, 28) at -0.0245"), std::string::npos) << over.reason;
  EXPECT_NE(over.reason.find("above the deposit bound -0.03 m (MARS of the initial terrain at kappa 0.3), more than "
                             "0.005"),
            std::string::npos)
      << over.reason;
}

TEST_F(DepositBound, PilesCannotRaiseTheBound) {
  // Earlier construction (as piles judged against the current terrain left it) raised the hole's eight neighbours by
  // 0.05 m: the current terrain's MARS over the hole is now 0.05 - 0.03 = 0.02 m, 0.05 m above the initial one.
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc)
      if (dr != 0 || dc != 0) state_.terrain(kHole.row + dr, kHole.col + dc) += 0.05;
  const Heightmap current_bound = MarsProcessor(0.3).project(state_.terrain);
  ASSERT_NEAR(current_bound(kHole), 0.02, 1e-9);
  // A pile with its apex at 0 m: 0.02 m under the current terrain's MARS, 0.03 m above the initial terrain's.
  const DepositShape shape = cone_pile_shape(state_.terrain, kGrid.cell_center(kHole), 0.002, 34.0);
  ASSERT_EQ(shape.rises.size(), 1u);
  ASSERT_NEAR(state_.terrain(kHole) + shape.rises[0].rise_m, 0.0, 1e-12);
  ASSERT_LE(state_.terrain(kHole) + shape.rises[0].rise_m, current_bound(kHole) + kAllowedM);
  const Verdict v = validate_request(state_, 2, pile(0.002));
  EXPECT_FALSE(v.accepted);
  EXPECT_NE(v.reason.find("above the deposit bound -0.03 m"), std::string::npos) << v.reason;
}

TEST_F(DepositBound, ACubeColumnIsJudgedByTheSameBound) {
  // One 0.1 m cube on flat ground 0.8 m east of agent 1: 0.1 m above the bound (0 m there).
  protocol::ActionRequest r = request_for(state_, 1);
  const Position at = kGrid.cell_center({30, 18});
  r.deposits = {{at.x, at.y, 0.001}};
  const Verdict v = validate_request(state_, 1, r);
  EXPECT_FALSE(v.accepted);
  EXPECT_NE(v.reason.find("above the deposit bound 0 m"), std::string::npos) << v.reason;
}

TEST_F(DepositBound, ALayerRobotsDepositionsAreJudgedByTheSameBound) {
  // Agent 3 (layers of 0.0125 m: 0.05 m cubes on 0.1 m cells) at (1.05, 3.05), cell (9, 17) 0.7 m east of it. On flat
  // ground the bound is the ground: one layer leaves the cell 0.0125 m above it, more than 0.1 eps (0.005 m).
  const CellIndex cell{9, 17};
  ASSERT_NEAR(state_.deposit_bound(cell), 0.0, 1e-12);
  protocol::ActionRequest r = request_for(state_, 3);
  r.depositions = {{cell.row, cell.col, 0.0125}};
  const Verdict over = validate_request(state_, 3, r);
  EXPECT_FALSE(over.accepted);
  EXPECT_EQ(over.rule, 3);
  EXPECT_NE(over.reason.find("deposition would leave cell (9, 17) at 0.0125 m, 0.0125 m above the deposit bound 0 m"),
            std::string::npos)
      << over.reason;
  // Where the bound stands 0.02 m high (as beside a higher initial cell), one layer fits and three do not.
  state_.deposit_bound(cell) = 0.02;
  EXPECT_TRUE(validate_request(state_, 3, r).accepted);
  r.depositions = {{cell.row, cell.col, 0.0375}};
  EXPECT_FALSE(validate_request(state_, 3, r).accepted);
}

TEST(DepositBoundStart, ATeamOfLayerRobotsWithAScanningRobotHasTheBound) {
  // Exact layer robots never build above the bound (they fill up to their map's MARS height); a robot that builds
  // from its own scans may read a cell low and overshoot, so its team is judged.
  std::string text = kScenario;
  for (const char* kind : {"depositor { name: \"cube\" cube_size_m: 0.1 }", "depositor { name: \"cone\" repose_deg: 34 }"})
    text.replace(text.find(kind), std::string(kind).size(), "");
  text.insert(text.find("agent {"), "robot_type { name: \"scout\" behaviour: \"scripted\" body { kappa: 0.3 delta_m: 1.0 "
                                    "eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05 reach_m: "
                                    "1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 } sensor { name: "
                                    "\"laser\" } }\n");
  const std::string layers_only = text;
  text.replace(text.find("robot_type: \"layerer\""), 21, "robot_type: \"scout\"");
  const WorldState exact = make_world_state(scenario::parse_scenario(layers_only, "layers.pbtxt"), flat_terrain(), 3);
  EXPECT_EQ(exact.deposit_bound.size(), 0);
  const WorldState scanning = make_world_state(scenario::parse_scenario(text, "scanning.pbtxt"), flat_terrain(), 3);
  EXPECT_EQ(scanning.deposit_bound.rows(), 40);
}

TEST(DepositBoundStart, ATeamOfLayerRobotsHasNoBound) {
  std::string text = kScenario;
  for (const char* kind : {"depositor { name: \"cube\" cube_size_m: 0.1 }", "depositor { name: \"cone\" repose_deg: 34 }"})
    text.replace(text.find(kind), std::string(kind).size(), "");
  const WorldState state = make_world_state(scenario::parse_scenario(text, "layers.pbtxt"), flat_terrain(), 3);
  EXPECT_EQ(state.deposit_bound.size(), 0);
}

TEST(DepositorStart, ACubeNarrowerThanACellIsRefusedAtStart) {
  std::string text = kScenario;
  text.replace(text.find("cube_size_m: 0.1 }"), 18, "cube_size_m: 0.05 }");
  const scenario::Scenario s = scenario::parse_scenario(text, "narrow.pbtxt");
  try {
    make_world_state(s, flat_terrain(), 3);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("robot type 'cuber': depositor.cube_size_m 0.05 m is smaller than the cell "
                                         "size 0.1 m"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace marsala::world_server
