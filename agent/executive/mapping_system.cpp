#include "marsala/agent/executive/mapping_system.hpp"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "marsala/agent/executive/detail/voxel_occupancy.hpp"
#include "marsala/core/cpu_time.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala::agent::executive {
namespace {

std::string describe(const TerrainTile& t) {
  return fmt::format("tile ({}, {}) of {} x {} cells", t.tile_row, t.tile_col, t.rows, t.cols);
}

/// OctoMap keys are 16 bits around the origin: 32768 voxels each way.
constexpr double kOctreeHalfVoxels = 32768.0;
/// Voxels of one column a cell remembers hits in; more than a terrain column ever shows (ground, a wall's mixed hits).
constexpr std::size_t kVoxelsPerCell = 8;
/// Width of the band along each cell edge whose hits are left out: at least kEdgeBand cells, and at least
/// kEdgeBandNoise range-noise spreads at the hit's range (a wall's or a step's hits scatter that far across the
/// edge) [cells], [1]. A hit whose band would be wider than kMaxEdgeBand cells is too noisy to say which cell it
/// fell in and is left out (a depth camera's far hits) [cells].
constexpr double kEdgeBand = 0.1;
constexpr double kEdgeBandNoise = 3.0;
constexpr double kMaxEdgeBand = 0.3;
/// A hit this close to a cell edge lies on it, within the precision of a scan's float offsets [m]; a sensor whose
/// noise is smaller places it there only when the ray struck a face standing on the edge (docs/runtime.md#mapping).
constexpr double kOnEdgeM = 1e-5;
/// A face hit is credited to a cell only when no other cell's face lies within kFaceRivalNoise range-noise standard
/// deviations of it along the ray: a scan holds thousands of hits, and some lie past 3 of them [1].
constexpr double kFaceRivalNoise = 5.0;

/// The free part of a ray ends this many range-noise standard deviations before its hit: a hit measured long by
/// more is rare enough (3e-7 of the rays) that no overflight is set below a surface by one [1].
constexpr double kOverflightNoise = 5.0;

/// Calls visit(cell, z_m) for each cell whose column the horizontal path from `o` towards `end` crosses, up to
/// `end` or run_m [m] from `o`, whichever comes first, in order, with the ray's lowest height over the part of
/// the column it crossed [m] (a grid DDA; cells off the grid end the walk).
template <class Visit>
void cells_under_ray(const GridGeometry& g, Point3 o, Point3 end, double run_m, Visit&& visit) {
  const double dx = end.x - o.x, dy = end.y - o.y, dz = end.z - o.z, run = std::hypot(dx, dy);
  if (!(run > 0.0)) return;
  const double cs = g.cell_size_m, t_end = std::min(1.0, run_m / run);
  const double u = (o.x - g.xll_m) / cs, v = (o.y - g.yll_m) / cs;
  long long col = static_cast<long long>(std::floor(u)), south = static_cast<long long>(std::floor(v));
  constexpr double kNever = std::numeric_limits<double>::infinity();
  // The ray's parameter (0 at o, 1 at end) at the next x and y grid line it crosses, and between two such lines.
  const int step_col = dx > 0.0 ? 1 : -1, step_south = dy > 0.0 ? 1 : -1;
  double next_x = dx != 0.0 ? (dx > 0.0 ? col + 1 - u : u - col) * cs / std::abs(dx) : kNever;
  double next_y = dy != 0.0 ? (dy > 0.0 ? south + 1 - v : v - south) * cs / std::abs(dy) : kNever;
  const double every_x = dx != 0.0 ? cs / std::abs(dx) : kNever, every_y = dy != 0.0 ? cs / std::abs(dy) : kNever;
  double t = 0.0;
  while (t < t_end && col >= 0 && col < g.cols && south >= 0 && south < g.rows) {
    const double t_out = std::min({next_x, next_y, t_end});
    // A cell the ray only touches at a corner is not crossed.
    if (t_out > t)
      visit(CellIndex{g.rows - 1 - static_cast<int>(south), static_cast<int>(col)}, o.z + dz * (dz < 0.0 ? t_out : t));
    t = t_out;
    if (next_x < next_y)
      col += step_col, next_x += every_x;
    else
      south += step_south, next_y += every_y;
  }
}

/// Where a face hit may have struck: the faces of the cells the ray's horizontal path enters at the cell edges it
/// crosses near the hit along the ray (range noise moves a hit along its ray, before or past the face). kOne: one
/// crossing within within_m [m] of the hit, into `cell`, and no crossing into another cell within rival_m [m]
/// (>= within_m); kTwo: near a cell corner the ray enters two cells within rival_m, one across an x line and one
/// across a y line, and the hit may lie on either's face; kNone: no crossing within within_m (or a (nearly) vertical
/// ray) (docs/runtime.md#mapping).
struct FaceCell {
  enum Kind { kNone, kOne, kTwo } kind = kNone;
  CellIndex cell{-1, -1};
};
FaceCell face_cell(const GridGeometry& g, Point3 o, Point3 hit, double within_m, double rival_m) {
  const double dx = hit.x - o.x, dy = hit.y - o.y, run = std::hypot(dx, dy);
  if (!(run > 0.0)) return {};
  const double cs = g.cell_size_m, ux = dx / run, uy = dy / run;
  // The nearest grid line of each axis is that axis's only crossing within reach (lines of one axis lie at least a
  // cell apart along the ray; the reach is at most half a cell): its signed distance from the hit along the ray [m].
  struct Crossing {
    CellIndex cell;
    double distance_m;
  };
  std::optional<Crossing> near[2];
  const auto cross = [&](int axis, double along) {
    if (!(std::abs(along) <= rival_m)) return;
    const double past = along + 10.0 * kOnEdgeM;  // just past the crossing, in the cell the ray enters
    const std::optional<CellIndex> entered = g.cell_at({hit.x + past * ux, hit.y + past * uy});
    if (entered) near[axis] = Crossing{*entered, std::abs(along)};
  };
  if (std::abs(ux) > 1e-9) cross(0, (g.xll_m + std::round((hit.x - g.xll_m) / cs) * cs - hit.x) / ux);
  if (std::abs(uy) > 1e-9) cross(1, (g.yll_m + std::round((hit.y - g.yll_m) / cs) * cs - hit.y) / uy);
  if (near[0] && near[1] && near[0]->cell != near[1]->cell) return {FaceCell::kTwo, {-1, -1}};
  for (const std::optional<Crossing>& c : near)
    if (c && c->distance_m <= within_m) return {FaceCell::kOne, c->cell};
  return {};
}

/// Where a ray from `o` to `p` entered the column of `cell` (the cell holding p): the cell it crossed just before and
/// the ray's height at the crossing [m]; nullopt when the ray starts inside that column.
struct ColumnEntry {
  CellIndex from;
  double z_m;
};
std::optional<ColumnEntry> column_entry(const GridGeometry& g, Point3 o, Point3 p, CellIndex cell) {
  const Position c = g.cell_center(cell);
  const double half = 0.5 * g.cell_size_m, dx = p.x - o.x, dy = p.y - o.y;
  double t_enter = -std::numeric_limits<double>::infinity();
  if (dx != 0.0) t_enter = std::max(t_enter, std::min((c.x - half - o.x) / dx, (c.x + half - o.x) / dx));
  if (dy != 0.0) t_enter = std::max(t_enter, std::min((c.y - half - o.y) / dy, (c.y + half - o.y) / dy));
  if (!(t_enter > 0.0)) return std::nullopt;
  const double back = t_enter - 1e-6 * g.cell_size_m / std::hypot(dx, dy);
  const auto from = g.cell_at({o.x + back * dx, o.y + back * dy});
  if (!from || *from == cell) return std::nullopt;
  return ColumnEntry{*from, o.z + t_enter * (p.z - o.z)};
}

/// A point of the world frame [m] in the octree's frame: the grid's lower-left corner at x = y = 0, so voxel (i, j) is
/// the cell of column i, row rows - 1 - j (a voxel boundary on every cell boundary).
octomap::point3d tree_point(const GridGeometry& g, double x, double y, double z) {
  return octomap::point3d(static_cast<float>(x - g.xll_m), static_cast<float>(y - g.yll_m), static_cast<float>(z));
}

/// True when `hit` [m] lies within band_m [m] of an edge of its cell.
bool near_cell_edge(const GridGeometry& g, Point3 hit, double band_m) {
  const double cs = g.cell_size_m;
  const double u = (hit.x - g.xll_m) / cs, v = (hit.y - g.yll_m) / cs;
  const double fu = (u - std::floor(u)) * cs, fv = (v - std::floor(v)) * cs;
  return fu < band_m || fu > cs - band_m || fv < band_m || fv > cs - band_m;
}

}  // namespace

