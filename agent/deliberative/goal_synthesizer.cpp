#include "agent/deliberative/goal_synthesizer.hpp"

namespace marsala::agent::deliberative {

Position FixedTarget::target(const bus::Admission& admission, Position /*robot*/) const {
  return {admission.target_x_m, admission.target_y_m};
}

GoalSynthesizerRegistry make_goal_synthesizer_registry() { return GoalSynthesizerRegistry("goal synthesizer"); }

void register_builtins(GoalSynthesizerRegistry& registry) {
  registry.add("fixed_target", [] { return std::make_unique<FixedTarget>(); });
}

std::unique_ptr<GoalSynthesizer> make_goal_synthesizer(const std::string& name) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  register_builtins(registry);
  return registry.make(name);
}

}  // namespace marsala::agent::deliberative
