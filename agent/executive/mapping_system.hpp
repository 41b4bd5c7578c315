#pragma once
// Mapping system (paper §III, executive layer): the agent's own map of the world, built only from its sensor frames,
// and its trajectory. A ground-truth sensor's tiles are written as they are; a laser's or rgbd camera's scans go into
// the robot's own OctoMap occupancy octree (voxels of the grid's cell size, aligned with its cells), from which the
// heightmap of the deliberative layer is derived (OctoMap -> GridMap, docs/runtime.md#mapping). The agent never sees
// the global terrain: a cell it has not sensed stays unknown. OctoMap stays inside mapping_system.cpp.

#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "marsala/agent/deliberative/known_map.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/ray_caster.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/sensor_spec.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// Empty when `tile` fits the world grid cut in tile_size-cell tiles (its place, its size, as many heights as cells,
/// each finite and below kMaxMagnitude); otherwise the problem, naming the tile.
std::string tile_problem(const TerrainTile& tile, const GridGeometry& world, int tile_size);

/// Empty when `points` can be a scan of `sensor`: at most its ray count, each offset finite and no farther than
/// its max range plus 6 noise standard deviations (and 1 m); otherwise the problem, naming the first bad point.
std::string scan_problem(const std::vector<ScanPoint>& points, const SensorSpec& sensor);

/// The sensor origin the agent believes [m]: its believed position, the terrain height under it, plus the mount.
inline Point3 believed_sensor_origin(Position pose, double ground_z_m, const SensorSpec& sensor) {
  return {pose.x, pose.y, ground_z_m + sensor.mount_height_m};
}

/// The agent's map: heights [m] of the world grid with a known-mask, and the cells it stood on.
class MappingSystem {
 public:
  /// An empty map of the world grid cut in tile_size x tile_size tiles, for a robot sensing with `sensor`; throws
  /// InvalidArgument on a bad geometry, tile_size < 1, or a grid too large for the octree (32768 cells a side).
  MappingSystem(const GridGeometry& world, int tile_size, SensorSpec sensor = {});
  ~MappingSystem();
  MappingSystem(const MappingSystem& other);
  MappingSystem& operator=(const MappingSystem& other);
  MappingSystem(MappingSystem&&) noexcept;
  MappingSystem& operator=(MappingSystem&&) noexcept;

