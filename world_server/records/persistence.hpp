#pragma once
// The world's persistence (docs/runtime.md#persistence): the run.log records of what the world did, snapshots of its
// state, and the way back. Every change of the world state goes through admit(), drop_agent() or apply_step(); the
// log records each call's input in order, so replaying the records onto the initial state (or a snapshot) repeats
// the same calls and rebuilds the state exactly. Conversions and replay only; the runtime opens the files.

#include <cstdint>
#include <string>
#include <vector>

#include "idl/run_log.pb.h"
#include "marsala/core/heightmap.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/records/fork_replay.hpp"
#include "marsala/world_server/rules/admission.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// The snapshot's name in a run's output folder (the log's is runlog::kRunLogFile).
using runlog::kRunLogFile;
inline constexpr const char* kSnapshotFile = "snapshot.pb";

/// What a run starts from, as the log's header records it.
struct LogStart {
  std::string scenario_text;  ///< the scenario file's text (empty: the run cannot be resumed)
  std::string run_id;
  std::uint32_t agents = 0;
  std::uint64_t max_steps = 0;
  double step_deadline_s = 0.0;
  const ForkOrigin* fork = nullptr;  ///< where a fork comes from (none: no fork)
};

/// The header record of a run of `scenario` (its name, file and seed) from `initial` terrain.
proto::LogHeader log_header(const scenario::Scenario& scenario, const LogStart& start, const Heightmap& initial);

/// An admission (kFirst, kReadmission or kTakeover) of agent `id` as the state records it after admit().
proto::LogRecord admitted_record(const WorldState& state, std::uint32_t id, AdmissionKind kind);
/// A drop outside a step (liveliness), before drop_agent() is called.
proto::LogRecord dropped_record(const WorldState& state, std::uint32_t id, const std::string& reason);
/// The step just applied: its submissions in the order given to apply_step, each with its verdict, and the state's
/// deposited volume after it. `surplus` counts requests that were not submitted (beyond the per-partition limit).
proto::LogRecord step_record(const std::vector<Submission>& submissions, const StepOutcome& outcome,
                             const WorldState& after, std::uint32_t surplus = 0);

/// The submission a logged request records (what apply_record() gives apply_step()).
Submission logged_submission(const proto::LoggedRequest& request);

/// The state after a step, with the byte offset of run.log just after that step's record.
proto::Snapshot make_snapshot(const WorldState& state, const std::string& run_id, std::uint64_t log_offset);
/// Loads snapshot.pb; throws IoError when it cannot be read, ParseError when it does not parse or fails its checksum.
proto::Snapshot read_snapshot(const std::string& path);
/// Writes `snapshot` to `path` through a temporary file renamed into place; throws IoError.
void write_snapshot(const std::string& path, const proto::Snapshot& snapshot);
/// Puts the snapshot's state onto `state`, which make_world_state() made from the run's scenario, initial terrain
/// and agent count. Throws ParseError naming `file` when the snapshot does not fit (grid, agents, tiles, terrain
/// digest).
void restore_snapshot(WorldState& state, const proto::Snapshot& snapshot, const std::string& file);

/// Applies one record to `state` as the world did when it wrote it: admissions through admit(), drops through
/// drop_agent(), steps through apply_step() with the recorded submissions. A step must be the state's next one and
/// give the recorded verdicts and deposited volume bit for bit; otherwise throws ParseError naming `where` (the log
/// and the world's rules disagree: another version of the world, or a damaged log). Header, resumed and end records
/// change nothing.
void apply_record(WorldState& state, const proto::LogRecord& record, const std::string& where);

/// A state rebuilt from a run's folder.
struct RebuiltState {
  WorldState state;
  proto::LogHeader header;
  std::uint64_t good_bytes = 0;     ///< run.log's offset after its last good record
  std::uint64_t snapshot_step = 0;  ///< the snapshot restored (0 = none: replayed from the header)
  std::uint64_t records = 0;        ///< records replayed
  std::string tail_problem;         ///< what was wrong with run.log's tail (cut, never applied); empty when clean
  std::string snapshot_problem;     ///< why snapshot.pb was not used, when present and unusable
  bool ended = false;               ///< run.log holds a RunEnd record
  std::string end_reason;           ///< its end reason
};

/// Rebuilds the world state of the run in `dir`: `initial` (make_world_state() of the header's scenario, terrain and
/// agents), then snapshot.pb when it is usable (same run, its offset within the good records, the record at that
/// offset intact), then run.log's records after it. Throws ParseError/IoError when run.log cannot be read or
/// disagrees with the rules.
RebuiltState rebuild_state(const std::string& dir, WorldState initial, runlog::RunLogReader& reader);

}  // namespace marsala::world_server
