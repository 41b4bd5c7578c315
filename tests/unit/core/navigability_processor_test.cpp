#include "marsala/core/navigability_processor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/detail/navigability_kernel.hpp"
#include "marsala/core/error.hpp"
#include "support/navigability_brute_force.hpp"

namespace marsala {
namespace {

Heightmap flat(int rows, int cols, double cs, double height = 0.0) {
  return Heightmap(GridGeometry{rows, cols, 3.0, -2.0, cs}, height);
}

long long count(const CellMask& mask) {
  long long n = 0;
  for (Eigen::Index i = 0; i < mask.size(); ++i) n += mask.data()[i];
  return n;
}

/// First cell where the masks differ, as text ("" when equal), for readable failures.
std::string first_difference(const CellMask& fast, const CellMask& reference) {
  if (fast.rows() != reference.rows() || fast.cols() != reference.cols()) return "sizes differ";
  for (Eigen::Index r = 0; r < fast.rows(); ++r)
    for (Eigen::Index c = 0; c < fast.cols(); ++c)
      if (fast(r, c) != reference(r, c))
        return "cell (" + std::to_string(r) + ", " + std::to_string(c) + "): fast " + std::to_string(fast(r, c)) +
               ", reference " + std::to_string(reference(r, c));
  return "";
}

// ---- terrains for the comparisons ------------------------------------------------------------------------

enum class Terrain { kSmooth, kRough, kCliffs, kSpikes, kRampAlongRows, kRampAlongCols, kRampDiagonal, kQuantized };

const char* name(Terrain t) {
  switch (t) {
    case Terrain::kSmooth: return "smooth";
    case Terrain::kRough: return "rough";
    case Terrain::kCliffs: return "cliffs";
    case Terrain::kSpikes: return "spikes";
    case Terrain::kRampAlongRows: return "ramp along rows";
    case Terrain::kRampAlongCols: return "ramp along cols";
    case Terrain::kRampDiagonal: return "diagonal ramp";
    case Terrain::kQuantized: return "quantized";
  }
  return "?";
}

/// Bilinear value noise with lattice spacing `wavelength` cells, values in [-amplitude, amplitude] [m].
void add_value_noise(Heightmap& h, std::mt19937_64& rng, double wavelength, double amplitude) {
  const int lattice_rows = static_cast<int>(h.rows() / wavelength) + 2;
  const int lattice_cols = static_cast<int>(h.cols() / wavelength) + 2;
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  std::vector<double> lattice(static_cast<std::size_t>(lattice_rows) * lattice_cols);
  for (double& v : lattice) v = u(rng);
  for (int r = 0; r < h.rows(); ++r)
    for (int c = 0; c < h.cols(); ++c) {
      const double y = r / wavelength, x = c / wavelength;
      const int y0 = static_cast<int>(y), x0 = static_cast<int>(x);
      const double fy = y - y0, fx = x - x0;
      auto at = [&](int yy, int xx) { return lattice[static_cast<std::size_t>(yy) * lattice_cols + xx]; };
      h(r, c) += (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x0 + 1)) +
                 fy * ((1 - fx) * at(y0 + 1, x0) + fx * at(y0 + 1, x0 + 1));
    }
}

Heightmap make_terrain(Terrain t, int rows, int cols, const NavigabilityParams& p, double cs, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Heightmap h(GridGeometry{rows, cols, -1.5, 7.25, cs}, 0.0);
  const double cell_rise = p.kappa * cs;  // rise of a slope-kappa ramp over one cell [m]
  switch (t) {
    case Terrain::kSmooth: {
      const double wavelength = 2.0 + 6.0 * unit(rng);
      add_value_noise(h, rng, wavelength, cell_rise * wavelength * (0.2 + 1.2 * unit(rng)));
      break;
    }
    case Terrain::kRough: {
      std::uniform_real_distribution<double> u(0.0, (0.5 + 4.0 * unit(rng)) * (cell_rise + p.eps_m));
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) h(r, c) = u(rng);
      break;
    }
    case Terrain::kCliffs: {
      add_value_noise(h, rng, 4.0, cell_rise * 2.0);
      for (int step = 0; step < 2; ++step) {
        const double angle = 6.283185307179586 * unit(rng), offset = (unit(rng) - 0.5) * (rows + cols) * 0.5;
        const double height = (unit(rng) - 0.5) * 4.0 * (p.eps_m + 3.0 * cell_rise);
        for (int r = 0; r < rows; ++r)
          for (int c = 0; c < cols; ++c)
            if (std::cos(angle) * (c - cols / 2.0) + std::sin(angle) * (r - rows / 2.0) > offset) h(r, c) += height;
      }
      break;
    }
    case Terrain::kSpikes: {
      add_value_noise(h, rng, 5.0, cell_rise * 1.5);
      const int spikes = 1 + static_cast<int>(unit(rng) * rows * cols / 40.0);
      std::uniform_int_distribution<int> row(0, rows - 1), col(0, cols - 1);
      for (int i = 0; i < spikes; ++i) h(row(rng), col(rng)) += (unit(rng) - 0.3) * 3.0 * (p.eps_m + 4.0 * cell_rise);
      break;
    }
    case Terrain::kRampAlongRows:
    case Terrain::kRampAlongCols:
    case Terrain::kRampDiagonal: {
      // Slope exactly kappa (a built ramp), sometimes a hair above or below it.
      const double choice = unit(rng);
      const double slope = p.kappa * (choice < 0.5 ? 1.0 : choice < 0.75 ? 1.0 + 1e-6 : 1.0 - 1e-6);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
          const Position x = h.cell_center({r, c});
          h(r, c) = t == Terrain::kRampAlongRows   ? slope * x.x
                    : t == Terrain::kRampAlongCols ? slope * x.y
                                                   : slope * (x.x + x.y) / std::sqrt(2.0);
        }
      break;
    }
    case Terrain::kQuantized: {
      // Smooth ground rounded to multiples of kappa * cs (or of eps + kappa * cs): many pairs sit exactly on
      // eps + kappa |r - q|.
      const double quantum = unit(rng) < 0.5 ? cell_rise : p.eps_m + cell_rise;
      add_value_noise(h, rng, 3.0 + 4.0 * unit(rng), quantum * (1.0 + 4.0 * unit(rng)));
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) h(r, c) = std::round(h(r, c) / quantum) * quantum;
      break;
    }
  }
  return h;
}

