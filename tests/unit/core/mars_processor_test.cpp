#include "marsala/core/mars_processor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "marsala/core/detail/mars_seed.hpp"
#include "marsala/core/error.hpp"
#include "support/mars_brute_force.hpp"

namespace marsala {
namespace {

// Documented accuracy of MarsProcessor: never above the exact P (beyond rounding), at most
// 2 * 1e-10 m below it for these magnitudes.
constexpr double kShortfallM = 2e-10;
constexpr double kRoundingM = 1e-11;

GridGeometry geometry(int rows, int cols, double cs) { return {rows, cols, -3.0, 7.5, cs}; }

double distance_m(const Heightmap& h, CellIndex a, CellIndex b) {
  const Position pa = h.cell_center(a), pb = h.cell_center(b);
  return std::hypot(pa.x - pb.x, pa.y - pb.y);
}

// Compares the fast projection with the brute-force reference on every cell.
void expect_matches_brute_force(const Heightmap& h, double kappa, const std::string& label) {
  const Heightmap fast = MarsProcessor(kappa).project(h);
  const Heightmap slow = testing::mars_brute_force(h, kappa);
  ASSERT_EQ(fast.geometry(), h.geometry()) << label;
  int bad = 0;
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const double diff = fast(r, c) - slow(r, c);
      if (diff > kRoundingM || diff < -(kShortfallM + kRoundingM)) {
        if (++bad <= 5)
          ADD_FAILURE() << label << ": cell (" << r << ", " << c << ") fast " << fast(r, c) << " brute " << slow(r, c)
                        << " diff " << diff;
      }
    }
  EXPECT_EQ(bad, 0) << label;
}

// ---- small terrain families, each seeded ---------------------------------------------------

Heightmap uniform_noise(std::mt19937& rng, int rows, int cols, double cs, double amplitude) {
  std::uniform_real_distribution<double> u(0.0, amplitude);
  Heightmap h(geometry(rows, cols, cs));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) h(r, c) = u(rng);
  return h;
}

// Bilinear value noise with lattice period `period` cells plus a little white noise.
Heightmap smooth_noise(std::mt19937& rng, int rows, int cols, double cs, double amplitude, int period) {
  std::uniform_real_distribution<double> u(0.0, amplitude);
  const int lr = rows / period + 2, lc = cols / period + 2;
  std::vector<double> lattice(static_cast<std::size_t>(lr) * lc);
  for (double& v : lattice) v = u(rng);
  Heightmap h(geometry(rows, cols, cs));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double fr = static_cast<double>(r) / period, fc = static_cast<double>(c) / period;
      const int ir = static_cast<int>(fr), ic = static_cast<int>(fc);
      const double tr = fr - ir, tc = fc - ic;
      auto at = [&](int a, int b) { return lattice[static_cast<std::size_t>(a) * lc + b]; };
      h(r, c) = (1 - tr) * ((1 - tc) * at(ir, ic) + tc * at(ir, ic + 1)) +
                tr * ((1 - tc) * at(ir + 1, ic) + tc * at(ir + 1, ic + 1)) + 0.01 * u(rng);
    }
  return h;
}

// Flat ground cut by four straight cliffs (half-plane steps) at random angles, plus a plateau.
Heightmap cliffs(std::mt19937& rng, int rows, int cols, double cs) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(geometry(rows, cols, cs), 0.0);
  for (int k = 0; k < 4; ++k) {
    const double step = 0.3 + 2.0 * u(rng);
    const double a = u(rng) * 2 * M_PI, off = (u(rng) - 0.5) * (rows + cols) * 0.25;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        if ((c - cols / 2) * std::cos(a) + (r - rows / 2) * std::sin(a) > off) h(r, c) += step;
  }
  // A plateau with vertical walls.
  const int r0 = rows / 4, c0 = cols / 3;
  for (int r = r0; r < r0 + rows / 3; ++r)
    for (int c = c0; c < c0 + cols / 4; ++c) h(r, c) += 1.5;
  return h;
}

Heightmap spikes(std::mt19937& rng, int rows, int cols, double cs, int count) {
  std::uniform_int_distribution<int> rr(0, rows - 1), cc(0, cols - 1);
  std::uniform_real_distribution<double> height(0.5, 4.0);
  Heightmap h(geometry(rows, cols, cs), 0.0);
  for (int k = 0; k < count; ++k) h(rr(rng), cc(rng)) = height(rng);
  return h;
}

