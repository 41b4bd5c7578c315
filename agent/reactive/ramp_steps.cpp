#include "marsala/agent/reactive/ramp_steps.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "marsala/agent/deliberative/home_route.hpp"
#include "marsala/agent/executive/depositor.hpp"
#include "marsala/agent/executive/lane.hpp"
#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::reactive {
namespace {

constexpr EnumName<BuildPhase> kBuildPhaseNames[] = {
    {BuildPhase::kAdvance, "advance"}, {BuildPhase::kBuild, "build"}, {BuildPhase::kRetreat, "retreat"}};

/// Kept inside the world's base radius so a refill is never rejected on a tie [m].
constexpr double kBaseMarginM = 1e-6;

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

/// True when both `a` and `b` (local indices) lie in the window and in the body ball of radius `radius` [cells] around
/// `cell`: where a told drop's pair breaks the rule (the ball of disc_offsets()).
bool ball_holds(const deliberative::LocalMap& local, CellIndex cell, CellIndex a, CellIndex b, double radius) {
  const auto in = [&](CellIndex p) {
    const double dr = p.row - cell.row, dc = p.col - cell.col;
    return local.contains(p) && dr * dr + dc * dc <= radius * radius + tolerance::kBallCells2;
  };
  return in(a) && in(b);
}

}  // namespace

std::string to_string(BuildPhase phase) { return enum_to_string(kBuildPhaseNames, phase); }

double scan_gap_margin_m(const SensorSpec& sensor, double distance_m, double kappa) {
  if (!(distance_m >= 0.0) || !std::isfinite(distance_m) || !(kappa >= 0.0) || !std::isfinite(kappa))
    throw InvalidArgument(fmt::format("scan gap margin: distance {} m and kappa {} must be finite and >= 0",
                                      distance_m, kappa));
  const double range_m = std::hypot(distance_m, sensor.mount_height_m);
  if (!(range_m > 0.0)) return kScanGapMargin * sensor.noise_sd_at(0.0);
  const double up = sensor.mount_height_m / range_m, along = distance_m / range_m;
  return kScanGapMargin * sensor.noise_sd_at(range_m) * (up + kappa * along);
}

struct RampSteps::Modules {
  executive::MappingSystem map;
  deliberative::LocalMapSynthesizer synthesizer;
  NavigablePathPlanner planner;  // deposition paths (eq. 4-5)
  NavigablePathPlanner router;   // shortest routes through navigable cells (alpha = 0)
  executive::ActionManager actions;
  executive::DepositionManager depositions;
  int max_idle_retreat_moves;                       // retreat moves without work before trying to advance again
  std::unique_ptr<executive::Depositor> depositor;  // turns the manager's wish into depositions or deposits
};

RampSteps::RampSteps(const AgentContext& context, std::optional<PlannerParams> planner)
    : context_(context), planner_(std::move(planner)) {
  // Fail on an invalid body, construction or goal synthesizer name now rather than at admission.
  (void)NavigabilityProcessor(context_.type.body.navigability);
  (void)NavigabilityProcessor(construction_params(context_.type));
  deliberative::require_goal_synthesizer(context_.type.goal_synthesizer);
  (void)executive::make_depositor(context_.type);
}

RampSteps::~RampSteps() = default;

const executive::MappingSystem& RampSteps::map() const {
  if (!modules_) throw InvalidArgument("ramp steps: no map before admission");
  return modules_->map;
}

const executive::RefusedCells& RampSteps::refused() const {
  if (!modules_) throw InvalidArgument("ramp steps: no refused cells before admission");
  return *memory_.refused;
}

void RampSteps::admit(const protocol::Admission& admission) {
  context_.assignment = assignment_from(context_, admission);
  const GridGeometry world = context_.assignment.world;
  const RobotBody& body = context_.type.body;
  const NavigabilityParams build = construction_params(context_.type);
  PlannerParams planner = planner_ ? *planner_ : default_planner_params(build.delta_m, world.cell_size_m);
  executive::DepositionParams deposits =
      executive::deposition_params(body, world.cell_size_m, context_.neighbour_keep_out_m, build.delta_m);
  deposits.pad_centre = context_.assignment.base;
  deposits.pad_radius_m = kPadFraction * context_.assignment.base_radius_m;
  // A scanned map reads each surface within a few noise spreads at the manipulator's reach: leave that much unfilled.
  if (context_.type.sensor.casts_rays()) {
    deposits.gap_margin_m = scan_gap_margin_m(context_.type.sensor, body.reach_m + body.navigability.delta_m, build.kappa);
    // The cells next to the robot are read from about a body length away; a pair of them differs by noise of up to
    // about two spreads.
    deposits.exit_margin_m = kScanExitMargin * context_.type.sensor.noise_sd_at(body.navigability.delta_m);
    // A pile's edge beside the robot lands on cells read from about a body length away, within the same noise.
    deposits.pile_margin_m = deposits.exit_margin_m;
    deposits.keep_reach_without_way_out = true;
  }
  const std::size_t streak_cells =
      context_.type.sensor.casts_rays() ? static_cast<std::size_t>(world.rows) * world.cols : 0;
  memory_.gap_streaks.assign(streak_cells, {});
  memory_.others_near.assign(streak_cells, 0);
  if (band_centre_) memory_.raised.emplace(world.rows, world.cols);
  // A refused cell comes back once its ball reads differently: by more than the map's noise margin, at least half a
  // cube layer (the least another robot's deposit changes a cell).
  const double ball_cells = build.delta_m / (2.0 * world.cell_size_m);
  const double body_ball_cells = body.navigability.delta_m / (2.0 * world.cell_size_m);
  const double change = std::max(deposits.gap_margin_m, 0.5 * deposits.cube_layer_m);
  memory_.refused.emplace(body_ball_cells, change, kRefusedMotionSteps);
  memory_.refused_depositions.emplace(ball_cells, change, kRefusedMotionSteps);
  PlannerParams router = planner;
  router.alpha = 0.0;
  router.beta = 1.0;
  modules_ = std::make_unique<Modules>(
      Modules{executive::MappingSystem(world, context_.assignment.tile_size, context_.type.sensor),
              deliberative::LocalMapSynthesizer(body.navigability, body.sensing_range_m, build.kappa),
              NavigablePathPlanner(planner), NavigablePathPlanner(router), executive::ActionManager(body.max_step_m),
              executive::DepositionManager(deposits),
              static_cast<int>(std::ceil((body.reach_m + body.navigability.delta_m) / body.max_step_m)) + 1,
              executive::make_depositor(context_.type)});
  // The cells a scanning robot stands on were occupiable (docs/runtime.md#cells-stood-on): a fact its map keeps while
  // the ball reads the same, within the change that brings a refused cell back.
  if (context_.type.sensor.casts_rays()) modules_->map.keep_stood_cells(body_ball_cells, change);
  if (fill_under_rays_ && context_.type.sensor.casts_rays())
    modules_->map.record_overflights(body.reach_m + body.navigability.delta_m + body.max_step_m);
  goal_ = deliberative::make_goal_synthesizer(context_.type.goal_synthesizer, context_);
}

