#include "marsala/world_server/records/persistence.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/runlog/atomic_file.hpp"
#include "marsala/runlog/crc32c.hpp"
#include "marsala/runlog/sha256.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

constexpr std::uint32_t kSnapshotFormat = 1;

proto::LoggedRequest logged(const Submission& s, bool accepted, const std::vector<Deposition>* raised) {
  const protocol::ActionRequest& r = s.request;
  proto::LoggedRequest q;
  q.set_channel_id(s.channel_id);
  q.set_agent_id(r.agent_id);
  q.set_session(r.session);
  q.set_step(r.step);
  q.set_move(r.move);
  q.set_target_x_m(r.target_x_m);
  q.set_target_y_m(r.target_y_m);
  for (const Deposition& d : r.depositions) {
    proto::LoggedDeposition* ld = q.add_depositions();
    ld->set_row(d.row);
    ld->set_col(d.col);
    ld->set_height_m(d.height_m);
  }
  for (const Deposit& d : r.deposits) {
    proto::LoggedDeposit* ld = q.add_deposits();
    ld->set_x_m(d.centre.x);
    ld->set_y_m(d.centre.y);
    ld->set_volume_m3(d.volume_m3);
  }
  if (accepted && raised != nullptr && !r.deposits.empty())
    for (const Deposition& d : *raised) {
      proto::LoggedDeposition* ld = q.add_raised();
      ld->set_row(d.row);
      ld->set_col(d.col);
      ld->set_height_m(d.height_m);
    }
  q.set_refill(r.refill);
  q.set_state(r.state);
  q.set_waiting_for(kept_waiting_for(r.waiting_for));  // bounded: run.log never grows with what an agent sends
  q.set_accepted(accepted);
  return q;
}

Submission submission(const proto::LoggedRequest& q) {
  Submission s;
  s.channel_id = q.channel_id();
  protocol::ActionRequest& r = s.request;
  r.agent_id = q.agent_id();
  r.session = q.session();
  r.step = q.step();
  r.move = q.move();
  r.target_x_m = q.target_x_m();
  r.target_y_m = q.target_y_m();
  r.depositions.reserve(static_cast<std::size_t>(q.depositions_size()));
  for (const proto::LoggedDeposition& d : q.depositions()) r.depositions.push_back({d.row(), d.col(), d.height_m()});
  r.deposits.reserve(static_cast<std::size_t>(q.deposits_size()));
  for (const proto::LoggedDeposit& d : q.deposits()) r.deposits.push_back({{d.x_m(), d.y_m()}, d.volume_m3()});
  r.refill = q.refill();
  r.state = q.state();
  r.waiting_for = q.waiting_for();
  return s;
}

template <typename T>
std::string pack(const T* values, std::size_t count) {
  static_assert(std::is_trivially_copyable_v<T>);
  std::string bytes(count * sizeof(T), '\0');
  // Little-endian hosts only (x86-64, aarch64): the bytes are the values' memory.
  if (count > 0) std::memcpy(bytes.data(), values, bytes.size());
  return bytes;
}

template <typename T>
void unpack(const std::string& bytes, T* values, std::size_t count, const std::string& file, const char* what) {
  if (bytes.size() != count * sizeof(T))
    throw ParseError(file, 0, fmt::format("{} holds {} bytes, expected {}", what, bytes.size(), count * sizeof(T)));
  if (count > 0) std::memcpy(values, bytes.data(), bytes.size());
}

std::uint32_t snapshot_crc(proto::Snapshot s) {
  s.set_snapshot_crc32c(0);
  const std::string bytes = s.SerializeAsString();
  return runlog::crc32c(bytes.data(), bytes.size());
}

}  // namespace

