#pragma once
// The start of `marsala-world --fork DIR --at K` (docs/runtime.md#fork), decided before the bus as world_start.hpp's.

#include <cstdint>
#include <string>

#include "marsala/world_server/runtime/world_start.hpp"

namespace marsala::world_server {

/// A fork of the run in `dir` at step `at`: the scenario, seed and team from run.log's header (the terrain built from
/// it and checked against the header's digest), max_steps and the step deadline the parent's unless `options` sets
/// them, the parent's first `at` steps to replay (read_fork()), and from step `at` on a team of options.agents (0: the
/// parent's; fewer: the slots above it leave at step `at`). The run id and output folder are the fork's own. Throws
/// InvalidArgument (one line; nothing written) when the fork cannot be made: `dir` not a run, a torn log, `at` beyond
/// the parent's steps, a larger team, --set or --seed given, --out naming the parent's folder. An empty
/// options.out_dir checks the fork only (marsala-world --check --fork): no folder is touched.
WorldStart prepare_fork(const std::string& dir, std::uint64_t at, RuntimeOptions options, int domain_id);

}  // namespace marsala::world_server