// A few main spikes, each with satellites that its cone almost dominates (by 1e-5 .. 1e-3 m): a
// satellite wins only in a thin hyperbolic sliver behind it, which source propagation misses, so
// this family exercises the exact search itself.
// `rise` scales the spikes' heights above the ground [m].
void add_satellites(std::mt19937& rng, double kappa, double margin, Heightmap& h, double rise = 1.0) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int rows = h.rows(), cols = h.cols();
  for (int m = 0; m < 3; ++m) {
    const CellIndex s{static_cast<int>(rng() % rows), static_cast<int>(rng() % cols)};
    const double top = h(s) + rise * (1.0 + 2.0 * u(rng));
    h(s) = top;
    for (int k = 0; k < 25; ++k) {
      const CellIndex q{static_cast<int>(rng() % rows), static_cast<int>(rng() % cols)};
      h(q) = std::max(h(q), top - kappa * distance_m(h, q, s) + margin * (0.1 + u(rng)));
    }
  }
}

// Lifts a few random cells by 1e-9 .. 1e-4 m: each becomes the source of the cells that its
// slope-kappa surface nearly ties with, right where the plane, cone and bowl bounds are tight.
void add_bumps(std::mt19937& rng, Heightmap& h) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20; ++k)
    h(static_cast<int>(rng() % h.rows()), static_cast<int>(rng() % h.cols())) += std::pow(10.0, -9.0 + 5.0 * u(rng));
}

Heightmap satellites(std::mt19937& rng, double kappa, int rows, int cols, double cs, double margin, double noise) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(geometry(rows, cols, cs), 0.0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) h(r, c) = noise * u(rng);
  add_satellites(rng, kappa, margin, h);
  return h;
}

// h = kappa * (x cos(a) + y sin(a)): every cell is a source that no other cell dominates.
Heightmap exact_plane(double kappa, double angle, int rows, int cols, double cs) {
  Heightmap h(geometry(rows, cols, cs));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const Position p = h.cell_center({r, c});
      h(r, c) = kappa * (p.x * std::cos(angle) + p.y * std::sin(angle));
    }
  return h;
}

// h = max_i (H_i - kappa |p - a_i|); apexes anywhere (on_centres: on cell centres).
Heightmap exact_cones(std::mt19937& rng, double kappa, int rows, int cols, double cs, int count, bool on_centres) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(geometry(rows, cols, cs), -std::numeric_limits<double>::infinity());
  for (int k = 0; k < count; ++k) {
    Position a{-3.0 + u(rng) * cols * cs, 7.5 + u(rng) * rows * cs};
    if (on_centres) a = h.cell_center({static_cast<int>(u(rng) * rows), static_cast<int>(u(rng) * cols)});
    const double top = 1.0 + 3.0 * u(rng);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const Position p = h.cell_center({r, c});
        h(r, c) = std::max(h(r, c), top - kappa * std::hypot(p.x - a.x, p.y - a.y));
      }
  }
  return h;
}

// h = min_i (c_i + kappa |p - a_i|): bowls of slope exactly kappa (a distance field), apexes anywhere.
Heightmap exact_bowls(std::mt19937& rng, double kappa, int rows, int cols, double cs, int count) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(geometry(rows, cols, cs), std::numeric_limits<double>::infinity());
  for (int k = 0; k < count; ++k) {
    const Position a{-3.0 + u(rng) * cols * cs, 7.5 + u(rng) * rows * cs};
    const double bottom = 2.0 * u(rng);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const Position p = h.cell_center({r, c});
        h(r, c) = std::min(h(r, c), bottom + kappa * std::hypot(p.x - a.x, p.y - a.y));
      }
  }
  return h;
}

// h = H - kappa * distance to a segment (a ridge with half-cones at its ends) or, with
// `roof`, to a whole line (two planes of slope kappa meeting at a crest).
Heightmap exact_ridge(std::mt19937& rng, double kappa, int rows, int cols, double cs, bool roof) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Position a{-3.0 + u(rng) * cols * cs, 7.5 + u(rng) * rows * cs};
  const Position b{-3.0 + u(rng) * cols * cs, 7.5 + u(rng) * rows * cs};
  Heightmap h(geometry(rows, cols, cs));
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const Position p = h.cell_center({r, c});
      double t = ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2;
      if (!roof) t = std::clamp(t, 0.0, 1.0);
      h(r, c) = 3.0 - kappa * std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
    }
  return h;
}

// ---- numeric limits: combinations doubles cannot compute are refused, never looped on ----------------------

