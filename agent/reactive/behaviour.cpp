#include "marsala/agent/reactive/behaviour.hpp"

#include <cmath>
#include <string>

#include "marsala/agent/reactive/idle_behaviour.hpp"
#include "marsala/agent/reactive/noisy_localisation.hpp"
#include "marsala/agent/reactive/path_builder.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala::agent::reactive {

BehaviourRegistry make_behaviour_registry() { return BehaviourRegistry("behaviour"); }

void register_builtins(BehaviourRegistry& registry) {
  registry.add("idle", [](const AgentContext& c) { return std::make_unique<IdleBehaviour>(c); });
  registry.add("ramp_builder", [](const AgentContext& c) { return std::make_unique<RampBuilder>(c); });
  registry.add("path_builder", [](const AgentContext& c) { return std::make_unique<PathBuilder>(c); });
}

std::unique_ptr<Behaviour> make_behaviour(const std::string& name, const AgentContext& context) {
  BehaviourRegistry registry = make_behaviour_registry();
  register_builtins(registry);
  return registry.make(name, context);
}

std::unique_ptr<Behaviour> make_robot_behaviour(const AgentContext& context) {
  if (context.type.localisation.noise_sd_m > 0.0)
    return std::make_unique<NoisyLocalisation>(context, context.type.behaviour);
  return make_behaviour(context.type.behaviour, context);
}

protocol::ActionRequest empty_request(const AgentContext& context, const protocol::SensorFrame& frame,
                                      const std::string& state) {
  protocol::ActionRequest request;
  request.agent_id = context.agent_id;
  request.session = context.session;
  request.step = frame.step;
  request.state = state;
  return request;
}

Assignment assignment_from(const AgentContext& context, const protocol::Admission& admission) {
  if (admission.agent_id != context.agent_id || admission.session != context.session || !admission.accepted)
    throw InvalidArgument(fmt::format("admission for agent {} (session {}{}) does not admit agent {} (session {})",
                                      admission.agent_id, admission.session, admission.accepted ? "" : ", refused",
                                      context.agent_id, context.session));
  if (const std::string problem = assignment_problem(admission.assignment); !problem.empty())
    throw InvalidArgument(fmt::format("admission: {}", problem));
  return admission.assignment;
}

void check_frame(const AgentContext& context, const protocol::SensorFrame& frame) {
  if (frame.agent_id != context.agent_id)
    throw InvalidArgument(fmt::format("sensor frame for agent {} reached agent {}", frame.agent_id, context.agent_id));
}

}  // namespace marsala::agent::reactive
