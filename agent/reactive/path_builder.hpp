#pragma once
// "path_builder": the ramp builder's steps (ramp_steps.hpp) inside the construction pipeline (paper §V-A, Fig. 4;
// pipeline.hpp). It builds for its robot type's construction parameters (e.g. a payload's kappa over a band wide enough
// for it and two lanes); the front robot of the pipeline alone deposits, the others follow it at the pipeline's
// separation, and every robot goes back to the base to refill whenever it cannot make a deposition task or has
// reached the target.
//
// States and transitions (checked in this order on every frame):
//   any            --run_over frame---------------------------------------------------------------> kDone
//   kWaitAdmission --on_admission()---------------------------------------------------------------> kSurvey
//   kSurvey        --first frame: the map is built, then as kAdvance on the same frame
//   any but kReturnToBase --material below one deposition threshold (not enough for a deposition task), or the
//                    robot on the local goal's cell (the path is there: go back, refill, come again) -> kReturnToBase
//   kReturnToBase  --retrace the trajectory through navigable cells; at the base: refill--------------> kAdvance
//   any            --right of way (right_of_way.hpp, when the robot keeps it; no lanes: the pipeline has its own):
//                    giving way to a lower id that holds, or, on the way back, holding still after no way towards
//                    the base with a robot in contact ------------------------------------------------> kYield,
//                    then back to the state it interrupted. On the way out a robot never holds: the pipeline's own
//                    order (follow, hold, back off, the front robot's retreat) makes no way by design.
//   not kActive, and a returning neighbour within the separation that has not passed the robot yet (it is nearer the
//                    target): step aside, off the line from it to the base (the front robot builds on;
//                    returning robots go round it) ---------------------------------------------------> kYield
//   otherwise, by the pipeline role of this frame:
//     kActive  -> the ramp builder's building steps: from kRetreat its retreat step, else its build step
//                 (-> kAdvance / kBuild / kRetreat); no deposition path through known cells: the state stays.
//                 But a robot that gave way on its way out (kYield) and has nobody ahead in sight keeps the place
//                 where it last saw its front neighbour: it advances without depositing along the deposition path
//                 to that place -------------------------------------------------------------------> kFollow / kHold
//                 until that place is within the separation, not ahead of it, off its window or not passable,
//                 within half the band of its own line to the target, after kPatienceSteps frames without a
//                 motion or 2 x proximity range / step + kPatienceSteps frames (then it builds, as above)
//     kFollow  -> advance without depositing along the deposition path to the front neighbour's cell (not
//                 its own line to the target: it goes where the front builds) through navigable cells --> kFollow
//                 no motion, or it would end closer than the separation to the front neighbour -----> kHold
//                 (after kPatienceSteps frames in a row at the same position: make way as kHold does)
//     kHold    -> stand still; after kPatienceSteps frames in a row at the same position, a step aside off the
//                 front neighbour's line to the base (it may be on its way back, blocked) -------------> kHold / kYield
//     kBackOff -> step back the way it came, if that takes it away from the front neighbour; else, when
//                 another robot blocks the way back, a step aside off the front neighbour's line to the base -> kBackOff
// After a refill the robot is in kAdvance; its next frame's role decides whether it builds or follows.
// One band for every front robot (docs/runtime.md#the-construction-band): what the active robot fills follows its
// deposition path moved towards the centre line of the corridor it builds in, on its own map
// (RampSteps::set_band_centre), not the path from where it stands; it still drives its own path. What is left to fill
// there is the MARS gap of the way's own surface (the cells the body drives on along that path): high ground and
// structure beside it, in the band or beyond, raise nothing in it.
// Lanes: followers and robots on their way back keep lane_offset_m to the right of the band's centre line
// (executive/lane.hpp), so a returning robot passes followers in the other lane; the world rejects motions that
// would make bodies overlap, and every route goes around the bodies the frame shows (ramp_steps.hpp).

#include <cstdint>
#include <optional>
#include <string>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/agent/reactive/pipeline.hpp"
#include "marsala/agent/reactive/ramp_steps.hpp"
#include "marsala/agent/reactive/right_of_way.hpp"
#include "marsala/agent/reactive/waiting_for.hpp"
#include "marsala/core/navigable_path_planner.hpp"