TEST(MarsProcessorLimits, ARiseLostInRoundingIsRefusedNotLoopedOn) {
  // Heights of 1e16 m: doubles there are 2 m apart, so a 0.3 m rise per cell vanishes (this looped before).
  Heightmap high({5, 6, 0.0, 0.0, 1.0}, 1e16);
  high(2, 3) = 1e16 + 4.0;
  EXPECT_THROW(MarsProcessor(0.3).project(high), InvalidArgument);
  try {
    MarsProcessor(0.3).gap(high);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("kappa 0.3 x cell size 1 m = 0.3 m per cell is lost in rounding"),
              std::string::npos)
        << e.what();
  }
  // A scenario-legal but absurd kappa on ordinary heights.
  EXPECT_THROW(MarsProcessor(1e-300).project(Heightmap({4, 4, 0.0, 0.0, 0.1}, 1.0)), InvalidArgument);
  EXPECT_NE(mars_problem(1e-300, 0.1, 1.0, 4, 4).find("lost in rounding"), std::string::npos);
  // Overflow of the magnitude itself.
  EXPECT_NE(mars_problem(1e300, 1e300, 1.0, 4, 4).find("overflows"), std::string::npos);
}

TEST(MarsProcessorLimits, LargeButComputableHeightsStillMatchBruteForce) {
  // Heights of 1e12 m (doubles 1.2e-4 m apart) with 0.3 m per cell: 16 spacings are 2e-3 m, well below the rise.
  EXPECT_EQ(mars_problem(0.3, 1.0, 1e12, 9, 9), "");
  EXPECT_EQ(mars_problem(0.3, 0.1, 9000.0, 4000, 4000), "");  // a large real world
  Heightmap h({9, 9, 0.0, 0.0, 1.0}, 1e12);
  h(4, 4) = 1e12 + 5.0;
  h(0, 8) = 1e12 + 2.0;
  expect_matches_brute_force(h, 0.3, "1e12 m heights");
}

// ---- fast == brute force on many seeded random grids ---------------------------------------

struct Case {
  int rows, cols;
  double cs, kappa;
};

std::vector<Case> random_cases(std::mt19937& rng, int count) {
  std::uniform_int_distribution<int> size(20, 70);
  const double sizes[] = {0.05, 0.1, 0.25, 1.0, 2.5};
  const double kappas[] = {0.05, 0.3, 0.5, 1.0, 3.0};
  std::vector<Case> cases;
  for (int k = 0; k < count; ++k) cases.push_back({size(rng), size(rng), sizes[rng() % 5], kappas[rng() % 5]});
  return cases;
}

std::string describe(const std::string& family, int seed, const Case& k) {
  return family + " seed " + std::to_string(seed) + " " + std::to_string(k.rows) + "x" + std::to_string(k.cols) +
         " cs " + std::to_string(k.cs) + " kappa " + std::to_string(k.kappa);
}

void run_family(const std::string& family, int count,
                const std::function<Heightmap(std::mt19937&, const Case&)>& make) {
  for (int seed = 1; seed <= count; ++seed) {
    std::mt19937 rng(seed * 7919 + static_cast<int>(family.size()));
    const Case k = random_cases(rng, 1)[0];
    expect_matches_brute_force(make(rng, k), k.kappa, describe(family, seed, k));
  }
}

TEST(MarsProcessorBruteForce, UniformNoise) {
  run_family("uniform", 8,
             [](std::mt19937& rng, const Case& k) { return uniform_noise(rng, k.rows, k.cols, k.cs, 3.0); });
}

TEST(MarsProcessorBruteForce, SmoothNoise) {
  run_family("smooth", 8, [](std::mt19937& rng, const Case& k) {
    return smooth_noise(rng, k.rows, k.cols, k.cs, 0.5 + 4.0 * k.kappa * k.cs * 10, 6);
  });
}

TEST(MarsProcessorBruteForce, CliffsAndSteps) {
  run_family("cliffs", 8, [](std::mt19937& rng, const Case& k) { return cliffs(rng, k.rows, k.cols, k.cs); });
}

TEST(MarsProcessorBruteForce, SingleSpike) {
  run_family("spike", 5, [](std::mt19937& rng, const Case& k) { return spikes(rng, k.rows, k.cols, k.cs, 1); });
}

TEST(MarsProcessorBruteForce, SeveralSpikes) {
  run_family("spikes", 8, [](std::mt19937& rng, const Case& k) { return spikes(rng, k.rows, k.cols, k.cs, 12); });
}

TEST(MarsProcessorBruteForce, NearlyDominatedSatellites) {
  run_family("satellites", 10, [](std::mt19937& rng, const Case& k) {
    const double margins[] = {1e-3, 1e-5, 3e-9};
    const double margin = margins[rng() % 3];
    return satellites(rng, k.kappa, k.rows, k.cols, k.cs, margin, rng() % 2 ? 0.0 : 0.02);
  });
}

