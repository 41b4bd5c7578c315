// The renderer's overlays: per-cell label tints with a palette, polylines, arrows, rectangle and circle outlines,
// point marks and legend entries. Expected pixels are derived by hand from the placement rule of
// terrain_renderer.hpp (cell centre (r, c) at pixel ((c + 0.5) k, (r + 0.5) k) for k pixels per cell).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <tuple>

#include "marsala/core/error.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "unit/render/render_test_support.hpp"

namespace marsala::render {
namespace {

using test::at;
using test::Pixel;
using test::plain;

Pixel pixel(Rgb c) { return {c.r, c.g, c.b}; }

constexpr Pixel kHalo{30, 30, 30};

/// A flat map (one colour everywhere, no shading), cs 0.5 m, lower-left at (10, 20) so that world and pixel
/// coordinates differ.
Heightmap flat(int rows, int cols) { return Heightmap(GridGeometry{rows, cols, 10.0, 20.0, 0.5}, 1.0); }

/// Expected blend of `base` towards `tint` by alpha, per channel, before rounding.
void expect_blend(Pixel got, Pixel base, Pixel tint, double alpha, const char* what) {
  EXPECT_NEAR(got.r, base.r + alpha * (tint.r - base.r), 0.51) << what;
  EXPECT_NEAR(got.g, base.g + alpha * (tint.g - base.g), 0.51) << what;
  EXPECT_NEAR(got.b, base.b + alpha * (tint.b - base.b), 0.51) << what;
}

TEST(RenderPalette, TwelveDistinctColoursCycledByLabel) {
  const std::vector<Rgb>& p = default_palette();
  ASSERT_EQ(p.size(), 12u);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const int dr = p[i].r - p[j].r, dg = p[i].g - p[j].g, db = p[i].b - p[j].b;
      EXPECT_GT(std::sqrt(dr * dr + dg * dg + db * db), 60.0) << i << " vs " << j;
    }
  EXPECT_EQ(label_colour(1), p[0]);
  EXPECT_EQ(label_colour(12), p[11]);
  EXPECT_EQ(label_colour(13), p[0]);
  EXPECT_EQ(label_colour(26), p[1]);
  const std::vector<Rgb> two{{1, 2, 3}, {4, 5, 6}};
  EXPECT_EQ(label_colour(3, two), (Rgb{1, 2, 3}));
  EXPECT_EQ(label_colour(4, two), (Rgb{4, 5, 6}));
}

TEST(RenderOverlays, LabelledCellsAreTintedWithTheirPaletteColour) {
  const auto map = flat(10, 10);
  RenderOptions o = plain(100);  // 10 px per cell
  const Image base = render_terrain(map, o);
  CellLabels labels = CellLabels::Zero(10, 10);
  labels(3, 4) = 1;
  labels(6, 2) = 13;  // wraps to the first colour
  labels(8, 8) = 5;
  o.labels = labels;
  o.label_alpha = 1.0;
  const Image opaque = render_terrain(map, o);
  EXPECT_EQ(at(opaque, 45, 35), pixel(default_palette()[0]));
  EXPECT_EQ(at(opaque, 40, 30), pixel(default_palette()[0]));  // the whole cell square
  EXPECT_EQ(at(opaque, 49, 39), pixel(default_palette()[0]));
  EXPECT_EQ(at(opaque, 25, 65), pixel(default_palette()[0]));
  EXPECT_EQ(at(opaque, 85, 85), pixel(default_palette()[4]));
  EXPECT_EQ(at(opaque, 50, 35), at(base, 50, 35));  // the neighbour cell keeps its colour
  EXPECT_EQ(at(opaque, 5, 5), at(base, 5, 5));

  o.label_alpha = 0.6;
  const Image translucent = render_terrain(map, o);
  expect_blend(at(translucent, 45, 35), at(base, 45, 35), pixel(default_palette()[0]), 0.6, "alpha 0.6");
  o.palette = {{0, 0, 255}};
  const Image custom = render_terrain(map, o);
  expect_blend(at(custom, 85, 85), at(base, 85, 85), {0, 0, 255}, 0.6, "custom palette");
}

TEST(RenderOverlays, ADownsampledBlockShowsItsMostFrequentLabelInProportion) {
  const auto map = flat(4, 4);
  RenderOptions o = plain(2);  // 2 x 2 cells per pixel
  const Image base = render_terrain(map, o);
  CellLabels labels = CellLabels::Zero(4, 4);
  labels(0, 0) = 5;  // block (0, 0): labels 5, 2, 2 and none -> label 2 on 3/4 of the block
  labels(0, 1) = 2;
  labels(1, 0) = 2;
  labels(2, 2) = 3;  // block (1, 1): labels 3 and 4 once each -> the smaller, 3, on 2/4
  labels(3, 3) = 4;
  o.labels = labels;
  o.label_alpha = 1.0;
  const Image img = render_terrain(map, o);
  ASSERT_EQ(img.width, 2);
  expect_blend(at(img, 0, 0), at(base, 0, 0), pixel(label_colour(2)), 0.75, "block (0, 0)");
  expect_blend(at(img, 1, 1), at(base, 1, 1), pixel(label_colour(3)), 0.5, "block (1, 1)");
  EXPECT_EQ(at(img, 1, 0), at(base, 1, 0));
}

TEST(RenderOverlays, APolylineCoversItsWidthWithAHaloAroundIt) {
  const auto map = flat(20, 20);
  RenderOptions o = plain(200);  // 10 px per cell
  const Image base = render_terrain(map, o);
  // Along row 10 from the centre of column 2 to the centre of column 17: pixel y 105, x 25 .. 175.
  o.polylines.push_back({{map.cell_center({10, 2}), map.cell_center({10, 17})}, {255, 214, 0}, 4.0});
  const Image img = render_terrain(map, o);
  ASSERT_EQ(img.width, base.width);
  ASSERT_EQ(img.height, base.height);
  const Pixel yellow{255, 214, 0};
  for (int x : {25, 60, 100, 174})
    for (int y : {103, 104, 105, 106}) EXPECT_EQ(at(img, x, y), yellow) << x << ", " << y;  // centres within 2 px
  EXPECT_EQ(at(img, 100, 102), kHalo);  // centre 102.5: 2.5 px away, inside the halo (3 px)
  EXPECT_EQ(at(img, 100, 107), kHalo);
  EXPECT_EQ(at(img, 100, 101), at(base, 100, 101));  // 3.5 px away
  EXPECT_EQ(at(img, 100, 109), at(base, 100, 109));
  EXPECT_EQ(at(img, 180, 105), at(base, 180, 105));  // beyond the end cap
  EXPECT_EQ(at(img, 22, 105), kHalo);                // the round cap's halo
}

TEST(RenderOverlays, AnArrowHasAShaftAndAHeadAtItsHead) {
  const auto map = flat(20, 20);
  RenderOptions o = plain(200);
  const Image base = render_terrain(map, o);
  // Tail at pixel (25, 105), head at (175, 105); shaft width 2 -> head 3 * 2 + 4 = 10 px long, 6 px half-wide.
  o.arrows.push_back({map.cell_center({10, 2}), map.cell_center({10, 17}), {220, 30, 30}, 2.0});
  const Image img = render_terrain(map, o);
  const Pixel red{220, 30, 30};
  EXPECT_EQ(at(img, 100, 105), red);
  EXPECT_EQ(at(img, 100, 104), red);
  EXPECT_EQ(at(img, 100, 107), at(base, 100, 107));  // beside the shaft: 2.5 px from its axis
  EXPECT_EQ(at(img, 168, 108), red);                 // inside the head: half-width 3.9 px at x 168.5
  EXPECT_EQ(at(img, 168, 101), red);
  EXPECT_EQ(at(img, 172, 105), red);                 // just behind the tip: half-width 1.5 px at x 172.5
  EXPECT_NE(at(img, 150, 108), red);                 // same offset beside the shaft: not the head
  EXPECT_EQ(at(img, 180, 105), at(base, 180, 105));  // past the tip
  // Reversed, the head sits at the west end.
  o.arrows[0] = {map.cell_center({10, 17}), map.cell_center({10, 2}), {220, 30, 30}, 2.0};
  const Image back = render_terrain(map, o);
  EXPECT_EQ(at(back, 31, 108), red);
  EXPECT_NE(at(back, 168, 108), red);
}

TEST(RenderOverlays, RectangleAndCircleOutlines) {
  const auto map = flat(20, 20);
  RenderOptions o = plain(200);
  const Image base = render_terrain(map, o);
  // Cell edges: x 10 + 0.5 * 4 = 12 m is pixel x 40; y 20 + 0.5 * 14 = 27 m is pixel y (20 - 14) * 10 = 60.
  o.rectangles.push_back({{12.0, 27.0}, {17.0, 22.0}, {255, 255, 255}, 2.0});  // pixels x 40 .. 140, y 60 .. 160
  o.circles.push_back({{15.0, 24.5}, 1.0, {0, 200, 0}, 2.0});                  // centre (100, 110), radius 20 px
  const Image img = render_terrain(map, o);
  const Pixel white{255, 255, 255}, green{0, 200, 0};
  EXPECT_EQ(at(img, 90, 59), white);
  EXPECT_EQ(at(img, 90, 60), white);
  EXPECT_EQ(at(img, 139, 130), white);
  EXPECT_EQ(at(img, 39, 150), white);
  EXPECT_EQ(at(img, 90, 58), kHalo);
  EXPECT_EQ(at(img, 70, 70), at(base, 70, 70));  // inside
  EXPECT_EQ(at(img, 90, 40), at(base, 90, 40));  // outside
  EXPECT_EQ(at(img, 120, 110), green);           // on the circle (pixel centre 120.5: 20.5 px from the centre)
  EXPECT_EQ(at(img, 100, 89), green);
  EXPECT_EQ(at(img, 100, 110), at(base, 100, 110));  // its centre
}

TEST(RenderOverlays, PointMarksHaveTheirShapeColourAndOutline) {
  const auto map = flat(20, 20);
  RenderOptions o = plain(200);
  const Image base = render_terrain(map, o);
  o.points.push_back({map.cell_center({5, 5}), {0, 0, 255}, PointShape::kSquare, 5.0});    // centre (55, 55)
  o.points.push_back({map.cell_center({5, 14}), {0, 255, 0}, PointShape::kDiamond, 5.0});  // centre (145, 55)
  o.points.push_back({map.cell_center({14, 10}), {255, 0, 0}, PointShape::kDisc, 5.0});    // centre (105, 145)
  const Image img = render_terrain(map, o);
  EXPECT_EQ(at(img, 55, 55), (Pixel{0, 0, 255}));
  EXPECT_EQ(at(img, 51, 51), (Pixel{0, 0, 255}));  // a square's corner
  EXPECT_EQ(at(img, 145, 55), (Pixel{0, 255, 0}));
  EXPECT_EQ(at(img, 142, 52), (Pixel{0, 255, 0}));  // on the diamond's edge: |dx| + |dy| = 5
  EXPECT_EQ(at(img, 142, 51), kHalo);               // |dx| + |dy| = 6: inside its outline (6.5)
  EXPECT_EQ(at(img, 148, 55), (Pixel{0, 255, 0}));
  EXPECT_EQ(at(img, 105, 145), (Pixel{255, 0, 0}));
  EXPECT_EQ(at(img, 108, 148), (Pixel{255, 0, 0}));  // pixel centre 4.95 px away
  EXPECT_EQ(at(img, 109, 149), kHalo);               // 6.36 px away: the outline (6.5)
  EXPECT_EQ(at(img, 105, 160), at(base, 105, 160));
}

TEST(RenderOverlays, OverlaysScaleWithDownsampling) {
  // 400 x 400 cells into 200 px: two cells per pixel. A polyline along row 200 lands on pixel row 100.
  const auto map = flat(400, 400);
  RenderOptions o = plain(200);
  o.polylines.push_back({{map.cell_center({200, 20}), map.cell_center({200, 380})}, {255, 214, 0}, 2.0});
  const Image img = render_terrain(map, o);
  ASSERT_EQ(img.width, 200);
  EXPECT_EQ(at(img, 100, 100), (Pixel{255, 214, 0}));
  EXPECT_NE(at(img, 100, 96), (Pixel{255, 214, 0}));
}

TEST(RenderOverlays, LegendEntriesShowTheirColourSwatch) {
  const auto map = flat(30, 30);
  RenderOptions o;
  o.max_size_px = 300;
  const Image without = render_terrain(map, o);
  o.legend_entries = {{"agent 1", {1, 2, 3}},
                      {"agent 2", {4, 5, 6}},
                      {"disc", {7, 8, 9}, LegendSwatch::kDisc},
                      {"line", {10, 11, 12}, LegendSwatch::kLine},
                      {"arrow", {13, 14, 15}, LegendSwatch::kArrow},
                      {"ring", {16, 17, 18}, LegendSwatch::kRing}};
  const Image with = render_terrain(map, o);
  EXPECT_GE(with.height, without.height);
  int count[6] = {};
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const Pixel p = at(with, x, y);
      for (int k = 0; k < 6; ++k) count[k] += p == Pixel{3 * k + 1, 3 * k + 2, 3 * k + 3};
    }
  // The swatches are 14 x 14 px here (legend font 1).
  EXPECT_GT(count[0], 100);  // a filled square less its frame: 12 x 12
  EXPECT_GT(count[1], 100);
  EXPECT_GT(count[2], 40);  // a disc of radius 4.5 px: about 64
  EXPECT_LT(count[2], 100);
  EXPECT_GT(count[3], 20);  // a line 2.8 px wide, 12 px long
  EXPECT_LT(count[3], 60);
  EXPECT_GT(count[4], 20);  // shaft and head
  EXPECT_GT(count[5], 20);  // a ring of radius 4, 2 px wide: about 50
}