/// The octree, in a frame shifted by the grid's lower-left corner so that voxel columns are exactly the grid's cells,
/// and per cell the hits its voxels received: the octree says which voxels are occupied, the hits say where in the
/// highest one the surface lies (docs/runtime.md#mapping).
struct MappingSystem::Octree {
  struct VoxelHits {
    octomap::key_type key_z = 0;
    double estimate_m = 0.0;  ///< surface height in this voxel, from the latest scan that hit it [m]
    bool has_estimate = false;
    double scan_sum_m = 0.0;  ///< this scan's hits [m]
    int scan_count = 0;
    int hits_in_scan = 0;  ///< hits of the scan being integrated
  };

  // The terrain rises under construction: a voxel carved free many times must turn occupied at its first hit
  // (log-odds of a hit 0.85 > -log-odds of 0.4), not only after several scans as with OctoMap's default 0.12.
  explicit Octree(const GridGeometry& g) : tree(g.cell_size_m, g.rows, g.cols, 0.4) {}

  /// The hits of voxel key_z of cell `index` (row-major), made when new; a cell that has kVoxelsPerCell forgets its
  /// lowest one: the surface is the highest.
  VoxelHits& voxel(std::size_t index, octomap::key_type key_z) {
    std::vector<VoxelHits>& voxels = hits[index];
    auto it = std::find_if(voxels.begin(), voxels.end(), [&](const VoxelHits& v) { return v.key_z == key_z; });
    if (it != voxels.end()) return *it;
    if (voxels.size() == kVoxelsPerCell)
      voxels.erase(std::min_element(voxels.begin(), voxels.end(),
                                    [](const VoxelHits& a, const VoxelHits& b) { return a.key_z < b.key_z; }));
    voxels.push_back({key_z});
    return voxels.back();
  }

  /// This scan's hits replace each touched voxel's estimate: the surface changes as robots build, and a blend of old
  /// and new readings lags a deposit (a cell read half as raised as it is gets filled again, overshoots its MARS height
  /// and lifts its neighbours' bound: robots with scans built without end that way).
  void settle(std::vector<std::size_t> touched) {
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (std::size_t index : touched) {
      for (VoxelHits& v : hits[index]) {
        if (v.scan_count == 0) continue;
        v.estimate_m = v.scan_sum_m / v.scan_count;
        v.has_estimate = true;
        v.hits_in_scan = v.scan_count;
        v.scan_sum_m = 0.0;
        v.scan_count = 0;
      }
    }
  }

