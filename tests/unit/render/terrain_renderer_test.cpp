#include "marsala/render/terrain_renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "marsala/core/error.hpp"
#include "unit/render/render_test_support.hpp"

namespace marsala::render {
namespace {

using test::at;
using test::Pixel;
using test::plain;

Heightmap make_map(int rows, int cols, double cs = 0.5) { return Heightmap(GridGeometry{rows, cols, 0.0, 0.0, cs}); }

// An uneven but smooth test terrain.
Heightmap bumpy(int rows, int cols, double cs = 0.5) {
  auto m = make_map(rows, cols, cs);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(r, c) = std::sin(0.3 * r) + 0.5 * std::cos(0.2 * c) + 0.01 * r * c;
  return m;
}

TEST(TerrainRenderer, TerrainAreaSizeRules) {
  struct Case {
    int rows, cols, max_px, width, height;
  };
  const Case cases[] = {
      {10, 20, 100, 100, 50},         // upscale by 5
      {1, 1, 64, 64, 64},             // one cell fills the area
      {1, 37, 100, 74, 2},            // 1 x N strip, upscale by 2
      {37, 1, 100, 2, 74},            // N x 1 strip
      {2048, 1024, 1024, 512, 1024},  // block-average 2 x 2
      {3000, 5, 1024, 2, 1000},       // factor 3: 3000 / 3 rows, ceil(5 / 3) cols
      {1025, 1025, 1024, 513, 513},   // factor 2 with a partial last block
      {7, 7, 7, 7, 7},                // exactly fits
  };
  for (const Case& c : cases) {
    const Image img = render_terrain(make_map(c.rows, c.cols), plain(c.max_px));
    EXPECT_EQ(img.width, c.width) << c.rows << "x" << c.cols;
    EXPECT_EQ(img.height, c.height) << c.rows << "x" << c.cols;
    EXPECT_EQ(img.rgb.size(), 3u * img.width * img.height);
  }
}

TEST(TerrainRenderer, LongestSideStaysWithinHalfAndAllOfTheLimit) {
  for (int n : {1, 3, 50, 99, 100, 101, 333, 1000}) {
    const Image img = render_terrain(make_map(n, (n + 1) / 2), plain(100));
    const int longest = std::max(img.width, img.height);
    EXPECT_LE(longest, 100) << n;
    EXPECT_GT(longest, 50) << n;
  }
}

TEST(TerrainRenderer, LegendAddsMarginsAroundTheTerrain) {
  const auto map = bumpy(20, 30);
  RenderOptions o;
  o.max_size_px = 300;
  const Image bare = render_terrain(map, plain(300));
  const Image full = render_terrain(map, o);
  EXPECT_GT(full.width, bare.width);
  EXPECT_GT(full.height, bare.height);
  EXPECT_EQ(full.rgb.size(), 3u * full.width * full.height);
  // The title is drawn: a different title changes the picture, not its size.
  o.title = "A";
  const Image a = render_terrain(map, o);
  o.title = "B";
  const Image b = render_terrain(map, o);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_NE(a.rgb, b.rgb);
}

TEST(TerrainRenderer, FlatTerrainIsOneColour) {
  auto map = make_map(13, 17);
  map.heights().setConstant(2.0);
  const Image img = render_terrain(map, plain(170));
  const Pixel first = at(img, 0, 0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) ASSERT_EQ(at(img, x, y), first) << x << ", " << y;
}

TEST(TerrainRenderer, HigherGroundIsLighter) {
  // Two flat terraces (0 m west, 1 m east): away from the cliff the shading is neutral, so only the colour
  // map speaks, and its lightness rises with height.
  auto map = make_map(10, 20);
  for (int r = 0; r < 10; ++r)
    for (int c = 10; c < 20; ++c) map(r, c) = 1.0;
  const Image img = render_terrain(map, plain(200));  // 10 px per cell
  EXPECT_GT(at(img, 175, 50).luminance(), at(img, 25, 50).luminance());
}

TEST(TerrainRenderer, SunFromTheNorthWest) {
  // A ridge along x: west half rises eastward (faces west), east half falls eastward (faces east). Cells
  // at mirrored columns share a height, so any difference is shading: west-facing slopes get the sun.
  auto ridge = make_map(9, 21, 1.0);
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 21; ++c) ridge(r, c) = 0.3 * (10 - std::abs(c - 10));
  const Image a = render_terrain(ridge, plain(210));
  EXPECT_GT(at(a, 5 * 10 + 5, 45).luminance(), at(a, 15 * 10 + 5, 45).luminance());
  // A ridge along y: the north half faces north (row 0 on top), the south half faces south.
  auto ns = make_map(21, 9, 1.0);
  for (int r = 0; r < 21; ++r)
    for (int c = 0; c < 9; ++c) ns(r, c) = 0.3 * (10 - std::abs(r - 10));
  const Image b = render_terrain(ns, plain(210));
  EXPECT_GT(at(b, 45, 5 * 10 + 5).luminance(), at(b, 45, 15 * 10 + 5).luminance());
}

TEST(TerrainRenderer, SmallGridsUpscaleToUniformSquares) {
  const auto map = bumpy(5, 7);
  const Image img = render_terrain(map, plain(70));  // 10 px per cell
  ASSERT_EQ(img.width, 70);
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 7; ++c)
      for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x) ASSERT_EQ(at(img, c * 10 + x, r * 10 + y), at(img, c * 10, r * 10));
}

