#pragma once
// marsala-monitor export DIR --mcap FILE: a run folder as one MCAP file for Foxglove and Lichtblick
// (docs/runtime.md#mcap-export). The terrain is rebuilt from run.log on terrain_initial.asc as replay does (replay.hpp,
// with every check of the log), the robots from the log's requests and the scenario the log's header carries, the
// events from events.log. Channels (JSON encoding, schemas in foxglove_json.hpp):
//   /terrain  foxglove.Grid         at the start, after every K-th step, and at the end;
//   /robots   foxglove.SceneUpdate  at the start and after every step;
//   /events   foxglove.Log          each line of events.log.
// Step k's outcome is logged at (k + 1) x step time; the start at 0. The file appears whole or not at all.

#include <cstdint>
#include <string>

namespace marsala::monitor {

/// How to export.
struct McapExportOptions {
  std::uint64_t terrain_every = 100;  ///< a terrain after every K-th step (and at the start and end) [steps]
  std::uint64_t step_ns = 100000000;  ///< the time one step takes in the file [ns]
};

/// What an export wrote.
struct McapExportReport {
  std::string path;
  std::uint64_t steps = 0;        ///< steps of the run
  std::uint64_t terrains = 0;     ///< /terrain messages
  std::uint64_t robot_updates = 0;  ///< /robots messages
  std::uint64_t events = 0;       ///< /events messages
  std::uint64_t bytes = 0;        ///< the file's size
  double seconds = 0.0;           ///< wall time [s]
};

/// Writes `dir` as the MCAP file `file` (through "<file>.tmp", renamed). Throws InvalidArgument before anything is
/// written when `dir` is not a folder holding run.log and terrain_initial.asc, when `file` exists, or when an option
/// is out of range; ParseError when run.log fails its checksums (a damaged tail is refused, not skipped), disagrees
/// with its replay, or when events.log has a line that is not an event; IoError when writing fails. Nothing is left
/// under `file` then.
McapExportReport export_mcap(const std::string& dir, const std::string& file, const McapExportOptions& options);

/// One line for people: what went where.
std::string format_export_report(const McapExportReport& report);

}  // namespace marsala::monitor
