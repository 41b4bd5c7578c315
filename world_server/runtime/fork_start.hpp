#pragma once
// The start of `marsala-world --fork DIR --at K` (docs/runtime.md#fork), decided before the bus as world_start.hpp's.

#include <array>
#include <cstdint>
#include <string>

#include "marsala/world_server/runtime/world_start.hpp"

namespace marsala::world_server {

/// The scenario fields (top-level names of idl/scenario.proto's Scenario, with everything inside them) that only the
/// world reads: no agent is told them, so a fork may change them with --set without changing any request before K
/// (docs/runtime.md#fork).
inline constexpr std::array<const char*, 6> kForkSettableFields = {"max_steps",    "step_deadline_s", "stall_steps",
                                                                   "goal",         "payload_path",    "site"};

/// Empty when the override `field_value` ("FIELD=VALUE", FIELD a dot path as load_scenario() takes it) changes only
/// fields of kForkSettableFields; else one line naming it and why a fork may not change it.
std::string fork_override_problem(const std::string& field_value);

/// A fork of the run in `dir` at step `at`: the scenario, seed and team from run.log's header (the terrain built from
/// it and checked against the header's digest), max_steps and the step deadline the parent's unless `options` sets
/// them, the parent's first `at` steps to replay (read_fork()), and from step `at` on a team of options.agents (0: the
/// parent's; fewer: the slots above it leave at step `at`; more: the slots above the parent's join at step `at`,
/// unadmitted before). options.overrides (--set) are applied after the parent's,
/// from step 0, and may name only world-only fields (fork_override_problem()). The run id and output folder are the
/// fork's own. Throws InvalidArgument (one line; nothing written) when the fork cannot be made: `dir` not a run, a
/// torn log, `at` beyond the parent's steps, a team beyond the scenario's slots or whose late slots would change how
/// the parent's team is judged, --seed or a --set of a field the agents read, max_steps
/// below `at`, --out naming the parent's folder. An empty options.out_dir checks the fork only (marsala-world --check
/// --fork): no folder is touched.
WorldStart prepare_fork(const std::string& dir, std::uint64_t at, RuntimeOptions options, int domain_id);

}  // namespace marsala::world_server