void RampSteps::set_registration(CellIndex offset) {
  registration_ = offset;
  if (modules_) modules_->map.set_registration(offset);
}

BuildView RampSteps::look(const protocol::SensorFrame& frame, BuildTrace& trace) {
  modules_->map.set_registration(registration_);
  remember_result(frame);
  update_map(frame);
  learn_refusals(frame);
  BuildView view = synthesize_view(frame);
  if (memory_.raised) memory_.raised->observe(view.local);  // before the neighbours leave the window's masks
  keep_clear(frame, view);
  trace.window_offset = view.local.offset;
  trace.local_goal = view.local.goal;
  trace.local_origin = view.local.origin;
  trace.navigable_cells = view.local.navigable.cast<long long>().sum();
  return view;
}

void RampSteps::remember_result(const protocol::SensorFrame& frame) {
  Sent& sent = memory_.sent;
  const bool accepted = frame.last_result == protocol::ActionResult::kAccepted;
  const bool rejected = frame.last_result == protocol::ActionResult::kRejected;
  if (rejected && !sent.deposits.empty())
    memory_.deposit_limit = static_cast<int>(sent.deposits.size()) / 2;
  else if (accepted)
    memory_.deposit_limit = -1;
  // The robot's own construction, once accepted, is in its map even where its sensor cannot see it (a scanned map).
  if (accepted && context_.type.sensor.casts_rays()) {
    for (const Deposition& d : sent.layers) modules_->map.record_built({d.row, d.col}, d.height_m);
    if (context_.type.depositor.kind == DepositorKind::kCube) {
      const double side = depositor_cube_size_m(context_.type);
      for (const Deposit& d : sent.deposits)
        for (const CellRise& r : cube_column_shape(modules_->map.geometry(), d.centre, side,
                                                   static_cast<int>(whole_cubes(d.volume_m3, side)))
                                     .rises)
          modules_->map.record_built(r.cell, r.rise_m);
    } else if (context_.type.depositor.kind == DepositorKind::kCone) {
      // A pile settles on the terrain as the map reads it, each on the piles before it in the request (as the world
      // settles them): without it, a pile dumped beside the robot, where its camera does not look, stays unread and
      // the next pile there is planned on the bare ground it covered.
      for (const Deposit& d : sent.deposits)
        for (const CellRise& r :
             cone_pile_shape(modules_->map.heights(), d.centre, d.volume_m3, context_.type.depositor.repose_deg).rises)
          modules_->map.record_built(r.cell, r.rise_m);
    }
  }
  // A refusal is information (docs/runtime.md#refused-requests): which cell, and whether the terrain was the reason.
  // The world names cells in its own grid; the map registers them shifted by the localisation offset.
  memory_.refusal.reset();
  if (rejected) {
    const auto registered = [&](CellIndex c) { return CellIndex{c.row + registration_.row, c.col + registration_.col}; };
    const auto named = executive::cell_named(frame.last_reason);
    CellIndex cell = sent.motion.value_or(CellIndex{});
    if (named) cell = registered(*named);
    const auto starts = [&](const char* word) { return frame.last_reason.rfind(word, 0) == 0; };
    const bool motion = !starts("deposit") && !starts("refill") && !starts("robot type");  // rules 1, 2
    if (sent.motion && motion) {
      memory_.refusal = Memory::Refusal{cell, executive::refused_for_terrain(frame.last_reason), true, {}};
      for (executive::DropRefusal drop : executive::drops_named(frame.last_reason)) {
        drop.low = registered(drop.low);
        drop.high = registered(drop.high);
        memory_.refusal->drops.push_back(drop);
      }
    } else if (named && !motion) {
      // A pile that reached a robot's body: where it was dumped is held out, not the cell under the body (never a
      // target anyway), or the same pile is asked for again from the same place.
      if (const auto pile = executive::pile_under_robot_named(frame.last_reason))
        if (const auto dumped = modules_->map.geometry().cell_at(*pile)) cell = *dumped;
      memory_.refusal = Memory::Refusal{cell, false, false, {}};
    }
    // A deposition refused for the deposit bound names the height it would have left (in the cells the request
    // named): the cell stands at that less the rise asked for, whatever the map read there (a stale reading,
    // docs/runtime.md#deposit-bound).
    if (const auto bound = executive::bound_named(frame.last_reason); bound && context_.type.sensor.casts_rays())
      for (const Deposition& d : sent.layers)
        if (CellIndex{d.row, d.col} == bound->cell) modules_->map.record_floor(bound->cell, bound->height_m - d.height_m);
  }
  sent = Sent{};
}

