#include "marsala/bus/fastdds/fastdds_convert.hpp"

namespace marsala::bus::fastdds {
using protocol::ActionResult;
using protocol::AgentStatus;
using protocol::Deposit;
using protocol::Deposition;
using protocol::EventKind;
using protocol::Neighbour;
using protocol::ScanPoint;
using protocol::TerrainTile;

namespace {

wire::BodyParams to_msg(const RobotBody& in) {
  wire::BodyParams out;
  out.kappa(in.navigability.kappa);
  out.delta_m(in.navigability.delta_m);
  out.eps_m(in.navigability.eps_m);
  out.max_step_m(in.max_step_m);
  out.max_deposit_m3(in.max_deposit_m3);
  out.material_capacity_m3(in.material_capacity_m3);
  out.reach_m(in.reach_m);
  out.sensing_range_m(in.sensing_range_m);
  out.proximity_range_m(in.proximity_range_m);
  out.cube_size_m(in.cube_size_m);
  return out;
}

RobotBody from_msg(const wire::BodyParams& in) {
  RobotBody out;
  out.navigability.kappa = in.kappa();
  out.navigability.delta_m = in.delta_m();
  out.navigability.eps_m = in.eps_m();
  out.max_step_m = in.max_step_m();
  out.max_deposit_m3 = in.max_deposit_m3();
  out.material_capacity_m3 = in.material_capacity_m3();
  out.reach_m = in.reach_m();
  out.sensing_range_m = in.sensing_range_m();
  out.proximity_range_m = in.proximity_range_m();
  out.cube_size_m = in.cube_size_m();
  return out;
}

}  // namespace

wire::AgentHello to_msg(const AgentHello& in) {
  wire::AgentHello out;
  out.agent_id(in.agent_id);
  out.session(in.session);
  out.name(in.name);
  out.behaviour(in.behaviour);
  out.body(to_msg(in.body));
  return out;
}

AgentHello from_msg(const wire::AgentHello& in) {
  AgentHello out;
  out.agent_id = in.agent_id();
  out.session = in.session();
  out.name = in.name();
  out.behaviour = in.behaviour();
  out.body = from_msg(in.body());
  return out;
}

wire::Admission to_msg(const Admission& in) {
  wire::Admission out;
  out.agent_id(in.agent_id);
  out.session(in.session);
  out.accepted(in.accepted);
  out.reason(in.reason);
  out.run_id(in.run_id);
  out.rows(in.assignment.world.rows);
  out.cols(in.assignment.world.cols);
  out.xll_m(in.assignment.world.xll_m);
  out.yll_m(in.assignment.world.yll_m);
  out.cell_size_m(in.assignment.world.cell_size_m);
  out.tile_size(in.assignment.tile_size);
  out.start_x_m(in.assignment.start.x);
  out.start_y_m(in.assignment.start.y);
  out.target_x_m(in.assignment.target.x);
  out.target_y_m(in.assignment.target.y);
  out.base_x_m(in.assignment.base.x);
  out.base_y_m(in.assignment.base.y);
  out.base_radius_m(in.assignment.base_radius_m);
  out.world_key(in.world_key);
  out.world_proof(in.world_proof);
  return out;
}

Admission from_msg(const wire::Admission& in) {
  Admission out;
  out.agent_id = in.agent_id();
  out.session = in.session();
  out.accepted = in.accepted();
  out.reason = in.reason();
  out.run_id = in.run_id();
  out.assignment.world.rows = in.rows();
  out.assignment.world.cols = in.cols();
  out.assignment.world.xll_m = in.xll_m();
  out.assignment.world.yll_m = in.yll_m();
  out.assignment.world.cell_size_m = in.cell_size_m();
  out.assignment.tile_size = in.tile_size();
  out.assignment.start.x = in.start_x_m();
  out.assignment.start.y = in.start_y_m();
  out.assignment.target.x = in.target_x_m();
  out.assignment.target.y = in.target_y_m();
  out.assignment.base.x = in.base_x_m();
  out.assignment.base.y = in.base_y_m();
  out.assignment.base_radius_m = in.base_radius_m();
  out.world_key = in.world_key();
  out.world_proof = in.world_proof();
  return out;
}

wire::SensorFrame to_msg(const SensorFrame& in) {
  wire::SensorFrame out;
  out.agent_id(in.agent_id);
  out.step(in.step);
  out.x_m(in.x_m);
  out.y_m(in.y_m);
  out.z_m(in.z_m);
  out.material_m3(in.material_m3);
  out.last_result(static_cast<std::uint8_t>(in.last_result));
  out.last_reason(in.last_reason);
  out.tiles().reserve(in.tiles.size());
  for (const TerrainTile& t : in.tiles) {
    wire::TerrainTile tile;
    tile.tile_row(t.tile_row);
    tile.tile_col(t.tile_col);
    tile.rows(t.rows);
    tile.cols(t.cols);
    tile.heights(t.heights);
    out.tiles().push_back(std::move(tile));
  }
  out.neighbours().reserve(in.neighbours.size());
  for (const Neighbour& n : in.neighbours) {
    wire::Neighbour neighbour;
    neighbour.agent_id(n.agent_id);
    neighbour.x_m(n.position.x);
    neighbour.y_m(n.position.y);
    neighbour.z_m(n.z_m);
    neighbour.radius_m(n.radius_m);
    out.neighbours().push_back(neighbour);
  }
  out.run_over(in.run_over);
  out.scanned(in.scanned);
  out.points().reserve(in.points.size());
  for (const ScanPoint& p : in.points) {
    wire::ScanPoint point;
    point.x_m(p.x_m);
    point.y_m(p.y_m);
    point.z_m(p.z_m);
    out.points().push_back(point);
  }
  return out;
}

SensorFrame from_msg(const wire::SensorFrame& in) {
  SensorFrame out;
  out.agent_id = in.agent_id();
  out.step = in.step();
  out.x_m = in.x_m();
  out.y_m = in.y_m();
  out.z_m = in.z_m();
  out.material_m3 = in.material_m3();
  out.last_result = protocol::action_result_from_wire(in.last_result());
  out.last_reason = in.last_reason();
  out.tiles.reserve(in.tiles().size());
  for (const wire::TerrainTile& t : in.tiles()) {
    TerrainTile tile;
    tile.tile_row = t.tile_row();
    tile.tile_col = t.tile_col();
    tile.rows = t.rows();
    tile.cols = t.cols();
    tile.heights = t.heights();
    out.tiles.push_back(std::move(tile));
  }
  out.neighbours.reserve(in.neighbours().size());
  for (const wire::Neighbour& n : in.neighbours()) {
    Neighbour neighbour;
    neighbour.agent_id = n.agent_id();
    neighbour.position = {n.x_m(), n.y_m()};
    neighbour.z_m = n.z_m();
    neighbour.radius_m = n.radius_m();
    out.neighbours.push_back(neighbour);
  }
  out.run_over = in.run_over();
  out.scanned = in.scanned();
  out.points.reserve(in.points().size());
  for (const wire::ScanPoint& p : in.points()) out.points.push_back({p.x_m(), p.y_m(), p.z_m()});
  return out;
}

wire::ActionRequest to_msg(const ActionRequest& in) {
  wire::ActionRequest out;
  out.agent_id(in.agent_id);
  out.session(in.session);
  out.step(in.step);
  out.move(in.move);
  out.target_x_m(in.target_x_m);
  out.target_y_m(in.target_y_m);
  out.depositions().reserve(in.depositions.size());
  for (const Deposition& d : in.depositions) {
    wire::Deposition deposition;
    deposition.row(d.row);
    deposition.col(d.col);
    deposition.height_m(d.height_m);
    out.depositions().push_back(deposition);
  }
  out.deposits().reserve(in.deposits.size());
  for (const Deposit& d : in.deposits) {
    wire::Deposit deposit;
    deposit.x_m(d.centre.x);
    deposit.y_m(d.centre.y);
    deposit.volume_m3(d.volume_m3);
    out.deposits().push_back(deposit);
  }
  out.refill(in.refill);
  out.state(in.state);
  out.waiting_for(in.waiting_for);
  out.decision_us(in.decision_us);
  out.decision_cpu_us(in.decision_cpu_us);
  out.standing(in.standing);
  return out;
}

ActionRequest from_msg(const wire::ActionRequest& in) {
  ActionRequest out;
  out.agent_id = in.agent_id();
  out.session = in.session();
  out.step = in.step();
  out.move = in.move();
  out.target_x_m = in.target_x_m();
  out.target_y_m = in.target_y_m();
  out.depositions.reserve(in.depositions().size());
  for (const wire::Deposition& d : in.depositions()) {
    Deposition deposition;
    deposition.row = d.row();
    deposition.col = d.col();
    deposition.height_m = d.height_m();
    out.depositions.push_back(deposition);
  }
  out.deposits.reserve(in.deposits().size());
  for (const wire::Deposit& d : in.deposits()) {
    Deposit deposit;
    deposit.centre = {d.x_m(), d.y_m()};
    deposit.volume_m3 = d.volume_m3();
    out.deposits.push_back(deposit);
  }
  out.refill = in.refill();
  out.state = in.state();
  out.waiting_for = in.waiting_for();
  out.decision_us = in.decision_us();
  out.decision_cpu_us = in.decision_cpu_us();
  out.standing = in.standing();
  return out;
}

wire::WorldStatus to_msg(const WorldStatus& in) {
  wire::WorldStatus out;
  out.run_id(in.run_id);
  out.scenario(in.scenario);
  out.step(in.step);
  out.wall_seconds(in.wall_seconds);
  out.deposited_volume_m3(in.deposited_volume_m3);
  out.progress(in.progress);
  out.running(in.running);
  out.completed(in.completed);
  out.world_id(in.world_id);
  out.admitting(in.admitting);
  out.progress_detail(in.progress_detail);
  out.team_size(in.team_size);
  out.world_key(in.world_key);
  out.world_proof(in.world_proof);
  out.agents().reserve(in.agents.size());
  for (const AgentStatus& a : in.agents) {
    wire::AgentStatus agent;
    agent.agent_id(a.agent_id);
    agent.name(a.name);
    agent.state(a.state);
    agent.waiting_for(a.waiting_for);
    agent.x_m(a.x_m);
    agent.y_m(a.y_m);
    agent.z_m(a.z_m);
    agent.material_m3(a.material_m3);
    agent.deposited_m3(a.deposited_m3);
    agent.accepted(a.accepted);
    agent.rejected(a.rejected);
    agent.missed(a.missed);
    agent.alive(a.alive);
    agent.at_goal(a.at_goal);
    out.agents().push_back(std::move(agent));
  }
  return out;
}

WorldStatus from_msg(const wire::WorldStatus& in) {
  WorldStatus out;
  out.run_id = in.run_id();
  out.scenario = in.scenario();
  out.step = in.step();
  out.wall_seconds = in.wall_seconds();
  out.deposited_volume_m3 = in.deposited_volume_m3();
  out.progress = in.progress();
  out.running = in.running();
  out.completed = in.completed();
  out.world_id = in.world_id();
  out.admitting = in.admitting();
  out.progress_detail = in.progress_detail();
  out.team_size = in.team_size();
  out.world_key = in.world_key();
  out.world_proof = in.world_proof();
  out.agents.reserve(in.agents().size());
  for (const wire::AgentStatus& a : in.agents()) {
    AgentStatus agent;
    agent.agent_id = a.agent_id();
    agent.name = a.name();
    agent.state = a.state();
    agent.waiting_for = a.waiting_for();
    agent.x_m = a.x_m();
    agent.y_m = a.y_m();
    agent.z_m = a.z_m();
    agent.material_m3 = a.material_m3();
    agent.deposited_m3 = a.deposited_m3();
    agent.accepted = a.accepted();
    agent.rejected = a.rejected();
    agent.missed = a.missed();
    agent.alive = a.alive();
    agent.at_goal = a.at_goal();
    out.agents.push_back(std::move(agent));
  }
  return out;
}

wire::WorldEvent to_msg(const WorldEvent& in) {
  wire::WorldEvent out;
  out.step(in.step);
  out.agent_id(in.agent_id);
  out.kind(static_cast<std::uint8_t>(in.kind));
  out.volume_m3(in.volume_m3);
  out.detail(in.detail);
  return out;
}

WorldEvent from_msg(const wire::WorldEvent& in) {
  WorldEvent out;
  out.step = in.step();
  out.agent_id = in.agent_id();
  out.kind = protocol::event_kind_from_wire(in.kind());
  out.volume_m3 = in.volume_m3();
  out.detail = in.detail();
  return out;
}

}  // namespace marsala::bus::fastdds