TEST(TerrainRenderer, LargeGridsAreBlockAveraged) {
  // Rendering 8 x 8 cells into 4 x 4 px equals rendering the 2 x 2 block means on cells twice as large.
  // Heights are multiples of 0.5, so every block mean is exact; the global minimum (-1) and maximum (3) sit
  // in constant blocks, so both maps share the colour scale.
  auto fine = make_map(8, 8, 0.5);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) fine(r, c) = ((r * 7 + c * 3) % 5) * 0.5;
  fine.heights().block(0, 0, 2, 2).setConstant(-1.0);
  fine.heights().block(6, 6, 2, 2).setConstant(3.0);
  auto coarse = make_map(4, 4, 1.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      coarse(r, c) =
          (fine(2 * r, 2 * c) + fine(2 * r, 2 * c + 1) + fine(2 * r + 1, 2 * c) + fine(2 * r + 1, 2 * c + 1)) / 4;
  ASSERT_EQ(coarse.min_height(), -1.0);
  ASSERT_EQ(coarse.max_height(), 3.0);
  const Image a = render_terrain(fine, plain(4));
  ASSERT_EQ(a.width, 4);
  ASSERT_EQ(a.height, 4);
  EXPECT_EQ(a.rgb, render_terrain(coarse, plain(4)).rgb);
  // Not merely subsampled: the picture differs from rendering every other cell.
  auto subsampled = make_map(4, 4, 1.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) subsampled(r, c) = fine(2 * r, 2 * c);
  EXPECT_NE(a.rgb, render_terrain(subsampled, plain(4)).rgb);
}

TEST(TerrainRenderer, NavigableCellsAreGreener) {
  const auto map = bumpy(12, 12);
  CellMask nav = CellMask::Zero(12, 12);
  nav.block(2, 2, 6, 6).setOnes();
  RenderOptions o = plain(120);  // 10 px per cell
  const Image base = render_terrain(map, o);
  o.navigable = nav;
  const Image tinted = render_terrain(map, o);
  // Interior of the navigable block (cell (4, 4), centre pixel): greener than without the overlay.
  EXPECT_GT(at(tinted, 45, 45).greenness(), at(base, 45, 45).greenness() + 10);
  // Non-navigable cells keep their colour.
  EXPECT_EQ(at(tinted, 105, 105), at(base, 105, 105));
  EXPECT_EQ(at(tinted, 5, 5), at(base, 5, 5));
  // The border of the region is outlined: its edge pixel differs from the tinted interior and is dark green.
  const Pixel edge = at(tinted, 20, 45);  // first pixel of cell (4, 2), on the region's west edge
  EXPECT_NE(edge, at(tinted, 45, 45));
  EXPECT_GT(edge.g, edge.r);
  EXPECT_GT(edge.g, edge.b);
  EXPECT_LT(edge.luminance(), at(tinted, 45, 45).luminance());
}

