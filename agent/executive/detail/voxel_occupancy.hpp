#pragma once
// OctoMap's occupancy of leaf voxels, held flat: the mapping system's voxels are columns of the world grid, so a leaf is
// found by its column (an array over the grid) and its height in that column, not by a 16-level descent of the tree.
// A scan updates the leaves exactly as octomap::OcTree::insertPointCloud(cloud, origin, -1, lazy_eval = true,
// discretize = true) does (the same keys, rays and float log-odds, docs/runtime.md#mapping): the mapping system reads
// only leaves, never inner nodes, so nothing it reads differs. Internal to agent/executive (OctoMap types).

#include <octomap/OcTree.h>

#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace marsala::agent::executive::detail {

/// Leaf voxels of an octree of `resolution_m` [m] over a rows x cols grid whose lower-left corner is the tree's
/// origin (voxel column (x key, y key) = (kKeyZero + col, kKeyZero + rows - 1 - row)).
class VoxelOccupancy {
 public:
  /// An empty map; clamping_min_probability is the lower clamping threshold ([0, 1], OctoMap's 0.1192 by default).
  VoxelOccupancy(double resolution_m, int rows, int cols, double clamping_min_probability);

  /// Integrates one scan: points [m, tree frame] discretized to their voxels, each voxel a ray from `origin` crosses
  /// updated as a miss once, each end voxel as a hit once (ends win over crossings), as OctoMap's batch insertion.
  void insert(const octomap::Pointcloud& points, const octomap::point3d& origin);
  /// True when the leaf `key` exists and its log-odds reach the occupancy threshold (OcTree::isNodeOccupied).
  bool occupied(const octomap::OcTreeKey& key) const;
  /// The leaf's log-odds, or false when no leaf `key` exists.
  bool log_odds(const octomap::OcTreeKey& key, float& value) const;
  /// True when a ray crossed a voxel of the column of `key` (its x and y) at or below z key `max_z` and left it free
  /// (log-odds under the occupancy threshold): the surface there lies lower than that voxel's top.
  bool free_at_or_below(const octomap::OcTreeKey& key, octomap::key_type max_z) const;
  /// Leaves made so far (OcTree::getNumLeafNodes of the tree this replaces: it is never pruned).
  std::size_t leaves() const { return leaves_; }
  /// The key of a point [m, tree frame]; false when it lies outside the tree (OcTree::coordToKeyChecked).
  bool key_of(const octomap::point3d& point, octomap::OcTreeKey& key) const { return keys_.coordToKeyChecked(point, key); }

 private:
  struct Voxel {
    float log_odds = std::numeric_limits<float>::quiet_NaN();  ///< NaN: no leaf yet
    std::uint32_t miss_scan = 0;  ///< the last scan that counted it crossed
    std::uint32_t hit_scan = 0;   ///< the last scan with a point in it: counted occupied
  };
  struct Column {
    int z0 = 0;  ///< key of voxels[0]
    std::vector<Voxel> voxels;
  };
  Voxel& voxel(const octomap::OcTreeKey& key);  // made (not yet a leaf) when new
  const Voxel* find(const octomap::OcTreeKey& key) const;
  long long column_index(const octomap::OcTreeKey& key) const;  // -1 outside the grid's columns
  void update(Voxel& v, float change);

  octomap::OcTree keys_;  ///< an empty tree: OctoMap's key arithmetic, rays and log-odds parameters
  octomap::KeyRay ray_;
  int key_x0_, key_y0_, width_, height_;  ///< the columns held in the array (the grid and one more around)
  std::vector<Column> columns_;
  std::unordered_map<std::uint64_t, Voxel> outside_;  ///< voxels of columns beyond the array
  std::uint32_t scan_ = 0;
  std::size_t leaves_ = 0;
  std::vector<octomap::OcTreeKey> hits_;  ///< this scan's end voxels (reused)
  std::vector<octomap::point3d> ends_;    ///< and their centres, the rays' ends (reused)
};

}  // namespace marsala::agent::executive::detail
