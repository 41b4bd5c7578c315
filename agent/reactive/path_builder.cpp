#include "marsala/agent/reactive/path_builder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {
namespace {

constexpr EnumName<PathState> kPathStateNames[] = {{PathState::kWaitAdmission, "wait_admission"},
                                                   {PathState::kSurvey, "survey"},
                                                   {PathState::kAdvance, "advance"},
                                                   {PathState::kBuild, "build"},
                                                   {PathState::kRetreat, "retreat"},
                                                   {PathState::kReturnToBase, "return_to_base"},
                                                   {PathState::kFollow, "follow"},
                                                   {PathState::kHold, "hold"},
                                                   {PathState::kBackOff, "back_off"},
                                                   {PathState::kDone, "done"},
                                                   {PathState::kYield, "yield"}};

PathState state_of(BuildPhase phase) {
  switch (phase) {
    case BuildPhase::kAdvance: return PathState::kAdvance;
    case BuildPhase::kBuild: return PathState::kBuild;
    case BuildPhase::kRetreat: return PathState::kRetreat;
  }
  return PathState::kAdvance;
}

}  // namespace

std::string to_string(PathState state) { return enum_to_string(kPathStateNames, state); }

PathState path_state_from_string(const std::string& name) {
  return enum_from_string(kPathStateNames, name, "path builder state");
}

PipelineParams pipeline_params(const Pipeline& pipeline, const RobotBody& body) {
  PipelineParams p;
  p.separation_m = pipeline.separation_m;
  p.back_off_margin_m = 0.25 * p.separation_m;
  // The active robot's retreat (back to fill where it stood: reach + body + a step) is not a return to the base.
  p.return_detect_m =
      std::max(0.75 * p.separation_m, body.reach_m + body.navigability.delta_m + body.max_step_m);
  return p;
}

PathBuilder::PathBuilder(const AgentContext& context, PathBuilderOptions options)
    : steps_(context, std::move(options.planner)),
      pipeline_(pipeline_params(context.type.pipeline, context.type.body)),
      right_of_way_(context.agent_id, give_way_contact_m(context.type.body),
                    1.5 * context.type.body.navigability.delta_m, give_way_frames(context.type.body)),
      keeps_right_of_way_(context.right_of_way) {
  steps_.set_lane(context.type.pipeline.lane_offset_m, construction_params(context.type).delta_m);
  steps_.set_band_centre(true);
}

const executive::MappingSystem& PathBuilder::map() const {
  if (!steps_.admitted()) throw InvalidArgument("path builder: no map before admission");
  return steps_.map();
}

void PathBuilder::on_admission(const protocol::Admission& admission) {
  steps_.admit(admission);
  const RobotBody& body = steps_.context().type.body;
  return_below_m3_ = std::min(body.max_deposit_m3, body.material_capacity_m3);
  state_ = PathState::kSurvey;
}

protocol::ActionRequest PathBuilder::decide(const protocol::SensorFrame& frame) {
  if (!steps_.admitted())
    throw InvalidArgument(fmt::format("path builder: frame for step {} before admission", frame.step));
  check_frame(steps_.context(), frame);
  trace_ = PathBuilderTrace{};
  trace_.before = state_;
  waiting_for_.clear();
  protocol::ActionRequest request = empty_request(steps_.context(), frame, "");
  if (frame.run_over || state_ == PathState::kDone) {
    state_ = PathState::kDone;
  } else {
    BuildView view = steps_.look(frame, trace_);
    const Position here{frame.x_m, frame.y_m};
    still_steps_ = last_position_ && last_position_->x == here.x && last_position_->y == here.y ? still_steps_ + 1 : 0;
    last_position_ = here;
    if (state_ == PathState::kSurvey) state_ = PathState::kAdvance;
    // On the local goal's cell (the target's, or the nearest to a target off the grid) the path has reached it:
    // back to the base, to come again.
    const bool at_goal = view.local.goal == view.local.robot;
    pipeline_.observe(frame.neighbours, view.target);
    if (right_of_way_step(view, frame, request)) {
      // the protocol's frame
    } else if (state_ != PathState::kReturnToBase && (frame.material_m3 < return_below_m3_ - 1e-12 || at_goal)) {
      state_ = PathState::kReturnToBase;
    }
    if (state_ == PathState::kYield && resume_) {
      // the protocol's frame: nothing more
    } else if (state_ == PathState::kReturnToBase) {
      const double to_base_m = distance(here, steps_.context().assignment.base);
      const int no_nearer = return_progress_.observe(to_base_m);
      if (steps_.return_step(view.local, frame, trace_, request)) {
        state_ = PathState::kAdvance;
        return_progress_.reset();
      }
      waiting_for_ = return_waiting_text(trace_, request, close_by(frame), no_nearer, to_base_m);
    } else {
      pipeline_step(view, frame, request);
    }
  }
  trace_.after = state_;
  worked_ = !request.depositions.empty() || !request.deposits.empty() || request.refill;
  // Only a robot on its way back can be in a knot: on the way out the pipeline's own order (follow, hold, back off,
  // the front robot's retreat) makes no way towards the target by design.
  const bool returning = state_ == PathState::kReturnToBase || (resume_ && *resume_ == PathState::kReturnToBase);
  if (!returning) worked_ = true;
  request.state = to_string(state_);
  request.waiting_for = waiting_for_;
  return request;
}