TEST(MarsProcessorBruteForce, ShortSatelliteConesOnFlatGround) {
  // Cones reaching only 5 to 15 cells: the search then runs where the lower bound is flat.
  run_family("short-satellites", 16, [](std::mt19937& rng, const Case& k) {
    Heightmap h(geometry(k.rows, k.cols, k.cs), 0.0);
    for (int round = 0; round < 3; ++round)
      add_satellites(rng, k.kappa, round == 2 ? 1e-5 : 1e-3, h, 5.0 * k.kappa * k.cs);
    return h;
  });
}

TEST(MarsProcessorBruteForce, PlanesAtSlopeKappa) {
  run_family("plane", 10, [](std::mt19937& rng, const Case& k) {
    return exact_plane(k.kappa, std::uniform_real_distribution<double>(0, 2 * M_PI)(rng), k.rows, k.cols, k.cs);
  });
}

TEST(MarsProcessorBruteForce, ConesAtSlopeKappaAnyApex) {
  run_family("cones", 8, [](std::mt19937& rng, const Case& k) {
    return exact_cones(rng, k.kappa, k.rows, k.cols, k.cs, 1 + static_cast<int>(rng() % 4), false);
  });
}

TEST(MarsProcessorBruteForce, ConesAtSlopeKappaOnCellCentres) {
  run_family("cones-centred", 6, [](std::mt19937& rng, const Case& k) {
    return exact_cones(rng, k.kappa, k.rows, k.cols, k.cs, 1 + static_cast<int>(rng() % 4), true);
  });
}

TEST(MarsProcessorBruteForce, BowlsAtSlopeKappa) {
  run_family("bowls", 8, [](std::mt19937& rng, const Case& k) {
    return exact_bowls(rng, k.kappa, k.rows, k.cols, k.cs, 1 + static_cast<int>(rng() % 4));
  });
}

TEST(MarsProcessorBruteForce, RidgesAndRoofsAtSlopeKappa) {
  run_family("ridge", 6,
             [](std::mt19937& rng, const Case& k) { return exact_ridge(rng, k.kappa, k.rows, k.cols, k.cs, false); });
  run_family("roof", 6,
             [](std::mt19937& rng, const Case& k) { return exact_ridge(rng, k.kappa, k.rows, k.cols, k.cs, true); });
}

TEST(MarsProcessorBruteForce, SatellitesOnSlopeKappaSurfaces) {
  run_family("satellites-on-exact", 24, [](std::mt19937& rng, const Case& k) {
    Heightmap h;
    switch (rng() % 4) {
      case 0:
        h = exact_plane(k.kappa, std::uniform_real_distribution<double>(0, 2 * M_PI)(rng), k.rows, k.cols, k.cs);
        break;
      case 1: h = exact_cones(rng, k.kappa, k.rows, k.cols, k.cs, 2, false); break;
      case 2: h = exact_bowls(rng, k.kappa, k.rows, k.cols, k.cs, 2); break;
      default: h = exact_ridge(rng, k.kappa, k.rows, k.cols, k.cs, false); break;
    }
    const double margins[] = {1e-3, 1e-5, 3e-9};
    if (rng() % 2)
      add_satellites(rng, k.kappa, margins[rng() % 3], h);
    else
      add_bumps(rng, h);
    return h;
  });
}

TEST(MarsProcessorBruteForce, FarSatellitesAtBlockEdgesAndInEveryLeafQuarter) {
  // The search tests a node's bounds on the 64 targets of an 8 x 8 block at once (targets off the grid held at
  // +inf) and a leaf's sources quarter by quarter (4 x 4) before applying them one by one. Satellites 6 to 30 cells
  // from their spike beat its cone by 3e-9 .. 1e-4 m only in a sliver behind them, which the seed misses and only
  // the search finds; grid sides are not multiples of 8 and the ground is flat or a slope-kappa surface (tight shape
  // bounds), so every quarter, block edge and bound takes part.
  for (int seed = 1; seed <= 36; ++seed) {
    std::mt19937 rng(seed * 104729);
    std::uniform_int_distribution<int> side(9, 75);
    int rows = side(rng), cols = side(rng);
    if (rows % 8 == 0) ++rows;
    if (cols % 8 == 0) cols += 3;
    const double kappas[] = {0.1, 0.3, 1.0};
    const double kappa = kappas[rng() % 3], cs = seed % 2 ? 0.1 : 0.25;
    Heightmap h;
    switch (seed % 3) {
      case 0: h = Heightmap(geometry(rows, cols, cs), 0.0); break;
      case 1: h = exact_plane(kappa, std::uniform_real_distribution<double>(0, 2 * M_PI)(rng), rows, cols, cs); break;
      default: h = exact_cones(rng, kappa, rows, cols, cs, 2, false); break;
    }
    const double margins[] = {3e-9, 1e-6, 1e-4};
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int spike = 0; spike < 2; ++spike) {
      const CellIndex s{static_cast<int>(rng() % rows), static_cast<int>(rng() % cols)};
      const double top = h(s) + 1.0 + u(rng);
      h(s) = top;
      for (int k = 0; k < 40; ++k) {
        const CellIndex q{static_cast<int>(rng() % rows), static_cast<int>(rng() % cols)};
        const int dr = q.row - s.row, dc = q.col - s.col, d2 = dr * dr + dc * dc;
        if (d2 < 36 || d2 > 900) continue;
        h(q) = std::max(h(q), top - kappa * distance_m(h, q, s) + margins[rng() % 3]);
      }
    }
    expect_matches_brute_force(h, kappa,
                               "far satellites seed " + std::to_string(seed) + " " + std::to_string(rows) + "x" +
                                   std::to_string(cols) + " kappa " + std::to_string(kappa));
  }
}

