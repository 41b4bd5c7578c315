#include "marsala/world_server/records/fork_replay.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <utility>

#include "marsala/runlog/run_log.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/world_server/records/persistence.hpp"

namespace marsala::world_server {
namespace {

/// Each agent's requests of one step as logged, without what differs between two processes making the same
/// requests (session) and what the world adds (verdict, raised cells): serialized, in the agent's order.
using RequestsByAgent = std::map<std::uint32_t, std::vector<std::string>>;

std::string comparable(proto::LoggedRequest q) {
  q.clear_session();
  q.clear_accepted();
  q.clear_raised();
  return q.SerializeAsString();
}

RequestsByAgent by_agent(const proto::StepRecord& r) {
  RequestsByAgent out;
  for (const proto::LoggedRequest& q : r.requests()) out[q.channel_id()].push_back(comparable(q));
  return out;
}

/// What a run holds in its first steps that a fork cannot repeat, or empty.
std::string unrepeatable(const proto::LogRecord& record) {
  if (record.has_dropped()) return fmt::format("agent {} was dropped", record.dropped().agent_id());
  if (record.has_resumed()) return "the run was resumed";
  if (record.has_admitted() && (record.admitted().readmission() || record.admitted().takeover()))
    return fmt::format("agent {} was admitted again", record.admitted().agent_id());
  if (record.has_admitted() && record.admitted().step() > 0)  // a fork's late slot: not in a team started afresh
    return fmt::format("agent {} joined at step {}", record.admitted().agent_id(), record.admitted().step());
  return {};
}

}  // namespace

ForkReplay::ForkReplay(ForkOrigin origin, std::vector<proto::StepRecord> steps)
    : origin_(std::move(origin)), steps_(std::move(steps)) {
  if (steps_.size() != origin_.at_step)
    throw InvalidArgument(fmt::format("a fork at step {} needs {} recorded steps, got {}", origin_.at_step,
                                      origin_.at_step, steps_.size()));
}

const proto::StepRecord& ForkReplay::step_of(std::uint64_t step) const {
  if (step >= steps_.size() || steps_[step].step() != step)
    throw InvalidArgument(fmt::format("the fork holds no recorded step {}", step));
  return steps_[step];
}

std::string ForkReplay::mismatch(std::uint64_t step, const std::vector<Submission>& live) const {
  proto::LogRecord as_logged = step_record(live, StepOutcome{}, WorldState{});
  as_logged.mutable_step()->set_step(step);
  const RequestsByAgent want = by_agent(step_of(step));
  const RequestsByAgent got = by_agent(as_logged.step());
  for (const auto& [agent, requests] : want) {
    const auto it = got.find(agent);
    if (it == got.end())
      return fmt::format("agent {} sent no request at step {}, where the parent's run.log has {}", agent, step,
                         requests.size());
    if (it->second != requests)
      return fmt::format("agent {} at step {}: its request differs from the parent's run.log", agent, step);
  }
  for (const auto& [agent, requests] : got)
    if (want.count(agent) == 0)
      return fmt::format("agent {} at step {}: it sent {} request(s) where the parent's run.log has none", agent, step,
                         requests.size());
  return {};
}

std::vector<Submission> ForkReplay::recorded(std::uint64_t step, const WorldState& state) const {
  std::vector<Submission> out;
  for (const proto::LoggedRequest& q : step_of(step).requests()) {
    Submission s = logged_submission(q);
    if (state.has_agent(s.channel_id)) s.request.session = state.agent(s.channel_id).session;
    out.push_back(std::move(s));
  }
  return out;
}

double ForkReplay::deposited_after(std::uint64_t step) const { return step_of(step).deposited_volume_m3(); }

ForkReplay read_fork(const std::string& dir, std::uint64_t at, std::uint32_t agents, WorldState initial) {
  namespace fs = std::filesystem;
  const std::string log_path = (fs::path(dir) / kRunLogFile).string();
  if (!fs::is_regular_file(log_path))
    throw InvalidArgument(fmt::format("--fork {}: no {} there: not a run folder", dir, kRunLogFile));
  runlog::RunLogReader reader(log_path);
  ForkOrigin origin;
  origin.parent_dir = dir;
  origin.parent_run_id = reader.header().run_id();
  origin.at_step = at;
  origin.parent_agents = reader.header().agents();
  origin.agents = agents == 0 ? origin.parent_agents : agents;
  const proto::LogHeader& h = reader.header();
  if (h.fork_agents() > h.fork_parent_agents() && h.fork_parent_agents() > 0)
    throw InvalidArgument(fmt::format(
        "--fork {}: that run is a fork whose team grew at step {} (slots {}..{} joined late): a team started afresh "
        "would hold them from step 0; fork its parent {} instead",
        dir, h.fork_step(), h.fork_parent_agents() + 1, h.fork_agents(), h.fork_parent()));
  std::vector<proto::StepRecord> steps;
  std::uint64_t parent_steps = 0;
  std::string unrepeatable_before_k;
  proto::LogRecord record;
  for (std::uint64_t offset = reader.offset(); reader.next(record); offset = reader.offset()) {
    if (record.has_step()) ++parent_steps;
    if (steps.size() >= at || !unrepeatable_before_k.empty()) continue;
    unrepeatable_before_k = unrepeatable(record);
    if (!unrepeatable_before_k.empty()) continue;
    apply_record(initial, record, fmt::format("{} (record at byte {})", log_path, offset));
    if (record.has_step()) steps.push_back(record.step());
  }
  if (!reader.tail_problem().empty())
    throw InvalidArgument(fmt::format("--fork {}: torn run.log: {}", dir, reader.tail_problem()));
  if (at > parent_steps)
    throw InvalidArgument(fmt::format("--fork {} --at {}: the parent ran {} steps; K must lie in 0..{}", dir, at,
                                      parent_steps, parent_steps));
  if (!unrepeatable_before_k.empty())
    throw InvalidArgument(fmt::format("--fork {} --at {}: {} before step {}: a fork cannot repeat that", dir, at,
                                      unrepeatable_before_k, at));
  origin.parent_sha256_at_step = runlog::terrain_sha256(initial.terrain);
  return ForkReplay(std::move(origin), std::move(steps));
}

}  // namespace marsala::world_server
