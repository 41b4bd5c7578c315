#include "marsala/agent/reactive/ramp_builder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::reactive {
namespace {

constexpr RampState kStates[] = {RampState::kWaitAdmission, RampState::kSurvey,       RampState::kAdvance,
                                 RampState::kBuild,         RampState::kRetreat,      RampState::kReturnToBase,
                                 RampState::kAtGoal,        RampState::kDone,         RampState::kFollow,
                                 RampState::kHold,          RampState::kBackOff};

/// Kept inside the world's base radius so a refill is never rejected on a tie [m].
constexpr double kBaseMarginM = 1e-6;

double distance(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

executive::Neighbourhood neighbourhood(const protocol::SensorFrame& frame) {
  return {frame.agent_id, {frame.x_m, frame.y_m}, frame.neighbours};
}

/// The navigable cell of the window whose centre has the smallest score, if that is below `bound` (row-major order:
/// ties to the first).
template <typename Score>
std::optional<CellIndex> best_navigable_cell(const deliberative::LocalMap& local, double bound, Score score) {
  std::optional<CellIndex> best;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      if (local.navigable(r, c) == 0) continue;
      const double s = score(local.center({r, c}));
      if (s < bound) bound = s, best = CellIndex{r, c};
    }
  return best;
}


}  // namespace

std::string to_string(RampState state) {
  switch (state) {
    case RampState::kWaitAdmission: return "wait_admission";
    case RampState::kSurvey: return "survey";
    case RampState::kAdvance: return "advance";
    case RampState::kBuild: return "build";
    case RampState::kRetreat: return "retreat";
    case RampState::kReturnToBase: return "return_to_base";
    case RampState::kAtGoal: return "at_goal";
    case RampState::kDone: return "done";
    case RampState::kFollow: return "follow";
    case RampState::kHold: return "hold";
    case RampState::kBackOff: return "back_off";
  }
  return "unknown";
}

RampState ramp_state_from_string(const std::string& name) {
  std::string valid;
  for (RampState s : kStates) {
    if (to_string(s) == name) return s;
    valid += (valid.empty() ? "" : ", ") + to_string(s);
  }
  throw InvalidArgument("unknown ramp builder state '" + name + "'; valid: " + valid);
}

struct RampBuilder::Modules {
  executive::MappingSystem map;
  deliberative::LocalMapSynthesizer synthesizer;
  NavigablePathPlanner planner;  // deposition paths (eq. 4-5)
  NavigablePathPlanner router;   // shortest routes through navigable cells (alpha = 0)
  executive::ActionManager actions;
  executive::DepositionManager depositions;
  double return_below_m3;                      // less material than this on board: back to the base [m^3]
  int max_idle_retreat_moves;                  // retreat moves without work before trying to advance again
};

RampBuilder::RampBuilder(const AgentContext& context, RampBuilderOptions options)
    : context_(context),
      options_(std::move(options)) {
  // Fail on an invalid body, construction or goal synthesizer name now rather than at admission.
  (void)NavigabilityProcessor(context_.body.navigability);
  (void)NavigabilityProcessor(construction_params(context_));
  deliberative::require_goal_synthesizer(context_.task.goal_synthesizer);
  if (options_.pipeline) {
    PipelineParams p;
    p.separation_m = context_.task.separation_m;
    p.back_off_margin_m = 0.25 * p.separation_m;
    p.return_detect_m = 0.75 * p.separation_m;
    pipeline_.emplace(p);
  }
}

RampBuilder::~RampBuilder() = default;

const executive::MappingSystem& RampBuilder::map() const {
  if (!modules_) throw InvalidArgument("ramp builder: no map before admission");
  return modules_->map;
}

void RampBuilder::on_admission(const protocol::Admission& admission) {
  context_.assignment = assignment_from(context_, admission);
  const GridGeometry world = context_.assignment.world;
  const RobotBody& body = context_.body;
  const NavigabilityParams build = construction_params(context_);
  PlannerParams planner =
      options_.planner ? *options_.planner : default_planner_params(build.delta_m, world.cell_size_m);
  PlannerParams router = planner;
  router.alpha = 0.0;
  router.beta = 1.0;
  const double layer_m = cube_layer_m(body.cube_size_m, world.cell_size_m);
  modules_ = std::make_unique<Modules>(Modules{
      executive::MappingSystem(world, context_.assignment.tile_size),
      deliberative::LocalMapSynthesizer(body.navigability, body.sensing_range_m, build.kappa),
      NavigablePathPlanner(planner), NavigablePathPlanner(router),
      executive::ActionManager(body.max_step_m),
      executive::DepositionManager(
          executive::deposition_params(body, world.cell_size_m, context_.neighbour_keep_out_m, build.delta_m)),
      options_.pipeline ? std::min(body.max_deposit_m3, body.material_capacity_m3)
                        : layer_m * world.cell_size_m * world.cell_size_m,  // one cube
      static_cast<int>(std::ceil((body.reach_m + body.navigability.delta_m) / body.max_step_m)) + 1});
  goal_ = deliberative::make_goal_synthesizer(context_.task.goal_synthesizer, context_);
  state_ = RampState::kSurvey;
}

