#pragma once
// "ramp_builder": the reactive state machine that builds a navigable ramp to the robot's target (paper §IV,
// Fig. 2) with the ramp builder's steps (ramp_steps.hpp).
//
// Each frame: the mapping system takes the frame's tiles; the local map synthesizer builds the augmented local
// map; the navigable path planner plans a deposition path to the local goal; the action manager moves along it
// as far as is navigable now; the deposition manager fills the path's MARS gap within reach.
//
// States and transitions (checked in this order on every frame):
//   any            --run_over frame---------------------------------------------> kDone
//   kWaitAdmission --on_admission()---------------------------------------------> kSurvey
//   kSurvey        --first frame: the map is built, then as kAdvance on the same frame
//   any            --robot on the local goal's cell (the target's cell, or the nearest cell to a target off
//                    the grid)----------------------------------------------------> kAtGoal   (empty requests)
//   kAtGoal        --robot off it--------------------------------------------> kAdvance
//   any but kReturnToBase --giving way (right_of_way.hpp: stood still in contact with a lower id, or at the goal
//                    with anyone): a step away from that robot, for an episode of frames ---------> kGiveWay
//   any other      --material below one cube---------------------------------> kReturnToBase
//   kReturnToBase  --retrace the trajectory through navigable cells; at the base: refill --> kAdvance
//   kAdvance/kBuild: a motion along the path is possible -> move (and deposit ahead)       --> kAdvance
//                    blocked, but depositions within reach                                   --> kBuild
//                    blocked and nothing to deposit (the gap left is under the robot)        --> kRetreat
//                    no deposition path through known cells: nothing requested, the state stays
//   kRetreat:        depositions within reach -> deposit in place                            --> kRetreat
//                    after depositing (or after many idle retreat moves) and a motion along
//                    the path is possible                                                    --> kAdvance
//                    else step back the way it came (towards the local origin) and fill
//                    what comes into reach                                                   --> kRetreat
// Building thus runs from the top of the ramp down to its toe (the robot backs off to fill where it stood),
// then the robot climbs, filling ahead of itself, until it reaches the target.

#include <cstdint>
#include <optional>
#include <string>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/agent/reactive/ramp_steps.hpp"
#include "marsala/agent/reactive/waiting_for.hpp"
#include "marsala/agent/reactive/right_of_way.hpp"
#include "marsala/core/navigable_path_planner.hpp"

namespace marsala::agent::reactive {

/// States of the ramp builder.
enum class RampState : std::uint8_t {
  kWaitAdmission = 0,
  kSurvey = 1,
  kAdvance = 2,
  kBuild = 3,
  kRetreat = 4,
  kReturnToBase = 5,
  kAtGoal = 6,
  kDone = 7,
  kGiveWay = 8,
};
/// "wait_admission", "survey", "advance", "build", "retreat", "return_to_base", "at_goal", "done", "give_way".
std::string to_string(RampState state);
/// The inverse of to_string; throws InvalidArgument listing the valid names.
RampState ramp_state_from_string(const std::string& name);

/// Options of the ramp builder. The goal synthesizer is the robot type's goal_synthesizer; what it builds (MARS
/// kappa, band width) is construction_params(type).
struct RampBuilderOptions {
  std::optional<PlannerParams> planner;  ///< default: default_planner_params for the construction width
};

/// What the last decision saw and chose (for tests, logs and measurements).
struct RampBuilderTrace : BuildTrace {
  RampState before = RampState::kWaitAdmission;
  RampState after = RampState::kWaitAdmission;
};

/// Builds a navigable ramp to its target; see the transition table above.
class RampBuilder final : public Behaviour {
 public:
  /// Throws InvalidArgument for an unknown goal synthesizer, an invalid body or construction.
  explicit RampBuilder(const AgentContext& context, RampBuilderOptions options = {});

  std::string name() const override { return "ramp_builder"; }
  std::string state_name() const override { return to_string(state_); }
  std::string waiting_for() const override { return waiting_for_; }
  void on_admission(const protocol::Admission& admission) override;
  void set_registration(CellIndex offset) override { steps_.set_registration(offset); }
  void set_sub_cell_error(Position error_m) override { steps_.set_sub_cell_error(error_m); }
  std::optional<deliberative::KnownMap> known_map() const override {
    return steps_.admitted() ? std::optional<deliberative::KnownMap>(steps_.map().known_map()) : std::nullopt;
  }
  protocol::ActionRequest decide(const protocol::SensorFrame& frame) override;

  RampState state() const { return state_; }
  const RampBuilderTrace& last_trace() const { return trace_; }
  /// The agent's own map; throws InvalidArgument before admission.
  const executive::MappingSystem& map() const;

 private:
  RampSteps steps_;
  RightOfWay right_of_way_;
  bool keeps_right_of_way_ = false;  // the context's right_of_way: else none of the protocol's steps are taken
  bool worked_ = false;  // the last request deposited or refilled: building is progress, not waiting
  double return_below_m3_ = 0.0;  // less material than this (one cube) on board: back to the base [m^3]
  RampState state_ = RampState::kWaitAdmission;
  RampBuilderTrace trace_;
  std::string waiting_for_;         // what the last decision waits for (waiting_for.hpp)
  ReturnProgress return_progress_;  // how long the return to the base has come no nearer
};

}  // namespace marsala::agent::reactive
