// render_perspective: the surface's silhouette seen from above has the grid's proportions, nearer surfaces hide
// farther ones, built material is tinted and nothing else is, the picture is a pure function of its input, and bad
// input is refused.
#include "marsala/render/perspective.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "marsala/core/error.hpp"
#include "unit/render/render_test_support.hpp"

namespace marsala::render {
namespace {

using test::at;
using test::Pixel;

Heightmap flat(int rows, int cols, double cs = 1.0) { return Heightmap(GridGeometry{rows, cols, 0.0, 0.0, cs}); }

/// The orange of built material, shaded by any light: red well above green, green well above blue.
bool orange(const Pixel& p) { return p.r > 60 && p.r > p.g * 1.3 && p.g > p.b * 2.0; }

/// The sky's colours run from (16, 20, 28) to (44, 52, 68); the surface is lit in the terrain colour map.
bool sky(const Image& img, int x, int y) {
  const Pixel p = at(img, x, y);
  const double t = static_cast<double>(y) / img.height;
  return std::abs(p.r - (16 + 28 * t)) <= 1.0 && std::abs(p.g - (20 + 32 * t)) <= 1.0 &&
         std::abs(p.b - (28 + 40 * t)) <= 1.0;
}

TEST(Perspective, FromStraightAboveAFlatGridIsARectangleOfItsProportions) {
  PerspectiveOptions o;
  o.elevation_deg = 90.0;
  o.width_px = 600;
  o.height_px = 600;
  const Heightmap map = flat(20, 60);  // 60 m east-west, 20 m north-south
  const Image img = render_perspective(map, o);
  int x0 = img.width, x1 = -1, y0 = img.height, y1 = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (!sky(img, x, y)) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
  ASSERT_GT(x1, x0);
  // The vertices are the cell centres: the surface spans (cols - 1) x (rows - 1) cells; fitted with a 4 % margin.
  const double w = x1 - x0 + 1, h = y1 - y0 + 1;
  EXPECT_NEAR(w / h, 59.0 / 19.0, 0.05 * 59.0 / 19.0);
  EXPECT_NEAR(w, 600 * 0.92, 3.0);
  // Every pixel inside the silhouette is surface: a flat grid seen from above has no hole.
  for (int y = y0 + 1; y < y1; ++y)
    for (int x = x0 + 1; x < x1; ++x) ASSERT_FALSE(sky(img, x, y)) << x << ", " << y;
}

TEST(Perspective, ANearWallHidesTheGroundBehindIt) {
  // 40 x 40 m of flat ground; the southern quarter a block 10 m tall, marked as built so that it shows orange.
  Heightmap map = flat(40, 40);
  Heightmap built = flat(40, 40);
  for (int r = 30; r < 40; ++r)
    for (int c = 0; c < 40; ++c) {
      map(r, c) = 10.0;
      built(r, c) = 1.0;
    }
  PerspectiveOptions o;
  o.azimuth_deg = 180.0;  // from the south, low: the block stands between the camera and the centre
  o.elevation_deg = 20.0;
  o.deposit = built;
  const Image seen = render_perspective(map, o);
  // The camera looks at the grid's centre (20, 20) m at mid height (5 m); the line of sight passes the block's north
  // face (10 m south of the centre) 5 + 10 tan 20 deg = 8.6 m high, below its 10 m top: the centre shows the block.
  EXPECT_TRUE(orange(at(seen, seen.width / 2, seen.height / 2)));
  // From the north the ground comes first: the centre shows the unbuilt ground.
  o.azimuth_deg = 0.0;
  const Image behind = render_perspective(map, o);
  EXPECT_FALSE(orange(at(behind, behind.width / 2, behind.height / 2)));
}

TEST(Perspective, OnlyBuiltCellsAreTinted) {
  Heightmap map = flat(30, 30, 0.5);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 30; ++c) map(r, c) = 0.2 * std::sin(0.4 * r) * std::cos(0.3 * c);
  PerspectiveOptions o;
  o.width_px = 400;
  o.height_px = 300;
  const auto count_orange = [](const Image& img) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) n += orange(at(img, x, y)) ? 1 : 0;
    return n;
  };
  EXPECT_EQ(count_orange(render_perspective(map, o)), 0);
  Heightmap built = flat(30, 30, 0.5);
  for (int r = 10; r < 20; ++r)
    for (int c = 10; c < 20; ++c) built(r, c) = 0.1;
  o.deposit = built;
  const int tinted = count_orange(render_perspective(map, o));
  // A ninth of the grid is built; seen obliquely it covers a few percent of the picture at least.
  EXPECT_GT(tinted, 400 * 300 / 60);
  EXPECT_LT(tinted, 400 * 300 / 4);
}