struct Case {
  double cs, delta, kappa, eps;
  int max_size;  // largest side of the random grids (keeps the brute force quick)
};

/// Parameter sets: ball ties (0.6 / 0.2 = 2.9999999999999996, diagonal radii), one-cell balls, balls larger
/// than the grid, balls past 16 rings (ring groups), exact height ties (cs = 1, kappa = 0.5, eps = 0).
const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {0.1, 0.6, 0.3, 0.05, 20},                  // radius 2.9999999999999996 cells: (3, 0) is in by the tolerance
      {0.1, 1.0, 0.3, 0.05, 22},                  // the robot of the benchmarks: radius 5 cells
      {0.2, 0.6, 0.3, 0.0, 16},                   // radius 1.4999999999999998, eps 0
      {0.5, 2.0, 0.5, 0.0, 16},                   // radius exactly 2
      {1.0, 2.0 * std::sqrt(2.0), 0.5, 0.1, 16},  // radius^2 = 2 up to rounding: diagonal tie
      {1.0, 1.0, 0.5, 0.0, 14},                   // radius 0.5: the ball is one cell
      {0.1, 0.05, 0.3, 0.05, 8},                  // delta < cs: one cell
      {1.0, 2.0, 0.3, 0.05, 14},                  // radius 1: a plus
      {0.25, 1.5, 1.0, 0.2, 16},                  // radius 3, steep robot
      {1.0, 7.0, 0.5, 0.0, 12},                   // radius 3.5, exact height ties
      {0.05, 1.0, 0.3, 0.05, 13},                 // radius 10: 20 rings share 16 flag bits
      {0.01, 0.7, 0.3, 0.05, 12},                 // radius 35, clipped by the grid's extent
      {1.0, 1e6, 0.5, 0.0, 9},                    // a ball far larger than the grid: every ball holds the whole grid
  };
  return all;
}