  /// The voxel that holds the surface of cell `index` (its column's key in `key`, whose z is used up); `hit` tells
  /// whether this scan hit the cell. A cell this scan hit: the highest voxel it hit (a ray grazing just above a
  /// surface inside its voxel carves that voxel free in the octree, so occupancy alone would lose freshly built tops);
  /// otherwise the highest occupied voxel of the column. Null when there is none.
  const VoxelHits* surface(std::size_t index, octomap::OcTreeKey& key, bool& hit) const {
    const std::vector<VoxelHits>& voxels = hits[index];
    // The cell's hits in this scan (hits_in_scan is set for the touched cells only, until the scan is integrated).
    int count = 0;
    for (const VoxelHits& v : voxels) count += v.hits_in_scan;
    hit = count > 0;
    // A voxel a wall's scattered hits reached holds few of the cell's hits: the surface's voxel holds at least a
    // fifth of them (and two), else the highest hit voxel is all there is.
    const int enough = std::max(2, (count + 4) / 5);
    const VoxelHits* top = nullptr;
    const VoxelHits* top_any = nullptr;
    for (const VoxelHits& v : voxels) {
      if (hit) {
        if (v.hits_in_scan > 0 && (!top_any || v.key_z > top_any->key_z)) top_any = &v;
        if (v.hits_in_scan >= enough && (!top || v.key_z > top->key_z)) top = &v;
        continue;
      }
      if (!v.has_estimate || (top && v.key_z <= top->key_z)) continue;
      key[2] = v.key_z;
      if (tree.occupied(key)) top = &v;
    }
    return top ? top : top_any;
  }

  detail::VoxelOccupancy tree;               ///< the octree's leaves (OctoMap's updates, held per grid column)
  std::vector<std::vector<VoxelHits>> hits;  ///< per cell (row-major)
};

/// One scan's hits binned into the octree's voxels: the points to insert, the cells with hits and their bounding rows
/// and columns (max_row < 0: none).
struct MappingSystem::ScanBatch {
  /// A hit on the face of a cell standing on a cell edge: the cell is at least that high [m].
  struct Face {
    CellIndex cell;
    double z_m;
  };
  octomap::Pointcloud cloud;
  std::vector<Face> faces;
  std::vector<std::size_t> touched;  ///< cells (row-major) with a voxel first hit in this scan
  int min_row;
  int max_row;
  int min_col;
  int max_col;
};

MappingSystem::MappingSystem(const GridGeometry& world, int tile_size, SensorSpec sensor)
    : heights_(world, 0.0), tile_size_(tile_size), sensor_(std::move(sensor)) {
  if (tile_size < 1) throw InvalidArgument(fmt::format("mapping system: tile size must be >= 1, got {}", tile_size));
  const std::string problem = sensor_problem(sensor_);
  if (!problem.empty()) throw InvalidArgument(fmt::format("mapping system: sensor {}", problem));
  if (sensor_.casts_rays() && std::max(world.rows, world.cols) >= kOctreeHalfVoxels)
    throw InvalidArgument(fmt::format("mapping system: a {} x {} grid is too large for the octree ({} cells a side)",
                                      world.rows, world.cols, kOctreeHalfVoxels));
  known_ = CellMask::Zero(world.rows, world.cols);
  assumed_ = CellMask::Zero(world.rows, world.cols);
  bound_ = CellMask::Zero(world.rows, world.cols);
  not_assumable_ = CellMask::Zero(world.rows, world.cols);
}

MappingSystem::~MappingSystem() = default;
MappingSystem::MappingSystem(MappingSystem&&) noexcept = default;
MappingSystem& MappingSystem::operator=(MappingSystem&&) noexcept = default;
MappingSystem::MappingSystem(const MappingSystem& other)
    : heights_(other.heights_),
      known_(other.known_),
      assumed_(other.assumed_),
      bound_(other.bound_),
      not_assumable_(other.not_assumable_),
      known_count_(other.known_count_),
      scans_(other.scans_),
      hit_scan_(other.hit_scan_),
      tile_size_(other.tile_size_),
      registration_(other.registration_),
      built_(other.built_),
      ceiling_(other.ceiling_),
      told_scan_(other.told_scan_),
      face_floor_(other.face_floor_),
      face_scan_(other.face_scan_),
      face_hit_scan_(other.face_hit_scan_),
      sensor_(other.sensor_),
      trajectory_(other.trajectory_),
      stood_(other.stood_),
      octree_(other.octree_ ? std::make_unique<Octree>(*other.octree_) : nullptr),
      last_scan_cost_(other.last_scan_cost_),
      overflight_range_m_(other.overflight_range_m_),
      overflight_(other.overflight_),
      overflight_cells_(other.overflight_cells_) {}
MappingSystem& MappingSystem::operator=(const MappingSystem& other) {
  if (this != &other) *this = MappingSystem(other);
  return *this;
}

void MappingSystem::integrate(const std::vector<TerrainTile>& tiles, Position pose) {
  for (const TerrainTile& tile : tiles) integrate_tile(tile);
  record_pose(pose);
}