namespace marsala::agent::reactive {

/// States of the path builder.
enum class PathState : std::uint8_t {
  kWaitAdmission = 0,
  kSurvey = 1,
  kAdvance = 2,
  kBuild = 3,
  kRetreat = 4,
  kReturnToBase = 5,
  kFollow = 6,
  kHold = 7,
  kBackOff = 8,
  kDone = 9,
  kYield = 10,
};
/// "wait_admission", "survey", "advance", "build", "retreat", "return_to_base", "follow", "hold", "back_off",
/// "done", "yield".
std::string to_string(PathState state);
/// The inverse of to_string; throws InvalidArgument listing the valid names.
PathState path_state_from_string(const std::string& name);

/// Options of the path builder. The goal synthesizer is the robot type's goal_synthesizer; what it builds (MARS
/// kappa, band width) is construction_params(type); the pipeline's separation is type.pipeline.separation_m.
struct PathBuilderOptions {
  std::optional<PlannerParams> planner;  ///< default: default_planner_params for the construction width
};

/// What the last decision saw and chose (for tests, logs and measurements).
struct PathBuilderTrace : BuildTrace {
  PathState before = PathState::kWaitAdmission;
  PathState after = PathState::kWaitAdmission;
  std::optional<PipelineRole> role;  ///< the pipeline role of this frame, when it was asked for
};

/// Frames a holding (or blocked following) robot waits at the same position before it makes way for its front
/// neighbour.
inline constexpr int kPatienceSteps = 40;

/// The pipeline's distances for a robot type's pipeline and body: separation_m = pipeline.separation_m,
/// back_off_margin_m a quarter of it, return_detect_m three quarters of it or, when longer, the active robot's
/// retreat (reach + delta + max_step: it backs off to fill where it stood, which is no return to the base) [m].
PipelineParams pipeline_params(const Pipeline& pipeline, const RobotBody& body);

/// Builds a navigable path in the construction pipeline; see the transition table above.
class PathBuilder final : public Behaviour {
 public:
  /// Throws InvalidArgument for an unknown goal synthesizer, an invalid body, construction or separation.
  explicit PathBuilder(const AgentContext& context, PathBuilderOptions options = {});

  std::string name() const override { return "path_builder"; }
  std::string state_name() const override { return to_string(state_); }
  std::string waiting_for() const override { return waiting_for_; }
  void on_admission(const protocol::Admission& admission) override;
  void set_registration(CellIndex offset) override { steps_.set_registration(offset); }
  void set_sub_cell_error(Position error_m) override { steps_.set_sub_cell_error(error_m); }
  std::optional<deliberative::KnownMap> known_map() const override {
    return steps_.admitted() ? std::optional<deliberative::KnownMap>(steps_.map().known_map()) : std::nullopt;
  }
  protocol::ActionRequest decide(const protocol::SensorFrame& frame) override;

  PathState state() const { return state_; }
  const PathBuilderTrace& last_trace() const { return trace_; }
  /// The pipeline tracker (neighbours seen in the last frame).
  const PipelineTracker& pipeline() const { return pipeline_; }
  /// The agent's own map; throws InvalidArgument before admission.
  const executive::MappingSystem& map() const;

 private:
  void pipeline_step(const BuildView& view, const protocol::SensorFrame& frame, protocol::ActionRequest& request);
  void follow_step(const BuildView& view, Position front, protocol::ActionRequest& request);
  // A robot that would be the front: true when it keeps the way to lost_front_ instead (the request filled).
  bool lost_front_step(const BuildView& view, protocol::ActionRequest& request);
  void remember_front(const BuildView& view);  // last_front_ from this frame's neighbours; lost_front_ dropped
  int lost_front_frames() const;  // how long a front out of sight is kept: 2 x proximity range / step + patience
  void back_off_step(const BuildView& view, Position front, protocol::ActionRequest& request);
  std::optional<Neighbour> oncoming(const BuildView& view, const protocol::SensorFrame& frame) const;
  void yield_step(const BuildView& view, Position from, protocol::ActionRequest& request);
  std::string close_by(const protocol::SensorFrame& frame) const;  // robots_close_by() within a body length
  // The right of way's frame (right_of_way.hpp), when it takes this one: true, the request filled, the state kYield.
  bool right_of_way_step(BuildView& view, const protocol::SensorFrame& frame, protocol::ActionRequest& request);

  RampSteps steps_;
  PipelineTracker pipeline_;
  std::optional<Position> last_position_;  // the previous frame's
  int still_steps_ = 0;                    // frames in a row at the same position
  double return_below_m3_ = 0.0;  // less material than this (one deposition task) on board: back to the base [m^3]
  PathState state_ = PathState::kWaitAdmission;
  PathBuilderTrace trace_;
  std::string waiting_for_;         // what the last decision waits for (waiting_for.hpp), set where its state is chosen
  ReturnProgress return_progress_;  // how long the return to the base has come no nearer
  RightOfWay right_of_way_;
  bool keeps_right_of_way_ = false;  // the context's right_of_way: else none of the protocol's steps are taken
  // The last request deposited or refilled, or the robot is on its way out (the pipeline's order): no knot.
  bool worked_ = false;
  std::optional<PathState> resume_;  // the state a protocol frame interrupted
  // The way of the front it followed before it gave way (docs/runtime.md#the-construction-band, "Out of sight
  // after giving way").
  std::optional<Position> last_front_;  // where the last front neighbour seen stood; none once it is the front
  int last_front_age_ = 0;              // frames since then
  std::optional<Position> lost_front_;  // set by giving way: kept while nobody ahead is in sight
  int lost_front_age_ = 0;              // frames since it was set
  int lost_front_stuck_ = 0;            // frames in a row without a motion towards it
};

}  // namespace marsala::agent::reactive
