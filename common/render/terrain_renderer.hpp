#pragma once
// Terrain pictures: hillshaded, colour-mapped heightmaps with navigability, gap and marker overlays, and a
// legend (title, height colour bar, gap colour bar, scale bar in metres).
//
// Terrain area size: with n = max(rows, cols) and N = max_size_px, a grid with n > N is reduced by block
// averaging over f x f cells, f = ceil(n / N), giving ceil(rows / f) x ceil(cols / f) pixels; otherwise each
// cell becomes a k x k pixel square, k = floor(N / n). With legend = false the image is exactly the terrain
// area; with legend = true margins, the title, colour bars and the scale bar are added around it.

#include <optional>
#include <string>
#include <vector>

#include "common/grid/heightmap.hpp"
#include "common/render/image.hpp"
#include "common/types.hpp"

namespace marsala::render {

/// What to draw over the hillshaded, colour-mapped terrain.
struct RenderOptions {
  std::optional<grid::CellMask> navigable;   ///< tint navigable cells (translucent green), outline its border
  std::optional<grid::Heightmap> gap;        ///< MARS gap [m]: a heat overlay where gap > 1e-9 m
  std::vector<CellIndex> markers;            ///< e.g. navigability origins: drawn as crosses
  int max_size_px = 1024;                    ///< longest side of the terrain area [px]; small grids upscale by an integer
  bool legend = true;                        ///< a colour bar with min/max height, a scale bar in metres, title
  std::string title;                         ///< drawn above the terrain when not empty (legend only)
};

/// Renders the heightmap (north up, row 0 at the top) with hillshading (sun from the NW, 45 deg) and a colour map.
/// Throws InvalidArgument for an empty map, a non-finite height or gap, an overlay of another size, a marker off
/// the grid or max_size_px outside [1, 16384].
Image render_terrain(const grid::Heightmap& map, const RenderOptions& options = {});

}  // namespace marsala::render
