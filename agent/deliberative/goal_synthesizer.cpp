#include "agent/deliberative/goal_synthesizer.hpp"

#include "common/error.hpp"

namespace marsala::agent::deliberative {

std::optional<Position> FixedTarget::target(const GoalQuery& /*query*/) { return target_; }

GoalVectorMapSynthesizer::GoalVectorMapSynthesizer(const AgentContext& context)
    : self_id_(context.agent_id),
      cell_size_m_(world_geometry(context.admission).cell_size_m),
      map_(context.task.goal_vector_map ? *context.task.goal_vector_map
                                        : throw InvalidArgument("goal synthesizer 'goal_vector_map' needs the "
                                                                "scenario's goal_vector_map block"),
           world_geometry(context.admission)),
      finished_(map_.arrows().size(), false) {}

std::optional<Position> GoalVectorMapSynthesizer::target(const GoalQuery& /*query*/) {
  throw InvalidArgument("goal_vector_map: not built yet");
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

bool is_goal_synthesizer(const std::string& name) {
  GoalSynthesizerRegistry registry = make_goal_synthesizer_registry();
  register_builtins(registry);
  return registry.contains(name);
}

}  // namespace marsala::agent::deliberative
