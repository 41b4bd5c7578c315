#include "marsala/agent/reactive/path_builder.hpp"

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
                                                   {PathState::kDone, "done"}};

double distance(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

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

PipelineParams pipeline_params(const Pipeline& pipeline) {
  PipelineParams p;
  p.separation_m = pipeline.separation_m;
  p.back_off_margin_m = 0.25 * p.separation_m;
  p.return_detect_m = 0.75 * p.separation_m;
  return p;
}

PathBuilder::PathBuilder(const AgentContext& context, PathBuilderOptions options)
    : steps_(context, std::move(options.planner)), pipeline_(pipeline_params(context.type.pipeline)) {}

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
    throw InvalidArgument("path builder: frame for step " + std::to_string(frame.step) + " before admission");
  check_frame(steps_.context(), frame);
  trace_ = PathBuilderTrace{};
  trace_.before = state_;
  protocol::ActionRequest request = empty_request(steps_.context(), frame, "");
  if (frame.run_over || state_ == PathState::kDone) {
    state_ = PathState::kDone;
  } else {
    const BuildView view = steps_.look(frame, trace_);
    if (state_ == PathState::kSurvey) state_ = PathState::kAdvance;
    // On the local goal's cell (the target's, or the nearest to a target off the grid) the path has reached it:
    // back to the base, to come again.
    const bool at_goal = view.local.goal == view.local.robot;
    pipeline_.observe(frame.neighbours, view.target);
    if (state_ != PathState::kReturnToBase && (frame.material_m3 < return_below_m3_ - 1e-12 || at_goal))
      state_ = PathState::kReturnToBase;
    if (state_ == PathState::kReturnToBase) {
      if (steps_.return_step(view.local, frame, trace_, request)) state_ = PathState::kAdvance;
    } else {
      pipeline_step(view, frame, request);
    }
  }
  trace_.after = state_;
  request.state = to_string(state_);
  return request;
}

void PathBuilder::pipeline_step(const BuildView& view, const protocol::SensorFrame& frame,
                                protocol::ActionRequest& request) {
  const PipelinePlace place = pipeline_.place(view.robot, view.target);
  trace_.role = place.role;
  switch (place.role) {
    case PipelineRole::kActive:
      if (state_ == PathState::kRetreat) {
        state_ = state_of(steps_.retreat_step(view.local, frame, trace_, request));
      } else if (const auto phase = steps_.build_step(view.local, frame, trace_, request)) {
        state_ = state_of(*phase);
      }
      return;
    case PipelineRole::kFollow: follow_step(view, {place.front->x_m, place.front->y_m}, request); return;
    case PipelineRole::kHold: state_ = PathState::kHold; return;
    case PipelineRole::kBackOff: back_off_step(view, {place.front->x_m, place.front->y_m}, request); return;
  }
}

void PathBuilder::follow_step(const BuildView& view, Position front, protocol::ActionRequest& request) {
  state_ = PathState::kHold;
  if (!steps_.plan_path(view.local, trace_)) return;
  const auto motion = steps_.advance(view.local, trace_.plan.path, view.robot);
  if (!motion || distance(motion->target, front) < pipeline_.params().separation_m) return;
  steps_.move(*motion, trace_, request);
  state_ = PathState::kFollow;
}

void PathBuilder::back_off_step(const BuildView& view, Position front, protocol::ActionRequest& request) {
  state_ = PathState::kBackOff;
  const auto motion = steps_.step_back(view.local, view.robot);
  if (motion && distance(motion->target, front) > distance(view.robot, front)) steps_.move(*motion, trace_, request);
}

}  // namespace marsala::agent::reactive