void RampSteps::learn_refusals(const protocol::SensorFrame& frame) {
  // A motion refused for the terrain: the ground the map only assumed in the target's ball is what it guessed wrong.
  if (memory_.refusal && memory_.refusal->terrain && memory_.refusal->motion) {
    modules_->map.forget_assumed_ground(memory_.refusal->cell, 0.5 * context_.type.body.navigability.delta_m);
    // The drops the body found: their heights are facts the map keeps (a pit read at its rim's height).
    if (context_.type.sensor.casts_rays())
      for (const executive::DropRefusal& drop : memory_.refusal->drops) {
        modules_->map.record_drop(drop.low, drop.low_m, drop.high, drop.high_m);
        record_drop_level(drop);
      }
  }
  const executive::MappingSystem& map = modules_->map;
  memory_.refused->update(map.heights(), map.known(), frame.step);
  memory_.refused_depositions->update(map.heights(), map.known(), frame.step);
  if (!memory_.refusal) return;
  const Memory::Refusal& r = *memory_.refusal;
  executive::RefusedCells& cells = r.motion ? *memory_.refused : *memory_.refused_depositions;
  if (r.terrain)
    cells.refuse_terrain(r.cell, map.heights(), map.known(),
                         !r.drops.empty() && context_.type.sensor.casts_rays()
                             ? std::optional<CellIndex>(r.drops.front().low)
                             : std::nullopt);
  else
    cells.refuse_for_now(r.cell, frame.step);
}

void RampSteps::record_drop_level(const executive::DropRefusal& drop) {
  const GridGeometry& g = modules_->map.geometry();
  if (!g.contains(drop.low) || !std::isfinite(drop.high_m)) return;
  const NavigabilityParams& body = context_.type.body.navigability;
  const double kappa = std::max(body.kappa, construction_params(context_.type).kappa);
  const double d = g.cell_size_m * std::hypot(drop.high.row - drop.low.row, drop.high.col - drop.low.col);
  const double layer = modules_->depositions.params().cube_layer_m;
  // The pair passes the body's rule (2.3) once the low cell stands within eps + kappa d of the high one; a layer's
  // rounding and half the rest of eps below that level keep it passing, and the level stays under the high cell's
  // slope (the steeper of the body's and the construction's), so under every bound the world holds the cell to.
  // Below that level less the rounding (the level's own layer and half of eps), the pair still breaks the rule.
  const double fill_m = drop.high_m - kappa * d - 0.5 * std::max(0.0, body.eps_m - layer);
  const DropLevel level{fill_m, fill_m - 0.5 * (body.eps_m + layer), drop.high};
  auto [it, added] = memory_.drop_levels.try_emplace(drop.low, level);
  if (!added && level.pass_m > it->second.pass_m) it->second = level;
}

bool RampSteps::fails_a_told_drop(const deliberative::LocalMap& local, CellIndex cell) const {
  const double radius = 0.5 * context_.type.body.navigability.delta_m / local.geometry().cell_size_m;
  // The pair breaks the rule only in a ball that holds both its cells: a drop named ahead does not hold out the way
  // back, whose balls hold its low cell but not its high one.
  for (const auto& [low, level] : memory_.drop_levels) {
    const CellIndex p = local.to_local(low);
    if (ball_holds(local, cell, p, local.to_local(level.high), radius) && local.heights(p.row, p.col) < level.pass_m)
      return true;
  }
  return false;
}

void RampSteps::hold_out_told_drops(const deliberative::LocalMap& local, CellMask& mask) const {
  const double radius = 0.5 * context_.type.body.navigability.delta_m / local.geometry().cell_size_m;
  const std::vector<CellIndex> ball = disc_offsets(radius);
  // fails_a_told_drop() drop by drop instead of cell by cell: a cell whose ball holds a drop's lower cell lies in the
  // ball around that cell.
  for (const auto& [low, level] : memory_.drop_levels) {
    const CellIndex p = local.to_local(low), q = local.to_local(level.high);
    if (!local.contains(p) || !(local.heights(p.row, p.col) < level.pass_m)) continue;
    for (const CellIndex o : ball) {
      const CellIndex cell{p.row + o.row, p.col + o.col};
      if (local.contains(cell) && ball_holds(local, cell, p, q, radius)) mask(cell.row, cell.col) = 0;
    }
  }
}

void RampSteps::fill_to_drop_levels(deliberative::LocalMap& local) const {
  const double margin = modules_->depositions.params().gap_margin_m;
  for (const auto& [low, level] : memory_.drop_levels) {
    const CellIndex p = local.to_local(low);
    if (!local.contains(p) || local.known(p.row, p.col) == 0) continue;
    const double rise = level.fill_m - local.heights(p.row, p.col);
    if (rise > 0.0) local.gap(p.row, p.col) = std::max(local.gap(p.row, p.col), rise + margin);
  }
}

void RampSteps::update_map(const protocol::SensorFrame& frame) {
  const Position robot{frame.x_m, frame.y_m};
  const SensorSpec& sensor = context_.type.sensor;
  modules_->map.integrate(frame.tiles, robot);
  if (frame.scanned) {  // from where it believes its sensor is, to the sub-cell part of its localisation error
    const Position sensor_at{robot.x + sub_cell_error_.x, robot.y + sub_cell_error_.y};
    modules_->map.integrate_scan(frame.points, executive::believed_sensor_origin(sensor_at, frame.z_m, sensor));
  }
  if (sensor.casts_rays()) {  // docs/runtime.md#mapping: the ground its body stands on and may step onto next
    const NavigabilityParams& body = context_.type.body.navigability;
    const double radius_m = 0.5 * body.delta_m + context_.type.body.max_step_m;
    modules_->map.assume_ground(robot, frame.z_m, radius_m, body.eps_m + body.kappa * radius_m);
    modules_->map.record_stood(robot);  // the cell it stands on was occupiable
  }
}

BuildView RampSteps::synthesize_view(const protocol::SensorFrame& frame) {
  const Position robot{frame.x_m, frame.y_m};
  deliberative::GoalQuery query{robot, frame.neighbours, {}};
  // Level for what it builds: the construction's slope and discontinuity under the robot's own body.
  NavigabilityParams level = construction_params(context_.type);
  level.delta_m = context_.type.body.navigability.delta_m;
  query.unlevel = [this, level](const CellRect& area) {
    return deliberative::unlevel_cells(modules_->map.known_map(), area, level);
  };
  const std::optional<Position> goal = goal_->target(query);
  const Position target = goal.value_or(robot);  // nothing left to build towards: stay
  memory_.target = target;
  BuildView view{modules_->synthesizer.synthesize(modules_->map.known_map(), robot, target), robot, target};
  clear_pad_gap(view.local);
  if (context_.type.sensor.casts_rays()) {
    mark_others_near(frame);
    count_gap_scans(view.local, frame.scanned);
  }
  return view;
}