constexpr Terrain kTerrains[] = {Terrain::kSmooth,       Terrain::kRough,         Terrain::kCliffs,
                                 Terrain::kSpikes,       Terrain::kRampAlongRows, Terrain::kRampAlongCols,
                                 Terrain::kRampDiagonal, Terrain::kQuantized};

// ---- fast == brute force ---------------------------------------------------------------------------------

TEST(NavigabilityProcessor, OccupiableEqualsBruteForceOnRandomGrids) {
  std::mt19937_64 rng(20240611);
  long long cells = 0, occupiable_cells = 0;
  for (const Case& k : cases()) {
    const NavigabilityParams p{k.kappa, k.delta, k.eps};
    const NavigabilityProcessor processor(p);
    std::uniform_int_distribution<int> side(1, k.max_size);
    for (Terrain t : kTerrains)
      for (int seed = 0; seed < 6; ++seed) {
        const int rows = seed == 0 ? 1 : side(rng), cols = seed == 1 ? 1 : side(rng);
        const Heightmap h = make_terrain(t, rows, cols, p, k.cs, rng);
        const CellMask reference = testing::occupiable_brute_force(h, p);
        const CellMask fast = processor.occupiable(h);
        SCOPED_TRACE(std::string(name(t)) + " " + std::to_string(rows) + "x" + std::to_string(cols) + " cs " +
                     std::to_string(k.cs) + " delta " + std::to_string(k.delta));
        EXPECT_EQ(first_difference(fast, reference), "");
        // Both ways of clearing lenses give the same cells.
        EXPECT_EQ(first_difference(detail::occupiable_mask(h, p, detail::LensMarking::kSpans), reference), "");
        EXPECT_EQ(first_difference(detail::occupiable_mask(h, p, detail::LensMarking::kBitsets), reference), "");
        cells += h.size();
        occupiable_cells += count(reference);
      }
  }
  // The families must exercise both outcomes, or the comparison proves little.
  EXPECT_GT(occupiable_cells, cells / 5);
  EXPECT_LT(occupiable_cells, cells * 4 / 5);
}

TEST(NavigabilityProcessor, OccupiableEqualsBruteForceOnGridsSpanningSeveralStrips) {
  // Taller than one strip of the bound computation (64 rows plus halo) and wide enough for cells whose
  // partners all lie on the grid; slope 0.36 > kappa makes only far-apart pairs fail (long-range rings).
  std::mt19937_64 rng(99);
  const NavigabilityParams p{0.3, 1.0, 0.05};
  const NavigabilityProcessor processor(p);
  for (const auto& [rows, cols] : {std::pair<int, int>{150, 36}, std::pair<int, int>{40, 130}})
    for (Terrain t : {Terrain::kSmooth, Terrain::kCliffs, Terrain::kSpikes, Terrain::kRough}) {
      Heightmap h = make_terrain(t, rows, cols, p, 0.1, rng);
      if (t == Terrain::kSmooth)  // a band at slope 0.36 along the rows
        for (int r = rows / 3; r < rows / 2; ++r)
          for (int c = 0; c < cols; ++c) h(r, c) += 0.36 * 0.1 * c;
      SCOPED_TRACE(std::string(name(t)) + " " + std::to_string(rows) + "x" + std::to_string(cols));
      const CellMask reference = testing::occupiable_brute_force(h, p);
      EXPECT_EQ(first_difference(processor.occupiable(h), reference), "");
      EXPECT_EQ(first_difference(detail::occupiable_mask(h, p, detail::LensMarking::kSpans), reference), "");
      if (t != Terrain::kRough) {  // rough ground is all blocked for this robot; the others must be mixed
        EXPECT_GT(count(reference), 0);
        EXPECT_LT(count(reference), h.size());
      }
    }
}

