#include "marsala/bus/cyclone/cyclone_convert.hpp"

#include <string>
#include <type_traits>

namespace marsala::bus::cyclone {
using protocol::ActionResult;
using protocol::AgentStatus;
using protocol::Deposit;
using protocol::Deposition;
using protocol::EventKind;
using protocol::Neighbour;
using protocol::ScanPoint;
using protocol::TerrainTile;

namespace {

// The C types are only read by dds_write, so borrowing const data through non-const pointers is safe.
char* borrow(const std::string& s) { return const_cast<char*>(s.c_str()); }
std::string copy(const char* s) { return s ? std::string(s) : std::string(); }

template <typename Seq, typename Elem>
Seq borrow_seq(const std::vector<Elem>& v) {
  Seq seq{};
  seq._maximum = seq._length = static_cast<std::uint32_t>(v.size());
  seq._buffer = v.empty() ? nullptr : const_cast<Elem*>(v.data());
  seq._release = false;
  return seq;
}

template <typename Seq>
auto copy_seq(const Seq& seq) {
  using Elem = std::remove_cv_t<std::remove_pointer_t<decltype(seq._buffer)>>;
  return seq._length == 0 ? std::vector<Elem>() : std::vector<Elem>(seq._buffer, seq._buffer + seq._length);
}

marsala_wire_BodyParams to_msg(const RobotBody& in) {
  marsala_wire_BodyParams out{};
  out.kappa = in.navigability.kappa;
  out.delta_m = in.navigability.delta_m;
  out.eps_m = in.navigability.eps_m;
  out.max_step_m = in.max_step_m;
  out.max_deposit_m3 = in.max_deposit_m3;
  out.material_capacity_m3 = in.material_capacity_m3;
  out.reach_m = in.reach_m;
  out.sensing_range_m = in.sensing_range_m;
  out.proximity_range_m = in.proximity_range_m;
  out.cube_size_m = in.cube_size_m;
  return out;
}

RobotBody from_msg(const marsala_wire_BodyParams& in) {
  RobotBody out;
  out.navigability.kappa = in.kappa;
  out.navigability.delta_m = in.delta_m;
  out.navigability.eps_m = in.eps_m;
  out.max_step_m = in.max_step_m;
  out.max_deposit_m3 = in.max_deposit_m3;
  out.material_capacity_m3 = in.material_capacity_m3;
  out.reach_m = in.reach_m;
  out.sensing_range_m = in.sensing_range_m;
  out.proximity_range_m = in.proximity_range_m;
  out.cube_size_m = in.cube_size_m;
  return out;
}

}  // namespace

marsala_wire_AgentHello to_msg(const AgentHello& in, Storage&) {
  marsala_wire_AgentHello out{};
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.name = borrow(in.name);
  out.behaviour = borrow(in.behaviour);
  out.body = to_msg(in.body);
  return out;
}

AgentHello from_msg(const marsala_wire_AgentHello& in) {
  AgentHello out;
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.name = copy(in.name);
  out.behaviour = copy(in.behaviour);
  out.body = from_msg(in.body);
  return out;
}

marsala_wire_Admission to_msg(const Admission& in, Storage&) {
  marsala_wire_Admission out{};
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.accepted = in.accepted;
  out.reason = borrow(in.reason);
  out.run_id = borrow(in.run_id);
  out.rows = in.assignment.world.rows;
  out.cols = in.assignment.world.cols;
  out.xll_m = in.assignment.world.xll_m;
  out.yll_m = in.assignment.world.yll_m;
  out.cell_size_m = in.assignment.world.cell_size_m;
  out.tile_size = in.assignment.tile_size;
  out.start_x_m = in.assignment.start.x;
  out.start_y_m = in.assignment.start.y;
  out.target_x_m = in.assignment.target.x;
  out.target_y_m = in.assignment.target.y;
  out.base_x_m = in.assignment.base.x;
  out.base_y_m = in.assignment.base.y;
  out.base_radius_m = in.assignment.base_radius_m;
  out.world_key = borrow(in.world_key);
  out.world_proof = borrow(in.world_proof);
  return out;
}

Admission from_msg(const marsala_wire_Admission& in) {
  Admission out;
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.accepted = in.accepted;
  out.reason = copy(in.reason);
  out.run_id = copy(in.run_id);
  out.assignment.world.rows = in.rows;
  out.assignment.world.cols = in.cols;
  out.assignment.world.xll_m = in.xll_m;
  out.assignment.world.yll_m = in.yll_m;
  out.assignment.world.cell_size_m = in.cell_size_m;
  out.assignment.tile_size = in.tile_size;
  out.assignment.start.x = in.start_x_m;
  out.assignment.start.y = in.start_y_m;
  out.assignment.target.x = in.target_x_m;
  out.assignment.target.y = in.target_y_m;
  out.assignment.base.x = in.base_x_m;
  out.assignment.base.y = in.base_y_m;
  out.assignment.base_radius_m = in.base_radius_m;
  out.world_key = copy(in.world_key);
  out.world_proof = copy(in.world_proof);
  return out;
}

marsala_wire_SensorFrame to_msg(const SensorFrame& in, Storage& storage) {
  marsala_wire_SensorFrame out{};
  out.agent_id = in.agent_id;
  out.step = in.step;
  out.x_m = in.x_m;
  out.y_m = in.y_m;
  out.z_m = in.z_m;
  out.material_m3 = in.material_m3;
  out.last_result = static_cast<std::uint8_t>(in.last_result);
  out.last_reason = borrow(in.last_reason);
  storage.tiles.clear();
  for (const TerrainTile& t : in.tiles) {
    marsala_wire_TerrainTile tile{};
    tile.tile_row = t.tile_row;
    tile.tile_col = t.tile_col;
    tile.rows = t.rows;
    tile.cols = t.cols;
    tile.heights = borrow_seq<dds_sequence_double>(t.heights);
    storage.tiles.push_back(tile);
  }
  out.tiles = borrow_seq<dds_sequence_marsala_wire_TerrainTile>(storage.tiles);
  storage.neighbours.clear();
  for (const Neighbour& n : in.neighbours) {
    marsala_wire_Neighbour neighbour{};
    neighbour.agent_id = n.agent_id;
    neighbour.x_m = n.position.x;
    neighbour.y_m = n.position.y;
    neighbour.z_m = n.z_m;
    neighbour.radius_m = n.radius_m;
    storage.neighbours.push_back(neighbour);
  }
  out.neighbours = borrow_seq<dds_sequence_marsala_wire_Neighbour>(storage.neighbours);
  out.run_over = in.run_over;
  out.scanned = in.scanned;
  storage.points.clear();
  storage.points.reserve(in.points.size());
  for (const ScanPoint& p : in.points) storage.points.push_back({p.x_m, p.y_m, p.z_m});
  out.points = borrow_seq<dds_sequence_marsala_wire_ScanPoint>(storage.points);
  return out;
}

SensorFrame from_msg(const marsala_wire_SensorFrame& in) {
  SensorFrame out;
  out.agent_id = in.agent_id;
  out.step = in.step;
  out.x_m = in.x_m;
  out.y_m = in.y_m;
  out.z_m = in.z_m;
  out.material_m3 = in.material_m3;
  out.last_result = protocol::action_result_from_wire(in.last_result);
  out.last_reason = copy(in.last_reason);
  out.tiles.reserve(in.tiles._length);
  for (std::uint32_t i = 0; i < in.tiles._length; ++i) {
    const marsala_wire_TerrainTile& t = in.tiles._buffer[i];
    TerrainTile tile;
    tile.tile_row = t.tile_row;
    tile.tile_col = t.tile_col;
    tile.rows = t.rows;
    tile.cols = t.cols;
    tile.heights = copy_seq(t.heights);
    out.tiles.push_back(std::move(tile));
  }
  out.neighbours.reserve(in.neighbours._length);
  for (std::uint32_t i = 0; i < in.neighbours._length; ++i) {
    const marsala_wire_Neighbour& n = in.neighbours._buffer[i];
    Neighbour neighbour;
    neighbour.agent_id = n.agent_id;
    neighbour.position = {n.x_m, n.y_m};
    neighbour.z_m = n.z_m;
    neighbour.radius_m = n.radius_m;
    out.neighbours.push_back(neighbour);
  }
  out.run_over = in.run_over;
  out.scanned = in.scanned;
  out.points.reserve(in.points._length);
  for (std::uint32_t i = 0; i < in.points._length; ++i) {
    const marsala_wire_ScanPoint& p = in.points._buffer[i];
    out.points.push_back({p.x_m, p.y_m, p.z_m});
  }
  return out;
}

marsala_wire_ActionRequest to_msg(const ActionRequest& in, Storage& storage) {
  marsala_wire_ActionRequest out{};
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.step = in.step;
  out.move = in.move;
  out.target_x_m = in.target_x_m;
  out.target_y_m = in.target_y_m;
  storage.depositions.clear();
  for (const Deposition& d : in.depositions) {
    marsala_wire_Deposition deposition{};
    deposition.row = d.row;
    deposition.col = d.col;
    deposition.height_m = d.height_m;
    storage.depositions.push_back(deposition);
  }
  out.depositions = borrow_seq<dds_sequence_marsala_wire_Deposition>(storage.depositions);
  storage.deposits.clear();
  for (const Deposit& d : in.deposits) {
    marsala_wire_Deposit deposit{};
    deposit.x_m = d.centre.x;
    deposit.y_m = d.centre.y;
    deposit.volume_m3 = d.volume_m3;
    storage.deposits.push_back(deposit);
  }
  out.deposits = borrow_seq<dds_sequence_marsala_wire_Deposit>(storage.deposits);
  out.refill = in.refill;
  out.state = borrow(in.state);
  out.waiting_for = borrow(in.waiting_for);
  out.decision_us = in.decision_us;
  out.decision_cpu_us = in.decision_cpu_us;
  out.standing = in.standing;
  return out;
}

ActionRequest from_msg(const marsala_wire_ActionRequest& in) {
  ActionRequest out;
  out.agent_id = in.agent_id;
  out.session = in.session;
  out.step = in.step;
  out.move = in.move;
  out.target_x_m = in.target_x_m;
  out.target_y_m = in.target_y_m;
  out.depositions.reserve(in.depositions._length);
  for (std::uint32_t i = 0; i < in.depositions._length; ++i) {
    const marsala_wire_Deposition& d = in.depositions._buffer[i];
    Deposition deposition;
    deposition.row = d.row;
    deposition.col = d.col;
    deposition.height_m = d.height_m;
    out.depositions.push_back(deposition);
  }
  out.deposits.reserve(in.deposits._length);
  for (std::uint32_t i = 0; i < in.deposits._length; ++i) {
    const marsala_wire_Deposit& d = in.deposits._buffer[i];
    Deposit deposit;
    deposit.centre = {d.x_m, d.y_m};
    deposit.volume_m3 = d.volume_m3;
    out.deposits.push_back(deposit);
  }
  out.refill = in.refill;
  out.state = copy(in.state);
  out.waiting_for = copy(in.waiting_for);
  out.decision_us = in.decision_us;
  out.decision_cpu_us = in.decision_cpu_us;
  out.standing = in.standing;
  return out;
}

marsala_wire_WorldStatus to_msg(const WorldStatus& in, Storage& storage) {
  marsala_wire_WorldStatus out{};
  out.run_id = borrow(in.run_id);
  out.scenario = borrow(in.scenario);
  out.step = in.step;
  out.wall_seconds = in.wall_seconds;
  out.deposited_volume_m3 = in.deposited_volume_m3;
  out.progress = in.progress;
  out.running = in.running;
  out.completed = in.completed;
  out.world_id = in.world_id;
  out.admitting = in.admitting;
  out.progress_detail = borrow(in.progress_detail);
  out.team_size = in.team_size;
  out.world_key = borrow(in.world_key);
  out.world_proof = borrow(in.world_proof);
  storage.agents.clear();
  for (const AgentStatus& a : in.agents) {
    marsala_wire_AgentStatus agent{};
    agent.agent_id = a.agent_id;
    agent.name = borrow(a.name);
    agent.state = borrow(a.state);
    agent.waiting_for = borrow(a.waiting_for);
    agent.x_m = a.x_m;
    agent.y_m = a.y_m;
    agent.z_m = a.z_m;
    agent.material_m3 = a.material_m3;
    agent.deposited_m3 = a.deposited_m3;
    agent.accepted = a.accepted;
    agent.rejected = a.rejected;
    agent.missed = a.missed;
    agent.alive = a.alive;
    agent.at_goal = a.at_goal;
    storage.agents.push_back(agent);
  }
  out.agents = borrow_seq<dds_sequence_marsala_wire_AgentStatus>(storage.agents);
  return out;
}

WorldStatus from_msg(const marsala_wire_WorldStatus& in) {
  WorldStatus out;
  out.run_id = copy(in.run_id);
  out.scenario = copy(in.scenario);
  out.step = in.step;
  out.wall_seconds = in.wall_seconds;
  out.deposited_volume_m3 = in.deposited_volume_m3;
  out.progress = in.progress;
  out.running = in.running;
  out.completed = in.completed;
  out.world_id = in.world_id;
  out.admitting = in.admitting;
  out.progress_detail = copy(in.progress_detail);
  out.team_size = in.team_size;
  out.world_key = copy(in.world_key);
  out.world_proof = copy(in.world_proof);
  out.agents.reserve(in.agents._length);
  for (std::uint32_t i = 0; i < in.agents._length; ++i) {
    const marsala_wire_AgentStatus& a = in.agents._buffer[i];
    AgentStatus agent;
    agent.agent_id = a.agent_id;
    agent.name = copy(a.name);
    agent.state = copy(a.state);
    agent.waiting_for = copy(a.waiting_for);
    agent.x_m = a.x_m;
    agent.y_m = a.y_m;
    agent.z_m = a.z_m;
    agent.material_m3 = a.material_m3;
    agent.deposited_m3 = a.deposited_m3;
    agent.accepted = a.accepted;
    agent.rejected = a.rejected;
    agent.missed = a.missed;
    agent.alive = a.alive;
    agent.at_goal = a.at_goal;
    out.agents.push_back(std::move(agent));
  }
  return out;
}

marsala_wire_WorldEvent to_msg(const WorldEvent& in, Storage&) {
  marsala_wire_WorldEvent out{};
  out.step = in.step;
  out.agent_id = in.agent_id;
  out.kind = static_cast<std::uint8_t>(in.kind);
  out.volume_m3 = in.volume_m3;
  out.detail = borrow(in.detail);
  return out;
}

WorldEvent from_msg(const marsala_wire_WorldEvent& in) {
  WorldEvent out;
  out.step = in.step;
  out.agent_id = in.agent_id;
  out.kind = protocol::event_kind_from_wire(in.kind);
  out.volume_m3 = in.volume_m3;
  out.detail = copy(in.detail);
  return out;
}

}  // namespace marsala::bus::cyclone