TEST(MarsProcessorBruteForce, SlightlySteeperThanKappa) {
  // Near-ties that no bound separates (the slow case): cones and planes 0.01% .. 1% too steep.
  run_family("steeper", 8, [](std::mt19937& rng, const Case& k) {
    const double factors[] = {1.0001, 1.001, 1.01};
    const double f = factors[rng() % 3];
    if (rng() % 2)
      return exact_plane(f * k.kappa, std::uniform_real_distribution<double>(0, 2 * M_PI)(rng), k.rows, k.cols, k.cs);
    return exact_cones(rng, f * k.kappa, k.rows, k.cols, k.cs, 1 + static_cast<int>(rng() % 3), false);
  });
}

TEST(MarsProcessorBruteForce, LargerGridsWithDeeperTrees) {
  // 100+ cells a side: node levels above the exactly recomputed ones take part.
  std::mt19937 rng(77);
  Heightmap bowls = exact_bowls(rng, 0.3, 104, 117, 0.1, 3);
  add_bumps(rng, bowls);
  expect_matches_brute_force(bowls, 0.3, "bowls with bumps 104x117");
  Heightmap cones = exact_cones(rng, 0.5, 111, 98, 0.2, 3, false);
  add_satellites(rng, 0.5, 1e-4, cones);
  expect_matches_brute_force(cones, 0.5, "cones with satellites 111x98");
}

TEST(MarsProcessorBruteForce, ExtremeKappaAndCellSizes) {
  std::mt19937 rng(13);
  for (double kappa : {1e-6, 1e-3, 1e3})
    for (double cs : {1e-3, 1e3}) {
      Heightmap h = uniform_noise(rng, 23, 31, cs, 1.0);
      add_satellites(rng, kappa, 1e-3, h, 1.0);
      expect_matches_brute_force(h, kappa, "kappa " + std::to_string(kappa) + " cs " + std::to_string(cs));
    }
}

TEST(MarsProcessorBruteForce, MarsOutputFedBack) {
  run_family("fed-back", 8, [](std::mt19937& rng, const Case& k) {
    const Heightmap h =
        rng() % 2 ? spikes(rng, k.rows, k.cols, k.cs, 6) : smooth_noise(rng, k.rows, k.cols, k.cs, 3.0, 5);
    // Both the reference's and the fast projection, so ties from either formula are exercised.
    return rng() % 2 ? testing::mars_brute_force(h, k.kappa) : MarsProcessor(k.kappa).project(h);
  });
}

TEST(MarsProcessorBruteForce, MixedTerrainAndCones) {
  run_family("mixed", 6, [](std::mt19937& rng, const Case& k) {
    Heightmap h = smooth_noise(rng, k.rows, k.cols, k.cs, 1.0, 7);
    const Heightmap cones = exact_cones(rng, k.kappa, k.rows, k.cols, k.cs, 2, false);
    h.heights() = h.heights().cwiseMax(cones.heights());
    return h;
  });
}

TEST(MarsProcessorBruteForce, DegenerateShapes) {
  std::mt19937 rng(42);
  for (const auto& shape :
       std::vector<std::pair<int, int>>{{1, 1}, {1, 2}, {1, 37}, {53, 1}, {2, 2}, {3, 65}, {9, 9}}) {
    for (double kappa : {0.1, 0.7, 2.0}) {
      const std::string label = std::to_string(shape.first) + "x" + std::to_string(shape.second);
      expect_matches_brute_force(uniform_noise(rng, shape.first, shape.second, 0.3, 2.0), kappa, "uniform " + label);
      expect_matches_brute_force(spikes(rng, shape.first, shape.second, 0.3, 2), kappa, "spikes " + label);
      expect_matches_brute_force(exact_plane(kappa, 0.7, shape.first, shape.second, 0.3), kappa, "plane " + label);
    }
  }
}

