#pragma once
// Goal synthesizer (paper §III-A): compiles the target location a robot builds towards from its state. Variants
// are chosen by name from a registry filled by register_builtins():
//   "fixed_target"     the scenario's target for this agent (from its admission), wherever the robot is;
//   "goal_vector_map"  site preparation (paper §V-B, Fig. 6): the robot goes to the nearest free arrow tail of the
//                      scenario's goal vector map and builds towards its head, then follows the arrows of its strip.
// A synthesizer may keep state between frames (the arrow it is on); target() is called once per frame.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/deliberative/known_map.hpp"
#include "marsala/core/goal_vector_map.hpp"
#include "marsala/core/registry.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::deliberative {

/// What a goal synthesizer sees in one frame.
struct GoalQuery {
  Position robot;                     ///< where the robot stands [m]
  std::vector<Neighbour> neighbours;  ///< robots within proximity range (from the frame)
  /// Site preparation: 1 where the robot's map shows a cell of the given rectangle of world cells not yet level, on
  /// a mask of its size (unlevel_cells()). Asked only once the robot has finished every arrow; empty: never asked.
  std::function<CellMask(const CellRect&)> unlevel;
};

/// The cells of `area` (world cell indices) that `map` shows not level for `level`: not occupiable (paper eq. 1) on
/// the map cut to the area, as the world judges a site (docs/runtime.md#level_site), where every cell within
/// delta/2 is known from a sensor reading (not unknown, not assumed ground). A mask of area.rows x area.cols; throws
/// InvalidArgument when the area is empty or leaves the map's grid.
CellMask unlevel_cells(const KnownMap& map, const CellRect& area, const NavigabilityParams& level);

/// Picks the target location [m] for the robot's current state.
class GoalSynthesizer {
 public:
  virtual ~GoalSynthesizer() = default;
  /// The registry name of this variant.
  virtual std::string name() const = 0;
  /// The target [m] for this frame, or nullopt when there is nothing left to build towards (the robot is done).
  virtual std::optional<Position> target(const GoalQuery& query) = 0;
};

/// The admission's target_x/y, wherever the robot is.
class FixedTarget final : public GoalSynthesizer {
 public:
  explicit FixedTarget(const AgentContext& context) : target_{context.assignment.target} {}
  std::string name() const override { return "fixed_target"; }
  std::optional<Position> target(const GoalQuery& query) override;

 private:
  Position target_;
};

/// Site preparation: arrows of a goal vector map.
///   no arrow yet     -> the nearest free tail: among arrows this robot has not finished, the one whose tail is
///                       nearest the robot, skipping tails that a neighbour stands nearer to (it takes that one;
///                       ties to the lower agent id); target = that tail until the robot stands on its cell
///   on the tail cell -> target = the arrow's head
///   on the head cell -> the arrow is finished; the next arrow of the strip continues (target its head at once),
///                       else the nearest free tail again
///   all finished     -> the arrows whose stretch holds a cell the robot's map shows not level (query.unlevel) are
///                       open again (once per frame), and the nearest free tail is picked; when none is, nullopt
/// "Stands on" means the robot's position is within half a cell (Chebyshev, in metres) of the point.
class GoalVectorMapSynthesizer final : public GoalSynthesizer {
 public:
  /// Compiles the map on the admission's grid; throws InvalidArgument when the context has no goal vector map
  /// specification or the map does not fit the grid.
  explicit GoalVectorMapSynthesizer(const AgentContext& context);
  std::string name() const override { return "goal_vector_map"; }
  std::optional<Position> target(const GoalQuery& query) override;

  const GoalVectorMap& map() const { return map_; }
  /// The arrow it is on, if any (index into map().arrows()).
  std::optional<std::size_t> current_arrow() const { return current_; }
  /// True while it heads for the current arrow's tail (false: for its head).
  bool heading_for_tail() const { return to_tail_; }
  /// Arrows this robot has finished.
  const std::vector<bool>& finished() const { return finished_; }
  /// How many times finished arrows were opened again for ground still not level.
  int reopenings() const { return reopenings_; }

 private:
  std::uint32_t self_id_;
  GridGeometry map_grid_;
  GoalVectorMap map_;
  CellRect area_cells_;  ///< the world cells whose centres lie in the map's rectangle
  std::optional<std::size_t> current_;
  bool to_tail_ = true;
  std::vector<bool> finished_;
  int reopenings_ = 0;

  // Opens the finished arrows whose stretch holds a cell query.unlevel shows; true when it opened any.
  bool reopen_unlevel(const GoalQuery& query);
};

/// Goal synthesizers by name; each is made from the admitted agent's context.
using GoalSynthesizerRegistry = Registry<GoalSynthesizer, const AgentContext&>;

/// An empty registry whose messages speak of goal synthesizers.
GoalSynthesizerRegistry make_goal_synthesizer_registry();
/// Registers the built-in goal synthesizers ("fixed_target", "goal_vector_map").
void register_builtins(GoalSynthesizerRegistry& registry);
/// A built-in goal synthesizer by name for an admitted context; throws InvalidArgument listing the valid names when
/// unknown, or what the variant needs when the context lacks it.
std::unique_ptr<GoalSynthesizer> make_goal_synthesizer(const std::string& name, const AgentContext& context);
/// Throws InvalidArgument listing the valid names unless `name` is a built-in goal synthesizer (a check before
/// admission, when the variant cannot be made yet).
void require_goal_synthesizer(const std::string& name);

}  // namespace marsala::agent::deliberative
