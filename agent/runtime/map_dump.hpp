#pragma once
// marsala-agent --dump-map DIR (docs/runtime.md#seeing-the-map): the robot's own map when its admitted run ends, for
// any reason (run over, a signal, the world gone), so that its quality can be seen (`marsala-terrain compare`):
//
//   DIR/agent-<id>-height.asc  the heights the robot believes [m] on the world grid, NODATA_value -9999 where it
//                              knows nothing (ESRI ASCII grid, the conventions of the run's terrain_final.asc)
//   DIR/agent-<id>-map.json    its record: run_id, agent_id, name, step, end, the grid, cells, known_cells,
//                              assumed_cells (known only as the ground under the body), sensor, height_file
//
// The .asc is written first, then the record, each under "<name>.tmp" renamed into place: a record always names a
// whole map. A folder holds the maps of one run: one holding a record of another run id is refused before anything
// is written (a record that cannot be read: at start-up; another run: at admission, when the run id becomes known).

#include <cstdint>
#include <memory>
#include <string>

#include "marsala/agent/deliberative/known_map.hpp"

namespace marsala::agent::runtime {

struct RuntimeConfig;

/// What a map's record says besides the map.
struct MapDumpInfo {
  std::string run_id;          ///< the run the agent was admitted to
  std::uint32_t agent_id = 0;  ///< its slot
  std::string name;            ///< e.g. "husky-1"
  std::uint64_t step = 0;      ///< step of the last frame it received
  std::string end;             ///< why its run ended (to_string(RunOutcome)), or "error"
  std::string sensor;          ///< its terrain sensor: ground_truth, laser, rgbd
};

/// A map record as read back.
struct MapRecord {
  std::string run_id;
  std::uint32_t agent_id = 0;
  std::uint64_t step = 0;
  long long known_cells = 0;  ///< [count]
  std::string height_file;    ///< the .asc beside it (file name only)
};

/// Reads a record (agent-<id>-map.json); throws ParseError naming the file when it is not one, IoError when unreadable.
MapRecord read_map_record(const std::string& path);

/// The folder an agent dumps its map into.
class MapDump {
 public:
  /// Creates `dir` (and its parents) when missing. Throws InvalidArgument naming the path when it is not a folder or
  /// cannot be made or written, and ParseError naming the file when it holds a record that cannot be read.
  explicit MapDump(std::string dir);

  /// Empty when the folder may take the maps of run `run_id` (every record in it is of that run); otherwise one line
  /// naming a record of another run. Reads the folder again.
  std::string problem_for_run(const std::string& run_id) const;

  /// Writes `map` (NODATA where not known) and its record for `info`, atomically each; throws IoError (or
  /// InvalidArgument for a map write_asc refuses) with the path.
  void write(const deliberative::KnownMap& map, const MapDumpInfo& info) const;

  /// DIR/agent-<id>-height.asc.
  std::string height_path(std::uint32_t agent_id) const;
  /// DIR/agent-<id>-map.json.
  std::string record_path(std::uint32_t agent_id) const;
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

/// Makes `config`'s agent use `dump`: it refuses a run whose maps the folder may not take (problem_for_run) and writes
/// its map there when its admitted run ends (nothing for a behaviour that keeps no map; a failed write is logged and
/// thrown when the run ended without error).
void dump_maps_into(std::shared_ptr<const MapDump> dump, RuntimeConfig& config);

}  // namespace marsala::agent::runtime
