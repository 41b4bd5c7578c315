#include "marsala/world_server/rules/step.hpp"

#include <algorithm>
#include <bitset>
#include <string>

#include "marsala/core/format.hpp"
#include "marsala/world_server/rules/arbiter.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

constexpr std::size_t kMaxStateChars = 64;  // behaviour state names are for display only

protocol::WorldEvent event(std::uint64_t step, std::uint32_t agent, protocol::EventKind kind, std::string detail,
                           double volume_m3 = 0.0) {
  protocol::WorldEvent e;
  e.step = step;
  e.agent_id = agent;
  e.kind = kind;
  e.volume_m3 = volume_m3;
  e.detail = std::move(detail);
  return e;
}

/// Counts one rejected request of the step, of `reason`.
void count_rejection(StepOutcome& out, RejectionReason reason) {
  ++out.rejected;
  ++out.rejected_by_reason[static_cast<std::size_t>(reason)];
}

/// Applies the requests that arrived on one live agent's partition.
void apply_agent(WorldState& state, AgentRecord& agent, const std::vector<Submission>& submissions,
                 const std::vector<std::size_t>& mine, std::vector<CellIndex>& changed_cells, StepOutcome& out,
                 bool& deposited) {
  const std::uint64_t step = state.step;
  bool answered = false;
  const protocol::ActionRequest* first = nullptr;  // the request that answered the step
  for (std::size_t index : mine) {
    const protocol::ActionRequest* r = &submissions[index].request;
    if (!carries_identity_of(agent, *r)) {
      // Forged or misdirected: charged to the admitted agent whose identity it carries (it wrote on another's
      // partition), else to no agent; never to the partition's owner, the victim.
      const bool known = state.has_agent(r->agent_id) && state.agent(r->agent_id).admitted &&
                         state.agent(r->agent_id).session == r->session;
      if (known)
        ++state.agent(r->agent_id).rejected;
      else
        ++state.unattributed_rejections;
      count_rejection(out, RejectionReason::kIdentity);
      out.events.push_back(event(step, known ? r->agent_id : 0, protocol::EventKind::kRejected,
                                 fmt::format("request claiming agent {} session {} on agent {}'s partition "
                                             "rejected: not its admitted identity",
                                             r->agent_id, r->session, agent.id)));
      continue;
    }
    if (r->step < step) {
      out.notes.push_back(fmt::format("agent {}: request for past step {} dropped", agent.id, r->step));
      continue;
    }
    if (answered && r->step == step && protocol::same_request(*r, *first)) {
      out.notes.push_back(fmt::format("agent {}: request for step {} repeated; the first stands", agent.id, step));
      continue;
    }
    if (r->step > step || answered) {
      const std::string reason =
          r->step > step ? fmt::format("request for future step {} rejected", r->step)
                         : fmt::format("duplicate request for step {} rejected; the first stands", step);
      ++agent.rejected;
      count_rejection(out, r->step > step ? RejectionReason::kFutureStep : RejectionReason::kDuplicate);
      out.events.push_back(event(step, agent.id, protocol::EventKind::kRejected, reason));
      continue;
    }
    answered = true;
    first = r;
    agent.state = r->state.substr(0, kMaxStateChars);
    agent.waiting_for = kept_waiting_for(r->waiting_for);
    const Verdict verdict = validate_request(state, agent.id, *r);
    if (verdict.accepted) {
      apply_request(state, *r, verdict, changed_cells);
      out.accepted_submissions[index] = true;
      out.raised_cells[index] = raised_cells(*r, verdict);
      deposited = deposited || !out.raised_cells[index].empty();
      agent.last_result = protocol::ActionResult::kAccepted;
      agent.last_reason.clear();
      ++out.accepted;
      if (verdict.volume_m3 > 0.0)
        out.events.push_back(event(step, agent.id, protocol::EventKind::kDeposited,
                                   fmt::format("{} cells", out.raised_cells[index].size()), verdict.volume_m3));
    } else {
      agent.last_result = protocol::ActionResult::kRejected;
      agent.last_reason = verdict.reason;
      ++agent.rejected;
      count_rejection(out, rejection_reason_of_rule(verdict.rule));
      if (verdict.rule == 2) ++state.rejected_motions;
      out.events.push_back(event(step, agent.id, protocol::EventKind::kRejected, verdict.reason));
    }
  }
  agent.recent_misses = static_cast<std::uint16_t>((agent.recent_misses << 1) | (answered ? 0u : 1u));
  if (answered) {
    agent.consecutive_missed = 0;
    return;
  }
  ++agent.missed;
  ++agent.consecutive_missed;
  ++out.missed;
  agent.last_result = protocol::ActionResult::kMissed;
  agent.last_reason = fmt::format("no request for step {} before the deadline", step);
  out.events.push_back(event(step, agent.id, protocol::EventKind::kMissed, agent.last_reason));
  const int recent = std::bitset<kMissWindowSteps>(agent.recent_misses).count();
  std::string why;
  if (agent.consecutive_missed >= kMaxConsecutiveMisses)
    why = fmt::format("{} consecutive missed deadlines", agent.consecutive_missed);
  else if (recent >= kMaxMissesInWindow)
    why = fmt::format("{} missed deadlines in its last {} steps", recent, kMissWindowSteps);
  if (!why.empty()) {
    out.events.push_back(drop_agent(state, agent.id, why));
    out.dropped.push_back(agent.id);
  }
}

