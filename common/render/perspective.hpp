#pragma once
// A perspective view of a terrain, like the paper's figures: the heightmap as a lit surface seen from a camera above
// one side, with built material tinted.
//
// Camera: it looks at the grid's centre from `azimuth_deg` (the compass direction the camera stands in, seen from
// the centre: 0 north, 90 east, 180 south, 225 south-west) and `elevation_deg` above the horizon, at a distance of
// 1.6 times the grid's diagonal, with a pinhole projection; heights are multiplied by `vertical_exaggeration`. Each
// cell is drawn as two triangles between its centre heights and its neighbours', flat-shaded (Lambert, sun from the
// north-west, 45 deg up, plus ambient light) in the terrain colour map of render_terrain, with a z-buffer: nearer
// surfaces hide farther ones. Cells whose `deposit` exceeds 1e-9 m are tinted orange, more strongly where more was
// built. The picture is width x height pixels on a dark sky, the surface scaled to fill it with a small margin.
// Robots (`bodies`) stand on the surface as boxes of their colour, flat-shaded like it and z-buffered with it.

#include <optional>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/render/image.hpp"

namespace marsala::render {

/// A robot drawn on the surface: an axis-aligned box of side side_m standing on the cell under its centre.
struct PerspectiveBody {
  double x_m = 0.0, y_m = 0.0;  ///< centre, in the map's world frame [m]; off the map: not drawn
  double side_m = 0.8;          ///< footprint side [m]
  double height_m = 0.4;        ///< above the terrain [m] (multiplied by the exaggeration like every height)
  Rgb colour{255, 255, 255};
};

/// How to look at the terrain.
struct PerspectiveOptions {
  double azimuth_deg = 225.0;          ///< where the camera stands, seen from the centre (0 north, 90 east)
  double elevation_deg = 35.0;         ///< above the horizon, in (0, 90]
  double vertical_exaggeration = 1.0;  ///< heights multiplied by this, > 0
  int width_px = 1200;
  int height_px = 800;
  std::optional<Heightmap> deposit;  ///< built material per cell [m] (final - initial), same grid; tints it
  std::string title;                 ///< drawn in the top-left corner when not empty
  std::vector<PerspectiveBody> bodies;  ///< robots standing on the surface
};

/// Renders `map` as seen with `options`. Throws InvalidArgument for an empty map, a non-finite height or deposit, a
/// deposit grid of another size, an elevation outside (0, 90], an exaggeration <= 0 or not finite, or a picture size
/// outside [16, 8192] px.
Image render_perspective(const Heightmap& map, const PerspectiveOptions& options = {});

}  // namespace marsala::render
