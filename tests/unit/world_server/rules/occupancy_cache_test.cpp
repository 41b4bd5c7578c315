// OccupancyCache: after any changes, the incrementally updated mask equals NavigabilityProcessor on the whole area
// (balls cut at the area's edge), for balls smaller and larger than a change block; and the cost of one payload and
// one site check of apply_step on a 640 x 640 grid (printed; run in Release for the numbers).

#include "marsala/world_server/rules/occupancy_cache.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>

#include "marsala/core/error.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/scenario/terrain_builder.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

Heightmap rough(std::mt19937& rng, int rows, int cols, double cs) {
  Heightmap h(GridGeometry{rows, cols, 0.0, 0.0, cs});
  std::uniform_real_distribution<double> noise(0.0, 0.01);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) h(r, c) = 0.02 * std::sin(0.3 * r) * std::cos(0.2 * c) + noise(rng);
  return h;
}

CellMask full(const Heightmap& h, const CellRect& a, NavigabilityParams p) {
  return NavigabilityProcessor(p).occupiable(h.window(a.first, a.rows, a.cols));
}

TEST(OccupancyCache, IncrementalUpdatesEqualTheWholeComputation) {
  std::mt19937 rng(3);
  for (const double delta : {0.3, 1.0, 2.5, 4.1}) {  // reach 1, 5, 12 and 20 cells (one more than a block)
    Heightmap h = rough(rng, 90, 75, 0.1);
    const NavigabilityParams p{0.3, delta, 0.03};
    for (const CellRect area : {CellRect{{0, 0}, 90, 75}, CellRect{{17, 9}, 50, 41}}) {
      OccupancyCache cache(h, area, p);
      ASSERT_EQ(cache.occupiable(), full(h, area, p));
      std::uniform_int_distribution<int> row(0, 89), col(0, 74), count(1, 6);
      std::uniform_real_distribution<double> raise(0.01, 0.4);
      for (int round = 0; round < 8; ++round) {
        const int clusters = count(rng);
        for (int k = 0; k < clusters; ++k) {
          const int r0 = row(rng), c0 = col(rng);
          for (int j = 0; j < 4; ++j) {
            const CellIndex c{std::min(89, r0 + j % 2), std::min(74, c0 + j / 2)};
            h(c) += raise(rng);
            cache.mark_changed(c);
          }
        }
        if (round % 3 == 0) {  // the grid's corner cells
          h(0, 0) += 0.2;
          h(89, 74) += 0.2;
          cache.mark_changed({0, 0});
          cache.mark_changed({89, 74});
        }
        const bool changed = cache.has_changes();
        const long long work = cache.update(h);
        EXPECT_EQ(work > 0, changed);
        EXPECT_FALSE(cache.has_changes());
        ASSERT_EQ(cache.occupiable(), full(h, area, p)) << "delta " << delta << " round " << round;
      }
    }
  }
}

TEST(OccupancyCache, OnlyCellsNearChangesAreRecomputedAndOutsideChangesAreIgnored) {
  std::mt19937 rng(8);
  Heightmap h = rough(rng, 160, 160, 0.1);
  const NavigabilityParams p{0.3, 1.0, 0.03};
  OccupancyCache cache(h, {{40, 40}, 80, 80}, p);
  EXPECT_EQ(cache.reach(), 5);
  EXPECT_EQ(cache.update(h), 0);
  h(10, 10) += 1.0;  // outside the area: its cells' balls are cut at the area's edge
  cache.mark_changed({10, 10});
  EXPECT_FALSE(cache.has_changes());
  h(80, 80) += 1.0;
  cache.mark_changed({80, 80});  // area cell (40, 40)
  const long long work = cache.update(h);
  EXPECT_EQ(work, 11 * 11);  // the cells within reach 5 of the change
  EXPECT_EQ(cache.occupiable(), full(h, {{40, 40}, 80, 80}, p));
  EXPECT_EQ(cache.occupiable()(40, 40), 0);  // the raised cell itself
}

