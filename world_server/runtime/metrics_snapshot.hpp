#pragma once
// What marsala-world --metrics-port serves (docs/runtime.md#metrics), as one immutable value: the world makes a
// snapshot when its state changes (each step, while admitting, at the end) and a scrape renders the latest one
// (metrics_exposition.hpp), so a scrape never waits for the step loop nor sees half a step.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "marsala/protocol/end_reason.hpp"
#include "marsala/world_server/rules/rejection_reason.hpp"
#include "marsala/world_server/rules/world_state.hpp"
#include "marsala/world_server/runtime/duration_histogram.hpp"

namespace marsala::world_server {

/// Where the run stands.
enum class RunPhase : std::uint8_t {
  kAdmitting,  ///< waiting for its agents (or for them to reconnect, after a resume)
  kRunning,    ///< in the lockstep
  kOver,       ///< ended; MetricsSnapshot::end_reason says why
};

/// One agent slot's numbers (summary.json's per_agent).
struct AgentMetrics {
  std::uint32_t id = 0;
  bool admitted = false;
  bool alive = false;      ///< admitted and not dropped
  bool connected = false;  ///< alive and its request writer alive
  std::uint64_t accepted = 0;    ///< requests accepted [count]
  std::uint64_t rejected = 0;    ///< requests rejected [count]
  std::uint64_t missed = 0;      ///< deadlines missed [count]
  double deposited_m3 = 0.0;     ///< material placed [m^3]
  double material_m3 = 0.0;      ///< material on board [m^3]
};

/// The world's numbers at one moment.
struct MetricsSnapshot {
  std::string run_id;
  std::string scenario;  ///< the scenario's name
  std::string dds;       ///< the vendor: cyclone, fastdds or inprocess
  RunPhase phase = RunPhase::kAdmitting;
  std::optional<protocol::EndReason> end_reason;  ///< set when phase is kOver
  std::uint64_t steps = 0;                        ///< steps applied (state.step) [count]
  DurationHistogram step_seconds;        ///< wall time of each step this process ran [s]
  DurationHistogram step_world_seconds;  ///< the world's own part of each: less its waits for requests [s]
  std::uint32_t agents_expected = 0;     ///< slots of the team [count]
  std::uint32_t agents_admitted = 0;     ///< slots ever admitted [count]
  std::uint32_t agents_live = 0;         ///< admitted and not dropped [count]
  std::uint32_t agents_connected = 0;    ///< live with their request writer alive [count]
  std::uint32_t agents_dropped = 0;      ///< dropped and not back [count]
  std::uint64_t deadline_misses = 0;     ///< the agents' missed deadlines [count]
  std::uint64_t rejected_requests = 0;   ///< the agents' rejected requests [count]
  std::uint64_t unattributed_rejections = 0;  ///< rejected requests charged to no agent [count]
  std::uint64_t surplus_requests = 0;         ///< requests beyond a partition's limit, never applied [count]
  RejectionCounts rejections_by_reason{};     ///< every rejection this process made, by reason [count]
  double progress = 0.0;                      ///< [0, 1]
  double deposited_m3 = 0.0;                  ///< total placed [m^3]
  std::vector<AgentMetrics> agents;           ///< every slot, ascending id
};

/// Fills the state's part of `snapshot` from `state`: steps, agent counts and each slot's numbers, misses,
/// rejections, surplus, progress, deposited volume; `connected[id - 1]` says whether slot id's request writer is
/// alive (missing entries: false). Leaves the run's names, phase, histograms and rejections by reason as they are.
void take_state(MetricsSnapshot& snapshot, const WorldState& state, const std::vector<bool>& connected);

}  // namespace marsala::world_server
