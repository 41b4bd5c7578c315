// Refused cells (agent/executive/refused_cells.hpp): what the world's refusals teach a robot, on small maps.

#include "marsala/agent/executive/refused_cells.hpp"

#include <gtest/gtest.h>

#include "marsala/core/error.hpp"

namespace marsala::agent::executive {
namespace {

Heightmap flat(double h = 0.0) { return Heightmap({20, 20, 0.0, 0.0, 0.1}, h); }
CellMask all_known() { return CellMask::Ones(20, 20); }

TEST(RefusedCells, ReadsTheCellTheWorldsReasonsName) {
  // The reasons of docs/runtime.md#validation, rules 2.3, 2.4, 3.5 and 3d.8.
  EXPECT_EQ(cell_named("target cell (99, 158) is not occupiable for this body"), (CellIndex{99, 158}));
  EXPECT_EQ(cell_named("motion passes through cell (3, 4), not occupiable for this body"), (CellIndex{3, 4}));
  EXPECT_EQ(cell_named("deposition cell (7, 12) is under agent 2"), (CellIndex{7, 12}));
  EXPECT_EQ(cell_named("deposit at (1.05, 2.05) m raises cell (5, 6), under agent 1"), (CellIndex{5, 6}));
  EXPECT_FALSE(cell_named("motion of 0.3 m exceeds max_step_m 0.2").has_value());
  EXPECT_FALSE(cell_named("").has_value());
  EXPECT_TRUE(refused_for_terrain("target cell (99, 158) is not occupiable for this body"));
  EXPECT_TRUE(refused_for_terrain("motion passes through cell (3, 4), not occupiable for this body"));
  EXPECT_FALSE(refused_for_terrain("motion ends 0.8 m from agent 2, whose body it would overlap (bodies need 1 m)"));
  // The drop the body found, when the world names it: the lower cell first, each with its height to the last bit.
  const std::string dropped = "target cell (119, 128) is not occupiable for this body: cell (120, 131) at 0.05 m lies "
                              "too far below cell (119, 127) at 1.3750000000000002 m";
  EXPECT_EQ(cell_named(dropped), (CellIndex{119, 128}));
  const auto drop = drop_named(dropped);
  ASSERT_TRUE(drop.has_value());
  EXPECT_EQ(drop->low, (CellIndex{120, 131}));
  EXPECT_EQ(drop->low_m, 0.05);
  EXPECT_EQ(drop->high, (CellIndex{119, 127}));
  EXPECT_EQ(drop->high_m, 1.3750000000000002);
  EXPECT_FALSE(drop_named("target cell (1, 2) is not occupiable for this body: cell (3, 4) lies too far below cell "
                          "(5, 6)")
                   .has_value());  // no heights: nothing to learn
  EXPECT_FALSE(drop_named("target cell (1, 2) is not occupiable for this body: cell (3, 4) at nan m lies too far "
                          "below cell (5, 6) at 1 m")
                   .has_value());
  EXPECT_FALSE(drop_named("target cell (99, 158) is not occupiable for this body").has_value());
  // Every drop a refusal names, the worst first; a malformed entry ends the list there.
  const auto drops = drops_named(dropped + "; cell (121, 131) at 0.1 m lies too far below cell (119, 127) at 1.375 m; "
                                           "cell (122, 130) at 0 m lies too far below cell (118, 126) at 1.5 m");
  ASSERT_EQ(drops.size(), 3u);
  EXPECT_EQ(drops[0].low, drop->low);
  EXPECT_EQ(drops[0].high_m, drop->high_m);
  EXPECT_EQ(drops[1].low, (CellIndex{121, 131}));
  EXPECT_EQ(drops[1].low_m, 0.1);
  EXPECT_EQ(drops[1].high, (CellIndex{119, 127}));
  EXPECT_EQ(drops[2].low, (CellIndex{122, 130}));
  EXPECT_EQ(drops[2].high, (CellIndex{118, 126}));
  EXPECT_EQ(drops[2].high_m, 1.5);
  EXPECT_EQ(drops_named(dropped + "; cell (1, 2) at nan m lies too far below cell (3, 4) at 1 m; cell (5, 6) at 0 m "
                                  "lies too far below cell (7, 8) at 1 m")
                .size(),
            1u);
  EXPECT_EQ(drops_named(dropped).size(), 1u);
  EXPECT_TRUE(drops_named("target cell (99, 158) is not occupiable for this body").empty());
  // The deposit bound's refusals (rules 3.5b, 3d.10) name the height the request would have left.
  const auto bound = bound_named("deposition would leave cell (113, 141) at 0.6 m, 0.27 m above the deposit bound "
                                 "0.33 m (MARS of the initial terrain at kappa 0.3), more than 0.005 m");
  ASSERT_TRUE(bound.has_value());
  EXPECT_EQ(bound->cell, (CellIndex{113, 141}));
  EXPECT_DOUBLE_EQ(bound->height_m, 0.6);
  EXPECT_TRUE(bound_named("deposit at (2.85, 1.95) would leave cell (20, 28) at -0.0245 m, 0.0055 m above the deposit "
                          "bound -0.03 m (MARS of the initial terrain at kappa 0.3), more than 0.005 m")
                  .has_value());
  EXPECT_FALSE(bound_named("deposition cell (7, 12) is under agent 2").has_value());
  EXPECT_FALSE(bound_named("deposition would leave cell (1, 2) at nan m, x m above the deposit bound").has_value());
  EXPECT_FALSE(drop_named("target cell (1, 2) is not occupiable for this body: cell (3, x) lies").has_value());
  // A pile that reached a robot's body (rule 3d.8) names where it was dumped, to the last bit the world printed.
  const auto pile = pile_under_robot_named("deposit at (17.150000000000002, 11.25) m raises cell (86, 170), under agent 3");
  ASSERT_TRUE(pile.has_value());
  EXPECT_EQ(*pile, (Position{17.150000000000002, 11.25}));
  EXPECT_FALSE(pile_under_robot_named("deposition cell (7, 12) is under agent 2").has_value());
  EXPECT_FALSE(pile_under_robot_named("deposit at (2.85, 1.95) m is 1.6 m away, beyond reach_m 1.5").has_value());
  EXPECT_FALSE(pile_under_robot_named("deposit at (nan, 1.95) m raises cell (1, 2), under agent 3").has_value());
}

TEST(RefusedCells, ATerrainRefusalHoldsUntilTheMapAroundTheCellChanges) {
  RefusedCells refused(2.0, 0.01, 40);
  Heightmap h = flat();
  CellMask known = all_known();
  refused.refuse_terrain({10, 10}, h, known);
  // The same map for ever: the cell stays out, however many steps pass.
  for (std::uint64_t step = 1; step < 1000; step += 97) {
    refused.update(h, known, step);
    EXPECT_TRUE(refused.contains({10, 10})) << step;
  }
  // A change within the map's noise margin, or outside the ball (2 cells), is no news.
  h(10, 11) = 0.009;
  h(10, 13) = 1.0;
  refused.update(h, known, 2000);
  EXPECT_TRUE(refused.contains({10, 10}));
  // A height in the ball read differently (another robot built there) is.
  h(11, 11) = 0.05;
  refused.update(h, known, 2001);
  EXPECT_FALSE(refused.contains({10, 10}));
  EXPECT_TRUE(refused.empty());

  // So is a cell of the ball that became known (or unknown).
  known(8, 10) = 0;
  refused.refuse_terrain({10, 10}, h, known);
  known(8, 10) = 1;
  refused.update(h, known, 2002);
  EXPECT_FALSE(refused.contains({10, 10}));
  EXPECT_EQ(refused.refusals(), 2);
}

// A refusal that named its drop: the lower cell rising at all (the robot's own construction in the pit, a layer less
// than the change that counts) releases it; the same rise elsewhere in the ball does not. Even beyond the ball.
TEST(RefusedCells, ARiseOfTheNamedDropsLowerCellReleasesTheRefusal) {
  RefusedCells refused(2.0, 0.04, 40);
  Heightmap h = flat();
  const CellMask known = all_known();
  refused.refuse_terrain({10, 10}, h, known, CellIndex{10, 14});
  h(11, 11) = 0.0125;  // a layer in the ball, under the change that counts
  refused.update(h, known, 1);
  EXPECT_TRUE(refused.contains({10, 10}));
  h(10, 14) = 0.0125;  // the same layer in the named pit
  refused.update(h, known, 2);
  EXPECT_FALSE(refused.contains({10, 10}));
  // Without a named drop the pit's layer is no news.
  h = flat();
  refused.refuse_terrain({10, 10}, h, known);
  h(10, 12) = 0.0125;
  refused.update(h, known, 3);
  EXPECT_TRUE(refused.contains({10, 10}));
}

// A cell refused again after its map changed needs twice the change the time after: 0.01, 0.02, 0.04 m.
TEST(RefusedCells, EachRepeatedTerrainRefusalAsksForAChangeTwiceAsLarge) {
  RefusedCells refused(2.0, 0.01, 40);
  Heightmap h = flat();
  const CellMask known = all_known();
  double level = 0.0;
  for (const double needed : {0.01, 0.02, 0.04}) {
    refused.refuse_terrain({10, 10}, h, known);
    h(10, 11) = level + 0.9 * needed;
    refused.update(h, known, 1);
    EXPECT_TRUE(refused.contains({10, 10})) << needed;
    h(10, 11) = level + 1.1 * needed;
    refused.update(h, known, 2);
    EXPECT_FALSE(refused.contains({10, 10})) << needed;
    level = h(10, 11);
  }
}

TEST(RefusedCells, AnotherRefusalHoldsForItsStepsAndATerrainRefusalStaysOne) {
  RefusedCells refused(2.0, 0.01, 40);
  const Heightmap h = flat();
  const CellMask known = all_known();
  refused.refuse_for_now({3, 3}, 100);
  refused.update(h, known, 139);
  EXPECT_TRUE(refused.contains({3, 3}));
  refused.update(h, known, 140);
  EXPECT_FALSE(refused.contains({3, 3}));

  refused.refuse_terrain({5, 5}, h, known);
  refused.refuse_for_now({5, 5}, 100);
  refused.update(h, known, 5000);
  EXPECT_TRUE(refused.contains({5, 5}));
  EXPECT_EQ(refused.cells(), (std::vector<CellIndex>{{5, 5}}));
}

TEST(RefusedCells, RefusesBadParameters) {
  EXPECT_THROW(RefusedCells(-1.0, 0.01, 40), InvalidArgument);
  EXPECT_THROW(RefusedCells(2.0, 0.0, 40), InvalidArgument);
  EXPECT_THROW(RefusedCells(2.0, 0.01, 0), InvalidArgument);
}

}  // namespace
}  // namespace marsala::agent::executive