void RampSteps::keep_clear(const protocol::SensorFrame& frame, BuildView& view) {
  const RobotBody& body = context_.type.body;
  memory_.others =
      executive::body_clearances(frame.neighbours, context_.agent_id, 0.5 * body.navigability.delta_m, body.max_step_m);
  memory_.corridor = view.local.navigable;
  memory_.terrain_occupiable = view.local.occupiable;
  executive::keep_clear(view.local, view.robot, memory_.others);
  if (memory_.refused->empty()) return;
  executive::keep_off(view.local, memory_.refused->cells());
}

bool RampSteps::plan_path(const deliberative::LocalMap& local, BuildTrace& trace) {
  if (!trace.planned) plan_to(local, local.goal, trace);
  return trace.plan.found;
}

bool RampSteps::plan_path_towards(const deliberative::LocalMap& local, Position towards, BuildTrace& trace) {
  const auto cell = local.cell_at(towards);
  if (!cell || local.passable(cell->row, cell->col) == 0) return plan_path(local, trace);
  plan_to(local, *cell, trace);
  return trace.plan.found;
}

void RampSteps::plan_to(const deliberative::LocalMap& local, CellIndex goal, BuildTrace& trace) {
  trace.plan = memory_.raised ? modules_->planner.plan(plan_gap(local), local.passable, local.robot, goal)
                              : modules_->planner.plan(local.gap, local.passable, local.robot, goal);
  trace.planned = true;
}

std::optional<executive::Motion> RampSteps::advance(const deliberative::LocalMap& local,
                                                    const std::vector<CellIndex>& path, Position robot) const {
  return modules_->actions.advance(local, path, robot, memory_.others);
}

void RampSteps::clear_pad_gap(deliberative::LocalMap& local) const {
  const Position base = context_.assignment.base;
  const double radius = kPadFraction * context_.assignment.base_radius_m;
  // within() holds only for centres within the radius along both axes: the cells centred in that square.
  Rect square;
  square.x0 = base.x - radius;
  square.x1 = base.x + radius;
  square.y0 = base.y - radius;
  square.y1 = base.y + radius;
  const CellRect cells = cells_centred_in(local.geometry(), square);
  for (int r = cells.first.row; r < cells.first.row + cells.rows; ++r)
    for (int c = cells.first.col; c < cells.first.col + cells.cols; ++c)
      if (within(local.center({r, c}).x - base.x, local.center({r, c}).y - base.y, radius)) local.gap(r, c) = 0.0;
}

void RampSteps::count_gap_scans(const deliberative::LocalMap& local, bool scanned) {
  const executive::MappingSystem& map = modules_->map;
  const int cols = map.geometry().cols;
  const double margin = modules_->depositions.params().gap_margin_m;
  if (!scanned) return;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const CellIndex g = local.to_global({r, c});
      if (!(deliberative::rise_wanted_m(local, {r, c}, margin) > 0.0) || !current(g)) continue;
      GapStreak& streak = memory_.gap_streaks[static_cast<std::size_t>(g.row) * cols + g.col];
      streak.scans = streak.last_scan == map.scans() - 1 ? streak.scans + 1 : 1;
      streak.last_scan = map.scans();
    }
}

void RampSteps::mark_others_near(const protocol::SensorFrame& frame) {
  const executive::MappingSystem& map = modules_->map;
  const RobotBody& body = context_.type.body;
  for (const Neighbour& n : frame.neighbours) {
    if (!std::isfinite(n.position.x) || !std::isfinite(n.position.y)) continue;
    const auto cell = map.geometry().cell_at(n.position);
    if (!cell) continue;
    for (DiscIterator it(map.geometry(), *cell, body.reach_m + body.max_step_m); !it.is_past_end(); ++it)
      memory_.others_near[static_cast<std::size_t>((*it).row) * map.geometry().cols + (*it).col] = map.scans();
  }
}

bool RampSteps::current(CellIndex cell) const {
  const executive::MappingSystem& map = modules_->map;
  if (map.hit_within(cell, kFreshScans)) return true;
  // An unknown cell under the latest scan's rays: its gap is from that scan (fill_under_rays()).
  if (!map.is_known(cell) && map.overflown(cell)) return true;
  const int last = std::max(map.last_hit_scan(cell), map.told_scan(cell));
  return last > 0 && memory_.others_near[static_cast<std::size_t>(cell.row) * map.geometry().cols + cell.col] < last;
}

void RampSteps::clear_unconfirmed_gap(deliberative::LocalMap& local) const {
  const executive::MappingSystem& map = modules_->map;
  const int cols = map.geometry().cols;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c) {
      const CellIndex g = local.to_global({r, c});
      const GapStreak& streak = memory_.gap_streaks[static_cast<std::size_t>(g.row) * cols + g.col];
      if (streak.last_scan != map.scans() || streak.scans < kConfirmScans) local.gap(r, c) = 0.0;
    }
}

void RampSteps::set_lane(double offset_m, double corridor_width_m) {
  lane_offset_m_ = offset_m;
  corridor_width_m_ = corridor_width_m;
}

std::vector<CellIndex> RampSteps::in_lane(const deliberative::LocalMap& local,
                                          const std::vector<CellIndex>& path) const {
  if (!(lane_offset_m_ > 0.0) || memory_.corridor.rows() != local.rows() || memory_.corridor.cols() != local.cols())
    return path;
  return executive::lane_path(local, memory_.corridor, path, lane_offset_m_, corridor_width_m_);
}