std::string tile_problem(const TerrainTile& tile, const GridGeometry& world, int tile_size) {
  const long long row0 = static_cast<long long>(tile.tile_row) * tile_size;
  const long long col0 = static_cast<long long>(tile.tile_col) * tile_size;
  const bool placed = tile.tile_row >= 0 && tile.tile_col >= 0 && row0 < world.rows && col0 < world.cols;
  // A tile is tile_size x tile_size, cut short only by the grid edge.
  const bool sized = placed && tile.rows == std::min<long long>(tile_size, world.rows - row0) &&
                     tile.cols == std::min<long long>(tile_size, world.cols - col0);
  if (!sized)
    return fmt::format("{} does not fit the {} x {} grid in {}-cell tiles", describe(tile), world.rows, world.cols,
                       tile_size);
  if (tile.heights.size() != static_cast<std::size_t>(tile.rows) * static_cast<std::size_t>(tile.cols))
    return fmt::format("{} carries {} heights", describe(tile), tile.heights.size());
  for (double h : tile.heights)
    if (!std::isfinite(h) || std::abs(h) >= kMaxMagnitude)
      return fmt::format("{} has a non-finite or huge height", describe(tile));
  return {};
}

std::string scan_problem(const std::vector<ScanPoint>& points, const SensorSpec& sensor) {
  if (static_cast<long long>(points.size()) > sensor.ray_count())
    return fmt::format("a scan of {} points from a '{}' sensor of {} rays", points.size(), to_string(sensor.kind),
                       sensor.ray_count());
  const double reach = sensor.max_range_m + std::max(1.0, 6.0 * sensor.noise_sd_at(sensor.max_range_m));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ScanPoint& p = points[i];
    const double x = p.x_m, y = p.y_m, z = p.z_m;
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || std::sqrt(x * x + y * y + z * z) > reach)
      return fmt::format("scan point {} at ({}, {}, {}) m from the sensor is not finite or beyond its reach of {} m", i,
                         x, y, z, reach);
  }
  return {};
}

void MappingSystem::mark_known(int row, int col) {
  assumed_(row, col) = 0;
  bound_(row, col) = 0;
  if (known_(row, col) == 0) {
    known_(row, col) = 1;
    ++known_count_;
  }
}

void MappingSystem::integrate_tile(const TerrainTile& tile) {
  const std::string problem = tile_problem(tile, heights_.geometry(), tile_size_);
  if (!problem.empty()) throw InvalidArgument(fmt::format("sensor frame: {}", problem));
  const long long row0 = static_cast<long long>(tile.tile_row) * tile_size_;
  const long long col0 = static_cast<long long>(tile.tile_col) * tile_size_;
  for (int r = 0; r < tile.rows; ++r)
    for (int c = 0; c < tile.cols; ++c) {
      const int row = static_cast<int>(row0) + r + registration_.row,
                col = static_cast<int>(col0) + c + registration_.col;
      if (!heights_.contains({row, col})) continue;
      heights_(row, col) = tile.heights[static_cast<std::size_t>(r) * tile.cols + c];
      mark_known(row, col);
    }
}

void MappingSystem::integrate_scan(const std::vector<ScanPoint>& points, Point3 origin) {
  const std::string problem = scan_problem(points, sensor_);
  if (!problem.empty()) throw InvalidArgument(fmt::format("sensor frame: {}", problem));
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z) ||
      std::abs(origin.z) >= kMaxMagnitude)
    throw InvalidArgument(
        fmt::format("mapping system: sensor origin ({}, {}, {}) m is not finite", origin.x, origin.y, origin.z));
  const GridGeometry& g = heights_.geometry();
  ++scans_;
  if (hit_scan_.empty()) hit_scan_.assign(static_cast<std::size_t>(g.rows) * g.cols, 0);
  if (!octree_) {
    octree_ = std::make_unique<Octree>(g);
    octree_->hits.resize(static_cast<std::size_t>(g.size()));
  }
  const double began_ms = thread_cpu_ms();
  if (overflight_range_m_ > 0.0) record_overflight(points, origin);
  const ScanBatch batch = bin_hits(points, origin);
  // Rays carve free space up to each end voxel, which becomes more likely occupied (OctoMap's log-odds update).
  // Only leaves are ever read, so no inner node is kept (detail/voxel_occupancy.hpp).
  octree_->tree.insert(batch.cloud, tree_point(g, origin.x, origin.y, origin.z));
  const double inserted_ms = thread_cpu_ms();
  octree_->settle(batch.touched);
  if (batch.max_row >= 0) rederive_heights(batch);
  for (std::size_t index : batch.touched)
    for (Octree::VoxelHits& v : octree_->hits[index]) v.hits_in_scan = 0;
  // A face's hit bounds its cell from below for good (terrain only rises), as the robot's own construction does.
  for (const ScanBatch::Face& f : batch.faces) {
    const long long index = static_cast<long long>(f.cell.row) * g.cols + f.cell.col;
    if (ceiling_.count(index) > 0) continue;  // the height the world told holds (record_drop())
    double& least = face_floor_.try_emplace(index, f.z_m).first->second;
    if (f.z_m > least || face_scan_.count(index) == 0) face_scan_[index] = scans_;
    face_hit_scan_[index] = scans_;
    least = std::max(least, f.z_m);
    // A surface read at or above the face stays, and so does one read in an earlier scan only: the cell rose since
    // (terrain only rises), its top at least the face. Else the cell is a bound, no surface: never a deposition target.
    const bool read = known_(f.cell.row, f.cell.col) != 0 && assumed_(f.cell.row, f.cell.col) == 0;
    const bool surface = read && (heights_(f.cell) >= least || rose_since_read(f.cell));
    if (!surface || heights_(f.cell) < least) {
      const auto built = built_.find(index);
      heights_(f.cell) = built == built_.end() ? least : std::max(least, built->second);
    }
    mark_known(f.cell.row, f.cell.col);
    assumed_(f.cell.row, f.cell.col) = surface ? 0 : 1;
    bound_(f.cell.row, f.cell.col) = surface ? 0 : 1;
  }
  last_scan_cost_ = {inserted_ms - began_ms, thread_cpu_ms() - inserted_ms};
}

