#pragma once
// One lockstep step as a pure function of (state, requests): validate and apply in agent-id order, each request
// against the state the previous ones left; count misses and drop agents after 3 consecutive ones; bump the
// versions of changed tiles; update who is at the goal; advance the step. No clock, no IO: the runtime logs and
// publishes what the outcome lists, so a recorded step can be replayed.

#include <cstdint>
#include <string>
#include <vector>

#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/rules/rejection_reason.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// Consecutive missed steps after which an agent is dropped from the run (docs/runtime.md#dropping-agents).
inline constexpr std::uint32_t kMaxConsecutiveMisses = 3;
/// A chronically late agent is dropped too: one that missed more than half of the last kMissWindowSteps steps it
/// was live for, i.e. kMaxMissesInWindow of them (e.g. two deadlines in every three, never three in a row).
inline constexpr int kMissWindowSteps = 16;
inline constexpr int kMaxMissesInWindow = 9;

/// A request as it arrived: the agent whose partition carried it, and the request.
struct Submission {
  std::uint32_t channel_id = 0;  ///< owner of the partition (reader) it came from
  protocol::ActionRequest request;
};

/// What happened in one step.
struct StepOutcome {
  std::uint64_t step = 0;                    ///< the step applied
  std::vector<protocol::WorldEvent> events;  ///< in agent-id order, as they happened
  std::vector<std::string> notes;            ///< things to log that are not events (late requests dropped)
  std::vector<int> changed_tiles;            ///< TileLayout indices whose heights changed, ascending
  std::vector<std::uint32_t> dropped;        ///< agents dropped in this step (3 consecutive misses)
  std::vector<bool> accepted_submissions;    ///< [i]: submission i was accepted and applied
  std::vector<std::vector<Deposition>> raised_cells;  ///< [i]: the cells accepted submission i raised, in order
  std::uint32_t accepted = 0;                ///< requests accepted
  std::uint32_t rejected = 0;                ///< requests rejected (including duplicates and future steps)
  RejectionCounts rejected_by_reason{};      ///< the rejected requests by reason; they add up to `rejected`
  std::uint32_t missed = 0;                  ///< live agents without a request for this step
  bool completion_checked = false;           ///< the payload/site check was evaluated in this step
  bool completed = false;                    ///< is_completed() after the step
};

/// Applies step `state.step`. `submissions` may come in any order across agents; within one agent's partition they
/// are taken in arrival order. Per live agent, in id order: requests for past steps are dropped (a note), for future
/// steps rejected; the first for this step is validated and applied (or rejected), later ones are duplicates
/// (rejected, the first stands); no request for this step is a miss (kMissed; dropped at 3 in a row). Submissions on
/// the partition of an agent that is not live are ignored with a note. A step in which no deposition is accepted
/// counts in state.idle_steps. Then z of every agent, tile versions, at_goal (event kAtGoal when reached); for
/// payload_path and level_site runs the changed cells are recorded in the completion check, which is evaluated when
/// (step + 1) % check_every_steps == 0 and the terrain of its area changed since its previous evaluation; then
/// completion; the stall detector observes the step (progress after it, terrain changed); finally state.step += 1.
StepOutcome apply_step(WorldState& state, const std::vector<Submission>& submissions);

/// The longest waiting_for the world keeps of a request [characters].
inline constexpr std::size_t kMaxWaitingForChars = 160;

/// What the world keeps of a request's waiting_for (docs/runtime.md#stall): its first kMaxWaitingForChars bytes,
/// each byte outside printable ASCII (0x20..0x7e) replaced by '?'. Idempotent.
std::string kept_waiting_for(const std::string& text);

/// Same, with each request taken as arriving on its own agent's partition (channel = request.agent_id).
StepOutcome apply_step(WorldState& state, const std::vector<protocol::ActionRequest>& requests);

/// Removes a live agent from the run (e.g. its request writer lost liveliness): alive = false, dropped, reason.
/// Returns the kDropped event; throws InvalidArgument when there is no such agent.
protocol::WorldEvent drop_agent(WorldState& state, std::uint32_t id, const std::string& reason);

}  // namespace marsala::world_server
