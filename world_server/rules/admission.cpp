#include "marsala/world_server/rules/admission.hpp"

#include <cstdio>

#include "marsala/core/format.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {
namespace {

constexpr std::size_t kMaxNameChars = 64;  // names are for display only

/// The first field in which `got` differs from `want`, as "kappa 0.2 != 0.3", or empty.
std::string body_difference(const RobotBody& got, const RobotBody& want) {
  const struct {
    const char* name;
    double got, want;
  } fields[] = {{"kappa", got.navigability.kappa, want.navigability.kappa},
                {"delta_m", got.navigability.delta_m, want.navigability.delta_m},
                {"eps_m", got.navigability.eps_m, want.navigability.eps_m},
                {"max_step_m", got.max_step_m, want.max_step_m},
                {"max_deposit_m3", got.max_deposit_m3, want.max_deposit_m3},
                {"material_capacity_m3", got.material_capacity_m3, want.material_capacity_m3},
                {"reach_m", got.reach_m, want.reach_m},
                {"sensing_range_m", got.sensing_range_m, want.sensing_range_m},
                {"proximity_range_m", got.proximity_range_m, want.proximity_range_m},
                {"cube_size_m", got.cube_size_m, want.cube_size_m}};
  for (const auto& f : fields)
    if (!(f.got == f.want))
      return fmt::format("{} {} != {}", f.name, f.got, f.want);
  return {};
}

}  // namespace

namespace {

AdmissionDecision decide_any_slot(const WorldState& state, const protocol::AgentHello& hello, bool run_started) {
  const auto refuse = [](const std::string& reason) {
    return AdmissionDecision{false, fmt::format("any slot: {}", reason), AdmissionKind::kRefused, kAnySlot};
  };
  for (const AgentRecord& a : state.agents)
    if (a.admitted && a.session == hello.session) return {true, {}, AdmissionKind::kRepeat, a.id};
  const std::string problem = body_problem(hello.body);
  if (!problem.empty()) return refuse(fmt::format("invalid body: {}", problem));
  if (run_started) return refuse("the run has already started");
  std::size_t of_type = 0;
  for (const AgentRecord& a : state.agents) {
    if (!body_difference(hello.body, a.type.body).empty() || a.type.behaviour != hello.behaviour) continue;
    ++of_type;
    if (!a.admitted && !a.dropped) return {true, {}, AdmissionKind::kFirst, a.id};
  }
  if (of_type == 0)
    return refuse(
        fmt::format("no slot of this run has a robot type with this body and behaviour '{}'", hello.behaviour));
  return refuse(fmt::format("all {} slots of this robot type are taken", of_type));
}

}  // namespace

AdmissionDecision decide_admission(const WorldState& state, const protocol::AgentHello& hello, bool run_started,
                                   bool holder_connected) {
  const auto refuse = [&](std::string reason) {
    return AdmissionDecision{false, std::move(reason), AdmissionKind::kRefused, hello.agent_id};
  };
  const auto accept = [&](AdmissionKind kind) { return AdmissionDecision{true, {}, kind, hello.agent_id}; };
  if (hello.agent_id == kAnySlot) return decide_any_slot(state, hello, run_started);
  if (!state.has_agent(hello.agent_id))
    return refuse(fmt::format("unknown agent id {}: this run has agents 1..{}", hello.agent_id, state.agents.size()));
  const AgentRecord& slot = state.agent(hello.agent_id);
  const std::string problem = body_problem(hello.body);
  if (!problem.empty()) return refuse(fmt::format("agent {}: invalid body: {}", hello.agent_id, problem));
  const std::string difference = body_difference(hello.body, slot.type.body);
  if (!difference.empty())
    return refuse(fmt::format("agent {}: body differs from robot type '{}' of its slot: {}", hello.agent_id,
                              slot.type.name, difference));
  if (slot.dropped) {
    if (slot.readmissions >= kMaxReadmissions)
      return refuse(
          fmt::format("agent {} was dropped from the run: {}; it has taken its slot back {} times, the most a run "
                      "allows",
                      hello.agent_id, slot.drop_reason, slot.readmissions));
    return accept(AdmissionKind::kReadmission);
  }
  if (slot.admitted) {
    if (slot.session == hello.session) return accept(AdmissionKind::kRepeat);
    if (!holder_connected) return accept(AdmissionKind::kTakeover);
    return refuse(
        fmt::format("agent {} is already admitted with another session that is still connected", hello.agent_id));
  }
  if (run_started) return refuse(fmt::format("agent {}: the run has already started", hello.agent_id));
  return accept(AdmissionKind::kFirst);
}

bool admit(WorldState& state, const protocol::AgentHello& hello, AdmissionKind kind) {
  AgentRecord& a = state.agent(hello.agent_id);
  if (kind == AdmissionKind::kReadmission || kind == AdmissionKind::kTakeover) {
    if (kind == AdmissionKind::kReadmission) ++a.readmissions;
    a.alive = true;
    a.dropped = false;
    a.drop_reason.clear();
    a.session = hello.session;
    a.name = hello.name.substr(0, kMaxNameChars);
    a.consecutive_missed = 0;
    a.recent_misses = 0;
    a.at_goal = at_goal(state, a);
    return true;
  }
  if (kind != AdmissionKind::kFirst || a.admitted) return false;
  a.admitted = true;
  a.alive = true;
  a.session = hello.session;
  a.name = hello.name.substr(0, kMaxNameChars);
  a.position.x = a.start.x;
  a.position.y = a.start.y;
  a.heading_rad = initial_heading_rad(a);
  a.z_m = height_under(state.terrain, a.position.x, a.position.y);
  a.material_m3 = a.type.body.material_capacity_m3;
  a.at_goal = at_goal(state, a);
  return true;
}

protocol::AgentHello slot_hello(const WorldState& state, const protocol::AgentHello& hello,
                                const AdmissionDecision& decision) {
  protocol::AgentHello slot = hello;
  slot.agent_id = decision.agent_id;
  if (hello.agent_id == kAnySlot && state.has_agent(slot.agent_id))
    slot.name = fmt::format("{}-{}", state.agent(slot.agent_id).type.name, slot.agent_id);
  return slot;
}

protocol::Admission admission_message(const WorldState& state, const protocol::AgentHello& hello,
                                      const AdmissionDecision& decision, const std::string& run_id) {
  protocol::Admission m;
  m.agent_id = decision.agent_id != kAnySlot ? decision.agent_id : hello.agent_id;
  m.session = hello.session;
  m.accepted = decision.accepted;
  m.reason = decision.reason;
  m.run_id = run_id;
  const GridGeometry& g = state.terrain.geometry();
  m.assignment.world = g;
  m.assignment.tile_size = state.tile_size;
  m.assignment.base = {state.base.centre.x, state.base.centre.y};
  m.assignment.base_radius_m = state.base.radius_m;
  if (state.has_agent(m.agent_id)) {
    const AgentRecord& a = state.agent(m.agent_id);
    m.assignment.start = a.start;
    m.assignment.target = a.target;
  }
  return m;
}

}  // namespace marsala::world_server
