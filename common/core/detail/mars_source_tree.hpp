#pragma once
// Quadtree over the surviving sources of the MARS processor, with upper-bound surfaces per node.

#include <cstdint>
#include <vector>

#include "marsala/core/detail/mars_common.hpp"

namespace marsala::detail {

/// A surface S lying above every source q of a node, h(q) <= S(q), of one of three kinds:
///   plane: S(q) = m + a . (q - ref) with |a| < kcs;
///   cone:  S(q) = m - kcs |q - apex|;      bowl: S(q) = m + kcs |q - apex|.
/// Then for a target p whose distance to every such q is >= d (triangle inequality):
///   h(q) - kcs |p - q| <= S(p) - (kcs - |a|) d (plane),  <= S(p) (cone, bowl).
/// A plane is exact on a plane of slope kappa, a cone or bowl on a cone or bowl of slope kappa
/// (apex anywhere); two shapes per node cover a crease where two such pieces meet.
struct Shape {
  enum class Kind : std::uint8_t { kNone, kPlane, kCone, kBowl };
  Kind kind = Kind::kNone;
  double r = 0, c = 0;    ///< plane: reference point; cone, bowl: apex [cells]
  double ar = 0, ac = 0;  ///< plane slope [m/cell]
  double deficit2 = 0;    ///< plane: (kcs - |a|)^2 [m^2/cell^2]
  double m = 0;           ///< max over the sources of h - a.(q - ref), h + kcs |q - apex|, h - kcs |q - apex| [m]
};

/// One node of the source quadtree.
struct SourceNode {
  int r0 = 1, r1 = 0, c0 = 1, c1 = 0;  ///< bounding box of the sources [cells]; empty when r0 > r1
  double max_h = -kInf;                ///< highest source [m]
  Shape shapes[2];                     ///< bounding surfaces; kind kNone when unused
  /// True when the node holds no source.
  bool empty() const { return r0 > r1; }
};

/// Level 0 holds kBlock x kBlock leaves (row-major), each level above halves both dimensions
/// (rounding up) and the top level is one node.
class SourceTree {
 public:
  /// masks: the surviving sources, one 64-bit mask per leaf (as from seed_lower_bound()).
  SourceTree(const Problem& pb, std::vector<std::uint64_t> masks);

  /// Index of the single top node's level.
  int top_level() const { return static_cast<int>(levels_.size()) - 1; }
  /// Nodes per row at a level.
  int width(int level) const { return widths_[level]; }
  /// Nodes per column at a level.
  int height(int level) const { return heights_[level]; }
  /// Node (i, j) of a level.
  const SourceNode& node(int level, int i, int j) const {
    return levels_[level][static_cast<std::size_t>(i) * widths_[level] + j];
  }
  /// Surviving sources of leaf (i, j): bit (row % kBlock) * kBlock + col % kBlock.
  std::uint64_t leaf_mask(int i, int j) const { return masks_[static_cast<std::size_t>(i) * widths_[0] + j]; }

 private:
  struct Builder;
  std::vector<std::uint64_t> masks_;
  std::vector<std::vector<SourceNode>> levels_;
  std::vector<int> widths_, heights_;
};

}  // namespace marsala::detail
