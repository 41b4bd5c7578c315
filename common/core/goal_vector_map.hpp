#pragma once
// Goal vector map (paper §V-B, Fig. 6): a field of arrows over a site; a robot at an arrow's tail targets its head.
// The goal synthesizer of site preparation compiles it from a specification:
//
//   heading east, strip_width w, arrow_length L        y
//   +------------------------------------------+  y1   ^
//   |  o-------> o-------> o-------> o----->   |       |   strip 2: centre line y1 - w/2 ... (the last strip,
//   |  o-------> o-------> o-------> o----->   |       |            at the far side, may be narrower)
//   |  o-------> o-------> o-------> o----->   |  y0   |   strip 0: centre line y0 + w/2
//   +------------------------------------------+       +----> x
//   x0                                        x1
//
// Strips of width w cover [x0, x1] x [y0, y1] across `heading` (strip 0 at the low-coordinate side: south for
// east/west, west for north/south); strip i's centre line is at the middle of its band. Along `heading` each strip
// runs from the rectangle's upwind edge to its downwind edge, cut into arrows of length L (the last one shorter,
// but never shorter than one cell: a shorter remainder is merged into the previous arrow). Tails and heads are
// snapped to the centre of the grid cell containing them (points on the rectangle's far edges are pulled half a
// cell inwards first), so a robot that stands on a head stands exactly on a cell centre, and a head is the next
// arrow's tail.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala {

/// Direction the arrows point.
enum class Heading : std::uint8_t { kEast = 0, kWest = 1, kNorth = 2, kSouth = 3 };
/// "east", "west", "north", "south".
std::string to_string(Heading heading);
/// The inverse; throws InvalidArgument listing the valid names.
Heading heading_from_string(const std::string& name);

/// What the map is compiled from (scenario block goal_vector_map).
struct GoalVectorMapSpec {
  Rect area;                                              ///< the site [m]
  double strip_width_m = 1.0;                             ///< [m]
  double arrow_length_m = 5.0;                            ///< [m]
  Heading heading = Heading::kEast;
};

/// One arrow: a robot at `tail` builds towards `head` [m] (both cell centres).
struct GoalArrow {
  Position tail;
  Position head;
  int strip = 0;  ///< 0 .. strips - 1
  int index = 0;  ///< position along the strip, 0 at the upwind edge
};

/// The compiled map.
class GoalVectorMap {
 public:
  /// Compiles the arrows on `grid`. Throws InvalidArgument when the rectangle is empty or not inside the grid, or
  /// strip width or arrow length is not finite and > 0, or a strip is narrower than one cell.
  GoalVectorMap(const GoalVectorMapSpec& spec, const GridGeometry& grid);

  const GoalVectorMapSpec& spec() const { return spec_; }
  /// Every arrow, strip by strip (strip 0 first), upwind to downwind within a strip.
  const std::vector<GoalArrow>& arrows() const { return arrows_; }
  int strips() const { return strips_; }

  /// The arrow whose tail is nearest `p` [m] among those with excluded[i] == false (excluded may be shorter than
  /// arrows(): missing entries count as false); ties go to the lower index. nullopt when every arrow is excluded.
  std::optional<std::size_t> nearest_free_tail(Position p, const std::vector<bool>& excluded) const;
  /// The arrow whose stretch of the site holds `p` [m]: the strip whose band holds p across the heading (a point on
  /// the line between two bands belongs to the lower strip), and along it the first arrow whose head is not behind
  /// p (the first arrow's stretch reaches back to the upwind edge, the last one's on to the downwind edge). nullopt
  /// when p lies outside the rectangle (edges included) or is not finite.
  std::optional<std::size_t> arrow_at(Position p) const;
  /// The arrow after arrow i on its strip (its tail is arrow i's head), or nullopt at the strip's end; throws
  /// InvalidArgument when i is out of range.
  std::optional<std::size_t> next(std::size_t i) const;

 private:
  GoalVectorMapSpec spec_;
  std::vector<GoalArrow> arrows_;
  int strips_ = 0;
};

}  // namespace marsala