proto::LogHeader log_header(const scenario::Scenario& scenario, const LogStart& start, const Heightmap& initial) {
  proto::LogHeader h;
  h.set_scenario(scenario.name);
  h.set_scenario_file(scenario.source_path);
  h.set_scenario_text(start.scenario_text);
  for (const std::string& o : scenario.overrides) h.add_overrides(o);
  h.set_run_id(start.run_id);
  h.set_seed(scenario.seed);
  h.set_agents(start.agents);
  h.set_max_steps(start.max_steps);
  h.set_step_deadline_s(start.step_deadline_s);
  h.set_rows(initial.rows());
  h.set_cols(initial.cols());
  h.set_cell_size_m(initial.cell_size_m());
  h.set_initial_terrain_sha256(runlog::terrain_sha256(initial));
  if (start.fork != nullptr) {
    h.set_fork_parent(start.fork->parent_dir);
    h.set_fork_parent_run_id(start.fork->parent_run_id);
    h.set_fork_step(start.fork->at_step);
    h.set_fork_parent_sha256(start.fork->parent_sha256_at_step);
    h.set_fork_agents(start.fork->agents);
    h.set_fork_parent_agents(start.fork->parent_agents);
    for (const std::string& o : start.fork->overrides) h.add_fork_overrides(o);
  }
  return h;
}

proto::LogRecord admitted_record(const WorldState& state, std::uint32_t id, AdmissionKind kind) {
  const AgentRecord& a = state.agent(id);
  proto::LogRecord record;
  proto::AgentAdmitted* r = record.mutable_admitted();
  r->set_step(state.step);
  r->set_agent_id(id);
  r->set_session(a.session);
  r->set_name(a.name);
  r->set_readmission(kind == AdmissionKind::kReadmission);
  r->set_takeover(kind == AdmissionKind::kTakeover);
  return record;
}

proto::LogRecord dropped_record(const WorldState& state, std::uint32_t id, const std::string& reason) {
  proto::LogRecord record;
  proto::AgentDropped* r = record.mutable_dropped();
  r->set_step(state.step);
  r->set_agent_id(id);
  r->set_reason(reason);
  return record;
}

proto::LogRecord step_record(const std::vector<Submission>& submissions, const StepOutcome& outcome,
                             const WorldState& after, std::uint32_t surplus) {
  proto::LogRecord record;
  proto::StepRecord* r = record.mutable_step();
  r->set_step(outcome.step);
  r->mutable_requests()->Reserve(static_cast<int>(submissions.size()));
  for (std::size_t i = 0; i < submissions.size(); ++i) {
    const bool accepted = i < outcome.accepted_submissions.size() && outcome.accepted_submissions[i];
    *r->add_requests() =
        logged(submissions[i], accepted, i < outcome.raised_cells.size() ? &outcome.raised_cells[i] : nullptr);
  }
  r->set_deposited_volume_m3(after.deposited_volume_m3);
  r->set_surplus_requests(surplus);
  return record;
}

Submission logged_submission(const proto::LoggedRequest& request) { return submission(request); }