protocol::ActionRequest RampBuilder::decide(const protocol::SensorFrame& frame) {
  if (!modules_) throw InvalidArgument("ramp builder: frame for step " + std::to_string(frame.step) +
                                       " before admission");
  check_frame(context_, frame);
  trace_ = DecisionTrace{};
  trace_.before = state_;
  protocol::ActionRequest request = empty_request(context_, frame, "");
  if (frame.run_over || state_ == RampState::kDone) {
    state_ = RampState::kDone;
  } else {
    modules_->map.integrate(frame.tiles, {frame.x_m, frame.y_m});
    const Position robot{frame.x_m, frame.y_m};
    const std::optional<Position> goal = goal_->target({robot, frame.neighbours});
    const Position target = goal.value_or(robot);  // nothing left to build towards: stay
    const deliberative::LocalMap local = modules_->synthesizer.synthesize(modules_->map, robot, target);
    trace_.window_offset = local.offset;
    trace_.local_goal = local.goal;
    trace_.local_origin = local.origin;
    trace_.navigable_cells = local.navigable.cast<long long>().sum();
    if (state_ == RampState::kSurvey) state_ = RampState::kAdvance;

    // At the goal: on the local goal's cell, which is the target's cell, or the nearest the robot can get to a
    // target off the grid. In the pipeline the path has reached it: back to the base, to come again.
    const bool at_goal = local.goal == local.robot;
    if (pipeline_) pipeline_->observe(frame.neighbours, target);
    if (at_goal && !pipeline_) {
      state_ = RampState::kAtGoal;
    } else {
      if (state_ == RampState::kAtGoal) state_ = RampState::kAdvance;
      if (state_ != RampState::kReturnToBase && (frame.material_m3 < modules_->return_below_m3 - 1e-12 || at_goal))
        state_ = RampState::kReturnToBase;
      if (state_ == RampState::kReturnToBase) {
        return_step(local, frame, request);
      } else if (pipeline_) {
        pipeline_step(local, frame, target, request);
      } else if (state_ == RampState::kRetreat) {
        retreat_step(local, frame, request);
      } else {
        build_step(local, frame, request);
      }
    }
  }
  trace_.after = state_;
  request.state = to_string(state_);
  return request;
}

bool RampBuilder::plan_path(const deliberative::LocalMap& local) {
  if (!trace_.planned) {
    trace_.plan = modules_->planner.plan(local.gap, local.known, local.robot, local.goal);
    trace_.planned = true;
  }
  return trace_.plan.found;
}

void RampBuilder::move(const executive::Motion& motion, protocol::ActionRequest& request) {
  trace_.motion = motion;
  request.move = true;
  request.target_x_m = motion.target.x;
  request.target_y_m = motion.target.y;
}

void RampBuilder::deposit(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position at,
                          std::size_t from, protocol::ActionRequest& request) {
  // The path from where the robot will stand: the cells it leaves behind are its way back, not work.
  const auto& path = trace_.plan.path;
  const std::vector<CellIndex> ahead(path.begin() + static_cast<std::ptrdiff_t>(std::min(from, path.size())),
                                     path.end());
  trace_.deposition = modules_->depositions.plan(local, ahead, at, frame.material_m3, neighbourhood(frame));
  request.depositions = trace_.deposition.depositions;
}

void RampBuilder::build_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                             protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  if (!plan_path(local)) return;  // no path through known cells: wait for the map to grow
  if (const auto motion = modules_->actions.advance(local, trace_.plan.path, robot)) {
    move(*motion, request);
    deposit(local, frame, motion->target, motion->path_index, request);
    state_ = RampState::kAdvance;
    return;
  }
  deposit(local, frame, robot, 0, request);
  if (!request.depositions.empty()) {
    state_ = RampState::kBuild;
    return;
  }
  state_ = RampState::kRetreat;
  deposited_since_blocked_ = false;
  idle_retreat_moves_ = 0;
  retreat_step(local, frame, request);
}

