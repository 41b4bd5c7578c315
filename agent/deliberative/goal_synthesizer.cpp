#include "marsala/agent/deliberative/goal_synthesizer.hpp"

#include <cmath>
#include <string>

#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::agent::deliberative {

std::optional<Position> FixedTarget::target(const GoalQuery& /*query*/) { return target_; }

GoalVectorMapSynthesizer::GoalVectorMapSynthesizer(const AgentContext& context)
    : self_id_(context.agent_id),
      map_grid_(context.assignment.world),
      map_(context.goal_vector_map ? *context.goal_vector_map
                                   : throw InvalidArgument("goal synthesizer 'goal_vector_map' needs the "
                                                           "scenario's goal_vector_map block"),
           context.assignment.world),
      area_cells_(cells_centred_in(context.assignment.world, map_.spec().area)),
      finished_(map_.arrows().size(), false) {}

namespace {

double distance2(Position a, Position b) {
  const double dx = a.x - b.x;
  const double dy = a.y - b.y;
  return dx * dx + dy * dy;
}

// Within half a cell (Chebyshev) of p; the tolerance keeps a robot placed on a cell centre from missing it by a
// rounding error.
bool stands_on(Position robot, Position p, double cell_size_m) {
  const double half = 0.5 * cell_size_m + 1e-9;
  return std::abs(robot.x - p.x) <= half && std::abs(robot.y - p.y) <= half;
}

// A neighbour stands nearer to `tail` than the robot does (an equal distance counts when its id is lower): that
// neighbour takes the tail.
bool neighbour_takes(Position tail, const GoalQuery& query, std::uint32_t self_id) {
  const double mine = distance2(query.robot, tail);
  for (const Neighbour& n : query.neighbours) {
    if (n.agent_id == self_id) continue;
    const double theirs = distance2(n.position, tail);
    if (theirs < mine || (theirs == mine && n.agent_id < self_id)) return true;
  }
  return false;
}

// The nearest unfinished tail that no neighbour takes. When neighbours take every unfinished tail the robot still
// has work, so it takes the nearest unfinished one rather than stopping. nullopt when every arrow is finished.
std::optional<std::size_t> pick_tail(const GoalVectorMap& map, const std::vector<bool>& finished,
                                     const GoalQuery& query, std::uint32_t self_id) {
  std::vector<bool> excluded = finished;
  for (std::size_t i = 0; i < excluded.size(); ++i)
    if (!excluded[i] && neighbour_takes(map.arrows()[i].tail, query, self_id)) excluded[i] = true;
  if (const std::optional<std::size_t> free = map.nearest_free_tail(query.robot, excluded)) return free;
  return map.nearest_free_tail(query.robot, finished);
}

}  // namespace

std::optional<Position> GoalVectorMapSynthesizer::target(const GoalQuery& query) {
  if (!std::isfinite(query.robot.x) || !std::isfinite(query.robot.y))
    throw InvalidArgument(
        fmt::format("goal synthesizer 'goal_vector_map' of agent {}: the robot's position {} is not finite", self_id_,
                    query.robot));
  const std::vector<GoalArrow>& arrows = map_.arrows();
  bool reopened = false;
  // Every pass returns, reaches a tail (once per pick) or finishes an arrow, so the loop ends.
  for (;;) {
    // A tail still ahead is given up as soon as a neighbour stands nearer to it, with the same rule that picks
    // tails: two robots that see each other never head for the same tail.
    if (!current_ || (to_tail_ && !stands_on(query.robot, arrows[*current_].tail, map_grid_.cell_size_m) &&
                      neighbour_takes(arrows[*current_].tail, query, self_id_))) {
      current_ = pick_tail(map_, finished_, query, self_id_);
      to_tail_ = true;
      if (!current_ && !reopened && reopen_unlevel(query)) {
        reopened = true;  // at most once a frame, so the loop ends even when the robot stands on such an arrow
        current_ = pick_tail(map_, finished_, query, self_id_);
      }
      if (!current_) return std::nullopt;
    }
    const GoalArrow& arrow = arrows[*current_];
    if (to_tail_) {
      if (!stands_on(query.robot, arrow.tail, map_grid_.cell_size_m)) return arrow.tail;
      to_tail_ = false;
    }
    if (!stands_on(query.robot, arrow.head, map_grid_.cell_size_m)) return arrow.head;
    finished_[*current_] = true;
    const std::optional<std::size_t> next = map_.next(*current_);
    if (next && !finished_[*next]) {
      current_ = next;  // its tail is where the robot stands
      to_tail_ = false;
    } else {
      current_.reset();
    }
  }
}