TEST(MarsProcessorBruteForce, LargeMagnitudeHeights) {
  std::mt19937 rng(5);
  Heightmap h = smooth_noise(rng, 40, 45, 1.0, 20.0, 6);
  h.heights().array() -= 4500.0;  // Gale-crater-like absolute elevations
  expect_matches_brute_force(h, 0.3, "elevations near -4500 m");
}

// The local pass (every source within the local radius applied densely) against the plain loop it stands for, bit
// for bit: each cell, each offset in the same order, out = out < v ? v : out with v = h - kcs sqrt(d2). Narrow,
// short and odd shapes reach the padded edges and the partial last chunk of a row; ties and -0.0 are in the input.
TEST(MarsProcessor, LocalPassEqualsThePlainLoopBitForBit) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const auto& shape : std::vector<std::pair<int, int>>{
           {1, 1}, {1, 37}, {37, 1}, {2, 3}, {5, 5}, {6, 11}, {11, 6}, {16, 16}, {17, 33}, {41, 41}, {23, 100}}) {
    const int rows = shape.first, cols = shape.second;
    const double kcs = 0.025 + 0.1 * (rng() % 3);
    std::vector<double> h(static_cast<std::size_t>(rows) * cols), start(h.size());
    for (std::size_t i = 0; i < h.size(); ++i) {
      const int kind = static_cast<int>(rng() % 4);
      h[i] = kind == 0 ? std::round(u(rng) * 4.0) / 4.0 : kind == 1 ? -0.0 : u(rng);  // ties, -0.0, noise
      start[i] = h[i] + (rng() % 2 ? 0.0 : 0.05 * std::abs(u(rng)));             // a seeded value >= h
    }
    detail::Problem pb;
    pb.h = h.data();
    pb.rows = rows;
    pb.cols = cols;
    pb.kcs = kcs;
    pb.tol = 1e-10;
    std::vector<double> fast = start;
    detail::apply_local_sources(pb, fast.data());
    std::vector<double> plain = start;
    int radius = 0;
    while ((radius + 1) * (radius + 1) <= detail::kLocalRadius2) ++radius;
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        double& out = plain[static_cast<std::size_t>(r) * cols + c];
        for (int dr = -radius; dr <= radius; ++dr)
          for (int dc = -radius; dc <= radius; ++dc) {
            const int d2 = dr * dr + dc * dc, sr = r + dr, sc = c + dc;
            if (d2 == 0 || d2 > detail::kLocalRadius2 || sr < 0 || sr >= rows || sc < 0 || sc >= cols) continue;
            const double v = h[static_cast<std::size_t>(sr) * cols + sc] - kcs * std::sqrt(static_cast<double>(d2));
            out = out < v ? v : out;
          }
      }
    for (std::size_t i = 0; i < h.size(); ++i)
      ASSERT_EQ(std::memcmp(&fast[i], &plain[i], sizeof(double)), 0)
          << rows << "x" << cols << " cell " << i << ": " << fast[i] << " vs " << plain[i];
  }
}

// ---- agents' windows: the solve's bits and the projection on part of the grid ----------------