void MappingSystem::record_overflights(double range_m) {
  if (!(range_m >= 0.0) || !std::isfinite(range_m))
    throw InvalidArgument(fmt::format("mapping system: overflights need a range finite and >= 0 m, got {}", range_m));
  overflight_range_m_ = range_m;
}

void MappingSystem::record_overflight(const std::vector<ScanPoint>& points, Point3 origin) {
  const GridGeometry& g = heights_.geometry();
  if (overflight_.rows() == 0) overflight_ = Heightmap(g, kUnderNoRay);
  // Only the latest scan's rays say where the terrain is now: it rises under construction.
  double* cells = overflight_.data();
  for (const std::size_t index : overflight_cells_) cells[index] = kUnderNoRay;
  overflight_cells_.clear();
  for (const ScanPoint& p : points) {
    const double range = std::sqrt(double{p.x_m} * p.x_m + double{p.y_m} * p.y_m + double{p.z_m} * p.z_m);
    const double free = range - kOverflightNoise * sensor_.noise_sd_at(range);
    if (!(free > 0.0)) continue;
    const double f = free / range;
    const Point3 end{origin.x + f * p.x_m, origin.y + f * p.y_m, origin.z + f * p.z_m};
    cells_under_ray(g, origin, end, overflight_range_m_, [&](CellIndex cell, double z_m) {
      double& lowest = cells[static_cast<std::size_t>(cell.row) * g.cols + cell.col];
      if (!(z_m < lowest)) return;
      if (lowest == kUnderNoRay) overflight_cells_.push_back(static_cast<std::size_t>(cell.row) * g.cols + cell.col);
      lowest = z_m;
    });
  }
}

MappingSystem::ScanBatch MappingSystem::bin_hits(const std::vector<ScanPoint>& points, Point3 origin) {
  const GridGeometry& g = heights_.geometry();
  const double cs = g.cell_size_m;
  const double z_limit = 0.99 * kOctreeHalfVoxels * cs;
  ScanBatch batch{{}, {}, {}, g.rows, -1, g.cols, -1};
  batch.cloud.reserve(points.size());
  // A hit on a wall between two cells lies on their common edge, and range noise puts it on either side: in the
  // lower cell's column it would read as a surface high above that cell. Hits within kEdgeBand of a cell edge are
  // therefore left out; the cell's interior hits say where its surface is (docs/runtime.md#mapping).
  for (const ScanPoint& p : points) {
    const Point3 hit{origin.x + p.x_m, origin.y + p.y_m, origin.z + p.z_m};
    const std::optional<CellIndex> cell = g.cell_at({hit.x, hit.y});
    if (!cell || std::abs(hit.z) >= z_limit) continue;
    const double range = std::sqrt(double{p.x_m} * p.x_m + double{p.y_m} * p.y_m + double{p.z_m} * p.z_m);
    const double spread = kEdgeBandNoise * sensor_.noise_sd_at(range);  // where noise may carry the hit [m]
    // A face hit (docs/runtime.md#mapping): a noise-free hit on a cell edge, or a hit whose ray did not descend (a
    // top face is only ever hit from above): it struck the face of the cell the ray enters at the edge, that cell is
    // at least as high. Placed by the band below, a wall's face hits would be left out or land in the column before
    // it, and a wall seen only from the side (above the sensor) would never be mapped.
    const bool exact = spread < kOnEdgeM, rising = hit.z >= origin.z;
    if (exact || rising) {
      const FaceCell face = exact ? face_cell(g, origin, hit, kOnEdgeM, kOnEdgeM)
                                  : face_cell(g, origin, hit, spread, kFaceRivalNoise / kEdgeBandNoise * spread);
      // Farther from every edge than noise carries a hit: an outlier. Within reach of two cells' faces at a corner:
      // either may be the one struck, and crediting the other raised a pit's floor to its neighbour's face.
      if ((face.kind == FaceCell::kNone && rising) || face.kind == FaceCell::kTwo) continue;
      if (face.kind == FaceCell::kOne && spread <= kMaxEdgeBand * cs + 1e-12) {
        const Position in = g.cell_center(face.cell);
        const Position at{std::clamp(hit.x, in.x - 0.49 * cs, in.x + 0.49 * cs),
                          std::clamp(hit.y, in.y - 0.49 * cs, in.y + 0.49 * cs)};
        batch.cloud.push_back(tree_point(g, at.x, at.y, hit.z));
        batch.faces.push_back({face.cell, hit.z});
        continue;
      }
    }
    const double band = std::max(kEdgeBand * cs, spread);
    if (band > kMaxEdgeBand * cs + 1e-12 || near_cell_edge(g, hit, band) || behind_edge(origin, hit, *cell, spread))
      continue;
    const octomap::point3d end = tree_point(g, hit.x, hit.y, hit.z);
    octomap::OcTreeKey key;
    if (!octree_->tree.key_of(end, key)) continue;
    batch.cloud.push_back(end);
    const std::size_t index = static_cast<std::size_t>(cell->row) * g.cols + cell->col;
    Octree::VoxelHits& voxel = octree_->voxel(index, key[2]);
    if (voxel.scan_count == 0) batch.touched.push_back(index);
    batch.min_row = std::min(batch.min_row, cell->row);
    batch.max_row = std::max(batch.max_row, cell->row);
    batch.min_col = std::min(batch.min_col, cell->col);
    batch.max_col = std::max(batch.max_col, cell->col);
    voxel.scan_sum_m += hit.z;
    ++voxel.scan_count;
  }
  return batch;
}