TEST(NavigabilityProcessor, NavigableEqualsBruteForceBfs) {
  std::mt19937_64 rng(77);
  int origins_occupiable = 0, origins_blocked = 0;
  for (const Case& k : cases()) {
    const NavigabilityParams p{k.kappa, k.delta, k.eps};
    const NavigabilityProcessor processor(p);
    std::uniform_int_distribution<int> side(1, k.max_size);
    for (Terrain t : {Terrain::kSmooth, Terrain::kCliffs, Terrain::kSpikes, Terrain::kRough})
      for (int seed = 0; seed < 3; ++seed) {
        const int rows = side(rng), cols = side(rng);
        const Heightmap h = make_terrain(t, rows, cols, p, k.cs, rng);
        const CellMask occupiable = testing::occupiable_brute_force(h, p);
        for (int trial = 0; trial < 3; ++trial) {
          const CellIndex origin{std::uniform_int_distribution<int>(0, rows - 1)(rng),
                                 std::uniform_int_distribution<int>(0, cols - 1)(rng)};
          const CellMask reference = testing::navigable_brute_force(h, p, origin);
          SCOPED_TRACE(std::string(name(t)) + " origin (" + std::to_string(origin.row) + ", " +
                       std::to_string(origin.col) + ")");
          EXPECT_EQ(first_difference(processor.navigable(h, origin), reference), "");
          EXPECT_EQ(first_difference(NavigabilityProcessor::navigable_from(occupiable, origin), reference), "");
          if (occupiable(origin.row, origin.col) != 0) {
            ++origins_occupiable;
            EXPECT_EQ(reference(origin.row, origin.col), 1);
          } else {
            ++origins_blocked;
            EXPECT_EQ(count(reference), 0);
          }
        }
      }
  }
  EXPECT_GT(origins_occupiable, 20);
  EXPECT_GT(origins_blocked, 20);
}

// The origin's component by a plain breadth-first search over the mask: the reference for navigable_from() on masks
// no terrain would give (mazes, runs across the 64-cell words of a row).
CellMask component_by_search(const CellMask& occupiable, CellIndex origin) {
  const int rows = static_cast<int>(occupiable.rows()), cols = static_cast<int>(occupiable.cols());
  CellMask out = CellMask::Zero(rows, cols);
  if (occupiable(origin.row, origin.col) == 0) return out;
  std::vector<CellIndex> queue{origin};
  out(origin.row, origin.col) = 1;
  for (std::size_t next = 0; next < queue.size(); ++next)
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const int r = queue[next].row + dr, c = queue[next].col + dc;
        if (r < 0 || r >= rows || c < 0 || c >= cols || out(r, c) != 0 || occupiable(r, c) == 0) continue;
        out(r, c) = 1;
        queue.push_back({r, c});
      }
  return out;
}

TEST(NavigabilityProcessor, NavigableFromEqualsASearchOnRandomAndMazeMasks) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> side(1, 200);
  std::uniform_real_distribution<double> density(0.45, 0.75), unit(0.0, 1.0);
  long long reached = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = side(rng), cols = side(rng);
    CellMask occupiable(rows, cols);
    const double d = density(rng);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) occupiable(r, c) = unit(rng) < d ? 1 : 0;
    const CellIndex origin{std::uniform_int_distribution<int>(0, rows - 1)(rng),
                           std::uniform_int_distribution<int>(0, cols - 1)(rng)};
    const CellMask reference = component_by_search(occupiable, origin);
    reached += count(reference);
    EXPECT_EQ(first_difference(NavigabilityProcessor::navigable_from(occupiable, origin), reference), "")
        << rows << " x " << cols << " density " << d;
  }
  EXPECT_GT(reached, 100000);  // large components, not only single cells
  // A comb: one-cell corridors joined alternately at the top and the bottom, so every corridor turns the way back;
  // 40 of them across more than two words of a row; the last corridor joins its bend by a diagonal step only.
  for (const int corridors : {3, 40}) {
    const int rows = 30, cols = 3 * corridors;
    CellMask comb = CellMask::Zero(rows, cols);
    for (int k = 0; k < corridors; ++k) {
      for (int r = 1; r < rows - 1; ++r) comb(r, 3 * k) = 1;
      if (k + 1 < corridors)
        for (int c = 3 * k; c <= 3 * k + 3; ++c) comb(k % 2 == 0 ? rows - 1 : 0, c) = 1;
    }
    comb(corridors % 2 == 0 ? rows - 1 : 0, 3 * corridors - 3) = 0;  // the last bend's corner cell
    const CellMask reference = component_by_search(comb, {1, 0});
    EXPECT_EQ(first_difference(NavigabilityProcessor::navigable_from(comb, {1, 0}), reference), "") << corridors;
    EXPECT_EQ(reference(1, 3 * (corridors - 1)), 1);  // the whole comb is one component
  }
}