/// Pairs (lower id, higher id) of live agents whose bodies overlap where they stand, in id order.
std::vector<std::pair<std::uint32_t, std::uint32_t>> overlapping_pairs(const WorldState& state) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < state.agents.size(); ++i) {
    const AgentRecord& a = state.agents[i];
    if (!a.alive) continue;
    for (std::size_t j = i + 1; j < state.agents.size(); ++j) {
      const AgentRecord& b = state.agents[j];
      if (b.alive && bodies_overlap(a, a.position.x, a.position.y, b, b.position.x, b.position.y))
        pairs.emplace_back(a.id, b.id);
    }
  }
  return pairs;
}

}  // namespace

StepOutcome apply_step(WorldState& state, const std::vector<Submission>& submissions) {
  StepOutcome out;
  out.step = state.step;
  // Per partition, in arrival order; partitions in id order. The order across partitions never matters.
  std::vector<std::vector<std::size_t>> by_agent(state.agents.size());
  out.accepted_submissions.assign(submissions.size(), false);
  out.raised_cells.assign(submissions.size(), {});
  for (std::size_t i = 0; i < submissions.size(); ++i) {
    const Submission& s = submissions[i];
    if (!state.has_agent(s.channel_id) || !state.agent(s.channel_id).alive) {
      out.notes.push_back(
          fmt::format("request on the partition of agent {}, which is not in the run, ignored", s.channel_id));
      continue;
    }
    by_agent[s.channel_id - 1].push_back(i);
  }
  std::vector<CellIndex> changed_cells;
  bool deposited = false;
  const auto overlapping_before = overlapping_pairs(state);
  for (AgentRecord& agent : state.agents)
    if (agent.alive) apply_agent(state, agent, submissions, by_agent[agent.id - 1], changed_cells, out, deposited);
  if (!deposited) ++state.idle_steps;
  // Collision statistics (docs/runtime.md#collisions): a close pass is a pair that overlaps now and did not before.
  const auto overlapping_after = overlapping_pairs(state);
  state.overlap_pair_steps += overlapping_after.size();
  for (const auto& pair : overlapping_after)
    if (!std::binary_search(overlapping_before.begin(), overlapping_before.end(), pair)) ++state.close_passes;

  const TileLayout tiles = state.tiles();
  for (const CellIndex& c : changed_cells) out.changed_tiles.push_back(tiles.index_of(c));
  std::sort(out.changed_tiles.begin(), out.changed_tiles.end());
  out.changed_tiles.erase(std::unique(out.changed_tiles.begin(), out.changed_tiles.end()), out.changed_tiles.end());
  for (int t : out.changed_tiles) ++state.tile_versions[static_cast<std::size_t>(t)];

  for (AgentRecord& agent : state.agents) {
    if (!agent.admitted) continue;
    agent.z_m = height_under(state.terrain, agent.position.x, agent.position.y);
    if (!agent.alive) continue;
    const bool reached = at_goal(state, agent);
    if (reached && !agent.at_goal) out.events.push_back(event(state.step, agent.id, protocol::EventKind::kAtGoal, ""));
    agent.at_goal = reached;
  }
  if (state.completion != scenario::CompletionKind::kAgentsAtGoal) {
    for (const CellIndex& c : changed_cells) state.check.occupancy.mark_changed(c);
    const std::uint32_t every = state.completion == scenario::CompletionKind::kPayloadPath
                                    ? state.payload_path.check_every_steps
                                    : state.site.check_every_steps;
    if ((state.step + 1) % std::max<std::uint32_t>(every, 1) == 0 && state.check.occupancy.has_changes()) {
      evaluate_completion(state);
      out.completion_checked = true;
    }
  }
  out.completed = is_completed(state);
  observe_step(state.stall, state.step, progress(state), !changed_cells.empty());
  ++state.step;
  return out;
}

std::string kept_waiting_for(const std::string& text) {
  std::string kept = text.substr(0, kMaxWaitingForChars);
  for (char& ch : kept) {
    const auto byte = static_cast<unsigned char>(ch);
    if (byte < 0x20 || byte > 0x7e) ch = '?';
  }
  return kept;
}

StepOutcome apply_step(WorldState& state, const std::vector<protocol::ActionRequest>& requests) {
  std::vector<Submission> submissions;
  submissions.reserve(requests.size());
  for (const protocol::ActionRequest& r : requests) submissions.push_back({r.agent_id, r});
  return apply_step(state, submissions);
}

protocol::WorldEvent drop_agent(WorldState& state, std::uint32_t id, const std::string& reason) {
  AgentRecord& agent = state.agent(id);
  agent.alive = false;
  agent.dropped = true;
  agent.at_goal = false;
  agent.drop_reason = reason;
  return event(state.step, id, protocol::EventKind::kDropped, reason);
}

}  // namespace marsala::world_server