bool MappingSystem::behind_edge(Point3 origin, Point3 hit, CellIndex cell, double spread) const {
  // A hit just past a higher cell's edge, from a ray that crossed into this column at or below that cell's surface, is
  // that edge's hit pushed over by range noise, not this cell's surface: in the shadow behind an edge nothing else
  // lands, and a few such hits over many scans would raise the cell to the edge's height. Judged on the map before
  // this scan; a cell that really rose to its neighbour's height reads so from a steeper ray.
  const auto entry = column_entry(heights_.geometry(), origin, hit, cell);
  if (!entry || known_(entry->from.row, entry->from.col) == 0) return false;
  const double edge = heights_(entry->from);
  const bool lower = known_(cell.row, cell.col) == 0 || heights_(cell) < edge - spread;
  return lower && entry->z_m <= edge + spread;
}

void MappingSystem::rederive_heights(const ScanBatch& batch) {
  // Heights of every cell the scan reached (carving may have freed a voxel of a cell it did not hit). Never below what
  // the robot itself built there (record_built).
  const GridGeometry& g = heights_.geometry();
  for (int row = batch.min_row; row <= batch.max_row; ++row)
    for (int col = batch.min_col; col <= batch.max_col; ++col) {
      const std::size_t index = static_cast<std::size_t>(row) * g.cols + col;
      if (octree_->hits[index].empty()) continue;
      const Position centre = g.cell_center({row, col});
      octomap::OcTreeKey key;
      if (!octree_->tree.key_of(tree_point(g, centre.x, centre.y, 0.0), key)) continue;
      bool hit = false;
      const Octree::VoxelHits* top = octree_->surface(index, key, hit);
      if (hit) hit_scan_[index] = scans_;
      if (!top) continue;  // every voxel it had was carved free since: keep what the map said
      const long long key_rc = static_cast<long long>(row) * g.cols + col;
      const auto built = built_.find(key_rc);
      heights_(row, col) = built == built_.end() ? top->estimate_m : std::max(top->estimate_m, built->second);
      mark_known(row, col);
      // A face above the reading: the reading was the face's, not the cell's top (a bound, no surface).
      const auto face = face_floor_.find(key_rc);
      if (face != face_floor_.end() && face->second > top->estimate_m && rose_since_read({row, col})) {
        heights_(row, col) = std::max(heights_(row, col), face->second);  // a stale reading: the face's bound is a top
      } else if (face != face_floor_.end() && face->second > top->estimate_m) {
        heights_(row, col) = std::max(heights_(row, col), face->second);
        assumed_(row, col) = 1;
        bound_(row, col) = 1;
      }
      // The height the world told holds against later scans (record_drop()).
      const auto ceiling = ceiling_.find(key_rc);
      if (ceiling == ceiling_.end()) continue;
      heights_(row, col) = std::min(heights_(row, col), ceiling->second);
      assumed_(row, col) = 0;
      bound_(row, col) = 0;
    }
}

void MappingSystem::record_drop(CellIndex low, double low_m, CellIndex high, double high_m) {
  if (!heights_.contains(low) || !std::isfinite(low_m) || std::abs(low_m) >= kMaxMagnitude) return;
  const long long index = static_cast<long long>(low.row) * heights_.cols() + low.col;
  ceiling_[index] = low_m;
  told_scan_[index] = scans_;
  // What the map held there (its reading, the floor of its own construction, a face's bound) was not the surface.
  heights_(low) = low_m;
  mark_known(low.row, low.col);
  if (const auto built = built_.find(index); built != built_.end()) built->second = std::min(built->second, low_m);
  if (const auto face = face_floor_.find(index); face != face_floor_.end()) face->second = std::min(face->second, low_m);
  assumed_(low.row, low.col) = 0;
  bound_(low.row, low.col) = 0;
  if (std::isfinite(high_m)) record_floor(high, high_m);
}

int MappingSystem::told_scan(CellIndex cell) const {
  if (!heights_.contains(cell)) return 0;
  const auto told = told_scan_.find(static_cast<long long>(cell.row) * heights_.cols() + cell.col);
  return told == told_scan_.end() ? 0 : told->second;
}

bool MappingSystem::hit_within(CellIndex cell, int scans) const {
  if (hit_scan_.empty() || !heights_.contains(cell)) return false;
  const std::size_t index = static_cast<std::size_t>(cell.row) * heights_.cols() + cell.col;
  if (hit_scan_[index] > 0 && scans_ - hit_scan_[index] < scans) return true;
  // A bound's surface is never hit; its faces are what a scan reads of it (docs/runtime.md#mapping, pits).
  if (bound_(cell.row, cell.col) == 0) return false;
  const auto face = face_hit_scan_.find(static_cast<long long>(index));
  return face != face_hit_scan_.end() && scans_ - face->second < scans;
}

