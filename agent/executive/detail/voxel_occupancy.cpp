#include "marsala/agent/executive/detail/voxel_occupancy.hpp"

#include <algorithm>
#include <cmath>

namespace marsala::agent::executive::detail {
namespace {

/// The key of the tree's origin along each axis (OctoMap's tree_max_val for 16 levels).
constexpr int kKeyZero = 32768;

std::uint64_t packed(const octomap::OcTreeKey& key) {
  return static_cast<std::uint64_t>(key[0]) | static_cast<std::uint64_t>(key[1]) << 16 |
         static_cast<std::uint64_t>(key[2]) << 32;
}

}  // namespace

VoxelOccupancy::VoxelOccupancy(double resolution_m, int rows, int cols, double clamping_min_probability)
    : keys_(resolution_m),
      key_x0_(kKeyZero - 1),
      key_y0_(kKeyZero - 1),
      width_(cols + 2),
      height_(rows + 2),
      columns_(static_cast<std::size_t>(cols + 2) * static_cast<std::size_t>(rows + 2)) {
  keys_.setClampingThresMin(clamping_min_probability);
}

long long VoxelOccupancy::column_index(const octomap::OcTreeKey& key) const {
  const int x = static_cast<int>(key[0]) - key_x0_, y = static_cast<int>(key[1]) - key_y0_;
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return -1;
  return static_cast<long long>(y) * width_ + x;
}

VoxelOccupancy::Voxel& VoxelOccupancy::voxel(const octomap::OcTreeKey& key) {
  const long long index = column_index(key);
  if (index < 0) return outside_[packed(key)];
  Column& column = columns_[static_cast<std::size_t>(index)];
  const int z = key[2];
  if (column.voxels.empty()) {
    column.z0 = z;
    column.voxels.resize(1);
  } else if (z < column.z0) {
    column.voxels.insert(column.voxels.begin(), static_cast<std::size_t>(column.z0 - z), Voxel{});
    column.z0 = z;
  } else if (z >= column.z0 + static_cast<int>(column.voxels.size())) {
    column.voxels.resize(static_cast<std::size_t>(z - column.z0 + 1));
  }
  return column.voxels[static_cast<std::size_t>(z - column.z0)];
}

const VoxelOccupancy::Voxel* VoxelOccupancy::find(const octomap::OcTreeKey& key) const {
  const long long index = column_index(key);
  if (index < 0) {
    const auto it = outside_.find(packed(key));
    return it == outside_.end() || std::isnan(it->second.log_odds) ? nullptr : &it->second;
  }
  const Column& column = columns_[static_cast<std::size_t>(index)];
  const int at = static_cast<int>(key[2]) - column.z0;
  if (at < 0 || at >= static_cast<int>(column.voxels.size())) return nullptr;
  const Voxel& v = column.voxels[static_cast<std::size_t>(at)];
  return std::isnan(v.log_odds) ? nullptr : &v;
}

void VoxelOccupancy::update(Voxel& v, float change) {
  // OccupancyOcTreeBase::updateNode (early abort at a clamping threshold) and updateNodeLogOdds: a new leaf starts at
  // log-odds 0, the change is added in float, then clamped.
  if (std::isnan(v.log_odds)) {
    v.log_odds = 0.0f;
    ++leaves_;
  } else if ((change >= 0 && v.log_odds >= keys_.getClampingThresMaxLog()) ||
             (change <= 0 && v.log_odds <= keys_.getClampingThresMinLog())) {
    return;
  }
  v.log_odds += change;
  if (v.log_odds < keys_.getClampingThresMinLog())
    v.log_odds = keys_.getClampingThresMinLog();
  else if (v.log_odds > keys_.getClampingThresMaxLog())
    v.log_odds = keys_.getClampingThresMaxLog();
}

void VoxelOccupancy::insert(const octomap::Pointcloud& points, const octomap::point3d& origin) {
  ++scan_;
  hits_.clear();
  ends_.clear();
  // computeDiscreteUpdate: each end voxel once, in the order first met, its centre the ray's end; the end voxels are
  // the occupied set (the key of a voxel's centre is the voxel).
  for (std::size_t i = 0; i < points.size(); ++i) {
    const octomap::OcTreeKey key = keys_.coordToKey(points[i]);
    Voxel& v = voxel(key);
    if (v.hit_scan == scan_) continue;
    v.hit_scan = scan_;
    hits_.push_back(key);
    ends_.push_back(keys_.keyToCoord(key));
  }
  // computeUpdate: the voxels each ray crosses (its end excluded) are the free set, less the occupied ones. Each
  // voxel is updated once per scan, so the order of the updates does not matter (OctoMap walks its hash sets): a
  // crossed voxel is updated when first met, the occupied ones (all known by now) after.
  const float miss = keys_.getProbMissLog();
  for (const octomap::point3d& end : ends_) {
    if (!keys_.computeRayKeys(origin, end, ray_)) continue;
    for (const octomap::OcTreeKey& key : ray_) {
      Voxel& v = voxel(key);
      if (v.hit_scan == scan_ || v.miss_scan == scan_) continue;
      v.miss_scan = scan_;
      update(v, miss);
    }
  }
  for (const octomap::OcTreeKey& key : hits_) update(voxel(key), keys_.getProbHitLog());
}

bool VoxelOccupancy::occupied(const octomap::OcTreeKey& key) const {
  const Voxel* v = find(key);
  return v && v->log_odds >= keys_.getOccupancyThresLog();
}

bool VoxelOccupancy::free_at_or_below(const octomap::OcTreeKey& key, octomap::key_type max_z) const {
  const long long index = column_index(key);
  if (index < 0) return false;  // beyond the grid's columns: no cell's
  const Column& column = columns_[static_cast<std::size_t>(index)];
  const int last = std::min(static_cast<int>(max_z) - column.z0, static_cast<int>(column.voxels.size()) - 1);
  for (int at = 0; at <= last; ++at) {
    const float odds = column.voxels[static_cast<std::size_t>(at)].log_odds;
    if (!std::isnan(odds) && odds < keys_.getOccupancyThresLog()) return true;
  }
  return false;
}

bool VoxelOccupancy::log_odds(const octomap::OcTreeKey& key, float& value) const {
  const Voxel* v = find(key);
  if (!v) return false;
  value = v->log_odds;
  return true;
}

}  // namespace marsala::agent::executive::detail
