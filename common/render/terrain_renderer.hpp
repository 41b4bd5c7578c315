#pragma once
// Terrain pictures: hillshaded, colour-mapped heightmaps with navigability, gap and marker overlays, and a
// legend (title, height colour bar, gap colour bar, scale bar in metres).
//
// Terrain area size: with n = max(rows, cols) and N = max_size_px, a grid with n > N is reduced by block
// averaging over f x f cells, f = ceil(n / N), giving ceil(rows / f) x ceil(cols / f) pixels; otherwise each
// cell becomes a k x k pixel square, k = floor(N / n). With legend = false the image is exactly the terrain
// area; with legend = true margins, the title, colour bars and the scale bar are added around it.
//
// Overlays in world coordinates (polylines, arrows, rectangles, circles, points) are placed by the map's geometry:
// world (x, y) [m] -> continuous cell coordinates u = (x - xll) / cs (east), v = (yll + rows cs - y) / cs (south)
// -> pixels (u, v) * scale / factor; a pixel (px, py) covers [px, px + 1) x [py, py + 1), so a cell centre falls on
// the pixel that the cell's markers use. They are drawn over the terrain, tints, navigability and gap, in this
// order: rectangles, circles, polylines, arrows, markers, points; anything off the terrain area is clipped.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/render/image.hpp"

namespace marsala::render {

/// Per-cell labels, row-major like the heightmap: 0 = none, k >= 1 tints the cell with palette colour k.
using CellLabels = Eigen::Matrix<std::uint32_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The default label palette: 12 distinct colours (e.g. one per agent id), in this order: red, blue, green, orange,
/// purple, cyan, magenta, lime, brown, pink, teal, lavender. Label k uses entry (k - 1) mod 12.
const std::vector<Rgb>& default_palette();
/// Colour of label k >= 1 in `palette` (the default palette when empty): entry (k - 1) mod size.
Rgb label_colour(std::uint32_t label, const std::vector<Rgb>& palette = {});

/// A line through world points [m], drawn with a dark halo one pixel wide on each side.
struct Polyline {
  std::vector<Position> points;  ///< at least 2 to draw anything [m]
  Rgb colour{255, 214, 0};
  double width_px = 0.0;  ///< 0 = automatic (about 1/200 of the terrain area's longest side)
};

/// An arrow from `tail` to `head` [m]: a shaft and a filled triangular head at `head`, with a dark halo.
struct Arrow {
  Position tail;
  Position head;
  Rgb colour{220, 30, 30};
  double width_px = 0.0;  ///< shaft width; 0 = automatic
};

/// The outline of the axis-aligned rectangle with opposite corners `a` and `b` [m].
struct RectangleOutline {
  Position a;
  Position b;
  Rgb colour{255, 255, 255};
  double width_px = 0.0;  ///< 0 = automatic
};

/// A circle of radius_m around `centre` [m], outlined.
struct CircleOutline {
  Position centre;
  double radius_m = 1.0;
  Rgb colour{255, 255, 255};
  double width_px = 0.0;  ///< 0 = automatic
};

/// Shape of a point mark.
enum class PointShape : std::uint8_t { kDisc = 0, kSquare = 1, kDiamond = 2 };

/// A filled mark at a world point [m], with a dark outline.
struct PointMark {
  Position at;
  Rgb colour{255, 255, 255};
  PointShape shape = PointShape::kDisc;
  double radius_px = 0.0;  ///< half-size of the mark; 0 = automatic
};

/// How a legend entry's swatch is drawn: a filled square, a point mark's shape, a line, a circle or rectangle
/// outline (on a mid-blue ground, so that white shows), an arrow.
enum class LegendSwatch : std::uint8_t { kSquare = 0, kDisc, kDiamond, kLine, kRing, kOutline, kArrow };

/// A line of the legend's key: a colour swatch and its text.
struct LegendEntry {
  std::string text;
  Rgb colour;
  LegendSwatch swatch = LegendSwatch::kSquare;
};

/// What to draw over the hillshaded, colour-mapped terrain.
struct RenderOptions {
  std::optional<CellMask> navigable;  ///< tint navigable cells (translucent green), outline its border
  std::optional<Heightmap> gap;       ///< MARS gap [m]: a heat overlay where gap > 1e-9 m
  std::vector<CellIndex> markers;     ///< e.g. navigability origins: drawn as crosses
  std::optional<CellLabels> labels;   ///< tint labelled cells with their palette colour (below the overlays)
  std::vector<Rgb> palette;           ///< colours of labels 1, 2, ...; empty = default_palette()
  double label_alpha = 0.6;           ///< opacity of the label tint, in [0, 1]
  std::vector<RectangleOutline> rectangles;
  std::vector<CircleOutline> circles;
  std::vector<Polyline> polylines;
  std::vector<Arrow> arrows;
  std::vector<PointMark> points;
  std::vector<LegendEntry> legend_entries;  ///< extra key lines (legend only), after the built-in ones
  int max_size_px = 1024;  ///< longest side of the terrain area [px]; small grids upscale by an integer
  bool legend = true;      ///< a colour bar with min/max height, a scale bar in metres, title
  std::string title;       ///< drawn above the terrain when not empty (legend only)
};

/// Renders the heightmap (north up, row 0 at the top) with hillshading (sun from the NW, 45 deg) and a colour map.
/// A block of f x f cells (f > 1) shows its most frequent non-zero label (ties: the smallest), tinted in proportion to
/// its labelled cells. Throws InvalidArgument for an empty map, a non-finite height or gap, an overlay or label grid
/// of another size, a marker off the grid, a non-finite overlay coordinate, size or width, label_alpha outside
/// [0, 1], or max_size_px outside [1, 16384].
Image render_terrain(const Heightmap& map, const RenderOptions& options = {});

}  // namespace marsala::render