proto::Snapshot make_snapshot(const WorldState& state, const std::string& run_id, std::uint64_t log_offset) {
  proto::Snapshot s;
  s.set_format_version(kSnapshotFormat);
  s.set_run_id(run_id);
  s.set_step(state.step);
  s.set_log_offset(log_offset);
  s.set_heights(pack(state.terrain.data(), static_cast<std::size_t>(state.terrain.rows()) * state.terrain.cols()));
  if (state.depositor.size() > 0)
    s.set_depositor(pack(state.depositor.data(), static_cast<std::size_t>(state.depositor.size())));
  for (std::uint64_t v : state.tile_versions) s.add_tile_versions(v);
  s.set_deposited_volume_m3(state.deposited_volume_m3);
  s.set_idle_steps(state.idle_steps);
  s.set_close_passes(state.close_passes);
  s.set_overlap_pair_steps(state.overlap_pair_steps);
  s.set_rejected_motions(state.rejected_motions);
  s.set_stall_best_progress(state.stall.best_progress);
  s.set_stall_quiet_since(state.stall.quiet_since);
  s.set_stall_longest_quiet(state.stall.longest_quiet);
  s.set_check_met(state.check.met);
  s.set_check_level_fraction(state.check.level_fraction);
  s.set_check_evaluations(state.check.evaluations);
  s.set_check_route_gap_m3(state.check.route_gap_m3);
  if (state.completion != scenario::CompletionKind::kAgentsAtGoal)
    for (const CellIndex& c : state.check.occupancy.pending_changes()) {
      s.add_check_pending_cells(c.row);
      s.add_check_pending_cells(c.col);
    }
  for (const AgentRecord& a : state.agents) {
    proto::AgentSnapshot* p = s.add_agents();
    p->set_agent_id(a.id);
    p->set_admitted(a.admitted);
    p->set_alive(a.alive);
    p->set_dropped(a.dropped);
    p->set_drop_reason(a.drop_reason);
    p->set_readmissions(a.readmissions);
    p->set_session(a.session);
    p->set_name(a.name);
    p->set_x_m(a.position.x);
    p->set_y_m(a.position.y);
    p->set_z_m(a.z_m);
    p->set_material_m3(a.material_m3);
    p->set_accepted(a.accepted);
    p->set_rejected(a.rejected);
    p->set_missed(a.missed);
    p->set_consecutive_missed(a.consecutive_missed);
    p->set_recent_misses(a.recent_misses);
    p->set_deposited_m3(a.deposited_m3);
    p->set_at_goal(a.at_goal);
    p->set_state(a.state);
    p->set_waiting_for(a.waiting_for);
    p->set_last_result(static_cast<std::uint32_t>(a.last_result));
    p->set_last_reason(a.last_reason);
    p->set_heading_rad(a.heading_rad);
  }
  s.set_unattributed_rejections(state.unattributed_rejections);
  s.set_surplus_requests(state.surplus_requests);
  s.set_resumes(state.resumes);
  s.set_terrain_sha256(runlog::terrain_sha256(state.terrain));
  s.set_snapshot_crc32c(snapshot_crc(s));
  return s;
}

proto::Snapshot read_snapshot(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open the snapshot", path));
  std::ostringstream bytes;
  bytes << in.rdbuf();
  proto::Snapshot s;
  if (!s.ParseFromString(bytes.str())) throw ParseError(path, 0, "not a snapshot (it does not parse)");
  if (s.format_version() != kSnapshotFormat)
    throw ParseError(path, 0, fmt::format("snapshot format {} is not the known format 1", s.format_version()));
  if (snapshot_crc(s) != s.snapshot_crc32c()) throw ParseError(path, 0, "the snapshot fails its checksum");
  return s;
}

void write_snapshot(const std::string& path, const proto::Snapshot& snapshot) {
  runlog::write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !snapshot.SerializeToOstream(&out) || !out.flush())
      throw IoError(fmt::format("{}: cannot write the snapshot", tmp));
  });
}

