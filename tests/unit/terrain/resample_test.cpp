#include "marsala/terrain/resample.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::terrain {
namespace {

double plane(Position p) { return 2.0 + 0.3 * p.x - 0.7 * p.y; }

Heightmap plane_map(GridGeometry g) {
  Heightmap map(g);
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c) map(r, c) = plane(map.cell_center({r, c}));
  return map;
}

TEST(Resample, GeometryFollowsTheFloorRule) {
  const Heightmap map(GridGeometry{7, 9, 3.0, -2.0, 0.5});  // 4.5 m wide, 3.5 m high
  const Heightmap out = resample_bilinear(map, 0.2);
  EXPECT_EQ(out.cols(), 22);  // floor(4.5 / 0.2) = floor(22.5)
  EXPECT_EQ(out.rows(), 17);  // floor(3.5 / 0.2) = floor(17.5)
  EXPECT_EQ(out.cell_size_m(), 0.2);
  EXPECT_EQ(out.geometry().xll_m, 3.0);
  EXPECT_EQ(out.geometry().yll_m, -2.0);
  const Heightmap coarse = resample_bilinear(map, 1.3);
  EXPECT_EQ(coarse.cols(), 3);  // floor(3.46)
  EXPECT_EQ(coarse.rows(), 2);  // floor(2.69)
}

TEST(Resample, CountToleranceAbsorbsFloatingPointQuotients) {
  // 0.6 / 0.2 is 2.9999999999999996 in floating point: the extent still holds 3 cells.
  ASSERT_LT(0.6 / 0.2, 3.0);
  const Heightmap map(GridGeometry{1, 1, 0.0, 0.0, 0.6}, 4.0);
  const Heightmap out = resample_bilinear(map, 0.2);
  EXPECT_EQ(out.cols(), 3);
  EXPECT_EQ(out.rows(), 3);
}

TEST(Resample, ReproducesAPlaneBetweenTheOutermostCentres) {
  const GridGeometry g{7, 9, 3.0, -2.0, 0.5};
  const Heightmap map = plane_map(g);
  for (double cs : {0.2, 0.1, 0.35, 0.5, 0.9}) {
    const Heightmap out = resample_bilinear(map, cs);
    int checked = 0;
    for (int r = 0; r < out.rows(); ++r)
      for (int c = 0; c < out.cols(); ++c) {
        const Position p = out.cell_center({r, c});
        // Clamping makes the border flat; inside the hull of source centres the plane is exact.
        const bool inside =
            p.x >= g.xll_m + 0.25 && p.x <= g.xll_m + 4.25 && p.y >= g.yll_m + 0.25 && p.y <= g.yll_m + 3.25;
        if (!inside) continue;
        EXPECT_NEAR(out(r, c), plane(p), 1e-9) << "cs " << cs << " cell (" << r << ", " << c << ")";
        ++checked;
      }
    EXPECT_GT(checked, 0) << cs;
  }
}

TEST(Resample, ClampsAtTheBorder) {
  // Outside the outermost centres the value is that of the nearest edge interpolation: the plane at the
  // clamped position.
  const GridGeometry g{4, 4, 0.0, 0.0, 1.0};
  const Heightmap map = plane_map(g);
  const Heightmap out = resample_bilinear(map, 0.25);  // 16 x 16, first centre at 0.125 m
  const Position corner = out.cell_center({15, 0});    // (0.125, 0.125): clamped to (0.5, 0.5)
  EXPECT_NEAR(corner.x, 0.125, 1e-12);
  EXPECT_NEAR(out(15, 0), plane({0.5, 0.5}), 1e-12);
  EXPECT_NEAR(out(0, 15), plane({3.5, 3.5}), 1e-12);
  EXPECT_NEAR(out(0, 7), plane({out.cell_center({0, 7}).x, 3.5}), 1e-12);
}

TEST(Resample, ConstantMapsStayExactlyConstant) {
  const Heightmap map(GridGeometry{5, 6, -1.0, 2.0, 0.3}, 12.345678901234567);
  for (double cs : {0.07, 0.1, 0.3, 0.45, 1.1}) {
    const Heightmap out = resample_bilinear(map, cs);
    for (long long i = 0; i < out.size(); ++i) ASSERT_EQ(out.data()[i], 12.345678901234567) << cs;
  }
}

TEST(Resample, SameCellSizeIsTheIdentity) {
  Heightmap map(GridGeometry{3, 4, 0.0, 0.0, 0.1});
  for (long long i = 0; i < map.size(); ++i) map.data()[i] = std::sin(1.7 * i) * 10.0;
  const Heightmap out = resample_bilinear(map, 0.1);
  EXPECT_EQ(out.geometry(), map.geometry());
  EXPECT_TRUE(out.heights() == map.heights());
}