std::vector<CellIndex> RampSteps::on_band_centre(const deliberative::LocalMap& local,
                                                  const std::vector<CellIndex>& ahead) const {
  if (!(corridor_width_m_ > 0.0) || memory_.corridor.rows() != local.rows() || memory_.corridor.cols() != local.cols())
    return ahead;
  // Only as far off the robot's path as keeps the body ball of every cell it drives on inside the footprint (what it
  // drives on gets built): half the band less half a body, and less a cell's diagonal, since the shifted cells are
  // rounded to cells and the footprint is a disc of cells with a ragged edge.
  const double max_shift_m = 0.5 * (corridor_width_m_ - context_.type.body.navigability.delta_m) -
                             std::sqrt(2.0) * local.geometry().cell_size_m;
  if (!memory_.raised) return executive::band_centre_path(local, memory_.corridor, ahead, corridor_width_m_, max_shift_m);
  // Nothing is built along a path that runs beside the structure (the cells seen raised): the band is there already.
  const CellMask built = built_cells(local);
  return executive::band_centre_path(local, memory_.corridor, ahead, corridor_width_m_, max_shift_m, &built);
}

double RampSteps::way_radius_m() const {
  // The band holds the way and, each side of it, the room of a lane: what is left of its half-width without the
  // lane's offset; never less than the robot's own half body.
  return std::max(0.5 * context_.type.body.navigability.delta_m, 0.5 * corridor_width_m_ - lane_offset_m_);
}

Heightmap RampSteps::band_gap(const deliberative::LocalMap& local, const std::vector<CellIndex>& ahead) {
  if (!(corridor_width_m_ > 0.0)) return local.gap;
  // What is left to fill is judged against the slope of the way's own surface, the cells the body drives on along
  // the footprint's path from where it will stand (executive::way_fill_gap): the terrain and structure beside it,
  // also inside the band (other fronts' strips, high ground the band's edge reaches), neither raise its target nor
  // widen it. A robot that waits or is refused sees the same way on the same heights: it reuses the last bound.
  return executive::gap_below(
      local, bound_of(memory_.band_bound, local, executive::way_sources(local, ahead, way_radius_m())));
}

const Heightmap& RampSteps::bound_of(PlanBound& memo, const deliberative::LocalMap& local, Heightmap sources) const {
  // The bound is read only where the window's gap is positive (gap_below()): only those cells are projected.
  CellMask wanted = executive::gap_cells(local);
  if (!(memo.offset == local.offset && memo.first.rows() == sources.rows() && memo.first.cols() == sources.cols() &&
        (memo.first.heights().array() == sources.heights().array()).all() &&
        (memo.wanted.array() >= wanted.array()).all())) {
    memo.bound = MarsProcessor(construction_params(context_.type).kappa).project(sources, wanted);
    memo.first = std::move(sources);
    memo.wanted = std::move(wanted);
    memo.offset = local.offset;
  }
  return memo.bound;
}

CellMask RampSteps::built_cells(const deliberative::LocalMap& local) const {
  // A cell counts as raised by at least half a cube layer (the least a deposition adds), and beyond a scanned map's
  // noise margin.
  const executive::DepositionParams& deposits = modules_->depositions.params();
  return memory_.raised->raised(local, std::max(deposits.gap_margin_m, 0.5 * deposits.cube_layer_m));
}

Heightmap RampSteps::plan_gap(const deliberative::LocalMap& local) {
  // Every front prices its way by the same terrain, the one first seen, not by what other fronts raised since: a
  // strip built beside a robot's way would otherwise price the cells along it (the strip raises their MARS bound) and
  // send the next front round it, to build a strip of its own (docs/runtime.md#the-construction-band).
  // The bound of the first-seen heights changes only when the window moves or sees new cells: a robot building in
  // place reuses the last one.
  Heightmap gap = executive::gap_below(
      local, bound_of(memory_.plan_bound, local, executive::first_seen_heights(local, *memory_.raised)));
  // What is built is the structure: its cells cost nothing, so a front that meets a strip drives on along it and
  // extends it at its tip.
  const CellMask built = built_cells(local);
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (built(r, c) != 0) gap(r, c) = 0.0;
  return gap;
}

void RampSteps::move(const executive::Motion& motion, BuildTrace& trace, protocol::ActionRequest& request) {
  trace.motion = motion;
  memory_.sent.motion = modules_->map.geometry().cell_at(motion.target);
  request.move = true;
  request.target_x_m = motion.target.x;
  request.target_y_m = motion.target.y;
}

void RampSteps::deposit(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position at,
                        std::size_t from, BuildTrace& trace, protocol::ActionRequest& request) {
  // The path from where the robot will stand: the cells it leaves behind are its way back, not work.
  const auto& path = trace.plan.path;
  std::vector<CellIndex> ahead(path.begin() + static_cast<std::ptrdiff_t>(std::min(from, path.size())), path.end());
  if (band_centre_) ahead = on_band_centre(local, ahead);
  // Depositions are judged on the terrain alone (what stays occupiable and connected), not on where the other
  // robots stand this step: the masks before the neighbours were taken out.
  deliberative::LocalMap terrain_only = local;
  if (memory_.terrain_occupiable.rows() == local.rows() && memory_.terrain_occupiable.cols() == local.cols()) {
    terrain_only.occupiable = memory_.terrain_occupiable;
    terrain_only.navigable = memory_.corridor;
  }
  if (context_.type.sensor.casts_rays()) clear_unconfirmed_gap(terrain_only);
  if (band_centre_) terrain_only.gap = band_gap(terrain_only, ahead);
  if (context_.type.sensor.casts_rays()) fill_to_drop_levels(terrain_only);
  for (const CellIndex g : memory_.refused_depositions->cells()) {
    const CellIndex p = terrain_only.to_local(g);
    if (terrain_only.contains(p)) terrain_only.gap(p.row, p.col) = 0.0;
  }
  trace.deposition = modules_->depositor->plan(modules_->depositions, terrain_only, ahead, at, frame.material_m3,
                                               neighbourhood(frame));
  // A scanned map: where the path turned aside from the straight way to the target (its cells' balls hold cells no
  // scan reached, a drop's shadow), the confirmed gap on that way is still work (docs/runtime.md#mapping).
  if (context_.type.sensor.casts_rays() && !trace.deposition.any())
    if (const auto stand = terrain_only.cell_at(at))
      trace.deposition = modules_->depositor->plan(modules_->depositions, terrain_only,
                                                   executive::line_cells(terrain_only, *stand, memory_.target), at,
                                                   frame.material_m3, neighbourhood(frame));
  auto& deposits = trace.deposition.deposits;
  if (memory_.deposit_limit >= 0 && deposits.size() > static_cast<std::size_t>(memory_.deposit_limit)) {
    deposits.resize(static_cast<std::size_t>(memory_.deposit_limit));
    trace.deposition.volume_m3 = 0.0;
    for (const Deposit& d : deposits) trace.deposition.volume_m3 += d.volume_m3;
  }
  request.depositions = trace.deposition.depositions;
  request.deposits = deposits;
  memory_.sent.layers = request.depositions;
  memory_.sent.deposits = request.deposits;
}

