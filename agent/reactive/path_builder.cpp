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

// The distance of `p` [m] from the line through `from` and `to` (from `from` when they coincide) [m].
double off_line(Position from, Position to, Position p) {
  const double dx = to.x - from.x, dy = to.y - from.y, length = std::hypot(dx, dy);
  return length > 0.0 ? std::abs((p.x - from.x) * dy - (p.y - from.y) * dx) / length : distance(p, from);
}

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
  steps_.set_fill_under_rays(true);
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
    remember_front(view);
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
  // Giving way on the way out (the right of way's step away, the pipeline's step aside) can take the robot out of
  // sight of the front it followed: it keeps that front's way for a while (lost_front_step).
  if (state_ == PathState::kYield && !(resume_ && *resume_ == PathState::kReturnToBase) && last_front_ &&
      last_front_age_ <= lost_front_frames()) {
    lost_front_ = last_front_;
    lost_front_age_ = 0;
    lost_front_stuck_ = 0;
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
      if (state_ != PathState::kRetreat && lost_front_step(view, request)) return;
      last_front_.reset();  // the front itself: nobody's way to keep when it next gives way
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

int PathBuilder::lost_front_frames() const {
  const RobotBody& body = steps_.context().type.body;
  return static_cast<int>(std::ceil(2.0 * body.proximity_range_m / body.max_step_m)) + kPatienceSteps;
}

void PathBuilder::remember_front(const BuildView& view) {
  ++last_front_age_;
  ++lost_front_age_;
  if (const auto front = pipeline_.front(view.robot, view.target)) {
    last_front_ = front->position, last_front_age_ = 0;
    lost_front_.reset();  // a robot ahead in sight: the pipeline's own order
  }
  if (state_ == PathState::kReturnToBase || lost_front_age_ > lost_front_frames()) lost_front_.reset();
}

bool PathBuilder::lost_front_step(const BuildView& view, protocol::ActionRequest& request) {
  if (!lost_front_) return false;
  const Position at = *lost_front_;
  const auto cell = view.local.cell_at(at);
  // It is the front after all where that place is reached (within the separation), is not ahead of it, lies out of
  // the window or is not passable, where its own line to the target passes within half the band of it (its own
  // way is that way), or after kPatienceSteps frames in a row without a motion towards it.
  const double half_band_m = 0.5 * construction_params(steps_.context().type).delta_m;
  if (distance(view.robot, at) <= pipeline_.params().separation_m ||
      !(distance(at, view.target) < distance(view.robot, view.target) - kAheadMarginM) || !cell ||
      view.local.passable(cell->row, cell->col) == 0 || off_line(view.robot, view.target, at) <= half_band_m ||
      lost_front_stuck_ >= kPatienceSteps) {
    lost_front_.reset();
    return false;
  }
  state_ = PathState::kHold;
  waiting_for_ = fmt::format("the way of a front out of sight, {:.1f} m away", distance(view.robot, at));
  if (steps_.plan_path_towards(view.local, at, trace_))
    if (const auto motion = steps_.advance(view.local, steps_.in_lane(view.local, trace_.plan.path), view.robot)) {
      steps_.move(*motion, trace_, request);
      state_ = PathState::kFollow;
      lost_front_stuck_ = 0;
      return true;
    }
  ++lost_front_stuck_;
  return true;
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
  std::optional<executive::Motion> best;
  double best_off = off_line(from, base, view.robot) + 1e-9;
  const CellIndex at = view.local.robot;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex next{at.row + dr, at.col + dc};
      if ((dr == 0 && dc == 0) || !view.local.contains(next) || view.local.navigable(next.row, next.col) == 0)
        continue;
      const auto motion = steps_.advance(view.local, {at, next}, view.robot);
      if (motion && off_line(from, base, motion->target) > best_off)
        best_off = off_line(from, base, motion->target), best = motion;
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