  /// Writes one sensing's tiles (heights copied bit for bit) and records the pose it was taken from [m]; throws
  /// InvalidArgument when a tile does not fit the grid or the pose is off the grid (a broken contract by the sender).
  void integrate(const std::vector<TerrainTile>& tiles, Position pose);
  /// Writes one tile; throws InvalidArgument naming the tile when its place, size or heights are inconsistent.
  /// Each cell goes to its world index moved by the registration offset; cells moved off the grid are dropped.
  void integrate_tile(const TerrainTile& tile);
  /// Where the robot believes the terrain it senses lies: tiles integrated from now on write world cell (r, c) at
  /// (r + offset.row, c + offset.col). A robot with localisation error registers what it senses at its believed pose
  /// (docs/runtime.md#localisation-error); (0, 0), the default, is the world's registration.
  void set_registration(CellIndex offset) { registration_ = offset; }
  /// Inserts one scan into the octree, rays from `sensor_origin` (where the agent believes its sensor was, [m]) to
  /// each point (origin + offset): the end voxel is marked occupied, the voxels the ray crosses free. Then re-derives
  /// the heights of the cells around (docs/runtime.md#mapping). Points off the grid are left out. Throws
  /// InvalidArgument when scan_problem() finds one or the origin is not finite.
  void integrate_scan(const std::vector<ScanPoint>& points, Point3 sensor_origin);
  /// The ground under the robot's body: every still unknown cell within radius_m of the cell under `pose` (centre to
  /// centre) becomes known at `ground_z_m`, the height under the robot's centre (it stands there; a scan sees no nearer
  /// than its minimum range and the camera nothing behind it), unless a scan's ray crossed its column lower than
  /// below_m under that height and left it free: that cell lies lower (a drop's shadow, a pit) and stays unknown; and a
  /// cell of the disc known only as such assumed ground becomes unknown again once a ray went below_m under its
  /// assumed height, and is never assumed again (nor a cell forget_assumed_ground() forgot). A later scan's hits
  /// replace it. [m]
  void assume_ground(Position pose, double ground_z_m, double radius_m,
                     double below_m = std::numeric_limits<double>::infinity());
  /// The world refused a motion to `cell` (world index) as not occupiable: the cells within radius_m of it (centre to
  /// centre) known only as assumed ground (never hit by a scan, no face bound) are what the map guessed there, so they
  /// become unknown again (docs/runtime.md#refused-requests); and so do the cells known only as assumed ground that are
  /// 8-connected to those of them outside every ball of radius_m around a cell the robot stood on (trajectory()),
  /// through such cells on the same side of its path (offset from the nearest cell stood on, dot product > 0): the
  /// whole edge it guessed wrong along its path, not one ball of it. Off-grid cells are ignored. [m]
  void forget_assumed_ground(CellIndex cell, double radius_m);
  /// The world refused a motion because, in the body ball it asked for, cell `low` at low_m lies too far below cell
  /// `high` at high_m (world indices as the map registers them) [m]: what the body found there. `low` stands at low_m
  /// now: a pit read at its rim's height, which no ray corrects (a camera sees no narrow pit's floor,
  /// docs/runtime.md#refused-requests), gets its height and a ceiling there that later scans do not lift (an outlier
  /// hit short of the rim's face keeps landing in it); the ceiling rises with the robot's own construction there
  /// (record_built()) and goes when the world names the cell higher (record_floor()). `high` stands at least at high_m
  /// (record_floor()). Off-grid cells and heights that are not finite are ignored.
  void record_drop(CellIndex low, double low_m, CellIndex high, double high_m);
  /// The world says `cell` (world index, as the map registers it) stands at least floor_m [m] now (a deposition it
  /// refused for the deposit bound named the height it would have left: that less the rise asked for). Kept as the
  /// robot's own construction is (record_built()): the cell is at least that high from now on, whatever a stale
  /// reading says. Unknown or off-grid cells and floors that are not finite are ignored.
  void record_floor(CellIndex cell, double floor_m);
  /// The robot's own construction: the world accepted its request to raise `cell` (world index, as the map registers
  /// it) by rise_m [m]. Terrain only ever rises (depositions add material), so the cell is at least its map height
  /// plus rise_m from now on, whatever a later scan reads there: a scan may not see the top of what the robot just
  /// built beside it (a column above the sensor, its faces left out as wall hits) and would otherwise keep the old
  /// height, and the robot would fill the same cell again without end. Ground-truth tiles are exact and replace it.
  /// A cell without a surface reading (unknown, or known only as ground assumed under the body) gets no such floor: its
  /// height is not known to add to.
  /// Off-grid cells and rises that are not finite and > 0 are ignored.
  void record_built(CellIndex cell, double rise_m);
  /// Appends the cell under `pose` [m] to the trajectory (consecutive repeats are kept once); throws
  /// InvalidArgument when the pose is off the grid or not finite.
  void record_pose(Position pose);
  /// From now on record_stood() remembers the cells stood on with their body balls (radius_cells = delta / (2 cs)),
  /// each kept while every cell of its ball reads within margin_m of then. Throws InvalidArgument unless both are
  /// finite and >= 0.
  void keep_stood_cells(double radius_cells, double margin_m);
  /// The robot stands on the cell under `pose` [m]: the world put it there, so that cell was occupiable for its body,
  /// whatever this map's readings of its ball say. Remembers the ball as the map reads it now; known_map().stood
  /// holds it while its cells read within the margin of that (LocalMapSynthesizer: occupiable on a scanned map), until
  /// the robot's own construction lands in the ball (record_built()). Nothing before keep_stood_cells(); off-grid or
  /// non-finite poses are ignored.
  void record_stood(Position pose);

  /// From now on each scan also records, for every cell the free part of a ray crosses within range_m [m]
  /// (horizontally) of the sensor, the lowest height a ray of that scan crossed the cell's column at: the ray struck
  /// nothing there, so the cell's top lies below it (overflight(); docs/runtime.md#mapping, "Under the rays"). The free
  /// part of a ray ends kOverflightNoise range-noise spreads before its hit, whether or not the hit itself could be
  /// placed in a cell (a depth camera's far hits cannot). 0 (the default): nothing recorded. Throws InvalidArgument
  /// unless finite and >= 0.
  void record_overflights(double range_m);
  /// Per cell, the lowest height [m] a ray of the latest scan crossed its column at without striking it, raised by the
  /// robot's own construction there since (record_built()); +inf where no such ray passed (and without
  /// record_overflights()). The world grid's size once a scan was recorded, else empty.
  const Heightmap& overflight() const { return overflight_; }
  /// True when a ray of the latest scan crossed the cell's column without striking it (overflight() is finite there).
  bool overflown(CellIndex cell) const {
    return overflight_.rows() > 0 && overflight_.contains(cell) && overflight_(cell) < kUnderNoRay;
  }

