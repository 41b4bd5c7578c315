#include "marsala/agent/executive/detail/voxel_occupancy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace marsala::agent::executive::detail {
namespace {

// The flat leaves must be OctoMap's own: the same scans go into a real octomap::OcTree with the mapping system's
// call (insertPointCloud(cloud, origin, -1, lazy_eval = true, discretize = true)), and every leaf of the tree must
// exist in the flat map with bit-identical log-odds, and no other.

constexpr double kCell = 0.1;
constexpr int kRows = 60, kCols = 80;

// A rough surface with walls (rises of up to 1 m between cells) seen from a sensor 0.5 m above it; repeated points
// and points in the same voxel included, some off the grid (beyond the array of columns, 0.5 m around it).
octomap::Pointcloud rough_surface(std::mt19937& rng) {
  std::uniform_real_distribution<float> along(-0.5f, 8.5f), dz(-0.05f, 0.05f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < 3000; ++i) {
    const float x = along(rng), y = along(rng) * 0.7f;
    const bool wall = std::fmod(std::floor(y * 3.0f), 4.0f) > 2.0f;
    const float ground = static_cast<float>(std::floor(x) * 0.1 + (wall ? 1.0 : 0.0));
    cloud.push_back(x, y, ground + dz(rng));
    if (i % 7 == 0) cloud.push_back(x, y, ground);
  }
  return cloud;
}

void expect_same_leaves(const octomap::OcTree& tree, const VoxelOccupancy& flat) {
  std::size_t leaves = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    ASSERT_EQ(it.getDepth(), tree.getTreeDepth()) << "the tree was pruned: the comparison would not be leaf by leaf";
    float value = 0.0f;
    ASSERT_TRUE(flat.log_odds(it.getKey(), value)) << "a leaf of the tree is missing";
    EXPECT_EQ(value, it->getLogOdds());
    EXPECT_EQ(flat.occupied(it.getKey()), tree.isNodeOccupied(*it));
    ++leaves;
  }
  EXPECT_EQ(flat.leaves(), leaves);
}

TEST(VoxelOccupancy, ScansUpdateTheSameLeavesAsOctoMapsBatchInsertion) {
  for (double clamp_min : {0.4, 0.1192}) {
    octomap::OcTree tree(kCell);
    tree.setClampingThresMin(clamp_min);
    VoxelOccupancy flat(kCell, kRows, kCols, clamp_min);
    std::mt19937 rng(7);
    // Many scans from poses that revisit the same ground: leaves reach both clamping thresholds and flip.
    for (int k = 0; k < 25; ++k) {
      const octomap::point3d origin(0.3f + 0.25f * static_cast<float>(k % 9), 2.0f + 0.1f * static_cast<float>(k % 4),
                                    0.5f + 0.1f * static_cast<float>(k % 3));
      const octomap::Pointcloud cloud = rough_surface(rng);
      tree.insertPointCloud(cloud, origin, -1.0, true, true);
      flat.insert(cloud, origin);
    }
    expect_same_leaves(tree, flat);
  }
}

TEST(VoxelOccupancy, AVoxelNoScanReachedIsNeitherKnownNorOccupied) {
  VoxelOccupancy flat(kCell, kRows, kCols, 0.4);
  octomap::Pointcloud cloud;
  cloud.push_back(1.05f, 1.05f, 0.05f);
  flat.insert(cloud, octomap::point3d(0.05f, 1.05f, 0.05f));
  octomap::OcTreeKey end, crossed, beyond;
  ASSERT_TRUE(flat.key_of(octomap::point3d(1.05f, 1.05f, 0.05f), end));
  ASSERT_TRUE(flat.key_of(octomap::point3d(0.55f, 1.05f, 0.05f), crossed));
  ASSERT_TRUE(flat.key_of(octomap::point3d(2.05f, 1.05f, 0.05f), beyond));
  float value = 0.0f;
  EXPECT_TRUE(flat.occupied(end));
  EXPECT_TRUE(flat.log_odds(crossed, value));
  EXPECT_FALSE(flat.occupied(crossed));
  EXPECT_FALSE(flat.log_odds(beyond, value));
  EXPECT_FALSE(flat.occupied(beyond));
  EXPECT_EQ(flat.leaves(), 11u);  // the end and the ten voxels from x = 0 to 1 m its ray crosses
}

}  // namespace
}  // namespace marsala::agent::executive::detail
