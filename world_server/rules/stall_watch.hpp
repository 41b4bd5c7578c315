#pragma once
// The stall detector (docs/runtime.md#stall): a run whose progress has not risen above its best and whose terrain
// has not changed for the scenario's stall_steps steps ends "stalled". Pure: the steps are passed in, no clock.

#include <cstdint>

namespace marsala::world_server {

/// What the world remembers of a run's activity; part of the world state (snapshots keep it).
struct StallWatch {
  double best_progress = 0.0;       ///< the highest progress seen after a step [0, 1]
  std::uint64_t quiet_since = 0;    ///< the first step after the last one that raised the progress or changed terrain
  std::uint64_t longest_quiet = 0;  ///< the longest stretch of such steps the run has had so far [steps]
};

/// Progress must rise by more than this to count (rounding of the progress measure) [1].
inline constexpr double kProgressRiseEpsilon = 1e-12;

/// Takes step `step` (just applied) into account: its progress after the step [0, 1], and whether it changed a
/// terrain cell. A step with either starts a new quiet stretch at step + 1.
void observe_step(StallWatch& watch, std::uint64_t step, double progress, bool terrain_changed);

/// Steps in a row without activity up to (not including) `next_step`, the step whose requests are awaited.
std::uint64_t quiet_steps(const StallWatch& watch, std::uint64_t next_step);

/// True when the run has stalled before `next_step`: stall_steps > 0 and quiet_steps() >= stall_steps.
bool stalled(const StallWatch& watch, std::uint64_t next_step, std::uint64_t stall_steps);

}  // namespace marsala::world_server