  /// The map: known cells hold the sensed heights [m], unknown cells 0.
  const Heightmap& heights() const { return heights_; }
  /// 1 where the cell has been sensed at least once.
  const CellMask& known() const { return known_; }
  bool is_known(CellIndex cell) const { return heights_.contains(cell) && known_(cell.row, cell.col) != 0; }
  /// 1 where the cell's height is no surface a sensor read (never a deposition target): ground assume_ground() put
  /// under the body, or a lower bound from a face seen from below (its top above every ray that reached it).
  const CellMask& assumed() const { return assumed_; }
  /// 1 where the cell's height is a lower bound from faces seen from below, no surface read (a subset of assumed()).
  const CellMask& bound() const { return bound_; }
  /// Number of known cells.
  long long known_cells() const { return known_count_; }
  /// Scans integrated so far.
  int scans() const { return scans_; }
  /// True when one of the last `scans` scans hit the cell (its surface, or a face of a bound(): not only rays through
  /// its column): what it says there is current. Others may have built there since an older scan
  /// (docs/runtime.md#mapping).
  bool hit_within(CellIndex cell, int scans) const;
  /// The scan (1, 2, ...) that last hit the cell's surface, 0 when none did or the cell is off the grid.
  int last_hit_scan(CellIndex cell) const;
  /// The scan count when the world last told this cell's height (record_drop()), 0 when never: as recent a reading
  /// as a hit of that scan.
  int told_scan(CellIndex cell) const;
  /// Cells stood on, oldest first, consecutive repeats removed (global indices).
  const std::vector<CellIndex>& trajectory() const { return trajectory_; }
  /// The world grid.
  const GridGeometry& geometry() const { return heights_.geometry(); }
  /// This map as the deliberative layer reads it (the local map synthesizer); valid while this map lives, unchanged.
  deliberative::KnownMap known_map() const {
    return {heights_,
            known_,
            assumed_,
            bound_,
            trajectory_,
            sensor_.casts_rays(),
            stood_.balls.empty() ? nullptr : &stood_,
            overflight_.rows() > 0 ? &overflight_ : nullptr};
  }
  int tile_size() const { return tile_size_; }
  const SensorSpec& sensor() const { return sensor_; }
  /// What the last integrate_scan() cost [ms, CPU time of this thread]: inserting its hits into the octree (binning
  /// included), and deriving the heights (the cells it reached, its faces). For benchmarks (bench/sensing_bench).
  struct ScanCost {
    double insertion_ms = 0.0;
    double heights_ms = 0.0;
  };
  const ScanCost& last_scan_cost() const { return last_scan_cost_; }
  /// Leaf voxels of the octree, 0 before the first scan (for benchmarks and tests).
  std::size_t octree_leaves() const;

 private:
  struct Octree;                      // OctoMap's tree and the hits per cell, in mapping_system.cpp
  struct ScanBatch;                   // one scan's hits binned into the octree's voxels, in mapping_system.cpp
  void mark_known(int row, int col);  // observed by a sensor
  // integrate_scan()'s steps: bin the hits a scan can place, judge a hit in an edge's shadow, re-derive the heights.
  ScanBatch bin_hits(const std::vector<ScanPoint>& points, Point3 origin);
  bool behind_edge(Point3 origin, Point3 hit, CellIndex cell, double spread_m) const;
  bool carved_below(CellIndex cell, double z_m) const;  // a scan's ray left a voxel of its column free under z_m
  bool was_assumed_ground(CellIndex cell) const;        // known only from assume_ground(): never hit, no face
  bool rose_since_read(CellIndex cell) const;  // its surface was last read before a scan that raised its face floor
  void forget(CellIndex cell);                 // unknown again
  void keep_floor(CellIndex cell, double floor_m);  // built_: the cell is at least floor_m from now on [m]
  // forget_assumed_ground()'s edge: the guessed cells connected to `seeds` outside every ball the robot stood in.
  void forget_along_edge(const std::vector<CellIndex>& seeds, double radius_cells);
  void rederive_heights(const ScanBatch& batch);

  /// overflight()'s value where no ray passed [m].
  static constexpr double kUnderNoRay = std::numeric_limits<double>::infinity();
  // record_overflights(): the latest scan's rays over each cell within overflight_range_m_ of the sensor.
  void record_overflight(const std::vector<ScanPoint>& points, Point3 origin);

  Heightmap heights_;
  CellMask known_;
  CellMask assumed_;
  CellMask bound_;          ///< 1 where assumed_ is a face's lower bound, not ground assumed under the body
  CellMask not_assumable_;  ///< 1 where assumed ground was forgotten: no guess there again, only a reading
  long long known_count_ = 0;
  int scans_ = 0;
  std::vector<int> hit_scan_;  ///< per cell (row-major): the scan (1, 2, ...) that last hit it, 0 when none
  int tile_size_;
  CellIndex registration_{0, 0};
  std::unordered_map<long long, double> built_;  ///< record_built(): the least height of a cell (row-major index) [m]
  std::unordered_map<long long, double> ceiling_;     ///< record_drop(): the most a cell can be (row-major index) [m]
  std::unordered_map<long long, int> told_scan_;      ///< record_drop(): the scan count when the world told it
  std::unordered_map<long long, double> face_floor_;  ///< the highest face hit of a cell (row-major index) [m]
  std::unordered_map<long long, int> face_scan_;      ///< the scan that set face_floor_ (1, 2, ...)
  std::unordered_map<long long, int> face_hit_scan_;  ///< the last scan with a face hit on the cell (1, 2, ...)
  SensorSpec sensor_;
  std::vector<CellIndex> trajectory_;
  deliberative::StoodCells stood_;  ///< record_stood(); an empty ball: no cells stood on kept
  std::unique_ptr<Octree> octree_;  // made at the first scan
  ScanCost last_scan_cost_;
  double overflight_range_m_ = 0.0;           ///< record_overflights() [m]; 0: none recorded
  Heightmap overflight_;                      ///< overflight(); empty before the first recorded scan
  std::vector<std::size_t> overflight_cells_;  ///< the cells (row-major) overflight_ holds a finite height for
};

}  // namespace marsala::agent::executive