TEST(RenderOverlays, BadOverlaysAreRejected) {
  const auto map = flat(4, 5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  RenderOptions o;
  o.labels = CellLabels::Zero(5, 4);
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.label_alpha = 1.5;
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.polylines.push_back({{{11.0, 21.0}, {nan, 21.0}}, {}, 0.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.polylines.push_back({{{11.0, 21.0}, {12.0, 21.0}}, {}, -1.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.arrows.push_back({{11.0, 21.0}, {12.0, std::numeric_limits<double>::infinity()}, {}, 0.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.circles.push_back({{11.0, 21.0}, nan, {}, 0.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.rectangles.push_back({{11.0, 21.0}, {nan, 22.0}, {}, 0.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  o = {};
  o.points.push_back({{11.0, 21.0}, {}, PointShape::kDisc, -2.0});
  EXPECT_THROW(render_terrain(map, o), InvalidArgument);
  // Off the terrain is not an error: clipped.
  o = {};
  o.polylines.push_back({{{-100.0, -100.0}, {100.0, 100.0}}, {}, 0.0});
  o.points.push_back({{-5.0, 0.0}, {}, PointShape::kSquare, 0.0});
  EXPECT_NO_THROW(render_terrain(map, o));
}

}  // namespace
}  // namespace marsala::render