TEST(TerrainRenderer, GapOverlayColoursOnlyCellsWithAGap) {
  // Flat ground: a neutral base, so the overlay is the only change.
  auto map = make_map(10, 10);
  map.heights().setConstant(0.5);
  auto gap = make_map(10, 10);
  gap(3, 3) = 0.8;
  gap(6, 7) = 0.2;
  gap(8, 1) = 1e-12;  // numerically zero: no overlay
  RenderOptions o = plain(100);
  const Image base = render_terrain(map, o);
  o.gap = gap;
  const Image heat = render_terrain(map, o);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 10; ++c) {
      const Pixel p = at(heat, c * 10 + 5, r * 10 + 5), q = at(base, c * 10 + 5, r * 10 + 5);
      if ((r == 3 && c == 3) || (r == 6 && c == 7)) {
        EXPECT_NE(p, q) << r << ", " << c;
        EXPECT_GT(p.r - p.b, q.r - q.b) << r << ", " << c;  // warmer
      } else {
        EXPECT_EQ(p, q) << r << ", " << c;
      }
    }
  // The heat scale darkens as the gap grows.
  EXPECT_LT(at(heat, 35, 35).luminance(), at(heat, 75, 65).luminance());
}

TEST(TerrainRenderer, MarkersAreDrawnAsCrosses) {
  const auto map = bumpy(20, 20);
  RenderOptions o = plain(400);  // 20 px per cell
  const Image base = render_terrain(map, o);
  o.markers = {{5, 15}};
  const Image marked = render_terrain(map, o);
  const int cx = 15 * 20 + 10, cy = 5 * 20 + 10;
  EXPECT_NE(at(marked, cx, cy), at(base, cx, cy));
  // Arms reach a few pixels out horizontally and vertically, but not diagonally.
  EXPECT_EQ(at(marked, cx + 4, cy), at(marked, cx, cy));
  EXPECT_EQ(at(marked, cx, cy - 4), at(marked, cx, cy));
  EXPECT_EQ(at(marked, cx + 5, cy + 5), at(base, cx + 5, cy + 5));
  // Far away nothing changes.
  EXPECT_EQ(at(marked, 20, 20), at(base, 20, 20));
  // A marker on a downsampled grid lands in the display pixel of its block.
  const auto big = bumpy(40, 40);
  RenderOptions d = plain(20);  // 2 x 2 cells per pixel
  const Image big_base = render_terrain(big, d);
  d.markers = {{31, 9}};
  const Image big_marked = render_terrain(big, d);
  EXPECT_NE(at(big_marked, 4, 15), at(big_base, 4, 15));
}

TEST(TerrainRenderer, BadInputIsRejected) {
  EXPECT_THROW(render_terrain(Heightmap{}), InvalidArgument);
  auto nan_map = bumpy(4, 4);
  nan_map(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(render_terrain(nan_map), InvalidArgument);
  auto inf_map = bumpy(4, 4);
  inf_map(0, 3) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(render_terrain(inf_map), InvalidArgument);

  const auto map = bumpy(4, 5);
  RenderOptions o;
  o.navigable = CellMask::Zero(5, 4);
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.gap = make_map(4, 6);
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  auto gap = make_map(4, 5);
  gap(1, 1) = std::numeric_limits<double>::quiet_NaN();
  o.gap = gap;
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.markers = {{4, 0}};
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o.markers = {{0, -1}};
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.max_size_px = 0;
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o.max_size_px = -5;
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
}

TEST(TerrainRenderer, EveryPrintableCharacterCanBeDrawn) {
  RenderOptions o;
  o.max_size_px = 64;
  for (char c = 32; c < 127; ++c) o.title += c;
  o.title += "\t\xc3\xa9";  // non-printable and non-ASCII bytes fall back to a placeholder glyph
  const Image img = render_terrain(bumpy(8, 8), o);
  EXPECT_GT(img.width, 6 * 95);
}

}  // namespace
}  // namespace marsala::render
