#include "marsala/agent/reactive/noisy_localisation.hpp"

#include <cmath>
#include <vector>

#include "marsala/core/random.hpp"

namespace marsala::agent::reactive {

CellIndex registration_offset(Position error, double cell_size_m) {
  return {-static_cast<int>(std::floor(0.5 + error.y / cell_size_m)),
          static_cast<int>(std::floor(0.5 + error.x / cell_size_m))};
}

NoisyLocalisation::NoisyLocalisation(const AgentContext& context, const std::string& inner_name)
    : context_(context),
      inner_name_(inner_name),
      inner_(make_behaviour(inner_name, context)),
      pose_error_(context.type.localisation, random::derive_seed(context.seed, context.agent_id)) {}

void NoisyLocalisation::on_admission(const protocol::Admission& admission) {
  AgentContext planning = context_;
  planning.agent_id = admission.agent_id;  // an --id auto agent learns its id here
  const Assignment assignment = assignment_from(planning, admission);
  world_ = assignment.world;
  tile_size_ = assignment.tile_size;
  sensed_.clear();
  inner_ = make_behaviour(inner_name_, planning);
  inner_->on_admission(admission);
  pose_error_ = executive::PoseError(context_.type.localisation,
                                     random::derive_seed(context_.seed, admission.agent_id));
  admitted_ = true;
}

protocol::ActionRequest NoisyLocalisation::decide(const protocol::SensorFrame& frame) {
  if (!admitted_ || frame.run_over) return inner_->decide(frame);
  error_ = pose_error_.at(frame.step);
  protocol::SensorFrame believed = frame;
  // The sensor sees its whole window from where the robot truly is: the tiles received now and before that meet it.
  for (const TerrainTile& t : frame.tiles) sensed_[{t.tile_row, t.tile_col}] = t;
  believed.tiles.clear();
  const double s = context_.type.body.sensing_range_m, tile_m = tile_size_ * world_.cell_size_m;
  const double top_m = world_.yll_m + world_.rows * world_.cell_size_m;
  const int c0 = static_cast<int>(std::floor((frame.x_m - s - world_.xll_m) / tile_m));
  const int c1 = static_cast<int>(std::floor((frame.x_m + s - world_.xll_m) / tile_m));
  const int r0 = static_cast<int>(std::floor((top_m - (frame.y_m + s)) / tile_m));
  const int r1 = static_cast<int>(std::floor((top_m - (frame.y_m - s)) / tile_m));
  for (auto it = sensed_.lower_bound({r0, c0}); it != sensed_.end() && it->first.first <= r1; ++it)
    if (it->first.second >= c0 && it->first.second <= c1) believed.tiles.push_back(it->second);
  // The robot places itself and what it senses by the error in whole cells, the map's resolution: world cell (r, c)
  // is believed at (r + k.row, c + k.col) (rows grow southwards), and it believes itself k cells off too, so that
  // within one frame its pose and its map agree as they do for a robot without error.
  CellIndex k = registration_offset(error_, world_.cell_size_m);
  const auto believed_at = [&](CellIndex offset) {
    return Position{frame.x_m + offset.col * world_.cell_size_m, frame.y_m - offset.row * world_.cell_size_m};
  };
  while (!world_.cell_at(believed_at(k)))  // a belief off the map is held at its edge
    k = {k.row - (k.row > 0) + (k.row < 0), k.col - (k.col > 0) + (k.col < 0)};
  const Position pose = believed_at(k);
  believed.x_m = pose.x;
  believed.y_m = pose.y;
  // What proximity sensing measures is relative: the robot places its neighbours from where it believes it is.
  for (Neighbour& n : believed.neighbours) {
    n.position.x += pose.x - frame.x_m;
    n.position.y += pose.y - frame.y_m;
  }
  offset_ = k;
  inner_->set_registration(k);
  // Its scans measure offsets from where it truly is; it inserts them from where it believes its sensor is, the
  // frame's position plus the whole error e: so hits land displaced by e, continuously, not by whole cells.
  inner_->set_sub_cell_error({frame.x_m + error_.x - pose.x, frame.y_m + error_.y - pose.y});
  protocol::ActionRequest request = inner_->decide(believed);
  // What it asks its actuators for happens from where it truly is.
  if (request.move) {
    request.target_x_m += frame.x_m - pose.x;
    request.target_y_m += frame.y_m - pose.y;
  }
  for (Deposit& d : request.deposits) {  // a cube or cone depositor's positions
    d.centre.x += frame.x_m - pose.x;
    d.centre.y += frame.y_m - pose.y;
  }
  // Believed cell (r, c) is world cell (r - k.row, c - k.col).
  std::vector<Deposition> landed;
  landed.reserve(request.depositions.size());
  for (const Deposition& d : request.depositions)
    if (world_.contains({d.row - k.row, d.col - k.col})) landed.push_back({d.row - k.row, d.col - k.col, d.height_m});
  request.depositions = std::move(landed);
  return request;
}

}  // namespace marsala::agent::reactive