// ---- hand-derived cases ----------------------------------------------------------------------------------

TEST(NavigabilityProcessor, FlatGroundIsOccupiableAndNavigableEverywhere) {
  const NavigabilityProcessor processor({0.3, 1.0, 0.0});
  const Heightmap h = flat(17, 23, 0.1, 4.2);
  EXPECT_EQ(count(processor.occupiable(h)), 17 * 23);
  EXPECT_EQ(count(processor.navigable(h, {16, 0})), 17 * 23);
}

TEST(NavigabilityProcessor, OneCellGridIsOccupiable) {
  const NavigabilityProcessor processor({0.3, 1.0, 0.05});
  const Heightmap h = flat(1, 1, 0.1, -3.0);
  EXPECT_EQ(processor.occupiable(h)(0, 0), 1);
  EXPECT_EQ(processor.navigable(h, {0, 0})(0, 0), 1);
}

TEST(NavigabilityProcessor, StepBlocksTheCellsWhoseBallStraddlesIt) {
  // cs 0.1 m, delta 0.6 m: ball radius 0.6 / 0.2 = 2.9999999999999996 cells, so (0, +-3) is in the ball by the
  // tolerance and the ball spans columns c - 3 .. c + 3 on its own row. Heights 0 on columns 0..9, 1.5 m on
  // columns 10..19: any pair across the step fails (1.5 > 0.05 + 0.3 * 0.6). A ball straddles the step when
  // c - 3 <= 9 and c + 3 >= 10: columns 7..12, 6 columns x 10 rows = 60 cells.
  const NavigabilityProcessor processor({0.3, 0.6, 0.05});
  Heightmap h = flat(10, 20, 0.1);
  for (int r = 0; r < 10; ++r)
    for (int c = 10; c < 20; ++c) h(r, c) = 1.5;
  const CellMask occupiable = processor.occupiable(h);
  EXPECT_EQ(count(occupiable), 200 - 60);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 20; ++c) EXPECT_EQ(occupiable(r, c), (c >= 7 && c <= 12) ? 0 : 1) << r << ", " << c;

  // From the low side, columns 0..6 are navigable (70 cells) and nothing beyond the step.
  const CellMask navigable = processor.navigable(h, {5, 0});
  EXPECT_EQ(count(navigable), 70);
  for (int r = 0; r < 10; ++r)
    for (int c = 7; c < 20; ++c) EXPECT_EQ(navigable(r, c), 0);
  EXPECT_EQ(count(processor.navigable(h, {0, 19})), 70);
  // An origin on a blocked cell reaches nothing.
  EXPECT_EQ(count(processor.navigable(h, {5, 9})), 0);
}