int MappingSystem::last_hit_scan(CellIndex cell) const {
  if (hit_scan_.empty() || !heights_.contains(cell)) return 0;
  return hit_scan_[static_cast<std::size_t>(cell.row) * heights_.cols() + cell.col];
}

void MappingSystem::record_built(CellIndex cell, double rise_m) {
  if (!heights_.contains(cell) || !std::isfinite(rise_m) || !(rise_m > 0.0)) return;
  // The robot's own construction changes every ball it lands in: what it stood on there is no longer a fact.
  if (!stood_.balls.empty())
    for (const CellIndex o : stood_.ball) {
      const CellIndex centre{cell.row - o.row, cell.col - o.col};
      if (heights_.contains(centre))
        stood_.balls.erase(static_cast<long long>(centre.row) * heights_.cols() + centre.col);
    }
  const long long index = static_cast<long long>(cell.row) * heights_.cols() + cell.col;
  // Under the latest scan's rays the cell stood below them; it stands at most that plus the rise now.
  if (overflown(cell)) overflight_(cell) += rise_m;
  // A cell whose surface no sensor read has no height to add to.
  const bool surface_read =
      known_(cell.row, cell.col) != 0 &&
      (assumed_(cell.row, cell.col) == 0 || face_floor_.count(index) > 0 || built_.count(index) > 0);
  if (!surface_read) return;
  if (const auto ceiling = ceiling_.find(index); ceiling != ceiling_.end()) ceiling->second += rise_m;
  keep_floor(cell, heights_(cell) + rise_m);
}

void MappingSystem::record_floor(CellIndex cell, double floor_m) {
  if (!is_known(cell) || !std::isfinite(floor_m) || std::abs(floor_m) >= kMaxMagnitude) return;
  const long long index = static_cast<long long>(cell.row) * heights_.cols() + cell.col;
  if (const auto ceiling = ceiling_.find(index); ceiling != ceiling_.end() && ceiling->second < floor_m)
    ceiling_.erase(ceiling);
  keep_floor(cell, floor_m);
  assumed_(cell.row, cell.col) = 0;
  bound_(cell.row, cell.col) = 0;
}

void MappingSystem::keep_floor(CellIndex cell, double floor_m) {
  const long long index = static_cast<long long>(cell.row) * heights_.cols() + cell.col;
  double& built = built_.try_emplace(index, floor_m).first->second;
  built = std::max(built, floor_m);
  heights_(cell) = std::max(heights_(cell), built);
}

bool MappingSystem::rose_since_read(CellIndex cell) const {
  const long long index = static_cast<long long>(cell.row) * heights_.cols() + cell.col;
  const auto face = face_scan_.find(index);
  const int read = last_hit_scan(cell);
  return face != face_scan_.end() && read > 0 && read < face->second;
}

bool MappingSystem::carved_below(CellIndex cell, double z_m) const {
  if (!octree_ || !std::isfinite(z_m)) return false;
  const GridGeometry& g = heights_.geometry();
  const Position centre = g.cell_center(cell);
  octomap::OcTreeKey key;
  if (!octree_->tree.key_of(tree_point(g, centre.x, centre.y, z_m), key)) return false;
  // The voxel holding z_m reaches above it: only the voxels under it lie wholly below z_m.
  return key[2] > 0 && octree_->tree.free_at_or_below(key, static_cast<octomap::key_type>(key[2] - 1));
}

bool MappingSystem::was_assumed_ground(CellIndex cell) const {
  const std::size_t index = static_cast<std::size_t>(cell.row) * heights_.cols() + cell.col;
  return assumed_(cell.row, cell.col) != 0 && face_floor_.count(static_cast<long long>(index)) == 0 &&
         (hit_scan_.empty() || hit_scan_[index] == 0);
}

void MappingSystem::forget(CellIndex cell) {
  if (known_(cell.row, cell.col) != 0) --known_count_;
  known_(cell.row, cell.col) = 0;
  assumed_(cell.row, cell.col) = 0;
  bound_(cell.row, cell.col) = 0;
  not_assumable_(cell.row, cell.col) = 1;
  heights_(cell) = 0.0;
}

void MappingSystem::forget_assumed_ground(CellIndex cell, double radius_m) {
  if (!heights_.contains(cell) || !(radius_m >= 0.0) || !std::isfinite(radius_m)) return;
  const GridGeometry& g = heights_.geometry();
  const double radius_cells = radius_m / g.cell_size_m;
  const int reach = static_cast<int>(std::ceil(radius_cells));
  std::vector<CellIndex> guessed;
  for (int row = std::max(0, cell.row - reach); row <= std::min(g.rows - 1, cell.row + reach); ++row)
    for (int col = std::max(0, cell.col - reach); col <= std::min(g.cols - 1, cell.col + reach); ++col) {
      const double dr = row - cell.row, dc = col - cell.col;
      if (dr * dr + dc * dc <= radius_cells * radius_cells + 1e-9 && was_assumed_ground({row, col}))
        guessed.push_back({row, col});
    }
  forget_along_edge(guessed, radius_cells);
  for (const CellIndex c : guessed) forget(c);
}

