#pragma once
// Goal synthesizer (paper §III-A): compiles the target location a robot builds towards from its state. Variants
// are chosen by name from a registry filled by register_builtins(); today "fixed_target" (the scenario's target
// for this agent, from its admission); goal vector maps (paper §V-B) come later.

#include <memory>
#include <string>
#include <vector>

#include "agent/detail/registry.hpp"
#include "common/bus/messages.hpp"
#include "common/types.hpp"

namespace marsala::agent::deliberative {

/// Picks the target location [m] for the robot's current state.
class GoalSynthesizer {
 public:
  virtual ~GoalSynthesizer() = default;
  /// The registry name of this variant.
  virtual std::string name() const = 0;
  /// The target [m] for a robot at `robot` [m] admitted with `admission`.
  virtual Position target(const bus::Admission& admission, Position robot) const = 0;
};

/// The admission's target_x/y, wherever the robot is.
class FixedTarget final : public GoalSynthesizer {
 public:
  std::string name() const override { return "fixed_target"; }
  Position target(const bus::Admission& admission, Position robot) const override;
};

/// Goal synthesizers by name.
using GoalSynthesizerRegistry = detail::Registry<GoalSynthesizer>;

/// An empty registry whose messages speak of goal synthesizers.
GoalSynthesizerRegistry make_goal_synthesizer_registry();
/// Registers the built-in goal synthesizers ("fixed_target").
void register_builtins(GoalSynthesizerRegistry& registry);
/// A built-in goal synthesizer by name; throws InvalidArgument listing the valid names when unknown.
std::unique_ptr<GoalSynthesizer> make_goal_synthesizer(const std::string& name);

}  // namespace marsala::agent::deliberative