std::optional<BuildPhase> RampSteps::build_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                                                BuildTrace& trace, protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  if (!plan_path(local, trace)) return std::nullopt;  // no path through known cells: wait for the map to grow
  if (const auto motion = advance(local, trace.plan.path, robot)) {
    move(*motion, trace, request);
    deposit(local, frame, motion->target, motion->path_index, trace, request);
    return BuildPhase::kAdvance;
  }
  deposit(local, frame, robot, 0, trace, request);
  if (trace.deposition.any()) return BuildPhase::kBuild;
  if (const auto motion = ask_ahead(local, trace.plan.path, robot)) {
    move(*motion, trace, request);
    return BuildPhase::kAdvance;
  }
  memory_.deposited_since_blocked = false;
  memory_.idle_retreat_moves = 0;
  return retreat_step(local, frame, trace, request);
}

BuildPhase RampSteps::retreat_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                                   BuildTrace& trace, protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  if (!plan_path(local, trace)) {
    ++memory_.idle_retreat_moves;
    return BuildPhase::kRetreat;
  }
  const auto& path = trace.plan.path;
  deposit(local, frame, robot, 0, trace, request);
  if (trace.deposition.any()) {
    memory_.deposited_since_blocked = true;
    memory_.idle_retreat_moves = 0;
    return BuildPhase::kRetreat;
  }
  // Advance again only once something changed (or after a long idle retreat): advancing onto the cell just left
  // without building would only block again.
  if (memory_.deposited_since_blocked || memory_.idle_retreat_moves >= modules_->max_idle_retreat_moves) {
    if (const auto motion = advance(local, path, robot)) {
      move(*motion, trace, request);
      deposit(local, frame, motion->target, motion->path_index, trace, request);
      return BuildPhase::kAdvance;
    }
    memory_.deposited_since_blocked = false;
  }
  // Step back the way the robot came and fill what comes into reach: the gap where it stood.
  ++memory_.idle_retreat_moves;
  // A scanning robot its map walls in (no navigable cell a body length away) asks the world the way it came first:
  // stepping back and forth on its island would never change its map.
  const bool walled = walled_in(local, robot);
  if (!walled) memory_.ask_back_anchor.reset();
  auto motion = walled ? ask_back(local, robot, true) : std::nullopt;
  if (!motion) motion = step_back(local, robot);
  if (!motion) motion = retrace(local, robot);
  if (!motion && !walled) motion = ask_back(local, robot, false);  // a walled-in robot asked it first already
  if (!motion) return BuildPhase::kRetreat;
  move(*motion, trace, request);
  deposit(local, frame, motion->target, 0, trace, request);
  if (trace.deposition.any()) {
    memory_.deposited_since_blocked = true;
    memory_.idle_retreat_moves = 0;
  }
  return BuildPhase::kRetreat;
}

std::optional<executive::Motion> RampSteps::step_back(const deliberative::LocalMap& local, Position robot) const {
  std::optional<CellIndex> anchor;
  if (local.origin && *local.origin != local.robot) anchor = local.origin;
  if (!anchor) anchor = oldest_navigable_trajectory_cell(local);
  if (!anchor) anchor = farthest_navigable_from_goal(local);
  if (!anchor) return std::nullopt;
  auto route = modules_->router.plan(local.gap, local.navigable, local.robot, *anchor);
  if (!route.found) {
    // The way back is cut (another robot stands on it): back off to the reachable cell farthest from the goal.
    const auto away = farthest_navigable_from_goal(local);
    if (!away || *away == *anchor) return std::nullopt;
    route = modules_->router.plan(local.gap, local.navigable, local.robot, *away);
    if (!route.found) return std::nullopt;
  }
  return advance(local, route.path, robot);
}

std::optional<executive::Motion> RampSteps::retrace(const deliberative::LocalMap& local, Position robot) const {
  if (!context_.type.sensor.casts_rays() || local.navigable.cast<long long>().sum() > 1) return std::nullopt;
  const CellIndex here = local.to_global(local.robot);
  const auto& trajectory = modules_->map.trajectory();
  for (auto it = trajectory.rbegin(); it != trajectory.rend(); ++it) {
    if (*it == here) continue;
    const CellIndex cell = local.to_local(*it);
    if (memory_.refused->contains(*it) || !local.contains(cell)) return std::nullopt;
    const Position target = local.center(cell);
    const double d = distance(target, robot);
    if (!(d <= context_.type.body.max_step_m + tolerance::kLengthM)) return std::nullopt;
    return executive::Motion{cell, target, 0, d};
  }
  return std::nullopt;
}

std::optional<executive::Motion> RampSteps::ask_ahead(const deliberative::LocalMap& local,
                                                      const std::vector<CellIndex>& path, Position robot) const {
  if (!context_.type.sensor.casts_rays() || path.size() < 2) return std::nullopt;
  const CellIndex next = path[1];
  if (!local.contains(next) || local.known(next.row, next.col) == 0) return std::nullopt;
  // The robot's map of the terrain holds the cell out (a neighbour's body is no question for the world), and the
  // world has not refused it on the map as it reads now.
  const CellMask& terrain = memory_.terrain_occupiable;
  if (terrain.rows() != local.rows() || terrain.cols() != local.cols() || terrain(next.row, next.col) != 0)
    return std::nullopt;
  if (memory_.refused->contains(local.to_global(next))) return std::nullopt;
  if (fails_a_told_drop(local, next)) return std::nullopt;
  const Position target = local.center(next);
  const double d = distance(target, robot);
  if (!(d <= context_.type.body.max_step_m + tolerance::kLengthM) || !executive::clear_of(memory_.others, robot, target))
    return std::nullopt;
  return executive::Motion{next, target, 1, d};
}