TEST(Perspective, BodiesStandWhereTheyAreAsBoxesOfTheirColour) {
  PerspectiveOptions o;
  o.elevation_deg = 90.0;  // straight above: about 552 / 19 = 29 px per metre, north up
  o.width_px = 600;
  o.height_px = 600;
  const Heightmap map = flat(20, 20);
  const Image bare = render_perspective(map, o);
  o.bodies.push_back({5.5, 15.5, 4.0, 1.0, Rgb{255, 0, 0}});
  const Image img = render_perspective(map, o);
  const auto red = [&](int x, int y) {
    const Pixel p = at(img, x, y);
    return p.r > 150 && p.g < 30 && p.b < 30;
  };
  // Its top (lit 0.35 + 0.65 cos 45 deg) over x 3.5..7.5 m, y 13.5..17.5 m; the picture elsewhere unchanged.
  const int cx = static_cast<int>(24 + 5.0 * 552.0 / 19.0), cy = static_cast<int>(24 + 4.0 * 552.0 / 19.0);
  EXPECT_TRUE(red(cx, cy));
  EXPECT_FALSE(red(static_cast<int>(24 + 14.0 * 552.0 / 19.0), cy));
  EXPECT_FALSE(red(cx, static_cast<int>(24 + 14.0 * 552.0 / 19.0)));
  int count = 0, changed = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      count += red(x, y) ? 1 : 0;
      const Pixel a = at(img, x, y), b = at(bare, x, y);
      changed += (a.r != b.r || a.g != b.g || a.b != b.b) ? 1 : 0;
    }
  const double side_px = 4.0 * 552.0 / 19.0;  // a little more: the top is 1 m nearer the camera
  EXPECT_GT(count, 0.95 * side_px * side_px);
  EXPECT_LT(count, 1.2 * side_px * side_px);
  // Nothing else changed but the box: its top, and the sides the off-centre camera sees, darker.
  EXPECT_GE(changed, count);
  EXPECT_LT(changed, 1.1 * count);
  // A body off the map is not drawn.
  o.bodies = {{25.0, 5.0, 4.0, 1.0, Rgb{255, 0, 0}}};
  const Image off = render_perspective(map, o);
  EXPECT_EQ(off.rgb, bare.rgb);
}

TEST(Perspective, TheSameInputGivesTheSamePicture) {
  Heightmap map = flat(50, 70, 0.25);
  for (int r = 0; r < 50; ++r)
    for (int c = 0; c < 70; ++c) map(r, c) = std::sin(0.2 * r) + 0.3 * std::cos(0.15 * c);
  PerspectiveOptions o;
  o.title = "same";
  const Image a = render_perspective(map, o), b = render_perspective(map, o);
  EXPECT_EQ(a.rgb, b.rgb);
  o.azimuth_deg = 45.0;
  EXPECT_NE(render_perspective(map, o).rgb, a.rgb);
}

TEST(Perspective, BadInputIsRefused) {
  const Heightmap map = flat(10, 10);
  PerspectiveOptions o;
  o.elevation_deg = 0.0;
  EXPECT_THROW(render_perspective(map, o), InvalidArgument);
  o.elevation_deg = 91.0;
  EXPECT_THROW(render_perspective(map, o), InvalidArgument);
  o = {};
  o.vertical_exaggeration = 0.0;
  EXPECT_THROW(render_perspective(map, o), InvalidArgument);
  o = {};
  o.width_px = 8;
  EXPECT_THROW(render_perspective(map, o), InvalidArgument);
  o = {};
  o.deposit = flat(10, 11);
  EXPECT_THROW(render_perspective(map, o), InvalidArgument);
  Heightmap nan = flat(10, 10);
  nan(3, 4) = std::numeric_limits<double>::quiet_NaN();
  try {
    render_perspective(nan, {});
    FAIL() << "a NaN height was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("(3, 4)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(render_perspective(Heightmap(GridGeometry{0, 0, 0.0, 0.0, 1.0}), {}), InvalidArgument);
}

}  // namespace
}  // namespace marsala::render
