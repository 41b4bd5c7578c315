#pragma once
// "ramp_builder": the reactive state machine that builds a navigable ramp to the robot's target (paper §IV,
// Fig. 2) with the deliberative and executive modules of paper Fig. 1.
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
//   any other      --material below one cube---------------------------------> kReturnToBase
//   kReturnToBase  --retrace the trajectory through navigable cells; at the base: refill --> kAdvance
//   kAdvance/kBuild: a motion along the path is possible -> move (and deposit ahead)       --> kAdvance
//                    blocked, but depositions within reach                                   --> kBuild
//                    blocked and nothing to deposit (the gap left is under the robot)        --> kRetreat
//   kRetreat:        depositions within reach -> deposit in place                            --> kRetreat
//                    after depositing (or after many idle retreat moves) and a motion along
//                    the path is possible                                                    --> kAdvance
//                    else step back the way it came (towards the local origin) and fill
//                    what comes into reach                                                   --> kRetreat
// Building thus runs from the top of the ramp down to its toe (the robot backs off to fill where it stood),
// then the robot climbs, filling ahead of itself, until it reaches the target.
//
// "path_builder" is the same machine inside the construction pipeline (paper §V-A, Fig. 4; pipeline.hpp). It builds
// for the task's construction parameters (e.g. a payload's kappa over a band wide enough for it and two lanes) and
// changes these transitions:
//   any but kReturnToBase --material below one deposition threshold (not enough for a deposition task)--> kReturnToBase
//   any                   --robot on the target's cell: the path is there; go back, refill, come again----> kReturnToBase
//   kReturnToBase         --at the base: refill -----------------------------------------------------------> kFollow
//   otherwise, by the pipeline role of this frame:
//     kActive  -> the ramp builder's kAdvance / kBuild / kRetreat (the front robot alone deposits)
//     kFollow  -> advance along the planned path through navigable cells without depositing, never closer than
//                 the separation to the front neighbour (else stand still) --------------------------------> kFollow / kHold
//     kHold    -> stand still -------------------------------------------------------------------------------> kHold
//     kBackOff -> step back the way it came, away from the front neighbour ----------------------------------> kBackOff
// Lanes: the band is wide enough for two, but robots do not yet keep to one side (lane_offset_m is not used yet);
// the world does not model collisions between robots, so a returning robot passes a follower on the same line.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/deliberative/goal_synthesizer.hpp"
#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/core/navigable_path_planner.hpp"
#include "marsala/agent/executive/action_manager.hpp"
#include "marsala/agent/executive/deposition_manager.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/agent/reactive/pipeline.hpp"

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
  kFollow = 8,
  kHold = 9,
  kBackOff = 10,
};
/// "wait_admission", "survey", "advance", "build", "retreat", "return_to_base", "at_goal", "done", "follow", "hold",
/// "back_off".
std::string to_string(RampState state);
/// The inverse of to_string; throws InvalidArgument listing the valid names.
RampState ramp_state_from_string(const std::string& name);

/// Options of the ramp builder. The goal synthesizer is the context's task.goal_synthesizer; what it builds (MARS
/// kappa, band width) is construction_params(context).
struct RampBuilderOptions {
  std::optional<PlannerParams> planner;  ///< default: default_planner_params for the construction width
  bool pipeline = false;                               ///< true: "path_builder", the construction pipeline
};

/// What the last decision saw and chose (for tests, logs and measurements).
struct DecisionTrace {
  RampState before = RampState::kWaitAdmission;
  RampState after = RampState::kWaitAdmission;
  CellIndex window_offset;                  ///< world index of the local map's top-left cell
  CellIndex local_goal;                     ///< local index
  std::optional<CellIndex> local_origin;    ///< local index
  long long navigable_cells = 0;            ///< cells navigable from the robot in the local map [count]
  bool planned = false;                     ///< a deposition path was planned
  PlannerResult plan;         ///< path in local indices
  std::optional<executive::Motion> motion;  ///< local indices
  std::optional<PipelineRole> role;         ///< path_builder: the pipeline role of this frame
  executive::DepositionPlan deposition;
  bool refill = false;
};

/// Builds a navigable ramp to its target; see the transition table above.
class RampBuilder final : public Behaviour {
 public:
  /// Throws InvalidArgument for an unknown goal synthesizer, an invalid body or construction.
  explicit RampBuilder(const AgentContext& context, RampBuilderOptions options = {});
  ~RampBuilder() override;

  std::string name() const override { return options_.pipeline ? "path_builder" : "ramp_builder"; }
  std::string state_name() const override { return to_string(state_); }
  void on_admission(const protocol::Admission& admission) override;
  protocol::ActionRequest decide(const protocol::SensorFrame& frame) override;

  RampState state() const { return state_; }
  const DecisionTrace& last_trace() const { return trace_; }
  /// The agent's own map (valid after admission).
  const executive::MappingSystem& map() const;

 private:
  struct Modules;
  void build_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, protocol::ActionRequest& request);
  void retreat_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, protocol::ActionRequest& request);
  void return_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, protocol::ActionRequest& request);
  void pipeline_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position target,
                     protocol::ActionRequest& request);
  void follow_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position front,
                   protocol::ActionRequest& request);
  void back_off_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position front,
                     protocol::ActionRequest& request);
  std::optional<executive::Motion> step_back(const deliberative::LocalMap& local, Position robot);
  bool plan_path(const deliberative::LocalMap& local);
  std::optional<CellIndex> oldest_navigable_trajectory_cell(const deliberative::LocalMap& local) const;
  static std::optional<CellIndex> farthest_navigable_from_goal(const deliberative::LocalMap& local);
  void deposit(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position at, std::size_t from,
               protocol::ActionRequest& request);
  void move(const executive::Motion& motion, protocol::ActionRequest& request);

  AgentContext context_;
  RampBuilderOptions options_;
  std::unique_ptr<deliberative::GoalSynthesizer> goal_;
  std::unique_ptr<Modules> modules_;  // made on admission, when the grid is known
  std::optional<PipelineTracker> pipeline_;  // path_builder only
  RampState state_ = RampState::kWaitAdmission;
  DecisionTrace trace_;
  bool deposited_since_blocked_ = false;
  int idle_retreat_moves_ = 0;
};

}  // namespace marsala::agent::reactive
