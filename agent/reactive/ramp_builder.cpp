#include "marsala/agent/reactive/ramp_builder.hpp"

#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {
namespace {

constexpr EnumName<RampState> kRampStateNames[] = {{RampState::kWaitAdmission, "wait_admission"},
                                                   {RampState::kSurvey, "survey"},
                                                   {RampState::kAdvance, "advance"},
                                                   {RampState::kBuild, "build"},
                                                   {RampState::kRetreat, "retreat"},
                                                   {RampState::kReturnToBase, "return_to_base"},
                                                   {RampState::kAtGoal, "at_goal"},
                                                   {RampState::kDone, "done"},
                                                   {RampState::kGiveWay, "give_way"}};

RampState ramp_state_of(BuildPhase phase) {
  switch (phase) {
    case BuildPhase::kAdvance: return RampState::kAdvance;
    case BuildPhase::kBuild: return RampState::kBuild;
    case BuildPhase::kRetreat: return RampState::kRetreat;
  }
  return RampState::kAdvance;
}

}  // namespace

std::string to_string(RampState state) { return enum_to_string(kRampStateNames, state); }

RampState ramp_state_from_string(const std::string& name) {
  return enum_from_string(kRampStateNames, name, "ramp builder state");
}

RampBuilder::RampBuilder(const AgentContext& context, RampBuilderOptions options)
    : steps_(context, std::move(options.planner)),
      right_of_way_(context.agent_id, give_way_contact_m(context.type.body),
                    1.5 * context.type.body.navigability.delta_m,
                    give_way_frames(context.type.body)),
      keeps_right_of_way_(context.right_of_way) {}

const executive::MappingSystem& RampBuilder::map() const {
  if (!steps_.admitted()) throw InvalidArgument("ramp builder: no map before admission");
  return steps_.map();
}

void RampBuilder::on_admission(const protocol::Admission& admission) {
  steps_.admit(admission);
  const RobotBody& body = steps_.context().type.body;
  const double cell_size_m = steps_.context().assignment.world.cell_size_m;
  return_below_m3_ = cube_layer_m(body.cube_size_m, cell_size_m) * cell_size_m * cell_size_m;  // one cube
  state_ = RampState::kSurvey;
}

protocol::ActionRequest RampBuilder::decide(const protocol::SensorFrame& frame) {
  if (!steps_.admitted())
    throw InvalidArgument(fmt::format("ramp builder: frame for step {} before admission", frame.step));
  check_frame(steps_.context(), frame);
  trace_ = RampBuilderTrace{};
  trace_.before = state_;
  waiting_for_.clear();
  protocol::ActionRequest request = empty_request(steps_.context(), frame, "");
  if (frame.run_over || state_ == RampState::kDone) {
    state_ = RampState::kDone;
  } else {
    BuildView view = steps_.look(frame, trace_);
    deliberative::LocalMap& local = view.local;
    const RobotBody& body = steps_.context().type.body;
    const auto close_by = [&] {
      return robots_close_by(frame.neighbours, view.robot, 0.5 * body.navigability.delta_m, body.navigability.delta_m);
    };
    if (state_ == RampState::kSurvey) state_ = RampState::kAdvance;
    // At the goal: on the local goal's cell, which is the target's cell, or the nearest the robot can get to a
    // target off the grid.
    const bool at_goal = local.goal == local.robot;
    const Position going = state_ == RampState::kReturnToBase ? steps_.context().assignment.base : view.target;
    if (keeps_right_of_way_)
      right_of_way_.observe_towards(view.robot, frame.neighbours, at_goal, going, 0.5 * body.max_step_m, worked_);
    const auto protocol_frame =
        keeps_right_of_way_
            ? steps_.right_of_way_step(right_of_way_, local, view.robot, at_goal, close_by(), trace_, request)
            : std::nullopt;
    if (protocol_frame) {
      state_ = RampState::kGiveWay;
      waiting_for_ = *protocol_frame;
    } else if (at_goal) {
      state_ = RampState::kAtGoal;
    } else {
      if (state_ == RampState::kGiveWay) state_ = RampState::kAdvance;
      if (state_ == RampState::kAtGoal) state_ = RampState::kAdvance;
      if (state_ != RampState::kReturnToBase && frame.material_m3 < return_below_m3_ - 1e-12)
        state_ = RampState::kReturnToBase;
      if (state_ == RampState::kReturnToBase) {
        const Position base = steps_.context().assignment.base;
        const double to_base_m = std::hypot(view.robot.x - base.x, view.robot.y - base.y);
        const int no_nearer = return_progress_.observe(to_base_m);
        if (steps_.return_step(local, frame, trace_, request)) {
          state_ = RampState::kAdvance;
          return_progress_.reset();
        }
        waiting_for_ = return_waiting_text(trace_, request, close_by(), no_nearer, to_base_m);
      } else if (state_ == RampState::kRetreat) {
        state_ = ramp_state_of(steps_.retreat_step(local, frame, trace_, request));
      } else if (const auto phase = steps_.build_step(local, frame, trace_, request)) {
        state_ = ramp_state_of(*phase);
      } else {
        waiting_for_ = build_waiting_text(close_by());
      }
    }
  }
  trace_.after = state_;
  worked_ = !request.depositions.empty() || !request.deposits.empty() || request.refill;
  request.state = to_string(state_);
  request.waiting_for = waiting_for_;
  return request;
}

}  // namespace marsala::agent::reactive
