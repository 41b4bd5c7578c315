#pragma once
// The world server's runtime, the edge that owns the bus and the clock: the lockstep as the protocol reads.
//   admit:    hellos on the default partition through the admission gate (admission_gate.hpp: confirmation, takeover
//             wait, answer rate, refusals) and the rules' decision (rules/admission.hpp); each admitted session gets
//             its agent link (agent_links.hpp: endpoints on protocol::partition_for(run_id, id, session), liveliness,
//             readiness)
//   per step: frames -> collect (request_collector.hpp: deadline, per-partition limit, resends) -> apply
//             (rules/step.hpp) -> record (records/run_recorder.hpp: run.log first, snapshots, events.log, frames)
//             -> status (WorldStatus, WorldEvents)
//   end:      run_over frames, the final outputs, linger.
// What the run starts from is decided before, without the bus (world_start.hpp).

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/protocol/end_reason.hpp"
#include "marsala/world_server/runtime/world_start.hpp"

namespace marsala::world_server {

class MetricsServer;
class StepTrace;

/// How a run ended.
struct RunResult {
  bool completed = false;
  protocol::EndReason end_reason = protocol::EndReason::kSignal;  ///< why the run ended
  std::uint64_t steps = 0;                                        ///< steps applied
  double wall_seconds = 0.0;                                      ///< from the first frame to the end [s]
  std::uint32_t admitted = 0;
  std::uint32_t team = 0;           ///< slots of the team (--agents) [count]
  std::uint32_t slots_missing = 0;  ///< slots not in the run at its end: never admitted, or dropped and not back
  std::string terrain_sha256;                    ///< of the final heights
  std::optional<std::uint64_t> resumed_at_step;  ///< set when this process continued a run from its log
};

/// One run of the world server on one participant.
class WorldRuntime {
 public:
  /// Validates the options and prepares the state with prepare_world_start(); throws InvalidArgument.
  WorldRuntime(const scenario::Scenario& scenario, Heightmap terrain, RuntimeOptions options,
               bus::Participant& participant);
  /// Runs a prepared start: prepare_world_start() or prepare_resume().
  WorldRuntime(WorldStart start, bus::Participant& participant);
  ~WorldRuntime();
  WorldRuntime(const WorldRuntime&) = delete;
  WorldRuntime& operator=(const WorldRuntime&) = delete;

  /// Admits agents (a resumed run: reconnects its agents), runs the lockstep until completion, max_steps, no live
  /// agent or `stop`, sends run_over frames and writes the outputs; run.log records every change of the state before
  /// its results are published. Throws Error when no agent is admitted within the admit timeout (or before `stop`),
  /// IoError when the outputs or the log cannot be written.
  RunResult run(const std::atomic<bool>& stop);

  /// Publishes a metrics snapshot to `server` whenever WorldStatus goes out (while admitting, each step, at the end;
  /// docs/runtime.md#metrics); `server` must outlive run().
  void serve_metrics(MetricsServer& server);

  /// Appends every step's spans to `trace` (docs/runtime.md#step-traces); `trace` must outlive run().
  void trace_steps(StepTrace& trace);

  /// The world state (after run(): the final one).
  const WorldState& state() const;
  /// The run id in use.
  const std::string& run_id() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace marsala::world_server