bool PathBuilder::right_of_way_step(BuildView& view, const protocol::SensorFrame& frame,
                                    protocol::ActionRequest& request) {
  if (!keeps_right_of_way_) return false;
  const RobotBody& body = steps_.context().type.body;
  // Where it goes: the target, or the base on the way back. A path builder never parks at a goal.
  const Position going = state_ == PathState::kReturnToBase || (resume_ && *resume_ == PathState::kReturnToBase)
                             ? steps_.context().assignment.base
                             : view.target;
  right_of_way_.observe_towards(view.robot, frame.neighbours, false, going, 0.5 * body.max_step_m, worked_);
  const auto what =
      steps_.right_of_way_step(right_of_way_, view.local, view.robot, false, close_by(frame), trace_, request, false);
  if (!what) {
    if (resume_) state_ = *resume_, resume_.reset();
    return false;
  }
  if (!resume_) resume_ = state_;
  state_ = PathState::kYield;
  waiting_for_ = *what;
  return true;
}

std::string PathBuilder::close_by(const protocol::SensorFrame& frame) const {
  const RobotBody& body = steps_.context().type.body;
  return robots_close_by(frame.neighbours, {frame.x_m, frame.y_m}, 0.5 * body.navigability.delta_m,
                         body.navigability.delta_m);
}

void PathBuilder::pipeline_step(const BuildView& view, const protocol::SensorFrame& frame,
                                protocol::ActionRequest& request) {
  const PipelinePlace place = pipeline_.place(view.robot, view.target);
  trace_.role = place.role;
  if (place.role != PipelineRole::kActive)
    if (const auto other = oncoming(view, frame)) {
      waiting_for_ = fmt::format("robot {} on its way back at {:.1f} m (yield)", other->agent_id,
                                 distance(other->position, view.robot));
      return yield_step(view, other->position, request);
    }
  switch (place.role) {
    case PipelineRole::kActive:
      if (state_ == PathState::kRetreat) {
        state_ = state_of(steps_.retreat_step(view.local, frame, trace_, request));
      } else if (const auto phase = steps_.build_step(view.local, frame, trace_, request)) {
        state_ = state_of(*phase);
      } else {
        waiting_for_ = build_waiting_text(close_by(frame));
      }
      return;
    case PipelineRole::kFollow:
      follow_step(view, place.front->position, request);
      if (!request.move) waiting_for_ = front_neighbour_text(*place.front, view.robot, "follow");
      return;
    case PipelineRole::kHold:
      state_ = PathState::kHold;
      waiting_for_ = front_neighbour_text(*place.front, view.robot, "hold");
      // A front neighbour that stays put as long as this robot has waited may be waiting for it to make way (a
      // robot on its way back that has not got far enough to be seen returning): step aside, off its line to the base.
      if (still_steps_ >= kPatienceSteps) yield_step(view, place.front->position, request);
      return;
    case PipelineRole::kBackOff:
      waiting_for_ = front_neighbour_text(*place.front, view.robot, "back off");
      back_off_step(view, place.front->position, request);
      return;
  }
}

void PathBuilder::follow_step(const BuildView& view, Position front, protocol::ActionRequest& request) {
  state_ = PathState::kHold;
  std::optional<executive::Motion> motion;
  // The way to the front neighbour, not its own line to the target: it goes where the front builds, so whoever is
  // the front next builds on from there (docs/runtime.md#the-construction-band).
  if (steps_.plan_path_towards(view.local, front, trace_))
    motion = steps_.advance(view.local, steps_.in_lane(view.local, trace_.plan.path), view.robot);
  if (motion && distance(motion->target, front) >= pipeline_.params().separation_m) {
    steps_.move(*motion, trace_, request);
    state_ = PathState::kFollow;
    return;
  }
  // Stuck as long as a holding robot's patience: make way, as kHold does.
  if (still_steps_ >= kPatienceSteps) yield_step(view, front, request);
}

std::optional<Neighbour> PathBuilder::oncoming(const BuildView& view, const protocol::SensorFrame& frame) const {
  const double mine = distance(view.robot, view.target);
  std::optional<Neighbour> nearest;
  double nearest_d = pipeline_.params().separation_m;
  for (const Neighbour& n : frame.neighbours) {
    const Position p = n.position;
    if (!pipeline_.returning(n.agent_id) || !(distance(p, view.target) < mine)) continue;
    const double d = distance(p, view.robot);
    if (d <= nearest_d) nearest_d = d, nearest = n;
  }
  return nearest;
}

void PathBuilder::yield_step(const BuildView& view, Position from, protocol::ActionRequest& request) {
  state_ = PathState::kYield;
  // Off the line from the other robot (at `from`) to the base: to whichever side gains most, one step at most.
  const Position base = steps_.context().assignment.base;
  const double dx = base.x - from.x, dy = base.y - from.y, length = std::hypot(dx, dy);
  const auto off_line = [&](Position p) {
    return length > 0.0 ? std::abs((p.x - from.x) * dy - (p.y - from.y) * dx) / length : distance(p, from);
  };
  std::optional<executive::Motion> best;
  double best_off = off_line(view.robot) + 1e-9;
  const CellIndex at = view.local.robot;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex next{at.row + dr, at.col + dc};
      if ((dr == 0 && dc == 0) || !view.local.contains(next) || view.local.navigable(next.row, next.col) == 0)
        continue;
      const auto motion = steps_.advance(view.local, {at, next}, view.robot);
      if (motion && off_line(motion->target) > best_off) best_off = off_line(motion->target), best = motion;
    }
  if (best) steps_.move(*best, trace_, request);
}

void PathBuilder::back_off_step(const BuildView& view, Position front, protocol::ActionRequest& request) {
  state_ = PathState::kBackOff;
  const auto motion = steps_.step_back(view.local, view.robot);
  if (motion && distance(motion->target, front) > distance(view.robot, front)) {
    steps_.move(*motion, trace_, request);
    return;
  }
  // No way back (other robots behind it): make way to the side instead, off the front robot's line to the base.
  yield_step(view, front, request);
  if (request.move) state_ = PathState::kBackOff;
}

}  // namespace marsala::agent::reactive