TEST(OccupancyCache, BadAreasAreErrors) {
  const Heightmap h(GridGeometry{20, 20, 0.0, 0.0, 0.1});
  EXPECT_THROW(OccupancyCache(h, {{0, 0}, 0, 5}, {}), InvalidArgument);
  EXPECT_THROW(OccupancyCache(h, {{15, 0}, 6, 5}, {}), InvalidArgument);
  EXPECT_THROW(OccupancyCache(h, {{-1, 0}, 6, 5}, {}), InvalidArgument);
  EXPECT_THROW(OccupancyCache(h, {{0, 0}, 5, 5}, {0.3, -1.0, 0.05}), InvalidArgument);
  OccupancyCache cache(h, {{0, 0}, 20, 20}, {});
  cache.mark_changed({3, 3});
  EXPECT_THROW(cache.update(Heightmap(GridGeometry{10, 10, 0.0, 0.0, 0.1})), InvalidArgument);
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

/// Ten steps of twelve builders: each raises the cells within 1.2 m of its spot by one cube layer.
void deposit_round(WorldState& s, std::mt19937& rng) {
  std::uniform_int_distribution<int> spot(20, 619);
  const double cs = s.terrain.cell_size_m();
  const int reach = static_cast<int>(1.2 / cs);
  for (int agent = 0; agent < 12; ++agent) {
    const int r0 = spot(rng), c0 = spot(rng);
    for (int dr = -reach; dr <= reach; ++dr)
      for (int dc = -reach; dc <= reach; ++dc)
        if ((dr * dr + dc * dc) * cs * cs <= 1.44) {
          s.terrain(r0 + dr, c0 + dc) += 0.0125;
          s.check.occupancy.mark_changed({r0 + dr, c0 + dc});
        }
  }
}

/// One payload and one site check on 640 x 640 cells, after 12 builders deposited (median of 5), and the whole
/// computation beside it. Asserts that the incremental check gives the whole computation's answer.
TEST(CompletionCheckCost, PayloadAndSiteChecksOn640x640) {
  struct Case {
    const char* generator;
    double cs;
    std::string completion;
  };
  const Case cases[] = {
      {"mix", 0.25,
       "payload_path { body { kappa: 0.2 delta_m: 2.0 eps_m: 0.05 } from { x_m: 1 y_m: 1 } to { x_m: 159 y_m: 159 } }"},
      {"fractal", 0.25,
       "payload_path { body { kappa: 0.2 delta_m: 2.0 eps_m: 0.05 } from { x_m: 1 y_m: 1 } to { x_m: 159 y_m: 159 } }"},
      {"mix", 0.25, "site { x0_m: 0 y0_m: 0 x1_m: 160 y1_m: 160 kappa: 0.1 delta_m: 1.0 eps_m: 0.05 }"},
      {"fractal", 0.25, "site { x0_m: 0 y0_m: 0 x1_m: 160 y1_m: 160 kappa: 0.1 delta_m: 1.0 eps_m: 0.05 }"},
      {"flat", 0.25,
       "payload_path { body { kappa: 0.2 delta_m: 2.0 eps_m: 0.05 } from { x_m: 1 y_m: 1 } to { x_m: 159 y_m: 159 } }"},
      {"flat", 0.25, "site { x0_m: 0 y0_m: 0 x1_m: 160 y1_m: 160 kappa: 0.1 delta_m: 1.0 eps_m: 0.05 }"},
      {"fractal", 0.1,
       "payload_path { body { kappa: 0.2 delta_m: 2.0 eps_m: 0.05 } from { x_m: 1 y_m: 1 } to { x_m: 63 y_m: 63 } }"},
  };
  for (const Case& c : cases) {
    const std::string text =
        "name: \"bench\"\nterrain { generator: \"" + std::string(c.generator) +
        "\" rows: 640 cols: 640 cell_size_m: " + std::to_string(c.cs) + " seed: 7 }\n" + testing::kTestRobotType +
        "agent { robot_type: \"tester\" start { x_m: 1 y_m: 1 } target { x_m: 2 y_m: 2 } }\n" + c.completion + "\n";
    const scenario::Scenario sc = scenario::parse_scenario(text, "bench.pbtxt");
    auto t0 = std::chrono::steady_clock::now();
    WorldState s = make_world_state(sc, scenario::build_terrain(sc), 1);
    const double initial_ms = ms_since(t0);
    std::mt19937 rng(1);
    std::vector<double> check_ms, whole_ms;
    for (int round = 0; round < 5; ++round) {
      deposit_round(s, rng);
      t0 = std::chrono::steady_clock::now();
      evaluate_completion(s);
      check_ms.push_back(ms_since(t0));
      t0 = std::chrono::steady_clock::now();
      if (sc.completion == scenario::CompletionKind::kPayloadPath) {
        EXPECT_EQ(s.check.met, payload_path_navigable(s.terrain, sc.payload_path));
      } else {
        EXPECT_EQ(s.check.level_fraction, site_level_fraction(s.terrain, sc.site));
      }
      whole_ms.push_back(ms_since(t0));
    }
    std::sort(check_ms.begin(), check_ms.end());
    std::sort(whole_ms.begin(), whole_ms.end());
    std::printf(
        "%-12s %-8s cs %.2f m: one check %.1f ms (median of 5; max %.1f), whole computation %.1f ms, "
        "initial %.1f ms; met %d, level fraction %.4f\n",
        scenario::to_string(sc.completion).c_str(), c.generator, c.cs, check_ms[2], check_ms[4], whole_ms[2],
        initial_ms, s.check.met ? 1 : 0, s.check.level_fraction);
  }
}

}  // namespace
}  // namespace marsala::world_server