TEST(Resample, GoldenSaddleTwoByTwoToFourByFour) {
  // 2 x 2 cells of 1 m, only the south-east cell at 1 m: bilinear gives u * v, where u is the column
  // coordinate and v the row coordinate (from the north) between the centres, clamped to [0, 1].
  // New centres at 0.25, 0.75, 1.25, 1.75 m lie at u = -0.25 -> 0, 0.25, 0.75, 1.25 -> 1 (likewise v).
  Heightmap map(GridGeometry{2, 2, 0.0, 0.0, 1.0}, 0.0);
  map(1, 1) = 1.0;
  const Heightmap out = resample_bilinear(map, 0.5);
  ASSERT_EQ(out.rows(), 4);
  ASSERT_EQ(out.cols(), 4);
  const double expected[4][4] = {
      {0.0, 0.0, 0.0, 0.0}, {0.0, 0.0625, 0.1875, 0.25}, {0.0, 0.1875, 0.5625, 0.75}, {0.0, 0.25, 0.75, 1.0}};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_DOUBLE_EQ(out(r, c), expected[r][c]) << r << ", " << c;

  // Heights 1 (NW), 2 (NE), 3 (SW), 4 (SE): a plane in index space, 1 + u + 2 v.
  Heightmap ramp(GridGeometry{2, 2, 0.0, 0.0, 1.0});
  ramp(0, 0) = 1.0, ramp(0, 1) = 2.0, ramp(1, 0) = 3.0, ramp(1, 1) = 4.0;
  const Heightmap fine = resample_bilinear(ramp, 0.5);
  EXPECT_DOUBLE_EQ(fine(1, 1), 1.0 + 0.25 + 0.5);  // u = v = 0.25
  EXPECT_DOUBLE_EQ(fine(1, 2), 1.0 + 0.75 + 0.5);  // u = 0.75, v = 0.25
  EXPECT_DOUBLE_EQ(fine(2, 1), 1.0 + 0.25 + 1.5);  // u = 0.25, v = 0.75
  EXPECT_DOUBLE_EQ(fine(3, 3), 4.0);
  EXPECT_DOUBLE_EQ(fine(0, 0), 1.0);
}

TEST(Resample, RejectsBadCellSizes) {
  const Heightmap map(GridGeometry{2, 3, 0.0, 0.0, 1.0});
  EXPECT_THROW(resample_bilinear(map, 0.0), InvalidArgument);
  EXPECT_THROW(resample_bilinear(map, -0.5), InvalidArgument);
  EXPECT_THROW(resample_bilinear(map, std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
  EXPECT_THROW(resample_bilinear(map, std::numeric_limits<double>::infinity()), InvalidArgument);
  EXPECT_THROW(resample_bilinear(map, 2.5), InvalidArgument);  // 3 x 2 m holds 1 x 0 cells
  EXPECT_EQ(resample_bilinear(map, 2.0).size(), 1);
  EXPECT_THROW(resample_bilinear(map, 1e-6), InvalidArgument);  // 6e12 cells
  EXPECT_THROW(resample_bilinear(Heightmap(), 1.0), InvalidArgument);
}

TEST(Crop, MatchesABruteForceSelectionOfCentres) {
  Heightmap map(GridGeometry{6, 8, 10.0, 20.0, 0.5});
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 8; ++c) map(r, c) = 100 * r + c;
  struct Rect {
    double x0, y0, w, h;
  };
  // Edges on centres (10.25 + k / 2), between centres, past the grid, one cell.
  const Rect rects[] = {{10.25, 20.25, 1.0, 1.0}, {10.3, 20.0, 2.2, 1.6},   {9.0, 19.0, 100.0, 100.0},
                        {11.75, 21.25, 0.5, 0.5}, {11.0, 21.0, 0.26, 0.26}, {13.0, 21.5, 5.0, 0.75}};
  for (const Rect& rect : rects) {
    const Heightmap out = crop(map, rect.x0, rect.y0, rect.w, rect.h);
    int expected_cells = 0;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 8; ++c) {
        const Position p = map.cell_center({r, c});
        if (p.x < rect.x0 || p.x >= rect.x0 + rect.w || p.y < rect.y0 || p.y >= rect.y0 + rect.h) continue;
        ++expected_cells;
        // The kept cell sits at the same world position with the same height.
        const auto at = out.cell_at(p);
        ASSERT_TRUE(at.has_value()) << rect.x0 << ", " << rect.y0;
        EXPECT_EQ(out(*at), map(r, c));
        EXPECT_DOUBLE_EQ(out.cell_center(*at).x, p.x);
        EXPECT_DOUBLE_EQ(out.cell_center(*at).y, p.y);
      }
    EXPECT_EQ(out.size(), expected_cells) << rect.x0 << ", " << rect.y0;
    EXPECT_EQ(out.cell_size_m(), 0.5);
  }
}