bool RampSteps::walled_in(const deliberative::LocalMap& local, Position robot) const {
  if (!context_.type.sensor.casts_rays()) return false;
  const double far_m = context_.type.body.navigability.delta_m;
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (local.navigable(r, c) != 0 && distance(local.center({r, c}), robot) >= far_m) return false;
  return true;
}

std::optional<executive::Motion> RampSteps::ask_back(const deliberative::LocalMap& local, Position robot,
                                                     bool walled) {
  if (!context_.type.sensor.casts_rays()) return std::nullopt;
  // Where the robot came from: the latest cell of its trajectory a body length away and no nearer its goal, known on
  // its map.
  const double far_m = context_.type.body.navigability.delta_m;
  const Position goal = local.center(local.goal);
  const double here_m = distance(robot, goal);
  const auto& trajectory = modules_->map.trajectory();
  std::optional<CellIndex> anchor;
  // The one it headed for while walled in, while in the window, known and not reached: a step within the island would
  // otherwise turn it to another cell of its trajectory, and it would shuttle between two.
  if (memory_.ask_back_anchor) {
    const CellIndex cell = local.to_local(*memory_.ask_back_anchor);
    if (local.contains(cell) && local.known(cell.row, cell.col) != 0 && cell != local.robot) anchor = cell;
  }
  for (auto it = trajectory.rbegin(); it != trajectory.rend() && !anchor; ++it) {
    const CellIndex cell = local.to_local(*it);
    if (!local.contains(cell) || local.known(cell.row, cell.col) == 0) break;
    const Position at = local.center(cell);
    if (distance(at, robot) >= far_m && distance(at, goal) >= here_m) anchor = cell;
  }
  if (!anchor) return std::nullopt;
  if (walled) memory_.ask_back_anchor = local.to_global(*anchor);
  // Around what the world has answered already: it would refuse those cells again.
  CellMask open = local.known;
  hold_out_told_drops(local, open);
  for (const CellIndex g : memory_.refused->cells())
    if (const CellIndex p = local.to_local(g); local.contains(p)) open(p.row, p.col) = 0;
  open(local.robot.row, local.robot.col) = 1;
  const auto route = modules_->router.plan(local.gap, open, local.robot, *anchor);
  if (!route.found || route.path.size() < 2) return std::nullopt;
  if (const auto motion = advance(local, route.path, robot)) return motion;
  return ask_ahead(local, route.path, robot);
}

std::optional<executive::Motion> RampSteps::step_away(const deliberative::LocalMap& local, Position robot,
                                                      Position from) const {
  const double near = 2.0 * context_.type.body.navigability.delta_m;
  constexpr double kNone = std::numeric_limits<double>::infinity();
  const auto away = best_navigable_cell(local, -distance(robot, from) - 1e-9, [&](Position p) {
    return distance(p, robot) <= near ? -distance(p, from) : kNone;
  });
  if (!away) return std::nullopt;
  const auto route = modules_->router.plan(local.gap, local.navigable, local.robot, *away);
  if (!route.found) return std::nullopt;
  return advance(local, route.path, robot);
}

bool RampSteps::keep_out_of(deliberative::LocalMap& local, Position robot, const std::vector<Lane>& lanes) {
  if (lanes.empty()) return false;
  // Lane::contains() holds only for centres in Lane::box(): each lane tests the cells centred in it.
  CellMask in_lane = CellMask::Zero(local.rows(), local.cols());
  for (const Lane& lane : lanes) {
    const CellRect cells = cells_centred_in(local.geometry(), lane.box());
    for (int r = cells.first.row; r < cells.first.row + cells.rows; ++r)
      for (int c = cells.first.col; c < cells.first.col + cells.cols; ++c)
        if (in_lane(r, c) == 0 && local.occupiable(r, c) != 0 && CellIndex{r, c} != local.robot &&
            lane.contains(local.center({r, c})))
          in_lane(r, c) = 1;
  }
  for (int r = 0; r < local.rows(); ++r)
    for (int c = 0; c < local.cols(); ++c)
      if (in_lane(r, c) != 0) local.occupiable(r, c) = 0;
  local.navigable = NavigabilityProcessor::navigable_from(local.occupiable, local.robot);
  return in_any(lanes, robot);
}

std::optional<executive::Motion> RampSteps::leave_lanes(const deliberative::LocalMap& local, Position robot,
                                                        const std::vector<Lane>& lanes) const {
  // Breadth first through navigable cells: the first outside every lane is the nearest by route.
  std::vector<CellIndex> queue{local.robot};
  CellMask seen = CellMask::Zero(local.rows(), local.cols());
  seen(local.robot.row, local.robot.col) = 1;
  for (std::size_t i = 0; i < queue.size(); ++i) {
    const CellIndex at = queue[i];
    const Position p = local.center(at);
    if (i > 0 && !in_any(lanes, p)) {
      const auto route = modules_->router.plan(local.gap, local.navigable, local.robot, at);
      return route.found ? advance(local, route.path, robot) : std::nullopt;
    }
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const CellIndex next{at.row + dr, at.col + dc};
        if (!local.contains(next) || local.navigable(next.row, next.col) == 0 || seen(next.row, next.col) != 0) continue;
        seen(next.row, next.col) = 1;
        queue.push_back(next);
      }
  }
  return std::nullopt;
}