TEST(NavigabilityProcessor, SlopeJustUnderKappaIsOccupiableJustOverIsNot) {
  // delta 1 m at cs 0.1 m: ball radius 5 cells. A ramp along x with slope s.
  const auto ramp = [](double slope) {
    Heightmap h(GridGeometry{11, 30, 0.0, 0.0, 0.1}, 0.0);
    for (int r = 0; r < h.rows(); ++r)
      for (int c = 0; c < h.cols(); ++c) h(r, c) = slope * h.cell_center({r, c}).x;
    return h;
  };
  const NavigabilityProcessor tight({0.3, 1.0, 0.0});
  EXPECT_EQ(count(tight.occupiable(ramp(0.3 * (1.0 - 1e-6)))), 11 * 30);
  // Exactly kappa with eps 0: every pair sits on the tie and passes by the 1e-9 m tolerance.
  EXPECT_EQ(count(tight.occupiable(ramp(0.3))), 11 * 30);
  // kappa (1 + 1e-5) with eps 0: even two neighbours along x exceed their bound (by 3e-7 m, far above the
  // tolerance), and every ball holds such a pair.
  EXPECT_EQ(count(tight.occupiable(ramp(0.3 * (1.0 + 1e-5)))), 0);

  // Slope 0.36 with eps 0.05: a pair dx cells apart fails when 0.036 dx > 0.05 + 0.03 dx, i.e. dx >= 9.
  // A cell's ball row 0 spans columns c-5..c+5 clipped to 0..29: it holds 9 columns apart for c in 4..25.
  // Cells 0..3 and 26..29 pass (their widest span is 8 columns: 0.288 <= 0.29 and off-row pairs are longer).
  const NavigabilityProcessor robot({0.3, 1.0, 0.05});
  const CellMask occupiable = robot.occupiable(ramp(0.36));
  EXPECT_EQ(count(occupiable), 8 * 11);
  for (int r = 0; r < 11; ++r)
    for (int c = 0; c < 30; ++c) EXPECT_EQ(occupiable(r, c), (c >= 4 && c <= 25) ? 0 : 1) << r << ", " << c;
  // 0.34 (just over kappa, but by less than eps over the ball: 0.04 * 1.0 < 0.05) stays occupiable.
  EXPECT_EQ(count(robot.occupiable(ramp(0.34))), 11 * 30);
}

TEST(NavigabilityProcessor, DiagonalRampAtKappaIsOccupiableWithZeroEps) {
  const NavigabilityProcessor processor({0.3, 1.0, 0.0});
  Heightmap h(GridGeometry{25, 25, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < 25; ++r)
    for (int c = 0; c < 25; ++c) {
      const Position x = h.cell_center({r, c});
      h(r, c) = 0.3 * (x.x + x.y) / std::sqrt(2.0);
    }
  EXPECT_EQ(count(processor.occupiable(h)), 25 * 25);
}

TEST(NavigabilityProcessor, HeightTiesPassAndAnythingBeyondTheToleranceFails) {
  // cs 1 m, kappa 0.5, eps 0, delta 4 m: the ball (radius 2 cells) of each cell of a 1x3 strip holds all three.
  // Pairs: |0.5 - 0| <= 0.5 * 1, |1 - 0| <= 0.5 * 2, exact ties in floating point.
  const NavigabilityProcessor processor({0.5, 4.0, 0.0});
  Heightmap h = flat(1, 3, 1.0);
  h(0, 1) = 0.5;
  h(0, 2) = 1.0;
  EXPECT_EQ(count(processor.occupiable(h)), 3);
  h(0, 2) = 1.0 + 1e-10;  // within the 1e-9 m tolerance
  EXPECT_EQ(count(processor.occupiable(h)), 3);
  h(0, 2) = 1.0 + 1e-6;  // beyond it: every ball holds the failing pair (0, 2)
  EXPECT_EQ(count(processor.occupiable(h)), 0);
}

TEST(NavigabilityProcessor, GridSmallerThanTheBallIsAllOrNothing) {
  // delta 1 m at cs 0.1 m: every 3x3 cell's ball holds the whole grid.
  const NavigabilityProcessor processor({0.3, 1.0, 0.05});
  Heightmap h = flat(3, 3, 0.1);
  h(2, 1) = 0.05 + 0.3 * 0.1;  // rise allowed to its neighbours exactly: passes everywhere (farther pairs too)
  EXPECT_EQ(count(processor.occupiable(h)), 9);
  h(2, 1) = 0.2;  // 0.2 > 0.05 + 0.3 * 0.283 for every pair with it
  EXPECT_EQ(count(processor.occupiable(h)), 0);
}

TEST(NavigabilityProcessor, OneCellBallMakesEveryCellOccupiable) {
  // delta 0.05 m < cs 0.1 m: the ball is the cell itself, so there are no pairs.
  const NavigabilityProcessor processor({0.3, 0.05, 0.0});
  std::mt19937_64 rng(3);
  Heightmap h = flat(9, 7, 0.1);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 7; ++c) h(r, c) = u(rng);
  EXPECT_EQ(count(processor.occupiable(h)), 63);
  // Navigability still needs 8-connectivity: all of the grid.
  EXPECT_EQ(count(processor.navigable(h, {4, 3})), 63);
}