void RampBuilder::retreat_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                               protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  if (!plan_path(local)) {
    ++idle_retreat_moves_;
    return;
  }
  const auto& path = trace_.plan.path;
  deposit(local, frame, robot, 0, request);
  if (!request.depositions.empty()) {
    deposited_since_blocked_ = true;
    idle_retreat_moves_ = 0;
    return;
  }
  // Advance again only once something changed (or after a long idle retreat): advancing onto the cell just left
  // without building would only block again.
  if (deposited_since_blocked_ || idle_retreat_moves_ >= modules_->max_idle_retreat_moves) {
    if (const auto motion = modules_->actions.advance(local, path, robot)) {
      move(*motion, request);
      deposit(local, frame, motion->target, motion->path_index, request);
      state_ = RampState::kAdvance;
      return;
    }
    deposited_since_blocked_ = false;
  }
  // Step back the way the robot came and fill what comes into reach: the gap where it stood.
  ++idle_retreat_moves_;
  const auto motion = step_back(local, robot);
  if (!motion) return;
  move(*motion, request);
  deposit(local, frame, motion->target, 0, request);
  if (!request.depositions.empty()) {
    deposited_since_blocked_ = true;
    idle_retreat_moves_ = 0;
  }
}

std::optional<executive::Motion> RampBuilder::step_back(const deliberative::LocalMap& local, Position robot) {
  // Towards the local origin, or the oldest navigable cell of the trajectory in the window when the robot stands on
  // the origin; with no way it came (it has not moved yet), to the navigable cell farthest from the local goal.
  std::optional<CellIndex> anchor;
  if (local.origin && *local.origin != local.robot) anchor = local.origin;
  if (!anchor) anchor = oldest_navigable_trajectory_cell(local);
  if (!anchor) anchor = farthest_navigable_from_goal(local);
  if (!anchor) return std::nullopt;
  const auto route = modules_->router.plan(local.gap, local.navigable, local.robot, *anchor);
  if (!route.found) return std::nullopt;
  return modules_->actions.advance(local, route.path, robot);
}

void RampBuilder::pipeline_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position target,
                                protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  const PipelinePlace place = pipeline_->place(robot, target);
  trace_.role = place.role;
  const auto& front = place.front;
  switch (place.role) {
    case PipelineRole::kActive:
      if (state_ == RampState::kRetreat)
        retreat_step(local, frame, request);
      else
        build_step(local, frame, request);
      return;
    case PipelineRole::kFollow: follow_step(local, frame, {front->x_m, front->y_m}, request); return;
    case PipelineRole::kHold: state_ = RampState::kHold; return;
    case PipelineRole::kBackOff: back_off_step(local, frame, {front->x_m, front->y_m}, request); return;
  }
}

void RampBuilder::follow_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position front,
                              protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  state_ = RampState::kHold;
  if (!plan_path(local)) return;
  const auto motion = modules_->actions.advance(local, trace_.plan.path, robot);
  if (!motion || distance(motion->target, front) < pipeline_->params().separation_m) return;
  move(*motion, request);
  state_ = RampState::kFollow;
}

void RampBuilder::back_off_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position front,
                                protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  state_ = RampState::kBackOff;
  const auto motion = step_back(local, robot);
  if (motion && distance(motion->target, front) > distance(robot, front)) move(*motion, request);
}

std::optional<CellIndex> RampBuilder::farthest_navigable_from_goal(const deliberative::LocalMap& local) {
  const Position goal = local.center(local.goal);
  return best_navigable_cell(local, -distance(local.center(local.robot), goal),
                             [&](Position p) { return -distance(p, goal); });
}

std::optional<CellIndex> RampBuilder::oldest_navigable_trajectory_cell(const deliberative::LocalMap& local) const {
  for (const CellIndex global : modules_->map.trajectory()) {
    const CellIndex p = local.to_local(global);
    if (local.contains(p) && p != local.robot && local.navigable(p.row, p.col) != 0) return p;
  }
  return std::nullopt;
}

void RampBuilder::return_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                              protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  const Position base = context_.assignment.base;
  const double radius = context_.assignment.base_radius_m - kBaseMarginM;
  if (distance(robot, base) <= radius) {
    request.refill = trace_.refill = true;
    state_ = RampState::kAdvance;
    return;
  }
  // Where to go: the navigable cell within the base radius nearest the robot; else the navigable cell nearest the
  // base when that is nearer than the robot by at least a cell; else the oldest navigable cell of the trajectory in
  // the window (the way the robot came from the base).
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::optional<CellIndex> goal = best_navigable_cell(local, kNone, [&](Position p) {
    return distance(p, base) <= radius ? distance(p, robot) : kNone;
  });
  if (!goal)
    goal = best_navigable_cell(local, distance(robot, base) - local.geometry().cell_size_m,
                               [&](Position p) { return distance(p, base); });
  if (!goal) goal = oldest_navigable_trajectory_cell(local);
  if (!goal) return;
  trace_.plan = modules_->router.plan(local.gap, local.navigable, local.robot, *goal);
  trace_.planned = true;
  if (!trace_.plan.found) return;
  if (const auto motion = modules_->actions.advance(local, trace_.plan.path, robot)) {
    move(*motion, request);
    if (distance(motion->target, base) <= radius) {
      request.refill = trace_.refill = true;
      state_ = RampState::kAdvance;
    }
  }
}

}  // namespace marsala::agent::reactive