void restore_snapshot(WorldState& state, const proto::Snapshot& s, const std::string& file) {
  const auto bad = [&](const std::string& what) { return ParseError(file, 0, what); };
  const auto cells = static_cast<std::size_t>(state.terrain.rows()) * state.terrain.cols();
  if (static_cast<std::size_t>(s.agents_size()) != state.agents.size())
    throw bad(fmt::format("the snapshot holds {} agents, the run {}", s.agents_size(), state.agents.size()));
  if (static_cast<std::size_t>(s.tile_versions_size()) != state.tile_versions.size())
    throw bad(fmt::format("the snapshot holds {} tile versions, the grid has {} tiles", s.tile_versions_size(),
                          state.tile_versions.size()));
  unpack(s.heights(), state.terrain.data(), cells, file, "heights");
  if (runlog::terrain_sha256(state.terrain) != s.terrain_sha256())
    throw bad("the snapshot's heights do not match its terrain_sha256");
  if (!s.depositor().empty()) {
    state.depositor = AgentIdGrid::Zero(state.terrain.rows(), state.terrain.cols());
    unpack(s.depositor(), state.depositor.data(), cells, file, "depositor");
  }
  state.step = s.step();
  for (int i = 0; i < s.tile_versions_size(); ++i)
    state.tile_versions[static_cast<std::size_t>(i)] = s.tile_versions(i);
  state.deposited_volume_m3 = s.deposited_volume_m3();
  state.idle_steps = s.idle_steps();
  state.close_passes = s.close_passes();
  state.overlap_pair_steps = s.overlap_pair_steps();
  state.rejected_motions = s.rejected_motions();
  state.stall.best_progress = s.stall_best_progress();
  state.stall.quiet_since = s.stall_quiet_since();
  state.stall.longest_quiet = s.stall_longest_quiet();
  state.unattributed_rejections = s.unattributed_rejections();
  state.surplus_requests = s.surplus_requests();
  state.resumes = s.resumes();
  for (std::size_t i = 0; i < state.agents.size(); ++i) {
    const proto::AgentSnapshot& p = s.agents(static_cast<int>(i));
    AgentRecord& a = state.agents[i];
    if (p.agent_id() != a.id) throw bad(fmt::format("agent {} out of order", p.agent_id()));
    if (p.last_result() > static_cast<std::uint32_t>(protocol::ActionResult::kMissed))
      throw bad(fmt::format("agent {}: last_result {} is undefined", a.id, p.last_result()));
    a.admitted = p.admitted();
    a.alive = p.alive();
    a.dropped = p.dropped();
    a.drop_reason = p.drop_reason();
    a.readmissions = p.readmissions();
    a.session = p.session();
    a.name = p.name();
    a.position.x = p.x_m();
    a.position.y = p.y_m();
    a.z_m = p.z_m();
    a.material_m3 = p.material_m3();
    a.accepted = p.accepted();
    a.rejected = p.rejected();
    a.missed = p.missed();
    a.consecutive_missed = p.consecutive_missed();
    a.recent_misses = static_cast<std::uint16_t>(p.recent_misses());
    a.deposited_m3 = p.deposited_m3();
    a.at_goal = p.at_goal();
    a.state = p.state();
    a.waiting_for = p.waiting_for();
    a.last_result = static_cast<protocol::ActionResult>(p.last_result());
    a.last_reason = p.last_reason();
    if (p.has_heading_rad() && !std::isfinite(p.heading_rad()))
      throw bad(fmt::format("agent {}: heading {} is not finite", a.id, p.heading_rad()));
    a.heading_rad = p.has_heading_rad() ? p.heading_rad() : initial_heading_rad(a);
  }
  if (state.completion != scenario::CompletionKind::kAgentsAtGoal) {
    // The cache on the snapshot's terrain, with the changes its last evaluation has not seen yet: from here it
    // answers as the world's own cache did (occupancy_cache.hpp, pending_changes()).
    state.check.occupancy = OccupancyCache(state.terrain, state.check.occupancy.area(), state.check.occupancy.params());
    if (s.check_pending_cells_size() % 2 != 0) throw bad("check_pending_cells holds an odd count");
    for (int i = 0; i + 1 < s.check_pending_cells_size(); i += 2) {
      const CellIndex c{s.check_pending_cells(i), s.check_pending_cells(i + 1)};
      if (!state.terrain.contains(c)) throw bad("a pending cell lies off the grid");
      state.check.occupancy.mark_changed(c);
    }
  }
  state.check.met = s.check_met();
  state.check.level_fraction = s.check_level_fraction();
  state.check.evaluations = s.check_evaluations();
  state.check.route_gap_m3 = s.check_route_gap_m3();
}