TEST(NavigabilityProcessor, NavigableFromFollowsEightConnectivity) {
  // 1 = occupiable. The diagonal link (1,1)-(2,2) joins the two blocks; (0,4) is cut off by a column of zeros.
  CellMask occupiable(4, 5);
  occupiable << 1, 1, 0, 0, 1,  //
      1, 1, 0, 0, 1,            //
      0, 0, 1, 0, 0,            //
      0, 0, 1, 1, 0;
  const CellMask navigable = NavigabilityProcessor::navigable_from(occupiable, {0, 0});
  CellMask expected(4, 5);
  expected << 1, 1, 0, 0, 0,  //
      1, 1, 0, 0, 0,          //
      0, 0, 1, 0, 0,          //
      0, 0, 1, 1, 0;
  EXPECT_EQ(first_difference(navigable, expected), "");
  EXPECT_EQ(count(NavigabilityProcessor::navigable_from(occupiable, {0, 4})), 2);
  EXPECT_EQ(count(NavigabilityProcessor::navigable_from(occupiable, {0, 2})), 0);
}

// ---- bad input -------------------------------------------------------------------------------------------

TEST(NavigabilityProcessor, RejectsBadParameters) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(NavigabilityProcessor({0.0, 1.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({-0.3, 1.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({nan, 1.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({inf, 1.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, 0.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, -1.0, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, nan, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, inf, 0.05}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, 1.0, -0.01}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, 1.0, nan}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor({0.3, 1.0, inf}), InvalidArgument);
  const NavigabilityProcessor ok({0.3, 1.0, 0.0});
  EXPECT_DOUBLE_EQ(ok.params().kappa, 0.3);
  EXPECT_DOUBLE_EQ(ok.params().delta_m, 1.0);
  EXPECT_DOUBLE_EQ(ok.params().eps_m, 0.0);
}

TEST(NavigabilityProcessor, RejectsNonFiniteHeightsNamingTheCell) {
  const NavigabilityProcessor processor({0.3, 1.0, 0.05});
  Heightmap h = flat(5, 6, 0.1);
  h(2, 3) = std::numeric_limits<double>::quiet_NaN();
  h(4, 1) = std::numeric_limits<double>::infinity();
  try {
    processor.occupiable(h);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("(2, 3)"), std::string::npos) << e.what();
  }
  h(2, 3) = 0.0;
  try {
    processor.navigable(h, {0, 0});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("(4, 1)"), std::string::npos) << e.what();
  }
}

TEST(NavigabilityProcessor, RejectsOriginOffTheGrid) {
  const NavigabilityProcessor processor({0.3, 1.0, 0.05});
  const Heightmap h = flat(4, 6, 0.1);
  EXPECT_THROW(processor.navigable(h, {-1, 0}), InvalidArgument);
  EXPECT_THROW(processor.navigable(h, {0, 6}), InvalidArgument);
  EXPECT_THROW(processor.navigable(h, {4, 0}), InvalidArgument);
  const CellMask occupiable = CellMask::Ones(4, 6);
  EXPECT_THROW(NavigabilityProcessor::navigable_from(occupiable, {0, -1}), InvalidArgument);
  EXPECT_THROW(NavigabilityProcessor::navigable_from(occupiable, {7, 2}), InvalidArgument);
  EXPECT_NO_THROW(NavigabilityProcessor::navigable_from(occupiable, {3, 5}));
}

}  // namespace
}  // namespace marsala