// A portable stream of numbers (std's distributions differ between standard libraries; a golden value must not).
struct Stream {
  std::uint64_t x;
  std::uint64_t next() {  // splitmix64
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double unit() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

// Windows like an agent's (0.25 m cells, kappa 0.1): rough ground, ground levelled to a few heights (ties, -0.0 on
// the floor), a MARS output fed back (every ramp cell ties with its source), and rough ground beside a built ramp.
Heightmap agent_window(Stream& s, int rows, int cols, double kappa) {
  Heightmap h(GridGeometry{rows, cols, 12.0, -4.0, 0.25});
  const int kind = static_cast<int>(s.next() % 4);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double noise = 0.6 * s.unit();
      h(r, c) = kind == 1 ? (s.next() % 3 == 0 ? -0.0 : std::floor(noise * 8.0) / 8.0) : noise;
    }
  if (kind >= 2) {
    const Heightmap fed = MarsProcessor(kappa).project(h);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        if (kind == 2 || c < cols / 2) h(r, c) = fed(r, c);
  }
  return h;
}

// The projections of 240 agent windows hash to the value the solver gave before the search kept its leaves' heights
// and trimmed the blocks cut by the grid's edge (main 14785d3, FNV-1a over the bytes): every bit of the window solve
// is kept, ties and -0.0 included. 41 x 41 is an agent's window; the other shapes cut the last row or column of
// blocks anywhere, or hold a single row or column.
TEST(MarsProcessor, AgentWindowsKeepTheirBits) {
  Stream s{2026};
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  const int shapes[][2] = {{41, 41}, {41, 33}, {17, 41}, {9, 9}, {64, 64}, {1, 41}, {41, 2}, {25, 70}};
  for (int k = 0; k < 240; ++k) {
    const auto& shape = shapes[k % 8];
    const Heightmap h = agent_window(s, shape[0], shape[1], 0.1);
    const Heightmap p = MarsProcessor(0.1).project(h);
    const auto* bytes = reinterpret_cast<const unsigned char*>(p.data());
    for (std::size_t i = 0; i < static_cast<std::size_t>(p.size()) * sizeof(double); ++i)
      hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
  }
  EXPECT_EQ(hash, 0x4702db89a89f4f67ULL);
}

// project(h, wanted) against project(h), bit for bit: the whole projection on the wanted cells, h on the others. The
// masks: the cells with a gap (what the agents ask for), sparse and dense random cells, one cell, every cell, none.
TEST(MarsProcessor, ProjectionOnWantedCellsEqualsTheWholeOneBitForBit) {
  Stream s{7};
  const int shapes[][2] = {{41, 41}, {41, 33}, {17, 41}, {9, 9}, {64, 64}, {1, 41}, {41, 2}, {25, 70}};
  const MarsProcessor mars(0.1);
  for (int k = 0; k < 120; ++k) {
    const auto& shape = shapes[k % 8];
    const Heightmap h = agent_window(s, shape[0], shape[1], 0.1);
    const Heightmap whole = mars.project(h);
    for (int variant = 0; variant < 6; ++variant) {
      CellMask wanted = CellMask::Zero(h.rows(), h.cols());
      const CellIndex one{static_cast<int>(s.next() % h.rows()), static_cast<int>(s.next() % h.cols())};
      for (int r = 0; r < h.rows(); ++r)
        for (int c = 0; c < h.cols(); ++c) {
          const double u = s.unit();
          wanted(r, c) = variant == 0   ? whole(r, c) != h(r, c)
                         : variant == 1 ? u < 0.1
                         : variant == 2 ? u < 0.6
                         : variant == 3 ? CellIndex{r, c} == one
                                        : variant == 4;
        }
      const Heightmap part = mars.project(h, wanted);
      ASSERT_EQ(part.geometry(), h.geometry());
      for (int r = 0; r < h.rows(); ++r)
        for (int c = 0; c < h.cols(); ++c) {
          const double want = wanted(r, c) != 0 ? whole(r, c) : h(r, c);
          const double got = part(r, c);
          ASSERT_EQ(std::memcmp(&want, &got, sizeof(double)), 0)
              << "window " << k << " mask " << variant << " cell (" << r << ", " << c << "): " << part(r, c)
              << " vs " << want;
        }
    }
  }
  const Heightmap h(geometry(6, 7, 0.1), 1.0);
  EXPECT_THROW(mars.project(h, CellMask::Ones(7, 6)), InvalidArgument);
  Heightmap bad = h;
  bad(2, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(mars.project(bad, CellMask::Zero(6, 7)), InvalidArgument);
}

// ---- hand cases with known answers ---------------------------------------------------------

TEST(MarsProcessor, FlatGroundHasZeroGap) {
  const Heightmap h(geometry(17, 23, 0.1), 2.5);
  const Heightmap g = MarsProcessor(0.3).gap(h);
  EXPECT_EQ(g.geometry(), h.geometry());
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) EXPECT_EQ(g(r, c), 0.0);
}

TEST(MarsProcessor, SingleSpikeGivesACone) {
  const double kappa = 0.4, spike = 2.0;
  Heightmap h(geometry(31, 27, 0.1), 0.0);
  const CellIndex top{12, 9};
  h(top) = spike;
  const Heightmap p = MarsProcessor(kappa).project(h);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const double expected = std::max(0.0, spike - kappa * distance_m(h, {r, c}, top));
      EXPECT_NEAR(p(r, c), expected, 1e-12) << r << ", " << c;
    }
}

TEST(MarsProcessor, StepGivesARampOfSlopeKappaOnTheLowSide) {
  const double kappa = 0.5, cs = 0.1, step = 1.0;
  Heightmap h(geometry(12, 40, cs), 0.0);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 30; c < h.cols(); ++c) h(r, c) = step;
  const Heightmap g = MarsProcessor(kappa).gap(h);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      // The nearest high cell is in the same row, (30 - c) cells away: ramp 1 - 0.05 * (30 - c).
      const double expected = c >= 30 ? 0.0 : std::max(0.0, step - kappa * cs * (30 - c));
      EXPECT_NEAR(g(r, c), expected, 1e-12) << r << ", " << c;
    }
  EXPECT_NEAR(g(5, 29), 0.95, 1e-12);
  EXPECT_NEAR(g(5, 11), 0.05, 1e-12);
  EXPECT_NEAR(g(5, 10), 0.0, 1e-12);
}