TEST(Crop, KeepsWorldPositionsOfTheFirstKeptCell) {
  Heightmap map(GridGeometry{6, 8, 10.0, 20.0, 0.5});
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 8; ++c) map(r, c) = 100 * r + c;
  // Centres x = 10.25 + 0.5 c, y = 20.25 + 0.5 (5 - r). [11, 12.5) keeps c = 2..4; [20.5, 21.5) keeps r = 3..4.
  const Heightmap out = crop(map, 11.0, 20.5, 1.5, 1.0);
  ASSERT_EQ(out.cols(), 3);
  ASSERT_EQ(out.rows(), 2);
  EXPECT_EQ(out.geometry().xll_m, 11.0);
  EXPECT_EQ(out.geometry().yll_m, 20.5);
  EXPECT_EQ(out(0, 0), 302.0);
  EXPECT_EQ(out(1, 2), 404.0);
  // Half-open: a rectangle starting on a centre keeps it, one ending on a centre does not.
  const Heightmap on_centre = crop(map, 10.75, 20.25, 0.5, 0.5);
  ASSERT_EQ(on_centre.size(), 1);
  EXPECT_EQ(on_centre(0, 0), 501.0);
}

TEST(Crop, RejectsEmptyOrBadRectangles) {
  const Heightmap map(GridGeometry{4, 4, 0.0, 0.0, 1.0});
  EXPECT_THROW(crop(map, 0.0, 0.0, 0.0, 1.0), InvalidArgument);
  EXPECT_THROW(crop(map, 0.0, 0.0, 1.0, -1.0), InvalidArgument);
  EXPECT_THROW(crop(map, 10.0, 0.0, 2.0, 2.0), InvalidArgument);  // east of the grid
  EXPECT_THROW(crop(map, 0.0, -5.0, 2.0, 2.0), InvalidArgument);  // south of the grid
  EXPECT_THROW(crop(map, 0.6, 0.6, 0.3, 0.3), InvalidArgument);   // between centres 0.5 and 1.5
  EXPECT_THROW(crop(map, std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(crop(map, 0.0, 0.0, std::numeric_limits<double>::infinity(), 1.0), InvalidArgument);
}

TEST(CropResampleGale, WindowAtHalfMetre) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  const std::string path = root ? std::string(root) + "/../shared/data/terrains/gale_crater_1m.asc" : std::string();
  if (path.empty() || !std::filesystem::exists(path))
    GTEST_SKIP() << "gale_crater_1m.asc not found under $MARSALA_SOURCE_DIR/../shared/data/terrains";
  const Heightmap gale = read_asc(path);
  const Heightmap window = crop(gale, 100.0, 100.0, 160.0, 160.0);
  ASSERT_EQ(window.rows(), 160);
  ASSERT_EQ(window.cols(), 160);
  EXPECT_EQ(window.geometry().xll_m, 100.0);
  EXPECT_EQ(window.geometry().yll_m, 100.0);
  const Heightmap fine = resample_bilinear(window, 0.5);
  EXPECT_EQ(fine.rows(), 320);
  EXPECT_EQ(fine.cols(), 320);
  EXPECT_EQ(fine.geometry().xll_m, 100.0);
  EXPECT_EQ(fine.geometry().yll_m, 100.0);
  // Bilinear heights are convex combinations of the window's heights.
  EXPECT_GE(fine.min_height(), window.min_height());
  EXPECT_LE(fine.max_height(), window.max_height());
  // Fine cell (2k+1, 2j+1) has its centre a quarter of a window cell south-east of window cell (k, j)'s
  // centre: fine (21, 41) is at u = v = 0.25 from window (10, 20) towards (11, 21).
  const double u = 0.25, v = 0.25;
  const double top = window(10, 20) + u * (window(10, 21) - window(10, 20));
  const double bottom = window(11, 20) + u * (window(11, 21) - window(11, 20));
  EXPECT_NEAR(fine(21, 41), top + v * (bottom - top), 1e-12);
  const Heightmap tenth = resample_bilinear(crop(gale, 0.0, 0.0, 16.0, 16.0), 0.1);
  EXPECT_EQ(tenth.rows(), 160);
  EXPECT_EQ(tenth.cols(), 160);
}

}  // namespace
}  // namespace marsala::terrain