bool GoalVectorMapSynthesizer::reopen_unlevel(const GoalQuery& query) {
  if (!query.unlevel || area_cells_.empty()) return false;
  const CellMask unlevel = query.unlevel(area_cells_);
  if (unlevel.rows() != area_cells_.rows || unlevel.cols() != area_cells_.cols)
    throw InvalidArgument(fmt::format("goal synthesizer 'goal_vector_map' of agent {}: the unlevel mask is {} x {}, "
                                      "the map's area {} x {} cells",
                                      self_id_, unlevel.rows(), unlevel.cols(), area_cells_.rows, area_cells_.cols));
  const GridGeometry& grid = map_grid_;
  bool any = false;
  for (int r = 0; r < area_cells_.rows; ++r)
    for (int c = 0; c < area_cells_.cols; ++c) {
      if (unlevel(r, c) == 0) continue;
      const Position centre = grid.cell_center({area_cells_.first.row + r, area_cells_.first.col + c});
      const std::optional<std::size_t> arrow = map_.arrow_at(centre);
      if (arrow && finished_[*arrow]) {
        finished_[*arrow] = false;
        any = true;
      }
    }
  if (any) ++reopenings_;
  return any;
}

CellMask unlevel_cells(const KnownMap& map, const CellRect& area, const NavigabilityParams& level) {
  const GridGeometry& grid = map.geometry();
  if (area.empty() || !grid.contains(area.first) ||
      !grid.contains({area.first.row + area.rows - 1, area.first.col + area.cols - 1}))
    throw InvalidArgument(fmt::format("unlevel cells: the area of {} x {} cells from {} is empty or leaves the "
                                      "{} x {} grid",
                                      area.rows, area.cols, area.first, grid.rows, grid.cols));
  const Heightmap cut = map.heights.window(area.first, area.rows, area.cols);
  const CellMask occupiable = NavigabilityProcessor(level).occupiable(cut);
  // Cells whose ball holds a guess (unknown, or assumed ground) are not judged.
  const CellMask read = (map.known.block(area.first.row, area.first.col, area.rows, area.cols).array() != 0 &&
                         map.assumed.block(area.first.row, area.first.col, area.rows, area.cols).array() == 0)
                            .cast<std::uint8_t>();
  const CellMask blind = blind_cells(read, 0.5 * level.delta_m / grid.cell_size_m);
  return (blind.array() == 0 && occupiable.array() == 0).cast<std::uint8_t>();
}

GoalSynthesizerRegistry make_goal_synthesizer_registry() { return GoalSynthesizerRegistry("goal synthesizer"); }

void register_builtins(GoalSynthesizerRegistry& registry) {
  registry.add("fixed_target", [](const AgentContext& c) { return std::make_unique<FixedTarget>(c); });
  registry.add("goal_vector_map", [](const AgentContext& c) { return std::make_unique<GoalVectorMapSynthesizer>(c); });
}

std::unique_ptr<GoalSynthesizer> make_goal_synthesizer(const std::string& name, const AgentContext& context) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  register_builtins(registry);
  return registry.make(name, context);
}

void require_goal_synthesizer(const std::string& name) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  register_builtins(registry);
  registry.require(name);
}

}  // namespace marsala::agent::deliberative