TEST(MarsProcessor, ProjectionIsIdempotentAboveAndKappaLipschitz) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 4; ++trial) {
    const double kappa = 0.2 + 0.3 * trial, cs = 0.1 + 0.2 * trial;
    Heightmap h = trial % 2 ? smooth_noise(rng, 33, 29, cs, 3.0, 4) : uniform_noise(rng, 29, 33, cs, 2.0);
    const MarsProcessor mars(kappa);
    const Heightmap p = mars.project(h);
    const Heightmap pp = mars.project(p);
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) {
        EXPECT_GE(p(r, c), h(r, c));
        EXPECT_NEAR(pp(r, c), p(r, c), 1e-12);
      }
    // Lipschitz over all pairs.
    double worst = -1.0;
    for (int a = 0; a < h.size(); ++a)
      for (int b = a + 1; b < h.size(); ++b) {
        const CellIndex ia{a / h.cols(), a % h.cols()}, ib{b / h.cols(), b % h.cols()};
        worst = std::max(worst, std::abs(p(ia) - p(ib)) - kappa * distance_m(h, ia, ib));
      }
    EXPECT_LE(worst, 1e-9) << "trial " << trial;
  }
}

TEST(MarsProcessor, GapIsProjectionMinusHeight) {
  std::mt19937 rng(3);
  const Heightmap h = uniform_noise(rng, 25, 31, 0.2, 1.0);
  const MarsProcessor mars(0.3);
  const Heightmap p = mars.project(h), g = mars.gap(h);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      EXPECT_EQ(g(r, c), p(r, c) - h(r, c));
      EXPECT_GE(g(r, c), 0.0);
    }
}

// Gap volume around a W x D x H box on flat ground; the continuum limit is
// 2 (W + D) H^2 / (2 kappa) + pi H^3 / (3 kappa^2) = 14.19 m^3 for W = 2, D = 3, H = 1, kappa = 0.5.
double box_gap_volume(const MarsProcessor& mars, double cs, bool brute) {
  const int margin = static_cast<int>(std::lround(2.5 / cs));  // ramps reach H / kappa = 2 m
  const int w = static_cast<int>(std::lround(2.0 / cs)), d = static_cast<int>(std::lround(3.0 / cs));
  Heightmap h(geometry(d + 2 * margin, w + 2 * margin, cs), 0.0);
  for (int r = margin; r < margin + d; ++r)
    for (int c = margin; c < margin + w; ++c) h(r, c) = 1.0;
  const Heightmap p = brute ? testing::mars_brute_force(h, mars.kappa()) : mars.project(h);
  return (p.heights() - h.heights()).sum() * cs * cs;
}

TEST(MarsProcessor, BoxGapVolumeConverges) {
  const MarsProcessor mars(0.5);
  // Golden value: brute force on 0.2 m cells (computed here, stated below by hand from one run).
  const double brute_02 = box_gap_volume(mars, 0.2, true);
  EXPECT_NEAR(brute_02, 12.425738007, 1e-8);
  EXPECT_NEAR(box_gap_volume(mars, 0.2, false), brute_02, 1e-8);
  const double fast_01 = box_gap_volume(mars, 0.1, false);
  EXPECT_GT(fast_01, 13.1);
  EXPECT_LT(fast_01, 13.5);
  EXPECT_LT(brute_02, fast_01);  // converging from below towards 14.19
  EXPECT_LT(fast_01, 14.19);
}

// ---- bad input -----------------------------------------------------------------------------

TEST(MarsProcessor, RejectsBadKappa) {
  EXPECT_THROW(MarsProcessor(0.0), InvalidArgument);
  EXPECT_THROW(MarsProcessor(-0.3), InvalidArgument);
  EXPECT_THROW(MarsProcessor(std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
  EXPECT_THROW(MarsProcessor(std::numeric_limits<double>::infinity()), InvalidArgument);
  EXPECT_DOUBLE_EQ(MarsProcessor(0.3).kappa(), 0.3);
}

TEST(MarsProcessor, RejectsNonFiniteCellsNamingThem) {
  Heightmap h(geometry(6, 7, 0.1), 1.0);
  h(4, 2) = std::numeric_limits<double>::quiet_NaN();
  h(5, 6) = std::numeric_limits<double>::infinity();
  const MarsProcessor mars(0.3);
  try {
    mars.project(h);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("row 4, col 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mars.gap(h), InvalidArgument);
  h(4, 2) = 0.0;
  EXPECT_THROW(mars.project(h), InvalidArgument);
  h(5, 6) = -std::numeric_limits<double>::infinity();
  EXPECT_THROW(mars.project(h), InvalidArgument);
}

}  // namespace
}  // namespace marsala