std::optional<std::string> RampSteps::right_of_way_step(const RightOfWay& protocol, deliberative::LocalMap& local,
                                                        Position robot, bool at_goal, const std::string& close_by,
                                                        BuildTrace& trace, protocol::ActionRequest& request,
                                                        bool keep_lanes) {
  const RobotBody& body = context_.type.body;
  const std::vector<Lane> lanes =
      keep_lanes ? protocol.lanes(3.0 * body.navigability.delta_m, 0.5 * body.navigability.delta_m + body.max_step_m)
                 : std::vector<Lane>{};
  const bool in_lane = in_any(lanes, robot);
  if (!in_lane) keep_out_of(local, robot, lanes);
  std::string what;
  if (in_lane) {
    if (const auto out = leave_lanes(local, robot, lanes)) move(*out, trace, request);
    what = "leaving a lower id's lane";
  } else if (const auto from = protocol.giving_way()) {
    if (const auto motion = step_away(local, robot, *from)) move(*motion, trace, request);
    what = "giving way";
  } else if (at_goal) {
    return std::nullopt;
  } else if (protocol.standing_aside()) {
    what = "standing aside until the robot given way to has passed";
  } else if (protocol.holding()) {
    what = fmt::format("holding still, no way for {} steps", kStuckFrames);
  } else {
    return std::nullopt;
  }
  return close_by.empty() ? fmt::format("right of way: {}", what)
                          : fmt::format("right of way: {}; robots {} close by", what, close_by);
}

std::optional<CellIndex> RampSteps::farthest_navigable_from_goal(const deliberative::LocalMap& local) {
  const Position goal = local.center(local.goal);
  return best_navigable_cell(local, -distance(local.center(local.robot), goal),
                             [&](Position p) { return -distance(p, goal); });
}

std::optional<CellIndex> RampSteps::oldest_navigable_trajectory_cell(const deliberative::LocalMap& local) const {
  for (const CellIndex global : modules_->map.trajectory()) {
    const CellIndex p = local.to_local(global);
    if (local.contains(p) && p != local.robot && local.navigable(p.row, p.col) != 0) return p;
  }
  return std::nullopt;
}

bool RampSteps::return_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, BuildTrace& trace,
                            protocol::ActionRequest& request) {
  const Position robot{frame.x_m, frame.y_m};
  const Position base = context_.assignment.base;
  const double radius = context_.assignment.base_radius_m - kBaseMarginM;
  if (distance(robot, base) <= radius) {
    refilled(trace, request);
    return true;
  }
  // A robot that has got no nearer the base for as many steps as it takes to cross its window twice takes the way
  // home over its own map and keeps it for the rest of the trip: the nearest cell of a window that moves with the
  // robot can lie one way from here and the other way from the next cell, and a robot that follows it oscillates.
  const double to_base_m = distance(robot, base);
  if (to_base_m < memory_.return_nearest_m - 1e-9)
    memory_.return_nearest_m = to_base_m, memory_.return_no_nearer = 0;
  else
    ++memory_.return_no_nearer;
  const RobotBody& body = context_.type.body;
  const int patience_steps = static_cast<int>(std::ceil(4.0 * body.sensing_range_m / body.max_step_m));
  const bool patience_out = memory_.return_no_nearer >= patience_steps;
  // Where to go: the navigable cell within the base radius nearest the robot; else, once this trip has taken the way
  // home (below), along it; else the navigable cell nearest the base when that is nearer than the robot by at least a
  // cell; else (the window holds no way nearer: a pocket whose exit lies beyond it) the way home over the robot's own
  // map, kept for the rest of the trip (heading for the nearest cell again would lead back into the pocket); else the
  // oldest navigable cell of the trajectory in the window (the way the robot came from the base).
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::optional<CellIndex> goal = best_navigable_cell(
      local, kNone, [&](Position p) { return distance(p, base) <= radius ? distance(p, robot) : kNone; });
  if (!goal && (!memory_.home.empty() || patience_out)) goal = home_goal(local), trace.home_route = goal.has_value();
  if (!goal)
    goal = best_navigable_cell(local, distance(robot, base) - local.geometry().cell_size_m,
                               [&](Position p) { return distance(p, base); });
  if (!goal) goal = home_goal(local), trace.home_route = goal.has_value();
  if (!goal) goal = oldest_navigable_trajectory_cell(local);
  if (!goal) return false;
  trace.plan = modules_->router.plan(local.gap, local.navigable, local.robot, *goal);
  trace.planned = true;
  if (!trace.plan.found) return false;
  // In its lane; when the lane gives no motion, along the route itself: near a corridor's edge the lane's first cell
  // can lie two cells off, across a cell the robot cannot enter, and a robot that waits for it waits for ever.
  auto motion = advance(local, in_lane(local, trace.plan.path), robot);
  if (!motion) motion = advance(local, trace.plan.path, robot);
  if (motion) {
    move(*motion, trace, request);
    if (distance(motion->target, base) <= radius) {
      refilled(trace, request);
      return true;
    }
  }
  return false;
}

void RampSteps::refilled(BuildTrace& trace, protocol::ActionRequest& request) {
  request.refill = trace.refill = true;
  memory_.home.clear();
  memory_.return_nearest_m = std::numeric_limits<double>::infinity();
  memory_.return_no_nearer = 0;
}

std::optional<CellIndex> RampSteps::home_goal(const deliberative::LocalMap& local) {
  const CellIndex at = local.to_global(local.robot);
  const bool on_route = std::any_of(memory_.home.begin(), memory_.home.end(), [&](CellIndex g) {
    return std::abs(g.row - at.row) <= 1 && std::abs(g.col - at.col) <= 1;
  });
  if (!on_route) {  // also when the trip has no way home yet
    const RobotBody& body = context_.type.body;
    const auto route = deliberative::home_route(modules_->map.known_map(), body.navigability, at,
                                                context_.assignment.base,
                                                context_.assignment.base_radius_m - kBaseMarginM, body.sensing_range_m);
    memory_.home = route.value_or(std::vector<CellIndex>{});
  }
  for (auto it = memory_.home.rbegin(); it != memory_.home.rend(); ++it) {
    const CellIndex p = local.to_local(*it);
    if (local.contains(p) && p != local.robot && local.navigable(p.row, p.col) != 0) return p;
  }
  return std::nullopt;
}

}  // namespace marsala::agent::reactive