void apply_record(WorldState& state, const proto::LogRecord& record, const std::string& where) {
  const auto bad = [&](const std::string& what) { return ParseError(where, 0, what); };
  switch (record.record_case()) {
    case proto::LogRecord::kAdmitted: {
      const proto::AgentAdmitted& r = record.admitted();
      if (!state.has_agent(r.agent_id()))
        throw bad(fmt::format("admission of agent {}, which has no slot", r.agent_id()));
      protocol::AgentHello hello;
      hello.agent_id = r.agent_id();
      hello.session = r.session();
      hello.name = r.name();
      hello.body = state.agent(r.agent_id()).type.body;
      const AdmissionKind kind = r.readmission() ? AdmissionKind::kReadmission
                                 : r.takeover()  ? AdmissionKind::kTakeover
                                                 : AdmissionKind::kFirst;
      if (!admit(state, hello, kind) && kind == AdmissionKind::kFirst)
        throw bad(fmt::format("agent {} admitted twice", r.agent_id()));
      return;
    }
    case proto::LogRecord::kDropped: {
      const proto::AgentDropped& r = record.dropped();
      if (!state.has_agent(r.agent_id()) || !state.agent(r.agent_id()).alive)
        throw bad(fmt::format("drop of agent {}, which is not live", r.agent_id()));
      drop_agent(state, r.agent_id(), r.reason());
      return;
    }
    case proto::LogRecord::kStep: {
      const proto::StepRecord& r = record.step();
      if (r.step() != state.step)
        throw bad(fmt::format("step {} where step {} was due", r.step(), state.step));
      std::vector<Submission> submissions;
      submissions.reserve(static_cast<std::size_t>(r.requests_size()));
      for (const proto::LoggedRequest& q : r.requests()) submissions.push_back(submission(q));
      const StepOutcome outcome = apply_step(state, submissions);
      state.surplus_requests += r.surplus_requests();
      for (int i = 0; i < r.requests_size(); ++i)
        if (outcome.accepted_submissions[static_cast<std::size_t>(i)] != r.requests(i).accepted())
          throw bad(fmt::format(
              "step {}: request {} of agent {} was {} by the run and is {} on replay: the log and this world's rules "
              "disagree",
              r.step(), i, r.requests(i).agent_id(), r.requests(i).accepted() ? "accepted" : "rejected",
              outcome.accepted_submissions[static_cast<std::size_t>(i)] ? "accepted" : "rejected"));
      if (!(state.deposited_volume_m3 == r.deposited_volume_m3()))
        throw bad(fmt::format("step {}: deposited volume {} m3 on replay, {} m3 in the run", r.step(),
                              state.deposited_volume_m3, r.deposited_volume_m3()));
      return;
    }
    case proto::LogRecord::kResumed: ++state.resumes; return;
    case proto::LogRecord::kHeader:
    case proto::LogRecord::kEnd:
    case proto::LogRecord::RECORD_NOT_SET: return;
  }
}

RebuiltState rebuild_state(const std::string& dir, WorldState initial, runlog::RunLogReader& reader) {
  namespace fs = std::filesystem;
  RebuiltState out;
  out.state = std::move(initial);
  out.header = reader.header();
  const std::string log_path = (fs::path(dir) / kRunLogFile).string();
  const std::string snapshot_path = (fs::path(dir) / kSnapshotFile).string();
  std::uint64_t offset = reader.first_record_offset();
  if (fs::exists(snapshot_path)) {
    try {
      const proto::Snapshot s = read_snapshot(snapshot_path);
      if (s.run_id() != out.header.run_id())
        throw ParseError(snapshot_path, 0,
                         fmt::format("it belongs to run '{}', not '{}'", s.run_id(), out.header.run_id()));
      if (s.log_offset() < reader.first_record_offset() || s.log_offset() > reader.file_bytes())
        throw ParseError(snapshot_path, 0, fmt::format("its log offset {} lies outside run.log", s.log_offset()));
      WorldState restored = out.state;
      restore_snapshot(restored, s, snapshot_path);
      out.state = std::move(restored);
      out.snapshot_step = s.step();
      offset = s.log_offset();
    } catch (const Error& e) {
      out.snapshot_problem = e.what();
    }
  }
  reader.seek(offset);
  proto::LogRecord record;
  for (std::uint64_t at = reader.offset(); reader.next(record); at = reader.offset()) {
    const std::string where = fmt::format("{} (record at byte {})", log_path, at);
    apply_record(out.state, record, where);
    ++out.records;
    if (record.has_end()) {
      out.ended = true;
      out.end_reason = record.end().end_reason();
    }
  }
  out.tail_problem = reader.tail_problem();
  out.good_bytes = reader.offset();
  return out;
}

}  // namespace marsala::world_server
