#pragma once
// A fork of a run (docs/runtime.md#fork): a new run that replays its parent's first K steps with fresh agents, then
// goes on live. Up to step K every live request must be the one the parent's run.log recorded for that agent and step
// (the agents are deterministic: same scenario, seed and team give the same requests); the world applies the recorded
// requests, so the fork's state at K is the parent's. Reading the parent and comparing only; the runtime drives it.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "idl/run_log.pb.h"
#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// A live request before step K differs from the parent's: the fork cannot be the parent's run up to K.
class ForkMismatch : public Error {
 public:
  explicit ForkMismatch(const std::string& what) : Error(what) {}
};

/// marsala-world's exit code for a ForkMismatch (docs/runtime.md#exit-codes).
inline constexpr int kExitForkMismatch = 8;

/// Where a fork comes from.
struct ForkOrigin {
  std::string parent_dir;             ///< the parent run's folder, as given
  std::string parent_run_id;          ///< its run id
  std::uint64_t at_step = 0;          ///< K: steps 0..K-1 replayed, live from step K on
  std::uint32_t parent_agents = 0;    ///< the parent's team [count]
  std::uint32_t agents = 0;           ///< the fork's team from step K on (above parent_agents: late slots) [count]
  std::string parent_sha256_at_step;  ///< SHA-256 of the parent's terrain after its first K steps
  std::vector<std::string> overrides;  ///< the fork's own --set FIELD=VALUE (world-only fields), from step 0
};

/// The parent's first K steps as recorded, checked against and substituted for the live requests.
class ForkReplay {
 public:
  /// `steps`: the parent's step records 0..K-1 in order (origin.at_step of them).
  ForkReplay(ForkOrigin origin, std::vector<proto::StepRecord> steps);

  const ForkOrigin& origin() const { return origin_; }
  /// Records the fork's own --set (world-only fields, checked by the caller) in its origin.
  void set_overrides(std::vector<std::string> overrides) { origin_.overrides = std::move(overrides); }
  /// True while `step` is one of the replayed ones (before K).
  bool replaying(std::uint64_t step) const { return step < origin_.at_step; }
  /// Empty when the live submissions of `step` are, agent by agent and in each agent's order, the recorded ones
  /// (sessions, which are new in every process, and the trace-only fields aside); else one line naming the first
  /// agent that differs and the step.
  std::string mismatch(std::uint64_t step, const std::vector<Submission>& live) const;
  /// The recorded submissions of `step` in their recorded order, each with the session its agent holds in `state`
  /// (so that the rules take them as that agent's).
  std::vector<Submission> recorded(std::uint64_t step, const WorldState& state) const;
  /// The recorded deposited volume after `step` [m^3].
  double deposited_after(std::uint64_t step) const;

 private:
  const proto::StepRecord& step_of(std::uint64_t step) const;

  ForkOrigin origin_;
  std::vector<proto::StepRecord> steps_;
};

/// The parent run in `dir` read for a fork at step `at`: the header, the step records 0..at-1, the terrain SHA-256
/// after them (replayed onto `initial`, make_world_state() of the header's scenario, terrain and team). Throws
/// InvalidArgument (one line naming the folder) when there is no run.log, its tail is torn, `at` lies beyond the
/// parent's steps, or the first `at` steps hold what a fork cannot repeat (a drop, a re-admission, a takeover, a
/// resume, a late slot's join) or the parent is a fork whose team grew; ParseError when run.log cannot be read or
/// disagrees with the rules.
ForkReplay read_fork(const std::string& dir, std::uint64_t at, std::uint32_t agents, WorldState initial);

}  // namespace marsala::world_server
