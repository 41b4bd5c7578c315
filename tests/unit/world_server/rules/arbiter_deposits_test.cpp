// Rule 3 for cube and cone depositors (docs/runtime.md#rule-3-deposits): each condition accepted and rejected with
// its reason, and what an accepted request writes checked against the shape functions and the volume.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
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
  DepositsTest()
      : scenario_(scenario::parse_scenario(kScenario, "deposits.pbtxt")),
        state_(admitted_state(scenario_, flat_terrain(), 3)) {}
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