void MappingSystem::forget_along_edge(const std::vector<CellIndex>& seeds, double radius_cells) {
  if (trajectory_.empty()) return;  // no body stood anywhere: nothing says which side the wrong guess lies on
  // The nearest cell the robot stood on [cells^2] and the offset from it [cells].
  struct Side {
    double distance2;
    int dr, dc;
  };
  const auto side_of = [this](CellIndex c) {
    Side best{std::numeric_limits<double>::infinity(), 0, 0};
    for (const CellIndex t : trajectory_) {
      const int dr = c.row - t.row, dc = c.col - t.col;
      const double d2 = static_cast<double>(dr) * dr + static_cast<double>(dc) * dc;
      if (d2 < best.distance2) best = {d2, dr, dc};
    }
    return best;
  };
  const double vouched2 = radius_cells * radius_cells + 1e-9;  // in the body's ball where it stood: the world's check
  const GridGeometry& g = heights_.geometry();
  CellMask seen(g.rows, g.cols);
  seen.setZero();
  // From each guessed cell of the refused ball that no ball the robot stood in covered, along the connected guessed
  // cells no such ball covered either, on the same side of the robot's path (docs/runtime.md#mapping).
  std::vector<std::pair<CellIndex, Side>> open;
  for (const CellIndex s : seeds) {
    const Side side = side_of(s);
    if (side.distance2 > vouched2 && seen(s.row, s.col) == 0) open.push_back({s, side}), seen(s.row, s.col) = 1;
  }
  std::vector<CellIndex> edge;
  while (!open.empty()) {
    const auto [c, seed] = open.back();
    open.pop_back();
    edge.push_back(c);
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const CellIndex n{c.row + dr, c.col + dc};
        if (!heights_.contains(n) || seen(n.row, n.col) != 0 || !was_assumed_ground(n)) continue;
        const Side side = side_of(n);
        if (side.distance2 <= vouched2 || side.dr * seed.dr + side.dc * seed.dc <= 0) continue;
        seen(n.row, n.col) = 1;
        open.push_back({n, seed});
      }
  }
  for (const CellIndex c : edge) forget(c);
}

void MappingSystem::assume_ground(Position pose, double ground_z_m, double radius_m, double below_m) {
  if (!std::isfinite(ground_z_m) || std::abs(ground_z_m) >= kMaxMagnitude || !(radius_m >= 0.0) || !(below_m >= 0.0))
    throw InvalidArgument(
        fmt::format("mapping system: ground {} m within {} m, {} m below it, is not a finite height, radius and depth",
                    ground_z_m, radius_m, below_m));
  const std::optional<CellIndex> centre =
      std::isfinite(pose.x) && std::isfinite(pose.y) ? heights_.cell_at(pose) : std::nullopt;
  if (!centre) throw InvalidArgument(fmt::format("mapping system: pose {} is off the grid", pose));
  const GridGeometry& g = heights_.geometry();
  // The body's ball around the cell it stands on, with the project's tie tolerance (ARCHITECTURE.md, grid conventions).
  const double radius_cells = radius_m / g.cell_size_m;
  const int reach = static_cast<int>(std::ceil(radius_cells));
  for (int row = std::max(0, centre->row - reach); row <= std::min(g.rows - 1, centre->row + reach); ++row)
    for (int col = std::max(0, centre->col - reach); col <= std::min(g.cols - 1, centre->col + reach); ++col) {
      const double dr = row - centre->row, dc = col - centre->col;
      if (dr * dr + dc * dc > radius_cells * radius_cells + 1e-9) continue;
      if (known_(row, col) != 0) {
        if (was_assumed_ground({row, col}) && carved_below({row, col}, heights_(row, col) - below_m))
          forget({row, col});
        continue;
      }
      // A ray went down past where this ground would be: the cell lies lower than the robot stands
      // (docs/runtime.md#mapping).
      if (not_assumable_(row, col) != 0 || carved_below({row, col}, ground_z_m - below_m)) continue;
      heights_(row, col) = ground_z_m;
      mark_known(row, col);
      assumed_(row, col) = 1;
    }
}

std::size_t MappingSystem::octree_leaves() const { return octree_ ? octree_->tree.leaves() : 0; }

void MappingSystem::keep_stood_cells(double radius_cells, double margin_m) {
  if (!(radius_cells >= 0.0) || !std::isfinite(radius_cells) || !(margin_m >= 0.0) || !std::isfinite(margin_m))
    throw InvalidArgument(fmt::format("mapping system: cells stood on need a ball radius ({} cells) and a margin ({} m) "
                                      "finite and >= 0",
                                      radius_cells, margin_m));
  stood_ = {disc_offsets(radius_cells), margin_m, {}};
}

void MappingSystem::record_stood(Position pose) {
  const auto cell = std::isfinite(pose.x) && std::isfinite(pose.y) ? heights_.cell_at(pose) : std::nullopt;
  if (!cell || stood_.ball.empty()) return;
  std::vector<double> ball;
  ball.reserve(stood_.ball.size());
  for (const CellIndex o : stood_.ball) {
    const CellIndex b{cell->row + o.row, cell->col + o.col};
    ball.push_back(heights_.contains(b) && known_(b.row, b.col) != 0 ? heights_(b)
                                                                     : std::numeric_limits<double>::quiet_NaN());
  }
  stood_.balls[static_cast<long long>(cell->row) * heights_.cols() + cell->col] = std::move(ball);
}

void MappingSystem::record_pose(Position pose) {
  const auto cell = std::isfinite(pose.x) && std::isfinite(pose.y) ? heights_.cell_at(pose) : std::nullopt;
  if (!cell) throw InvalidArgument(fmt::format("mapping system: pose {} is off the grid", pose));
  if (trajectory_.empty() || trajectory_.back() != *cell) trajectory_.push_back(*cell);
}

}  // namespace marsala::agent::executive
